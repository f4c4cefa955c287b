"""Leave-one-object-out evaluation of the kernel prior (the paper's category table, section VI).

Every graph is a query against all graphs of the other objects: all samplings of the held-out
object leave the database together. Measures, as in the paper: accuracy of the argmax (ties
count as failures) and the mean rank of the true category in the prior.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from tg_drake.kernels.prior import N_NEIGHBOURS, category_priors, is_correct, true_category_rank
from tg_drake.types import CATEGORIES


@dataclass
class Score:
    accuracy: float  # share of queries whose prior's unique argmax is the true category (0–1).
    mean_rank: float  # mean rank of the true category (1 = best, ties share their mean rank).
    T: int | None  # diffusion iterations of K_T (None: not a kernel method).

    def as_dict(self) -> dict:
        return asdict(self)


def random_score(n_categories: int = len(CATEGORIES)) -> Score:
    """Random category assignment, in expectation: accuracy 1/11, mean rank (1 + 11)/2 = 6."""
    return Score(1.0 / n_categories, (1 + n_categories) / 2.0, None)


def score_priors(priors: np.ndarray, truth: np.ndarray, T: int | None) -> Score:
    return Score(float(np.mean(is_correct(priors, truth))),
                 float(np.mean(true_category_rank(priors, truth))), T)


def leave_one_object_out(k_hat: np.ndarray, object_ids, categories, *,
                         n_neighbours: int = N_NEIGHBOURS) -> list[Score]:
    """Scores for every T of a stack of normalised database kernels K̂ (T + 1, G, G)."""
    ids = np.asarray(object_ids)
    cats = np.asarray(categories)
    same_object = ids[:, None] == ids[None, :]
    scores = []
    for t, k in enumerate(k_hat):
        priors, _ = category_priors(np.where(same_object, -np.inf, k), cats,
                                    n_neighbours=n_neighbours)
        scores.append(score_priors(priors, cats, t))
    return scores


def query_scores(k_hat_rows: np.ndarray, query_ids, query_categories, db_ids, db_categories, *,
                 n_neighbours: int = N_NEIGHBOURS) -> list[Score]:
    """Scores of outside queries (e.g. perceived clouds) against a database, for every T.

    k_hat_rows: (T + 1, Q, G) normalised kernel rows; database graphs of the query's own object
    are left out.
    """
    same_object = np.asarray(query_ids)[:, None] == np.asarray(db_ids)[None, :]
    scores = []
    for t, k in enumerate(k_hat_rows):
        priors, _ = category_priors(np.where(same_object, -np.inf, k), db_categories,
                                    n_neighbours=n_neighbours)
        scores.append(score_priors(priors, np.asarray(query_categories), t))
    return scores


def best(scores: list[Score], *, by: str = "accuracy") -> Score:
    """The best T: highest accuracy (then lowest rank), or lowest rank (then highest accuracy);
    the smallest T among equals."""
    if by == "accuracy":
        return min(scores, key=lambda s: (-s.accuracy, s.mean_rank, s.T))
    return min(scores, key=lambda s: (s.mean_rank, -s.accuracy, s.T))
