"""The DGI training set: grasps per library scene and their features."""

import numpy as np
import pytest

from tg_drake.grasping.dataset import (
    KINDS,
    SamplingConfig,
    scene_cloud,
    scene_grasps,
    training_order,
    training_set,
)
from tg_drake.grasping.dgi import PAD_CENTER_Y, DgiConfig, dgi_features
from tg_drake.grasping.expansion import lowest_point
from tg_drake.objects import get_object
from tg_drake.types import PART_LABELS


@pytest.fixture(scope="module")
def cup():
    return get_object("cup_01")


def test_scene_grasps_are_reproducible_and_clear_the_table(cup):
    a = scene_grasps(cup, "upright", seed=0)
    b = scene_grasps(cup, "upright", seed=0)
    c = scene_grasps(cup, "upright", seed=1)
    np.testing.assert_array_equal(a.X_WG, b.X_WG)
    assert a.X_WG.shape != c.X_WG.shape or not np.allclose(a.X_WG, c.X_WG)
    cfg = SamplingConfig()
    # 1e-9 m below the clearance: a retreated grasp sits exactly at it, up to rounding.
    assert (lowest_point(a.X_WG, cfg.approach_distance)
            >= cfg.expansion.table_clearance - 1e-9).all()
    assert set(a.kinds) == set(KINDS)
    assert np.sum(a.kinds == "random") == cfg.n_random
    # The cup has four parts, each with 12 box hypotheses before the table check.
    assert np.sum(a.kinds == "box") + a.n_through_table >= 4 * 12
    assert set(a.parts) <= set(range(len(PART_LABELS)))
    # Box grasps aim at the object: their grasp points lie within the cup's bounding box.
    gp = a.X_WG[:, :3, 3] + PAD_CENTER_Y * a.X_WG[:, :3, 1]
    # cup_01 is 10.9 × 8.4 × 9.9 cm, handle along +x; a low side grasp's tilted variant moved
    # back above the table has its grasp point up to 1 cm outside.
    lo = np.array([-0.05, -0.05, -0.001])
    hi = np.array([0.07, 0.05, 0.10])
    box = gp[a.kinds == "box"]
    assert np.all((box > lo) & (box < hi))


def test_training_set_computes_features_of_ok_records_only(cup):
    scene = scene_grasps(cup, "sideways", seed=0)
    records = [{"object": "cup_01", "pose": "sideways", "kind": str(k), "part": int(p),
                "X_WG": X.ravel().tolist(), "status": "ok", "success": bool(i % 2)}
               for i, (X, k, p) in enumerate(zip(scene.X_WG[:6], scene.kinds, scene.parts,
                                                 strict=False))]
    records.append({"object": "cup_01", "pose": "sideways", "status": "sim_error",
                    "reason": "object fell through the table during close"})
    data = training_set(records, seed=0)
    assert data.X.shape == (6, DgiConfig().n_features)
    np.testing.assert_array_equal(data.y, [0, 1, 0, 1, 0, 1])
    p_W, _, _ = scene_cloud(cup, "sideways", seed=0)
    np.testing.assert_array_equal(data.X, dgi_features(p_W, scene.X_WG[:6]))
    assert set(data.scenes) == {"cup_01/sideways"}
    np.testing.assert_array_equal(data.X_WG, scene.X_WG[:6])
    np.testing.assert_allclose(data.centroids, np.repeat(p_W.mean(axis=0)[None], 6, axis=0))


def test_training_order_lines_records_up_with_the_training_rows(cup):
    # Two scenes, the later one in sorted order first in the file, a failed run between: the
    # rows come scene by scene in sorted order, each scene's grasps as in the file.
    rows = []
    for pose in ("upright", "sideways"):
        scene = scene_grasps(cup, pose, seed=0)
        rows += [{"job": f"cup_01/{pose}/0", "index": i, "object": "cup_01", "pose": pose,
                  "kind": str(scene.kinds[i]), "part": int(scene.parts[i]),
                  "X_WG": scene.X_WG[i].ravel().tolist(), "status": "ok",
                  "success": (i + len(rows)) % 3 == 0} for i in range(3)]
    rows.insert(2, {"job": "cup_01/upright/0", "index": 9, "object": "cup_01",
                    "pose": "upright", "status": "sim_error", "reason": "solver"})
    ordered = training_order(rows)
    assert [(r["pose"], r["index"]) for r in ordered] == [
        ("sideways", 0), ("sideways", 1), ("sideways", 2),
        ("upright", 0), ("upright", 1), ("upright", 2)]
    data = training_set(rows, seed=0)
    np.testing.assert_array_equal(data.y, [int(r["success"]) for r in ordered])
    np.testing.assert_array_equal(data.X_WG.reshape(-1, 16), [r["X_WG"] for r in ordered])
