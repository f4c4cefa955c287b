"""Label repeatability: the nudge, the stratified sample, and the ceiling from repeated labels."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tg_drake.errors import GraspingError
from tg_drake.grasping.dgi import PAD_CENTER_Y
from tg_drake.grasping.repeatability import (
    accuracy_ceiling,
    analyse,
    nudge,
    stratified_sample,
    stratum_weights,
)


def test_nudge_moves_the_grasp_point_and_turns_the_gripper_by_the_given_amounts():
    rng = np.random.default_rng(3)
    X = np.eye(4)
    X[:3, :3] = Rotation.from_euler("xyz", [0.3, -1.0, 2.0]).as_matrix()
    X[:3, 3] = [0.1, -0.2, 0.05]
    for _ in range(20):
        Y = nudge(X, rng, distance=0.001, angle=np.radians(1.0))
        R = Y[:3, :3]
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
        turn = Rotation.from_matrix(R @ X[:3, :3].T).magnitude()
        assert turn == pytest.approx(np.radians(1.0), abs=1e-9)
        point_X = X[:3, 3] + PAD_CENTER_Y * X[:3, 1]
        point_Y = Y[:3, 3] + PAD_CENTER_Y * Y[:3, 1]
        assert np.linalg.norm(point_Y - point_X) == pytest.approx(0.001, abs=1e-12)
    with pytest.raises(GraspingError, match="4×4"):
        nudge(np.eye(3), rng, distance=0.001, angle=0.01)


def test_ceiling_brackets_the_best_accuracy_of_coin_labels():
    assert accuracy_ceiling(1.0) == (1.0, 1.0)
    assert accuracy_ceiling(0.5) == (0.5, 0.5)
    # Grasps whose label is a coin with these p: the best classifier is right max(p, 1 − p).
    p = np.array([0.0, 0.05, 0.2, 0.5, 0.9, 1.0, 1.0])
    best = np.mean(np.maximum(p, 1 - p))
    lo, hi = accuracy_ceiling(float(np.mean(p**2 + (1 - p) ** 2)))
    assert lo <= best <= hi
    assert hi < 1.0
    with pytest.raises(GraspingError, match=r"\[0, 1\]"):
        accuracy_ceiling(1.2)


def record(job, index, obj, success, status="ok"):
    return {"job": job, "index": index, "object": obj, "success": success, "status": status}


def test_stratified_sample_and_weights_restore_the_data_mix():
    records = ([record("a", i, "x", True) for i in range(10)]
               + [record("b", i, "x", False) for i in range(2)]
               + [record("c", 0, "x", False, status="sim_error")])

    def stratum(r):
        return (r["object"], r["success"])

    sample = stratified_sample(records, 3, np.random.default_rng(0), stratum)
    assert len(sample) == 5  # 3 of 10 successes, both failures; the sim error is never drawn.
    assert sum(r["success"] for r in sample) == 3
    weights = stratum_weights(records, sample, stratum)
    assert weights[("b", 0)] == 1.0
    assert {weights[(r["job"], r["index"])] for r in sample if r["success"]} == {10 / 3}
    with pytest.raises(GraspingError, match="per_stratum"):
        stratified_sample(records, 0, np.random.default_rng(0), stratum)


def rerun(job, index, original, trial, success, *, gap=0.03, table=False):
    return {"source_job": job, "source_index": index, "original_success": original,
            "trial": trial, "status": "ok", "success": success, "finger_gap": gap,
            "touches_table": table, "kind": "box"}


def test_analyse_counts_repeats_flips_and_weights():
    rows = [
        # grasp 1: a success that repeats exactly and under both nudges.
        rerun("s", 1, True, "exact", True), rerun("s", 1, True, "nudge0", True),
        rerun("s", 1, True, "nudge1", True),
        # grasp 2: a success lost under one nudge, the fingers still on it on the table.
        rerun("s", 2, True, "exact", True), rerun("s", 2, True, "nudge0", False, table=True),
        rerun("s", 2, True, "nudge1", True),
        # grasp 3: a failure that held once nudged; one episode failed in physics.
        rerun("s", 3, False, "exact", False), rerun("s", 3, False, "nudge0", True),
        {"source_job": "s", "source_index": 3, "trial": "nudge1", "status": "sim_error"},
    ]
    result = analyse(rows, groups=lambda r: [f"kind/{r['kind']}"])
    assert result["n_grasps"] == 3
    assert result["n_sim_error"] == 1
    assert result["exact_repeat_rate"] == 1.0
    assert result["nudged_agreement"] == pytest.approx(3 / 5)
    assert result["nudged_all_agree"] == pytest.approx(1 / 3)
    assert result["by_group"] == {"kind/box": {"n": 5, "nudged_agreement": pytest.approx(0.6)}}
    assert result["flips"] == {"failure became success": 1,
                               "success became failure: closed on it, still on the table": 1}
    # Weighting grasp 1 up: its two agreeing nudges count 4 times each.
    weighted = analyse(rows, groups=lambda r: [], weights={("s", 1): 4.0})
    assert weighted["nudged_agreement"] == pytest.approx((8 + 1 + 0) / (8 + 2 + 1))
    assert weighted["nudged_agreement_sample"] == pytest.approx(3 / 5)
    lo, hi = weighted["accuracy_ceiling_interval"]
    assert lo == pytest.approx(weighted["nudged_agreement"]) and hi > lo
    with pytest.raises(GraspingError, match="nothing to analyse"):
        analyse(rows[:1], groups=lambda r: [])
    # Against the exact re-execution instead of the recorded label: grasp 2's exact run failing
    # makes its two nudges compare with failure (one agrees), the recorded label no longer counts.
    changed = [dict(r, success=False) if (r["source_index"], r["trial"]) == (2, "exact") else r
               for r in rows]
    assert analyse(changed, groups=lambda r: [])["nudged_agreement"] == pytest.approx(3 / 5)
    exact = analyse(changed, groups=lambda r: [], reference="exact")
    assert exact["nudged_agreement"] == pytest.approx((2 + 1 + 0) / 5)
    assert exact["exact_repeat_rate"] == pytest.approx(2 / 3)
    # Grasp 3 held the first time too, and its nudge held: a flip of the finger-gap rule only.
    both = [dict(r, original_held=r["source_index"] == 3, touches_left_pad=True,
                 touches_right_pad=True) for r in rows]
    assert analyse(both, groups=lambda r: [])["flips"] == {
        "held both times, the finger-gap rule flipped": 1,
        "success became failure: closed on it, still on the table": 1}
    with pytest.raises(GraspingError, match="allowed: recorded, exact"):
        analyse(rows, groups=lambda r: [], reference="first")
