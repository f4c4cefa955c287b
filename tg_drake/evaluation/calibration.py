"""Fitted inputs of the logic, from perceived records of the split's training objects.

- `prior_floor_of`: the floor ε of the kernel prior as the logic sees it, (1 − ε)·p_kernel + ε/11,
  by maximum likelihood of the true category over the records' views (the shipped database
  carries its own, fitted on its graphs: `KernelDatabase.floor`; this checks it on a suite).
- `dish_interior_miss`: how often perception misses the inside of a dish standing upright
  (rules/category_specific.pl, `interior_hidden`), Laplace-smoothed.

    python tools/measure_perception.py --fit RECORDS.jsonl   # both, on the training side
"""

from __future__ import annotations

import numpy as np

from tg_drake.kernels.prior import fit_prior_floor
from tg_drake.types import CATEGORIES

DISHES = ("cup", "glass", "bowl")  # rules/object_ontology.pl: subclass(C, dish)
SEEN = 0.5  # interior_seen at least this: perception saw the inside


def dish_interior_miss(records: list[dict]) -> tuple[float, int, int]:
    """(P(inside unseen | dish upright), misses, views): Laplace-smoothed, (misses + 1) /
    (views + 2), over the S_REAL records of dishes standing upright."""
    views = [r for r in records if r.get("setting") == "real" and "observations" in r
             and r["truth"]["category"] in DISHES and r["pose"] == "upright"]
    misses = sum(r["observations"]["interior_seen"] < SEEN for r in views)
    return (misses + 1) / (len(views) + 2), misses, len(views)


def prior_floor_of(records: list[dict]) -> tuple[float, int]:
    """(`fit_prior_floor` over the S_REAL records' kernel priors, the number of views)."""
    rows = [r for r in records if r.get("setting") == "real" and r.get("priors")]
    if not rows:
        raise ValueError("no S_REAL records with a kernel prior")
    P = np.array([r["priors"]["manifolds"] for r in rows], dtype=float)
    y = np.array([CATEGORIES.index(r["truth"]["category"]) for r in rows])
    return fit_prior_floor(P, y), len(rows)
