"""The pose likelihood is the calibrated frequency of the true pose per (decision, cue)."""

import json

import numpy as np
import pytest

from tg_drake.errors import PerceptionError
from tg_drake.perception.pose import PoseCalibration, load_pose_calibration
from tg_drake.types import POSES


def test_a_well_counted_key_gives_its_frequencies():
    c = PoseCalibration(counts={"upright/cavity": {"upright": 98, "sideways": 2}},
                        prior_views=2.0)
    p = c.likelihood("upright", "cavity")
    assert sum(p.values()) == pytest.approx(1.0)
    assert p["upright"] == pytest.approx(0.98 * 100 / 102 + (2 / 102) * (98 + 2 / 3) / 102,
                                         rel=1e-9)
    assert p["upsidedown"] < 0.01


def test_a_rare_key_leans_on_its_decision_and_an_unseen_one_is_its_decision():
    counts = {"upright/cavity": {"upright": 40}, "upright/straight": {"upright": 6,
                                                                      "upsidedown": 4},
              "upright/neck": {"upsidedown": 1}}
    c = PoseCalibration(counts=counts, prior_views=2.0)
    rare, unseen = c.likelihood("upright", "neck"), c.likelihood("upright", "handle")
    pooled = np.array([46, 0, 5]) + 2 / 3
    np.testing.assert_allclose([unseen[p] for p in POSES], pooled / pooled.sum())
    # One upside-down view moves the rare key towards upside down, not all the way.
    assert unseen["upsidedown"] < rare["upsidedown"] < 0.5


def test_no_counts_is_uniform():
    p = PoseCalibration().likelihood("sideways", "tool")
    np.testing.assert_allclose(list(p.values()), 1 / 3)


def test_the_shipped_calibration_loads_and_a_bad_file_is_a_clear_error(tmp_path):
    shipped = load_pose_calibration()
    assert shipped.counts and shipped.source
    for key, c in shipped.counts.items():
        assert key.split("/")[0] in POSES and set(c) <= set(POSES), key
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"counts": {}}))
    with pytest.raises(PerceptionError, match="not a pose calibration"):
        load_pose_calibration(str(bad))
    with pytest.raises(PerceptionError, match="no such"):
        load_pose_calibration(str(tmp_path / "missing.json"))


def _closed_top_cylinder(top_height):
    """Visible points of a 30 mm radius, 120 mm tall cylinder standing on the table (its half
    towards +x, and its whole top surface at the heights `top_height(r)` [m])."""
    from types import SimpleNamespace

    R, H, step = 0.03, 0.12, 0.0015
    th = np.linspace(-np.pi / 2, np.pi / 2, 60)
    wall = np.array([(R * np.cos(t), R * np.sin(t), z) for t in th
                     for z in np.arange(0.004, H, 0.003)])
    g = np.arange(-R, R + step, step)
    x, y = np.meshgrid(g, g)
    r = np.hypot(x, y)
    top = np.c_[x[r <= R], y[r <= R], [top_height(v) for v in r[r <= R]]]
    p = np.vstack([wall, top])
    n = len(p)
    return SimpleNamespace(p_T=p, visible=np.ones(n, bool), handle=np.zeros(n, bool),
                           p_TA=np.array([0.0, 0.0, H / 2]))


def test_the_closed_end_measures_a_recessed_lid_a_flat_and_a_domed_base():
    from tg_drake.perception.pose import closed_end

    H = 0.12
    lid = closed_end(_closed_top_cylinder(lambda r: H if r > 0.0225 else H - 0.004))
    flat = closed_end(_closed_top_cylinder(lambda r: H))
    domed = closed_end(_closed_top_cylinder(lambda r: H - 0.008 * max(0.0, 1 - r / 0.02)))
    assert lid.recess == pytest.approx(0.004, abs=2e-4) and abs(lid.dome) < 2e-4
    assert abs(flat.recess) < 2e-4 and abs(flat.dome) < 2e-4
    assert domed.recess > 0.004 and domed.dome > 0.0015  # [m] the dome rises off its centre
