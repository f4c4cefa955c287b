"""The logic's fitted inputs: the kernel prior's floor and the dish-interior miss rate."""

from __future__ import annotations

import numpy as np
import pytest

from tg_drake.evaluation.calibration import dish_interior_miss
from tg_drake.kernels.prior import fit_prior_floor


@pytest.mark.parametrize("eps", [0.0, 0.1, 0.3, 0.6])
def test_the_floor_fitted_to_priors_drawn_with_it_is_recovered(eps):
    # A retrieval prior that names one category, right with probability q; the truth drawn from
    # the floored prior (1 − ε)·p + ε/K: the maximum-likelihood floor is ε.
    rng = np.random.default_rng(3)
    n, k = 20000, 11
    named = rng.integers(0, k, n)
    P = np.eye(k)[named]
    floored = (1 - eps) * P + eps / k
    truth = np.array([rng.choice(k, p=row) for row in floored])
    assert fit_prior_floor(P, truth) == pytest.approx(eps, abs=0.02)


def test_a_prior_always_right_needs_no_floor_and_a_bad_input_is_refused():
    P = np.eye(4)[[0, 1, 2, 3]]
    assert fit_prior_floor(P, np.arange(4)) < 1e-3
    with pytest.raises(ValueError, match="one truth index per row"):
        fit_prior_floor(P, np.arange(3))


def _record(category, pose, seen, setting="real"):
    return {"setting": setting, "truth": {"category": category}, "pose": pose,
            "observations": {"interior_seen": seen}}


def test_dish_interior_miss_counts_upright_dishes_only():
    records = ([_record("cup", "upright", 0.95)] * 7 + [_record("glass", "upright", 0.0)]
               + [_record("can", "upright", 0.0)] * 5 + [_record("bowl", "upsidedown", 0.0)]
               + [_record("cup", "upright", 0.0, setting="semi")])
    p, misses, views = dish_interior_miss(records)
    assert (misses, views) == (1, 8)
    assert p == pytest.approx(2 / 10)
