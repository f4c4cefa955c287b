"""The pose likelihood is the calibrated frequency of the true pose per (decision, cue)."""

import json

import numpy as np
import pytest

from tg_drake.errors import PerceptionError
from tg_drake.perception.pose import (
    PoseCalibration,
    _profile_radii,
    closed_end,
    closed_end_decision,
    estimate_pose,
    load_pose_calibration,
    shoulder,
    wall_taper,
)
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


def _frustum(r_table, r_top, H=0.12, top_height=None):
    """Visible points and normals of a closed frustum on the table (radius r_table at the table,
    r_top at its flat or shaped top, `top_height(r)` [m]), its half towards +x (`_revolved`)."""
    return _revolved(lambda z: r_table - (r_table - r_top) * z / H, H, top_height)


def test_the_wall_taper_measures_the_draft_and_a_straight_wall_has_none():
    from tg_drake.perception.pose import wall_taper

    straight = wall_taper(*_frustum(0.03, 0.03))
    drafted = wall_taper(*_frustum(0.04, 0.034))  # 6 mm over 120 mm: 0.05 m/m, about 2.9°
    assert abs(straight.narrowing) < 1e-3 and not straight.significant
    assert drafted.narrowing == pytest.approx(0.05, abs=0.003) and drafted.significant


def test_a_flat_closed_top_is_the_flat_sign_unless_the_wall_narrows_or_the_end_is_pushed_in():
    """What the closed-end model reads as a base needs evidence beyond the missing lid: a flat
    top on a straight wall (a solid cylinder) is the flat end's sign (here upright, the default),
    on a wall narrowing from the table (a tumbler on its rim) it is upside-down, and a base
    pushed in (a can's bottom) is one."""
    from tg_drake.perception.pose import closed_end, closed_end_decision, wall_taper

    model = load_pose_calibration().closed_end  # fitted on perceived training views
    assert model is not None
    H = 0.12
    cases = {"flat": _frustum(0.03, 0.03), "rim": _frustum(0.04, 0.034),
             "base": _frustum(0.03, 0.03, top_height=lambda r: H - 0.008 * max(0.0, 1 - r / 0.02)),
             "lid": _frustum(0.03, 0.03, top_height=lambda r: H if r > 0.0225 else H - 0.004)}
    signs = {"flat": 1.0, "rim": -1.0, "base": -1.0, "lid": 1.0}
    for name, (c, n) in cases.items():
        end = closed_end(c, n)
        assert closed_end_decision(model, end, wall_taper(c, n)) == (signs[name], name), name


def test_a_base_read_wider_by_noise_is_no_taper_and_a_drafted_wall_is():
    """The taper cue's end radii are one quantile of each end's slice: a few points read wider
    at a straight can's base (the sensor's noise) make its base wider than its top. The wall's
    fit (`wall_taper`, medians per height bin) does not move, so `taper_confirmed` refuses that
    taper and keeps a wall that narrows by its draft."""
    from tg_drake.perception.pose import END_SLICE, _profile_radii, taper_confirmed, wall_taper

    c, n = _frustum(0.03, 0.03)
    c.axis_T = np.array([0.0, 0.0, 1.0])
    # A fifth as many points as the lowest 15 % of the wall holds, 6 mm wider, facing out.
    low = c.p_T[:, 2] < END_SLICE * 0.12
    k = max(1, int(0.2 * np.count_nonzero(low & (np.abs(n[:, 2]) < 0.5))))
    t = np.linspace(-np.pi / 2, np.pi / 2, k)
    z = np.linspace(0.004, 0.015, k)
    ring = np.c_[0.036 * np.cos(t), 0.036 * np.sin(t), z]
    c.p_T = np.vstack([c.p_T, ring])
    c.visible = np.ones(len(c.p_T), bool)
    c.handle = np.zeros(len(c.p_T), bool)
    n = np.vstack([n, np.c_[np.cos(t), np.sin(t), np.zeros(k)]])
    r_low, _, r_high = _profile_radii(c)
    assert r_high < 0.9 * r_low  # [m] the end radii read a strong taper ...
    assert not taper_confirmed(wall_taper(c, n))  # ... the wall says it is straight
    # A 2.9° draft (an upside-down tumbler) is a taper.
    assert taper_confirmed(wall_taper(*_frustum(0.04, 0.034)))


def test_a_flat_end_on_a_straight_wall_leaves_the_decision_to_the_end_radii_a_lid_does_not():
    """A taper the wall does not confirm goes to the closed end: a recessed lid says upright
    whatever the end radii read; a flat end shows nothing, so the radii's narrower top decides
    (upside-down, "taper"), and without it the usual pose stands (upright, "flat")."""
    from tg_drake.perception.pose import closed_end, closed_end_decision, wall_taper

    model = load_pose_calibration().closed_end
    H = 0.12
    flat = _frustum(0.03, 0.03)
    lid = _frustum(0.03, 0.03, top_height=lambda r: H if r > 0.0225 else H - 0.004)
    for (c, n), narrower, expected in ((flat, True, (-1.0, "taper")), (flat, False, (1.0, "flat")),
                                       (lid, True, (1.0, "lid"))):
        assert closed_end_decision(model, closed_end(c, n), wall_taper(c, n),
                                   narrower_top=narrower) == expected


def test_the_flat_sign_is_the_end_the_flat_views_rested_on_more_often_whatever_decided():
    """`PoseCalibration.flat_sign` counts the true poses of the views that reached the "flat"
    cue, under either decision (the calibration decides them with the sign it finds)."""
    assert PoseCalibration().flat_sign == 1.0  # no views: upright
    down = {"upright/flat": {"upsidedown": 2}, "upright/lid": {"upright": 30}}
    assert PoseCalibration(counts=down).flat_sign == -1.0
    again = {"upsidedown/flat": {"upsidedown": 2, "upright": 1}}
    assert PoseCalibration(counts=again).flat_sign == -1.0
    tie = {"upsidedown/flat": {"upsidedown": 1, "upright": 1}}
    assert PoseCalibration(counts=tie).flat_sign == 1.0


def test_only_a_flat_end_follows_the_flat_sign():
    model = load_pose_calibration().closed_end
    H = 0.12
    cases = {"flat": (_frustum(0.03, 0.03), -1.0), "rim": (_frustum(0.04, 0.034), -1.0),
             "lid": (_frustum(0.03, 0.03, top_height=lambda r: H if r > 0.0225 else H - 0.004),
                     1.0)}
    for name, ((c, n), sign) in cases.items():
        assert closed_end_decision(model, closed_end(c, n), wall_taper(c, n),
                                   flat_sign=-1.0) == (sign, name), name


def _revolved(radius, H=0.12, top_height=None):
    """Visible points and normals of a closed body of revolution standing on the table, its
    radius `radius(z)` [m] at height z, its top at the heights `top_height(r)` [m] (flat at H by
    default); its half towards +x."""
    from types import SimpleNamespace

    th = np.linspace(-np.pi / 2, np.pi / 2, 60)
    zs = np.arange(0.004, H - 0.001, 0.003)
    dz = 1e-4
    wall, n_wall = [], []
    for z in zs:
        r, slope = radius(z), (radius(z - dz) - radius(z + dz)) / (2 * dz)  # narrowing [m/m]
        for t in th:
            wall.append((r * np.cos(t), r * np.sin(t), z))
            n_wall.append((np.cos(t), np.sin(t), slope))
    step, r_top = 0.0015, radius(H)
    g = np.arange(-r_top, r_top + step, step)
    x, y = np.meshgrid(g, g)
    r = np.hypot(x, y)
    inside = r <= r_top
    top_height = top_height or (lambda r: H)
    top = np.c_[x[inside], y[inside], [top_height(v) for v in r[inside]]]
    p = np.vstack([wall, top])
    n_wall = np.array(n_wall)
    n = np.vstack([n_wall / np.linalg.norm(n_wall, axis=1, keepdims=True),
                   np.tile([0.0, 0.0, 1.0], (len(top), 1))])
    m = len(p)
    c = SimpleNamespace(p_T=p, visible=np.ones(m, bool), handle=np.zeros(m, bool),
                        p_TA=np.array([0.0, 0.0, H / 2]), axis_T=np.array([0.0, 0.0, 1.0]),
                        vertical=True)
    return c, n


def _bottle(z, shoulder_from=0.045, neck_from=0.105, r_body=0.03, r_neck=0.013):
    """A bottle's radius [m] at height z [m]: straight body, a shoulder narrowing steadily from
    `shoulder_from` (below mid-height) to the neck."""
    f = np.clip((z - shoulder_from) / (neck_from - shoulder_from), 0.0, 1.0)
    return r_body - f * (r_body - r_neck)


def test_a_bottle_whose_shoulder_begins_low_is_upright_by_its_neck():
    """The neck cue asks for a body as wide as its base at mid-height; a shoulder beginning
    lower fails that (the bottle read as a tapered container upside down). Its wall shows what
    it is: straight in its lower half, narrowing above (`shoulder`); a tumbler on its rim
    narrows from the table up, and a straight can does not narrow at all."""
    bottle = _revolved(_bottle)
    r_low, r_mid, r_high = _profile_radii(bottle[0])
    assert r_mid < 0.95 * r_low and r_high < 0.6 * r_low  # [m] mid-height already narrower
    assert shoulder(*bottle)
    est = estimate_pose(*bottle, np.array([0.6, 0.0, 0.5]))
    assert (est.pose, est.cue) == ("upright", "neck")
    tumbler = _revolved(lambda z: 0.04 - 0.05 * z)  # 2.9° draft, 40 mm rim on the table
    can = _revolved(lambda z: 0.03)
    assert not shoulder(*tumbler) and not shoulder(*can)
    est = estimate_pose(*tumbler, np.array([0.6, 0.0, 0.5]))
    assert (est.pose, est.cue) == ("upsidedown", "taper")
