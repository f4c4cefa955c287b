"""Leave-one-object-out evaluation of the kernel prior (the paper's category table, section VI).

Every graph is a query against all graphs of the other objects: all samplings of the held-out
object leave the database together. Measures, as in the paper: accuracy of the argmax (ties
count as failures) and the mean rank of the true category in the prior.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from tg_drake.kernels.database import ENTRIES
from tg_drake.kernels.library import VIEW_YAWS_DEG
from tg_drake.kernels.prior import N_NEIGHBOURS, category_priors, is_correct, true_category_rank
from tg_drake.types import CATEGORIES, source_objects


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
    ids = source_objects(object_ids)  # a scan-like version is its original's object
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
    same_object = source_objects(query_ids)[:, None] == source_objects(db_ids)[None, :]
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


def query_outcomes(k_hat_rows: np.ndarray, allowed: np.ndarray, db_categories, query_categories,
                   *, n_neighbours: int = N_NEIGHBOURS) -> tuple[np.ndarray, np.ndarray]:
    """Per query: (correct (Q,) bool, rank (Q,)) of the prior from one kernel row block
    (Q, G), comparing each query only with the database graphs `allowed` (Q, G) bool."""
    priors, _ = category_priors(np.where(allowed, k_hat_rows, -np.inf), db_categories,
                                n_neighbours=n_neighbours)
    truth = np.asarray(query_categories)
    return is_correct(priors, truth), true_category_rank(priors, truth)


@dataclass
class NestedResult:
    """Leave-one-object-out scores with the parameters chosen inside each fold."""

    score: Score  # over all queries; T is the T chosen most often.
    choices: dict  # held-out object → {"T": ..., "entries": ...} chosen without it.
    outcomes: dict  # (entries, T) → (correct (Q,), rank (Q,)) of the plain leave-one-out.


def nested_leave_one_object_out(k_hat_rows: np.ndarray, query_ids, query_categories, db_ids,
                                db_categories, entry_masks: dict, *, t_values=None,
                                n_neighbours: int = N_NEIGHBOURS) -> NestedResult:
    """Leave-one-object-out evaluation of outside queries, choosing T and the database entries
    by an inner leave-one-object-out on the other objects only.

    k_hat_rows: (T + 1, Q, G) normalised kernel rows of Q queries against G database graphs.
    entry_masks: name → (G,) bool, the database graphs each choice of entries compares with.
    t_values: the T to choose from (default all). For every held-out object o, its queries are
    scored with the (entries, T) that gives the best accuracy (then rank, then smallest T) on the
    queries of the other objects against a database without o and without the query's own
    object; o's graphs are never in the database of o's queries, nor of the inner choice.
    """
    q_ids, db_ids = source_objects(query_ids), source_objects(db_ids)
    q_cats = np.asarray(query_categories)
    t_values = list(range(k_hat_rows.shape[0])) if t_values is None else list(t_values)
    own = q_ids[:, None] == db_ids[None, :]
    objects = sorted(set(q_ids.tolist()))
    outcomes, inner = {}, {}
    for name, mask in entry_masks.items():
        allowed = np.asarray(mask, bool)[None, :] & ~own
        for t in t_values:
            outcomes[name, t] = query_outcomes(k_hat_rows[t], allowed, db_categories, q_cats,
                                               n_neighbours=n_neighbours)
            for o in objects:
                keep = q_ids != o
                a, r = query_outcomes(k_hat_rows[t][keep], allowed[keep] & (db_ids != o),
                                      db_categories, q_cats[keep], n_neighbours=n_neighbours)
                inner[o, name, t] = (float(a.mean()), float(r.mean()))
    order = {name: i for i, name in enumerate(entry_masks)}
    correct = np.zeros(q_ids.shape, bool)
    rank = np.zeros(q_ids.shape)
    choices = {}
    for o in objects:
        name, t = min(((n, t) for n in entry_masks for t in t_values),
                      key=lambda c: (-inner[o, c[0], c[1]][0], inner[o, c[0], c[1]][1], c[1],
                                     order[c[0]]))
        choices[o] = {"T": t, "entries": name}
        mine = q_ids == o
        correct[mine] = outcomes[name, t][0][mine]
        rank[mine] = outcomes[name, t][1][mine]
    ts = [c["T"] for c in choices.values()]
    mode = max(set(ts), key=lambda t: (ts.count(t), -t))
    return NestedResult(Score(float(correct.mean()), float(rank.mean()), mode), choices, outcomes)


def evaluate_members(db, queries, *, entries=None, t_values=None,
                     n_neighbours: int = N_NEIGHBOURS) -> NestedResult:
    """Nested leave-one-object-out of database graphs `queries` (indices into a
    `KernelDatabase`) used as queries: each is compared only with the graphs of other objects,
    and the choice of entries (default: all of `ENTRIES`) and T is made per held-out object on
    the other objects alone (`nested_leave_one_object_out`)."""
    queries = np.asarray(queries, dtype=np.int64)
    entries = ENTRIES if entries is None else entries
    return nested_leave_one_object_out(
        db.member_profile(queries), db.object_ids[queries], db.categories[queries],
        db.object_ids, db.categories, {e: db.entry_mask(e) for e in entries},
        t_values=t_values, n_neighbours=n_neighbours)


QUERY_YAWS_DEG = VIEW_YAWS_DEG  # yaws of the perceived queries of the evaluation (the
# database's perceived views, whose yaws the evaluation suites' do not share),
QUERY_VIEWPOINT = 0  # from the default scenario camera's viewpoint (library.VIEWPOINTS[0]).


def perceived_queries(db, *, viewpoint: int = QUERY_VIEWPOINT, yaws_deg=QUERY_YAWS_DEG
                      ) -> np.ndarray:
    """Indices of the database's perceived views that serve as the evaluation's queries (the
    S_REAL analogue): one viewpoint, a few yaws, every resting pose of every object."""
    return np.flatnonzero((db.sources == "perceived") & (db.viewpoints == viewpoint)
                          & np.isin(db.yaws, yaws_deg))
