"""The category prior from kernel similarities (paper section III-C) and its evaluation measures.

For a query G*, sort its row of K̂ against the database, keep the n = 10 most similar graphs and
average their categories with weights f(x) = exp(−x), x = 1..n the rank. The result is a
distribution over the 11 categories.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar

from tg_drake.errors import KernelError
from tg_drake.types import CATEGORIES

N_NEIGHBOURS = 10  # the paper's n.


def category_priors(similarities: np.ndarray, categories: np.ndarray, *,
                    n_neighbours: int = N_NEIGHBOURS, n_categories: int = len(CATEGORIES)
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Priors of many queries at once.

    similarities: (Q, G) normalised kernel rows against G database graphs; entries set to −inf
        are excluded (leave-one-out). categories: (G,) int category of each database graph.
    Returns (priors (Q, n_categories), neighbours (Q, n) database indices, most similar first).
    Ties in similarity keep database order.
    """
    s = np.atleast_2d(np.asarray(similarities, dtype=np.float64))
    cats = np.asarray(categories)
    if s.shape[1] != cats.shape[0]:
        raise KernelError(f"{s.shape[1]} similarities for {cats.shape[0]} database graphs")
    if n_neighbours < 1:
        raise KernelError(f"the number of neighbours n must be >= 1, got {n_neighbours}")
    available = np.isfinite(s).sum(axis=1)
    if np.any(available < 1):
        raise KernelError("no database graph left to compare with")
    n = min(n_neighbours, s.shape[1])
    neighbours = np.argsort(-s, axis=1, kind="stable")[:, :n]
    rank = np.arange(1, n + 1)
    weights = np.where(rank[None, :] <= available[:, None], np.exp(-rank)[None, :], 0.0)
    priors = np.zeros((s.shape[0], n_categories))
    np.add.at(priors, (np.arange(s.shape[0])[:, None], cats[neighbours]), weights)
    priors /= priors.sum(axis=1, keepdims=True)
    return priors, neighbours


def true_category_rank(priors: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """(Q,) rank of the true category in each prior (1 = most probable).

    Ties share the mean of the ranks they span (the eight categories no neighbour voted for all
    get rank 7.5 when three categories have votes), so a tie neither helps nor hurts.
    """
    p = np.atleast_2d(priors)
    mine = p[np.arange(p.shape[0]), truth][:, None]
    higher = np.sum(p > mine, axis=1)
    equal = np.sum(p == mine, axis=1)
    return higher + (equal + 1) / 2.0


def is_correct(priors: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """(Q,) bool: the argmax is the true category and no other category ties with it
    (the paper counts ties as failures)."""
    p = np.atleast_2d(priors)
    best = p.max(axis=1, keepdims=True)
    return (p[np.arange(p.shape[0]), truth] == best[:, 0]) & (np.sum(p == best, axis=1) == 1)


def fit_prior_floor(priors: np.ndarray, truth: np.ndarray) -> float:
    """ε in [0, 1] maximising Σ log((1 − ε)·p[i, truth[i]] + ε/K) over the rows of `priors`
    (N, K), each a kernel prior, `truth` (N,) the true category's index."""
    priors = np.asarray(priors, dtype=float)
    if priors.ndim != 2 or len(priors) == 0 or len(truth) != len(priors):
        raise ValueError("priors must be (N, K) with N ≥ 1 and one truth index per row")
    p_true = priors[np.arange(len(priors)), np.asarray(truth, dtype=int)]
    k = priors.shape[1]

    def nll(eps):
        return -np.mean(np.log((1.0 - eps) * p_true + eps / k))

    return float(minimize_scalar(nll, bounds=(0.0, 1.0), method="bounded",
                                 options={"xatol": 1e-4}).x)
