"""The feasibility core on arrays: collision of the gripper's boxes, the hold's contact mechanics,
the hold model (the executed poses: test_expansion.py)."""

import numpy as np
import pytest
from grasp_helpers import top_down

from tg_drake.evaluation.split import load_split
from tg_drake.grasping.feasibility import (
    FEATURES,
    GRAVITY,
    FeasibilityConfig,
    box_signed_distance,
    collision,
    deepest_cuts,
    grasp_feasibility,
    gripper_boxes,
    hold,
    hull_volume,
    load_hold_model,
    mean_density,
    others_hit,
    point_normals,
    why_no_pose,
)
from tg_drake.robot import WSG_BODY_CENTRE_G, WSG_BODY_SIZE, WSG_MAX_OPENING, WSG_PAD_SIZE
from tg_drake.types import GraspCandidates

CONFIG = FeasibilityConfig()


def box_surface(size, centre=(0.0, 0.0, 0.0), spacing=0.002):
    """Points on the surface of an axis-aligned box (world frame) every `spacing` [m]."""
    size, centre = np.asarray(size, float), np.asarray(centre, float)
    axes = [np.arange(-s / 2, s / 2 + 1e-9, spacing) for s in size]
    g = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    on = np.any(np.isclose(np.abs(g), size / 2, atol=spacing / 2), axis=1)
    return g[on] + centre


def test_signed_distance_of_points_to_a_box():
    d = box_signed_distance(np.array([[0.0, 0, 0], [0.2, 0, 0], [0.13, 0.14, 0]]),
                            np.array([0.1, 0.1, 0.1]))
    np.testing.assert_allclose(d, [-0.1, 0.1, np.hypot(0.03, 0.04)], atol=1e-12)


def test_a_box_wider_than_the_opening_is_cut_by_the_open_pads():
    # 120 mm across the closing axis: the pads, 110 mm apart, cut into each side by 5 mm; as a
    # neighbour that is a collision, as the target a cut the hold model weighs.
    wide = box_surface((0.12, 0.03, 0.06), centre=(0, 0, 0.03))
    X = top_down((0, 0, 0.04))
    c = collision(X, others_p_W=wide, table_z=-1.0, approach=0.1, config=CONFIG)
    assert c.what == "other object" and "pad" in c.box
    assert c.depth == pytest.approx((0.12 - WSG_MAX_OPENING) / 2, abs=0.0011)  # 1 mm: spacing/2
    h = hold(X, target_p_W=wide, mass=0.1, config=CONFIG, approach=0.1)
    assert h.pad_cut == pytest.approx((0.12 - WSG_MAX_OPENING) / 2, abs=0.0011)
    narrow = box_surface((0.06, 0.03, 0.06), centre=(0, 0, 0.03))
    assert collision(X, others_p_W=narrow + [0.0, 0.2, 0.0], table_z=-1.0, approach=0.1,
                     config=CONFIG).free
    h = hold(X, target_p_W=narrow, mass=0.1, config=CONFIG, approach=0.1)
    assert h.pad_cut == 0.0 and h.housing_cut == 0.0


def test_the_approach_sweep_and_a_neighbour_in_the_closing_pads():
    box_surface((0.04, 0.03, 0.06), centre=(0, 0, 0.03))
    X = top_down((0, 0, 0.04))
    # Something 35 mm above the housing's back (at 0.1525 m), in the gripper's way down.
    above = box_surface((0.01, 0.01, 0.01), centre=(0.06, 0, 0.19))
    c = collision(X, others_p_W=above, table_z=-1.0, approach=0.10,
                  config=CONFIG, closed_width=0.04)
    assert c.what == "other object"
    assert collision(X, others_p_W=above, table_z=-1.0, approach=0.0,
                     config=CONFIG, closed_width=0.04).free
    # A neighbour between the open pad and the target: the closing pad meets it.
    beside = box_surface((0.006, 0.01, 0.01), centre=(0.035, 0, 0.04))
    c = collision(X, others_p_W=beside, table_z=-1.0, approach=0.0,
                  config=CONFIG, closed_width=0.04)
    assert c.what == "other object" and c.box == "closing pad"


def test_the_table_under_the_pads():
    box_surface((0.04, 0.03, 0.06), centre=(0, 0, 0.03))
    X = top_down((0, 0, 0.03))  # the pads' tips reach 41 mm below the grasp point
    c = collision(X, others_p_W=np.zeros((0, 3)), table_z=0.0,
                  approach=0.1, config=CONFIG)
    tip_z = 0.03 - WSG_PAD_SIZE[1] / 2
    assert c.what == "table" and c.table_clearance == pytest.approx(tip_z, abs=1e-9)


def test_a_heavy_object_exceeds_the_friction_of_the_pads():
    # x_G horizontal, the weight along the pads' faces: 2 μ N against m (g + a_lift).
    target = box_surface((0.04, 0.04, 0.04), centre=(0, 0, 0.02))
    X = top_down((0, 0, 0.02))
    mu, N = CONFIG.friction, CONFIG.grip_force
    for mass in (1.0, 20.0):
        h = hold(X, target_p_W=target, mass=mass, config=CONFIG)
        load = mass * (GRAVITY + CONFIG.lift_acceleration)
        assert h.force_capacity == pytest.approx(2 * mu * N)
        assert h.translational_margin == pytest.approx(2 * mu * N / load, rel=1e-6)
        assert h.width == pytest.approx(0.04, abs=1e-9)
    assert hold(X, target_p_W=target, mass=20.0, config=CONFIG).margin < 1.0
    assert hold(X, target_p_W=target, mass=1.0, config=CONFIG).margin > 1.0


def test_a_patch_too_small_for_the_weight():
    # The same 0.5 kg with its weight 50 mm off the closing axis: over a 40 × 20 mm face the
    # pads' friction resists the turn; on a 2 mm sliver's edge it does not.
    X = top_down((0, 0, 0.03))
    com = np.array([0.0, 0.05, 0.03])
    wide = box_surface((0.04, 0.02, 0.04), centre=(0, 0, 0.03))
    sliver = box_surface((0.04, 0.002, 0.002), centre=(0, 0, 0.03), spacing=0.001)
    h_wide = hold(X, target_p_W=wide, mass=0.5, config=CONFIG, p_WCoM=com)
    h_thin = hold(X, target_p_W=sliver, mass=0.5, config=CONFIG, p_WCoM=com)
    assert h_thin.patch_area <= 2 * CONFIG.patch_cell ** 2 < h_wide.patch_area
    assert h_wide.lever == pytest.approx(0.05, abs=1e-3) and h_thin.lever == pytest.approx(0.05,
                                                                                          abs=1e-3)
    torque = 0.5 * (GRAVITY + CONFIG.lift_acceleration) * 0.05  # [N·m] the lift's
    assert h_thin.torque_capacity < torque < h_wide.torque_capacity
    assert h_thin.torsional_margin < 1.0 < h_wide.torsional_margin


def test_a_lever_too_long():
    X = top_down((0, 0, 0.03))
    face = box_surface((0.04, 0.02, 0.04), centre=(0, 0, 0.03))
    margins = [hold(X, target_p_W=face, mass=0.8, config=CONFIG,
                    p_WCoM=[0.0, lever, 0.03]).torsional_margin for lever in (0.02, 0.1, 0.3)]
    assert margins[0] > 1.0 > margins[2]
    # The torque grows with the lever: the margin falls as 1 / lever.
    assert margins[1] / margins[2] == pytest.approx(3.0, rel=0.05)


def lying_cylinder(radius, length, axis_z, spacing=0.002):
    """Points on a closed cylinder lying along y_W, its axis at height axis_z (x_W = 0)."""
    phi = np.arange(0.0, 2 * np.pi, spacing / radius)
    y = np.arange(-length / 2, length / 2 + 1e-9, spacing)
    P, Y = np.meshgrid(phi, y)
    side = np.column_stack([radius * np.cos(P.ravel()), Y.ravel(),
                            axis_z + radius * np.sin(P.ravel())])
    r = np.arange(spacing, radius, spacing)
    R, Q = np.meshgrid(r, np.arange(0.0, 2 * np.pi, spacing / radius))
    disc = np.column_stack([R.ravel() * np.cos(Q.ravel()), R.ravel() * np.sin(Q.ravel())])
    caps = [np.column_stack([disc[:, 0], np.full(len(disc), e), axis_z + disc[:, 1]])
            for e in (-length / 2, length / 2)]
    return np.concatenate([side, *caps])


def test_a_round_body_pinched_past_its_widest_section_is_squeezed_out():
    # A 66 mm can lying on its side, pinched across its diameter from above (x_G horizontal).
    # Through its axis the pads press where the surface faces them: no squeeze. With the axis
    # 30 mm past the fingertips the pads' tips press where the surface leans
    # asin(30 / 33) = 65° away: the grip pushes it out of the hand with N tan 65° per pad, more
    # than friction (μ = 1) carries — whatever it weighs.
    R, axis_z = 0.033, 0.033
    can = lying_cylinder(R, 0.12, axis_z)
    normals = point_normals(can)
    centred = hold(top_down((0, 0, axis_z)), target_p_W=can, mass=0.015, config=CONFIG,
                   normals_W=normals)
    assert centred.squeeze < 0.1 and centred.width == pytest.approx(2 * R, abs=0.002)
    tip_y = WSG_PAD_SIZE[1] / 2  # the fingertips lie this far past the grasp point
    X = top_down((0, 0, axis_z + tip_y + 0.030))
    past = hold(X, target_p_W=can, mass=0.015, config=CONFIG, normals_W=normals)
    lean = np.arcsin(0.030 / R)
    assert past.squeeze == pytest.approx(np.tan(lean) / CONFIG.friction, rel=0.25)
    assert past.squeeze > 1.0 and past.margin < 1.0
    assert hold(X, target_p_W=can, mass=0.015, config=CONFIG).squeeze == 0.0  # no normals
    f = grasp_feasibility(np.stack([top_down((0, 0, axis_z)), X]), target_p_W=can,
                          others_p_W=np.zeros((0, 3)), table_z=-1.0, approach=0.1,
                          category={"can": 1.0}, config=CONFIG)
    assert f.reasons[0] == "" and f.p_hold[0] > 0
    assert "squeezes it out" in f.reasons[1] and f.p_hold[1] == 0.0


def test_flat_faces_are_hardly_squeezed():
    # A box's faces face the pads: over the whole face no squeeze; with the pads over the top
    # half only, the points' normals blur around the top edge (k-nn normals mix the two faces
    # there) and lean a little: still far inside the friction cone.
    box = box_surface((0.05, 0.04, 0.06), centre=(0, 0, 0.03))
    normals = point_normals(box)
    whole = hold(top_down((0, 0, 0.03)), target_p_W=box, mass=0.1, config=CONFIG,
                 normals_W=normals)
    top = hold(top_down((0, 0, 0.06)), target_p_W=box, mass=0.1, config=CONFIG,
               normals_W=normals)
    assert whole.squeeze < 0.01 and top.n_points > 0 and top.squeeze < 0.1


def test_mass_from_volume_and_the_category_distribution():
    cube = box_surface((0.1, 0.1, 0.1))
    assert hull_volume(cube) == pytest.approx(1e-3, rel=1e-6)
    rho = load_hold_model().densities
    assert set(rho) >= {"can", "pan"} and all(10.0 < v < 5000.0 for v in rho.values())  # kg/m³
    assert mean_density({"can": 0.5, "pan": 0.5}, rho, 1.0) == pytest.approx(
        (rho["can"] + rho["pan"]) / 2)
    assert mean_density(None, rho, 321.0) == 321.0


def test_the_shipped_hold_model_was_fitted_on_training_objects_only():
    model = load_hold_model()
    assert model.features == FEATURES
    train, held = set(model.meta["train_objects"]), set(model.meta["held_out_objects"])
    assert train and held and not train & held
    split = load_split()  # object-wise: every fitted object on the split's training side
    assert all(split.role(o) == "train" for o in train)
    assert all(split.role(o) == "held_out" for o in held)
    assert "tools/fit_hold_model.py" in model.meta["command"]
    target = box_surface((0.04, 0.04, 0.04), centre=(0, 0, 0.02))
    f = grasp_feasibility(top_down((0, 0, 0.025))[None], target_p_W=target,
                          others_p_W=np.zeros((0, 3)), table_z=-1.0, approach=0.1,
                          category={"can": 1.0}, config=CONFIG)
    assert 0.0 < f.p_hold[0] < 1.0
    assert f.holds[0].margin > 1.0  # a 40 mm can-density cube between 60 N pads


def test_a_colliding_pose_gets_no_hold():
    target = box_surface((0.04, 0.03, 0.06), centre=(0, 0, 0.03))
    neighbour = box_surface((0.03, 0.03, 0.06), centre=(0.07, 0, 0.03))
    f = grasp_feasibility(top_down((0, 0, 0.04))[None], target_p_W=target,
                          others_p_W=neighbour, table_z=-1.0, approach=0.1,
                          category=None, config=CONFIG)
    assert f.p_hold[0] == 0.0 and f.collisions[0].what == "other object"
    assert f.reasons[0].startswith("collision")


def test_the_assessed_candidates_keep_the_scorers_score(monkeypatch):
    """Local and one-part scoring rank otherwise than P(part | task) · P(grasp | local shape);
    the stage multiplies their score by nothing but P(hold) (when it ranks by it) or 0."""
    from types import SimpleNamespace

    from tg_drake.grasping import feasibility
    from tg_drake.types import GraspCandidates, ObjectDescription, SceneDescription

    monkeypatch.setattr(feasibility, "grasp_feasibility", lambda X_WG, **kw: SimpleNamespace(
        reasons=["", "", "in collision with the table", ""], p_hold=np.full(len(X_WG), 0.5),
        holds=(None,) * len(X_WG)))
    monkeypatch.setattr(feasibility, "geometric_refusal", lambda *a, **kw: "")  # (tests of pads)
    obj = ObjectDescription(
        p_W=np.zeros((10, 3)), n_W=np.zeros((10, 3)), labels=np.zeros(10, int),
        visible=np.ones(10, bool), X_WO=np.eye(4), extents=np.full(3, 0.1), pose="upright",
        pose_likelihood={"upright": 1.0}, part_probabilities={}, part_boxes={},
        pregrasp_X_WG=np.tile(np.eye(4), (4, 1, 1)), pregrasp_parts=np.array([1, 3, 1, 0]))
    local = np.array([0.9, 0.8, 0.7, 0.5])  # ranked by P(grasp | local shape) alone
    candidates = GraspCandidates(np.tile(np.eye(4), (4, 1, 1)), np.array([0, 3, 1, 1]),
                                 np.array([0.1, 0.0, 0.9, 0.9]), local, local.copy())
    for rank_by_hold, p_hold in ((False, 1.0), (True, 0.5)):
        out = feasibility.assess_candidates(SceneDescription(objects=[obj], X_WT=np.eye(4)),
                                            candidates, category=None, approach=0.1,
                                            config=FeasibilityConfig(rank_by_hold=rank_by_hold))
        # The third is infeasible: 0, last.
        assert np.allclose(out.score, p_hold * np.array([0.9, 0.8, 0.5, 0.0]))
        assert out.source.tolist() == [0, 1, 3, 2]


def test_why_no_pose_counts_each_favoured_parts_refusals_by_class():
    n = 6
    candidates = GraspCandidates(
        np.tile(np.eye(4), (n, 1, 1)), np.array([1, 1, 1, 1, 2, 0]), np.array([0.9] * 4 + [0.1, 0]),
        np.array([0.8, 0.8, 0.8, 0.0, 0.5, 0.5]), np.zeros(n),
        feasibility_reasons=("does not fit: middle is 0.13 m across the fingers",
                             "does not fit: middle is 0.12 m across the fingers",
                             "collision: the housing would cut another object by 3 mm", "",
                             "would not hold: the lever", ""))
    why = why_no_pose(candidates, {"middle": 0.9, "bottom": 0.1, "top": 0.0})
    assert why == ("middle (P(part | task) 0.90): 4 poses, none feasible — does not fit 2, "
                   "collision 1, P(grasp | local shape) = 0 1 (e.g. does not fit: middle is "
                   "0.13 m across the fingers); bottom (P(part | task) 0.10): 1 poses, none "
                   "feasible — would not hold 1 (e.g. would not hold: the lever)")
    # A favoured part without poses is said so; unfavoured parts are left out.
    assert why_no_pose(candidates, {"handle": 1.0}) == (
        "handle (P(part | task) 1.00): no pose was made on it")
    assert why_no_pose(candidates, {"top": 0.0}) == ""
    # A part whose poses mostly scored 0 quotes a refusal's own words, not "scored 0".
    mostly_zero = GraspCandidates(
        np.tile(np.eye(4), (3, 1, 1)), np.array([3, 3, 3]), np.ones(3), np.array([0.5] * 3),
        np.zeros(3), feasibility_reasons=("", "", "would not hold: the lever"))
    assert why_no_pose(mostly_zero, {"handle": 0.8}) == (
        "handle (P(part | task) 0.80): 3 poses, none feasible — scored 0 2, would not hold 1 "
        "(e.g. would not hold: the lever)")


def test_deepest_cuts_and_others_hit_measure_how_deep_points_enter_the_housing():
    """A slab of points 4 mm inside the housing's back face (y_G = −0.0213 − 0.03625 m), at the
    identity pose and at one 1 m away: the deepest cut is 4 mm there, 0 away; `others_hit` names
    the housing for the first and nothing for the second."""
    back = WSG_BODY_CENTRE_G[1] - WSG_BODY_SIZE[1] / 2
    g = np.linspace(-0.02, 0.02, 9)
    p = np.stack(np.meshgrid(g, [back + 0.004], g, indexing="ij"), axis=-1).reshape(-1, 3)
    far = np.eye(4)
    far[:3, 3] = [1.0, 0.0, 0.0]
    X = np.array([np.eye(4), far])
    cuts = deepest_cuts(X, p, gripper_boxes(WSG_MAX_OPENING), 3)
    assert cuts == pytest.approx([0.004, 0.0], abs=1e-9)
    why = others_hit(X, others_p_W=p, approach=0.0, config=FeasibilityConfig(),
                     closed_widths=[None, None])
    assert "housing" in why[0] and "4.0 mm" in why[0] and why[1] == ""
