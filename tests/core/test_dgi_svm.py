"""The RBF SVM with a Platt sigmoid (paper, section V-B), on synthetic data."""

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.exceptions import NotFittedError
from sklearn.model_selection import cross_val_score

from tg_drake.errors import GraspingError
from tg_drake.grasping.dgi import GRIPPER_BASE_Y, dgi_features
from tg_drake.grasping.svm import PlattSvmClassifier, fit_platt_sigmoid, platt_probability


def test_sigmoid_maps_decision_values_monotonically_into_the_open_unit_interval():
    # |A f + b| ≤ 30.5 here: beyond about 36 the probability rounds to 1.0 in double precision.
    f = np.linspace(-15.0, 15.0, 2001)
    for A, b in ((-2.0, 0.5), (-0.3, -1.0), (2.0, 0.5)):
        p = platt_probability(f, A, b)
        assert np.all((p > 0.0) & (p < 1.0))
        step = np.diff(p)
        # Increasing when A < 0, decreasing when A > 0 (the paper's own A = 2, b = 0.5).
        assert np.all(step > 0) if A < 0 else np.all(step < 0)
    assert platt_probability(-0.25, -2.0, -0.5) == pytest.approx(0.5)  # A f + b = 0
    assert np.isfinite(platt_probability(np.array([-1e6, 1e6]), -2.0, 0.5)).all()


def test_platt_fit_recovers_the_sigmoid_that_made_the_labels():
    rng = np.random.default_rng(0)
    f = rng.normal(scale=2.0, size=40000)
    y = (rng.random(f.size) < platt_probability(f, -1.5, 0.4)).astype(int)
    A, b = fit_platt_sigmoid(f, y)
    # ±0.05: the maximum-likelihood estimate from 40 000 Bernoulli draws has a standard error
    # of about 0.015 in A and 0.013 in b; Platt's target smoothing shifts it by < 1e-4.
    assert A == pytest.approx(-1.5, abs=0.05)
    assert b == pytest.approx(0.4, abs=0.05)
    with pytest.raises(GraspingError, match="labels must be 0 or 1"):
        fit_platt_sigmoid(f[:3], np.array([0, 1, 2]))


def shapes(rng, n):
    """Synthetic grasps: a cylinder that fits between the fingers (1) or a plate that is wider than
    the opening and so blocks the fingers (0), at random depths, with a little noise."""
    x = np.arange(-0.07, 0.07, 0.001)
    z = np.arange(-0.012, 0.012, 0.002)
    xx, zz = (a.ravel() for a in np.meshgrid(x, z, indexing="ij"))
    features, labels = [], []
    for i in range(n):
        label = i % 2
        depth = rng.uniform(0.005, 0.04)
        if label:
            r = rng.uniform(0.015, 0.045)
            keep = np.abs(xx) < r
            d = depth + r - np.sqrt(r**2 - xx[keep] ** 2)
            xs, zs = xx[keep], zz[keep]
        else:
            d = depth + 0.1 * rng.normal() * xx
            xs, zs = xx, zz
        p_G = np.stack([xs, GRIPPER_BASE_Y + d + rng.normal(scale=5e-4, size=d.size), zs], axis=1)
        features.append(dgi_features(p_G, np.eye(4))[0])
        labels.append(label)
    return np.array(features), np.array(labels)


@pytest.fixture(scope="module")
def data():
    return shapes(np.random.default_rng(1), 400)


@pytest.fixture(scope="module")
def fitted(data):
    X, y = data
    return PlattSvmClassifier(gamma=1.0, random_state=0).fit(X, y)


def test_classifier_separates_graspable_from_blocked_shapes(data):
    X, y = data
    scores = cross_val_score(PlattSvmClassifier(gamma=1.0, random_state=0), X, y, cv=4)
    # The two classes differ in whether the outer pixels are empty: nearly separable. 0.95 leaves
    # room for a few thin cylinders at large depths that look like plates.
    assert scores.mean() >= 0.95


def test_probabilities_agree_with_predictions_and_decisions(data, fitted):
    X, _ = data
    p = fitted.predict_proba(X)
    np.testing.assert_allclose(p.sum(axis=1), 1.0)
    np.testing.assert_array_equal(fitted.predict(X), (p[:, 1] >= 0.5).astype(int))
    # Success must become more likely as the SVM's margin grows.
    assert fitted.A_ < 0
    f = fitted.decision_function(X)
    order = np.argsort(f)
    assert np.all(np.diff(p[order, 1]) >= 0)
    # 1e-9: the matrix-product expansion and libSVM's loop differ only by rounding.
    np.testing.assert_allclose(f, fitted.svm_.decision_function(X), atol=1e-9)


def test_follows_the_scikit_learn_estimator_api(data):
    X, y = data
    est = PlattSvmClassifier(gamma=3.0, C=2.0, n_folds=3, random_state=5)
    assert est.get_params() == {"gamma": 3.0, "C": 2.0, "n_folds": 3, "random_state": 5}
    assert clone(est).set_params(gamma=7.0).gamma == 7.0
    with pytest.raises(NotFittedError):
        est.predict_proba(X)
    a = est.fit(X, y)
    b = clone(est).fit(X, y)
    assert (a.A_, a.b_) == (b.A_, b.b_)  # random_state makes the folds reproducible
    with pytest.raises(GraspingError, match="labels must be 0"):
        clone(est).fit(X, np.where(y == 1, 1, 2))
    with pytest.raises(ValueError, match="features"):
        a.predict_proba(X[:, :10])
