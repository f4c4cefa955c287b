"""RBF support vector machine with a Platt sigmoid: P(grasp | local shape) (paper, section V-B).

The SVM's decision value f(x) = Σ_i α_i y_i exp(−γ |x − x_i|²) + ρ is mapped onto a probability by
the parametric sigmoid (paper eq. 9)

    P(grasp | local shape) = 1 / (1 + exp(A f(x) + b)),

with A and b fitted by maximum likelihood (Platt 1999) on decision values of *held-out* folds: the
training set is split in `n_folds` stratified folds, an SVM trained on the other folds gives the
decision values of each fold, and the sigmoid is fitted to all of them. The final SVM is then
trained on the whole set. We fit the sigmoid ourselves rather than use `SVC(probability=True)`,
whose internal cross-validation is separate from its decision function, so that its probabilities
can disagree with its predictions; here `predict` is exactly `predict_proba(X)[:, 1] ≥ 0.5`.

Note the sign: with labels 1 = success, f grows with the success margin, so the fitted A is
negative. (The paper reports A = 2, b = 0.5, which implies the opposite sign convention for f.)
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize
from scipy.special import expit, log_expit
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.model_selection import StratifiedKFold
from sklearn.svm import SVC
from sklearn.utils.multiclass import unique_labels
from sklearn.utils.validation import check_is_fitted, check_X_y, validate_data

from tg_drake.errors import GraspingError


def platt_probability(f: np.ndarray, A: float, b: float) -> np.ndarray:
    """P = 1 / (1 + exp(A f + b)), computed without overflow for any f."""
    return expit(-(A * np.asarray(f, dtype=float) + b))


def fit_platt_sigmoid(f: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """A and b of the sigmoid fitted to decision values `f` and labels `y` ∈ {0, 1} (Platt 1999).

    Minimises the cross-entropy against Platt's regularised targets t₊ = (N₊ + 1) / (N₊ + 2) and
    t₋ = 1 / (N₋ + 2), which keep the fit finite on separable data.
    """
    f = np.asarray(f, dtype=float).ravel()
    y = np.asarray(y).ravel()
    if f.shape != y.shape or f.size == 0:
        raise GraspingError(f"decision values {f.shape} and labels {y.shape} must match, non-empty")
    n_pos = int(np.sum(y == 1))
    n_neg = int(np.sum(y == 0))
    if n_pos + n_neg != y.size:
        raise GraspingError(f"labels must be 0 or 1, got {sorted(set(y.tolist()))}")
    t = np.where(y == 1, (n_pos + 1.0) / (n_pos + 2.0), 1.0 / (n_neg + 2.0))

    def loss(params):
        A, b = params
        z = A * f + b  # P = expit(−z); log P = log_expit(−z), log(1 − P) = log_expit(z).
        value = -np.sum(t * log_expit(-z) + (1.0 - t) * log_expit(z))
        dz = expit(z) - (1.0 - t)  # d loss / d z, per sample.
        return value, np.array([np.sum(dz * f), np.sum(dz)])

    b0 = np.log((n_neg + 1.0) / (n_pos + 1.0))
    result = minimize(loss, np.array([0.0, b0]), jac=True, method="L-BFGS-B")
    if not np.all(np.isfinite(result.x)):
        raise GraspingError(f"Platt sigmoid fit did not converge: {result.message}")
    return float(result.x[0]), float(result.x[1])


class PlattSvmClassifier(ClassifierMixin, BaseEstimator):
    """RBF SVM whose decision value goes through a Platt sigmoid fitted on held-out folds.

    Parameters
    ----------
    gamma : RBF kernel width γ in exp(−γ |x − x'|²) (paper: 50 on its features).
    C : soft-margin penalty of the SVM.
    n_folds : stratified folds whose held-out decision values fit the sigmoid (paper: 4).
    random_state : seeds the fold shuffling.

    Learned attributes: `svm_` (the sklearn SVC on the whole training set), `A_`, `b_` (sigmoid),
    `classes_` (must be [0, 1]: 1 = successful grasp), `n_features_in_`.
    """

    def __init__(self, gamma: float = 50.0, C: float = 1.0, n_folds: int = 4,
                 random_state: int | None = None):
        self.gamma = gamma
        self.C = C
        self.n_folds = n_folds
        self.random_state = random_state

    def _svm(self) -> SVC:
        return SVC(kernel="rbf", gamma=self.gamma, C=self.C, cache_size=500)

    def fit(self, X, y):
        X, y = check_X_y(X, y, dtype=np.float64)
        self.n_features_in_ = X.shape[1]
        self.classes_ = unique_labels(y)
        if list(self.classes_) != [0, 1]:
            raise GraspingError(
                f"labels must be 0 (failed grasp) and 1 (successful grasp), both present; got "
                f"{list(self.classes_)}")
        if not (self.gamma > 0 and self.C > 0 and int(self.n_folds) >= 2):
            raise GraspingError(
                f"need gamma > 0, C > 0, n_folds ≥ 2; got {self.gamma}, {self.C}, {self.n_folds}")
        folds = StratifiedKFold(n_splits=int(self.n_folds), shuffle=True,
                                random_state=self.random_state)
        f_held_out = np.empty(len(y))
        for train, test in folds.split(X, y):
            f_held_out[test] = self._svm().fit(X[train], y[train]).decision_function(X[test])
        self.A_, self.b_ = fit_platt_sigmoid(f_held_out, y)
        self.svm_ = self._svm().fit(X, y)
        # The RBF expansion, kept for a vectorised decision function (see decision_function).
        self.support_vectors_ = self.svm_.support_vectors_
        self.dual_coef_ = self.svm_.dual_coef_.ravel()
        self.intercept_ = float(self.svm_.intercept_[0])
        self.support_sq_norms_ = np.einsum("ij,ij->i", self.support_vectors_, self.support_vectors_)
        return self

    def decision_function(self, X) -> np.ndarray:
        """f(x) = Σ_i dual_coef_i exp(−γ |x − sv_i|²) + intercept, for all rows at once.

        The same value as `svm_.decision_function` (libSVM, labels 0 < 1 so f > 0 favours 1),
        computed with one matrix product over all support vectors instead of libSVM's per-sample
        loop.
        """
        check_is_fitted(self)
        X = validate_data(self, X, dtype=np.float64, reset=False)
        sq = (np.einsum("ij,ij->i", X, X)[:, None] + self.support_sq_norms_[None, :]
              - 2.0 * X @ self.support_vectors_.T)
        np.maximum(sq, 0.0, out=sq)  # rounding can make a zero distance slightly negative.
        return np.exp(-self.gamma * sq) @ self.dual_coef_ + self.intercept_

    def predict_proba(self, X) -> np.ndarray:
        """(M, 2): columns P(failure), P(success | local shape)."""
        p = platt_probability(self.decision_function(X), self.A_, self.b_)
        return np.stack([1.0 - p, p], axis=1)

    def predict(self, X) -> np.ndarray:
        return (self.predict_proba(X)[:, 1] >= 0.5).astype(int)
