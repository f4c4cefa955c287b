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
