"""The grasp planner core: IK for side and top grasps, unreachable objects as results, and a
pick-and-place trajectory that keeps the velocity limits and its clearance."""

from __future__ import annotations

import numpy as np
import pytest
from grasp_helpers import GRASP_POINT, box_object, grasp_pose, ranked, scene_with_box
from pydrake.math import RigidTransform, RotationMatrix

from tg_drake.planning import ik
from tg_drake.planning.ik import (
    CONSTRAINT_TOLERANCE,
    beyond_reach,
    clearance,
    make_arm_plant,
    solve_ik_seeds,
)
from tg_drake.planning.planner import (
    PlannerConfig,
    carried_box,
    place_pose,
    plan_pick_and_place,
    reseat_duration,
    reseated,
)
from tg_drake.planning.regrasp import plan_task_leg
from tg_drake.planning.trajectory import IIWA_VELOCITY_LIMITS
from tg_drake.robot import IIWA_HOME, IIWA_POSITION_LIMITS, wrist_reach_margin
from tg_drake.types import PartBox

# The IK tolerances of PlannerConfig: 2 mm per axis (so up to 2·√3 mm), 0.02 rad; plus what the
# accepted constraint violation (ik.CONSTRAINT_TOLERANCE, 1e-5) allows: 1e-5 m, and, on the
# orientation constraint's cosine near 0.02 rad, 1e-5 / (2 sin 0.02) ≈ 2.5e-4 rad.
IK_POSITION_ERROR = 2e-3 * np.sqrt(3) + 1e-5
IK_ANGLE_ERROR = 0.02 + 3e-4


def assert_gripper_at(arm, q, X_WG):
    arm.plant.SetPositions(arm.plant_context, arm.full_q(q))
    X = arm.G.CalcPoseInWorld(arm.plant_context)
    assert np.linalg.norm(X.translation() - X_WG[:3, 3]) <= IK_POSITION_ERROR
    angle = (X.rotation().inverse() @ RotationMatrix(X_WG[:3, :3])).ToAngleAxis().angle()
    assert angle <= IK_ANGLE_ERROR


def assert_within_joint_limits(arm, q):
    idx = arm.iiwa_indices
    assert np.all(q >= arm.plant.GetPositionLowerLimits()[idx] - 1e-9)
    assert np.all(q <= arm.plant.GetPositionUpperLimits()[idx] + 1e-9)


# A 0.07 × 0.07 × 0.20 m box standing at the table centre, 0.75 m in front of the robot, a little
# to the left.
BOX = box_object([0.75, 0.1, 0.10], [0.07, 0.07, 0.20])
SIDE = grasp_pose([0.75, 0.1, 0.15], approach_W=[1, 0, 0], closing_W=[0, 1, 0])
TOP = grasp_pose([0.75, 0.1, 0.17], approach_W=[0, 0, -1], closing_W=[0, 1, 0])


@pytest.fixture(scope="module")
def arm_with_box():
    """The arm plant with the box as an obstacle its finger pads may overlap (as when grasping)."""
    return make_arm_plant(obstacles=[("box", RigidTransform(BOX.X_WO), tuple(BOX.extents))],
                          finger_contact=["box"])


@pytest.mark.parametrize("X_WG", [SIDE, TOP], ids=["side", "top"])
def test_ik_finds_a_grasp_on_a_box(arm_with_box, X_WG):
    r = solve_ik_seeds(arm_with_box, RigidTransform(X_WG), [np.array(IIWA_HOME)],
                       min_distance=0.003)
    assert r.success, r.reason
    assert_gripper_at(arm_with_box, r.q, X_WG)
    assert_within_joint_limits(arm_with_box, r.q)
    # 3 mm: the IK's minimum-distance bound; the palm and the arm keep clear of the box.
    assert clearance(arm_with_box, r.q) >= 0.003 - 1e-4


def test_pregrasp_into_the_box_is_refused_when_the_box_is_an_obstacle():
    """A grasp pose whose palm would sit inside the box: the fingers may overlap it, the palm
    may not."""
    arm = make_arm_plant(obstacles=[("box", RigidTransform(BOX.X_WO), tuple(BOX.extents))],
                         finger_contact=["box"])
    deep = grasp_pose([0.75, 0.1, 0.10], approach_W=[0, 0, -1], closing_W=[0, 1, 0])
    r = solve_ik_seeds(arm, RigidTransform(deep), [np.array(IIWA_HOME)], min_distance=0.003)
    assert not r.success
    assert "clearance" in r.reason


def test_a_pose_beyond_the_arms_reach_fails_without_a_solver_call(monkeypatch):
    arm = make_arm_plant()
    far = grasp_pose([1.3, 0.0, 0.2], approach_W=[1, 0, 0], closing_W=[0, 1, 0])
    monkeypatch.setattr(ik, "solve_ik", lambda *a, **k: pytest.fail("the solver was called"))
    r = solve_ik_seeds(arm, RigidTransform(far), [np.array(IIWA_HOME)], min_distance=0.003)
    assert not r.success
    assert "out of reach" in r.reason
    # The wrist centre 1.3 − 0.055 − 0.195 m out, 0.16 m below the shoulder: 0.23 m past 0.82 m.
    assert r.position_error == pytest.approx(0.23, abs=0.01)


def test_an_ik_without_clearance_is_asked_once_per_pose_and_seed_whatever_the_obstacles():
    """Its answer depends on the arm's kinematics only: a second arm plant with an obstacle (the
    clearance IK then runs again) gets the remembered one, the same configuration."""
    X = RigidTransform(SIDE)
    bare = solve_ik_seeds(make_arm_plant(), X, [np.array(IIWA_HOME)], min_distance=None)
    n = ik.ik_solves()
    arm = make_arm_plant(obstacles=[("far", RigidTransform([0.0, 0.9, 0.1]), (0.1, 0.1, 0.1))])
    again = solve_ik_seeds(arm, X, [np.array(IIWA_HOME)], min_distance=None)
    assert ik.ik_solves() == n and again.success and bare.success
    np.testing.assert_array_equal(again.q, bare.q)
    clear = solve_ik_seeds(arm, X, [np.array(IIWA_HOME)], min_distance=0.003)
    assert ik.ik_solves() == n + 1 and clear.success  # only the clearance IK was solved


def test_no_pose_the_arm_reaches_is_beyond_reach():
    """Forward kinematics of configurations across the joint ranges, joint 4 straight and at
    both limits among them (the shell's two boundaries, where the margin is 0): none is refused
    even with no tolerance, and the boundaries are tight (the shell is exact, not loose)."""
    arm = make_arm_plant()
    rng = np.random.default_rng(0)
    qs = rng.uniform(-IIWA_POSITION_LIMITS, IIWA_POSITION_LIMITS, (150, 7))
    qs[:50, 3] = 0.0
    qs[50:100, 3] = IIWA_POSITION_LIMITS[3] * np.where(np.arange(50) % 2, 1.0, -1.0)
    for k, q in enumerate(qs):
        arm.plant.SetPositions(arm.plant_context, arm.full_q(q))
        X_WG = arm.G.CalcPoseInWorld(arm.plant_context)
        assert beyond_reach(arm, X_WG, 0.0, 0.0) == 0.0
        margin = wrist_reach_margin(X_WG.GetAsMatrix4())
        assert margin >= -1e-5  # [m] the model files' rounding of the kinematic table
        if k < 100:
            assert margin == pytest.approx(0.0, abs=1e-5)


def test_velocity_limits_are_the_robot_facts():
    arm = make_arm_plant()
    # The KUKA data sheet's max velocity of joints 1–7 [rad/s].
    np.testing.assert_array_equal(IIWA_VELOCITY_LIMITS,
                                  [1.48353, 1.48353, 1.74533, 1.30900, 2.26893, 2.35619, 2.35619])
    np.testing.assert_allclose(arm.plant.GetVelocityUpperLimits()[arm.iiwa_indices],
                               IIWA_VELOCITY_LIMITS, rtol=1e-12)


def test_object_out_of_reach_is_an_unreachable_result():
    far = box_object([1.6, 0.0, 0.06], [0.07, 0.07, 0.12])
    c = ranked([(grasp_pose([1.6, 0, 0.09], [1, 0, 0], [0, 1, 0]), "middle"),
                    (grasp_pose([1.6, 0, 0.11], [0, 0, -1], [0, 1, 0]), "top"),
                    (grasp_pose([1.6, 0, 0.11], [0, 0, -1], [1, 0, 0]), "top")])
    r = plan_pick_and_place(c, target=far, place_xy=(0.7, -0.3))
    assert r.status == "unreachable"
    assert r.plan is None
    assert set(r.unreachable_parts) == {"middle", "top"}
    assert r.part_reachable == {"middle": False, "top": False}
    assert np.all(np.isinf(r.costs))
    assert all("pre-grasp pose unreachable" in reason for reason in r.candidate_reasons)
    assert "middle" in r.reason and "top" in r.reason


def test_max_parts_tries_only_the_leading_part():
    """The closed loop asks for one part at a time: the leading part's candidates are all
    unreachable (they approach from under the table), the next part is not examined."""
    c = ranked([(grasp_pose([0.75, 0.1, 0.03], [0, 0, 1], [0, 1, 0]), "bottom"),
                    (grasp_pose([0.75, 0.1, 0.03], [0, 0, 1], [1, 0, 0]), "bottom"),
                    (TOP, "top")])
    r = plan_pick_and_place(c, target=BOX, place_xy=(0.75, -0.25), max_parts=1)
    assert r.status == "unreachable"
    assert r.unreachable_parts == ("bottom",)
    assert np.all(np.isinf(r.costs[:2])) and np.isnan(r.costs[2])
    # With the bottom excluded (the logic's collision(bottom) evidence), the top is planned.
    r = plan_pick_and_place(c, target=BOX, place_xy=(0.75, -0.25), max_parts=1,
                            exclude_parts=("bottom",))
    assert r.status == "planned"
    assert (r.candidate, r.part) == (2, "top")


def test_unreachable_place_is_not_a_collision_of_the_part():
    c = ranked([(TOP, "top")])
    r = plan_pick_and_place(c, target=BOX, place_xy=(1.6, 0.0))
    assert r.status == "unreachable"
    assert r.unreachable_parts == ()  # the top can be picked: no collision(top) evidence
    assert r.picked_parts == ("top",)
    assert r.part_reachable == {"top": True}
    assert r.candidate_reasons[0].startswith("pre-place pose unreachable")
    assert "picked but not placed at (1.600, 0.000) m: pre-place pose unreachable" in r.reason


def test_zero_scores_are_ruled_out_not_unreachable():
    """A part the logic gave probability 0 is skipped without blaming its reach."""
    c = ranked([(SIDE, "middle"), (TOP, "top")], scores=[0.0, 0.0])
    r = plan_pick_and_place(c, target=BOX, place_xy=(0.75, -0.25))
    assert r.status == "unreachable"
    assert r.unreachable_parts == () and r.part_reachable == {}
    assert np.all(np.isinf(r.costs))
    assert all(reason.startswith("score 0") for reason in r.candidate_reasons)


def test_a_feasibility_reason_is_kept_for_a_candidate_it_ruled_out():
    """A pose the feasibility stage gave score 0 keeps its reason and says nothing about reach."""
    c = ranked([(SIDE, "middle"), (TOP, "top")], scores=[0.0, 0.0])
    c.feasibility_reasons = ("would not hold: P(hold) 0.10", "collision: the left pad would cut "
                             "another object by 4.0 mm")
    r = plan_pick_and_place(c, target=BOX, place_xy=(0.75, -0.25))
    assert r.status == "unreachable" and r.unreachable_parts == ()
    assert r.candidate_reasons == c.feasibility_reasons


def test_place_pose_keeps_orientation_and_lifts_the_box_off_the_table():
    X_WO = RigidTransform(RotationMatrix.MakeXRotation(np.pi / 2), [0.7, 0.1, 0.035])
    X = place_pose(X_WO.GetAsMatrix4(), [0.07, 0.2, 0.07], (0.6, -0.3), release_height=0.01)
    np.testing.assert_allclose(X[:3, :3], X_WO.rotation().matrix(), atol=1e-15)
    # Turned about x, the box's 0.2 m side (its y axis) is vertical: its centre goes 0.1 m up,
    # plus the release height.
    np.testing.assert_allclose(X[:3, 3], [0.6, -0.3, 0.1 + 0.01], atol=1e-12)


def lying_cylinder(slant_deg: float):
    """A cylinder (r 4 cm, 12 cm long) lying on the table along world y, its surface points, and
    a perceived frame O on its axis turned `slant_deg` about it (as perception's box follows a
    mug's handle pointing up at a slant), with the box of the points along O's axes."""
    rng = np.random.default_rng(0)
    theta, s = rng.uniform(0, 2 * np.pi, 2000), rng.uniform(-0.06, 0.06, 2000)
    centre = np.array([0.7, 0.1, 0.04])
    p_W = centre + np.column_stack([0.04 * np.cos(theta), s, 0.04 * np.sin(theta)])
    a = np.deg2rad(slant_deg)
    # z_O along the axis (world y), x_O turned by the slant about it
    R = np.column_stack([[np.cos(a), 0.0, np.sin(a)], [-np.sin(a), 0.0, np.cos(a)], [0, 1.0, 0]])
    R[:, 1] = np.cross(R[:, 2], R[:, 0])
    obj = box_object(centre, [0.08, 0.08, 0.12])
    obj.X_WO = np.eye(4)
    obj.X_WO[:3, :3], obj.X_WO[:3, 3] = R, centre
    q = (p_W - centre) @ R
    obj.extents = q.max(axis=0) - q.min(axis=0)
    obj.p_W = p_W
    return obj


@pytest.mark.parametrize("slant_deg", [0.0, 35.0])
def test_the_carried_box_sets_a_lying_object_down_where_its_points_rest(slant_deg):
    obj = lying_cylinder(slant_deg)
    held = carried_box(obj)
    X = place_pose(obj.X_WO, held.size, (0.6, -0.3), release_height=0.01, X_OB=held.X_OB)
    np.testing.assert_allclose(X[:3, :3], obj.X_WO[:3, :3], atol=1e-15)
    # the object is set down with its lowest point 1 cm up: its axis at 4 cm + 1 cm
    assert X[2, 3] == pytest.approx(0.05, abs=2e-4)
    # the box's bottom is level: the carried box has a vertical side
    R_WB = obj.X_WO[:3, :3] @ held.X_OB[:3, :3]
    np.testing.assert_allclose(np.abs(R_WB[:, 2]), [0.0, 0.0, 1.0], atol=1e-9)
    # the perceived box, turned with O, puts a corner 4 cm·(cos + sin − 1) lower
    X_box = place_pose(obj.X_WO, obj.extents, (0.6, -0.3), release_height=0.01)
    a = np.deg2rad(slant_deg)
    assert X_box[2, 3] - X[2, 3] == pytest.approx(0.04 * (np.cos(a) + np.sin(a) - 1), abs=5e-4)


def test_without_points_the_carried_box_is_the_perceived_box():
    held = carried_box(BOX)
    np.testing.assert_array_equal(held.X_OB, np.eye(4))
    assert held.size == tuple(BOX.extents)


# A full plan with a second object next to the target, reused by the trajectory checks.
OTHER = box_object([0.62, 0.28, 0.08], [0.08, 0.08, 0.16])
PLACE_XY = (0.7, -0.3)


@pytest.fixture(scope="module")
def planned():
    c = ranked([(SIDE, "top"), (TOP, "top")])
    return plan_pick_and_place(c, target=BOX, obstacles=[OTHER], place_xy=PLACE_XY,
                               q_start=IIWA_HOME)


def test_plan_reaches_its_key_poses(planned):
    r = planned
    assert r.status == "planned", r.reason
    plan = r.plan
    assert plan.candidate == r.candidate == 0 and plan.part == "top"
    assert np.isfinite(r.costs[0]) and np.isnan(r.costs[1])
    arm = make_arm_plant()
    np.testing.assert_allclose(plan.q(0.0), IIWA_HOME, atol=1e-9)
    assert_gripper_at(arm, plan.q(plan.t_grasp_closed), SIDE)
    X_lift = SIDE.copy()
    X_lift[2, 3] += PlannerConfig().lift_height
    assert_gripper_at(arm, plan.q(plan.t_lift_done), X_lift)
    # At release the box's frame is at the place target (its grasp offset carried along).
    X_WG_place = plan.X_WO_place @ np.linalg.inv(BOX.X_WO) @ SIDE
    assert_gripper_at(arm, plan.q(plan.t_place_done), X_WG_place)
    np.testing.assert_allclose(plan.X_WO_place[:2, 3], PLACE_XY, atol=1e-12)
    # The gripper: open on the way in, closed from the grasp to the release, open at the end.
    c = PlannerConfig()
    assert plan.width(plan.t_grasp_closed - c.settle_duration - c.close_duration) == c.open_width
    assert plan.width(plan.t_grasp_closed) == c.closed_width
    assert plan.width(plan.t_lift_done) == c.closed_width
    assert plan.width(plan.t_place_done) == c.open_width
    assert plan.width(plan.duration + 1.0) == c.open_width
    assert 0 < plan.t_grasp_closed < plan.t_lift_done < plan.t_place_done < plan.duration
    # At rest at the end, and held there afterwards.
    np.testing.assert_allclose(plan.v(plan.duration), 0.0, atol=1e-9)
    np.testing.assert_allclose(plan.q(plan.duration + 5.0), plan.q(plan.duration), atol=0)


def test_the_pads_stand_open_at_the_place_before_the_retreat(planned):
    plan, c = planned.plan, PlannerConfig()
    assert plan.t_place_done - plan.t_opened == pytest.approx(c.release_dwell)
    for t in np.linspace(plan.t_opened, plan.t_place_done, 5):
        assert plan.width(t) == c.open_width
        np.testing.assert_allclose(plan.v(t), 0.0, atol=1e-9)
        np.testing.assert_allclose(plan.q(t), plan.q(plan.t_place_done), atol=1e-12)


def test_a_reseat_closes_and_opens_the_pads_at_the_place_and_delays_the_retreat(planned):
    plan, c = planned.plan, PlannerConfig()
    t_at = plan.t_opened + 0.05
    new = reseated(plan, t_at, c)
    shift = new.duration - plan.duration
    assert shift == pytest.approx(reseat_duration(c) + c.release_dwell - (plan.t_place_done - t_at))
    assert new.t_opened == pytest.approx(t_at + reseat_duration(c))
    assert new.t_place_done == pytest.approx(new.t_opened + c.release_dwell)
    # Unchanged up to the re-seat; the arm holds its place posture through it.
    for t in np.linspace(0.0, t_at, 40):
        np.testing.assert_allclose(new.q(t), plan.q(t), atol=1e-12)
        assert new.width(t) == pytest.approx(plan.width(t))
    for t in np.linspace(t_at, new.t_place_done, 20):
        np.testing.assert_allclose(new.q(t), plan.q(plan.t_place_done), atol=1e-12)
        np.testing.assert_allclose(new.v(t), 0.0, atol=1e-9)
    # The pads close on the object (the grasp's squeeze), then open again.
    assert new.width(t_at + c.close_duration + c.squeeze_duration) == c.closed_width
    assert new.width(new.t_opened) == c.open_width
    # The retreat and everything after it, delayed.
    for x in np.linspace(0.0, plan.duration - plan.t_place_done, 20):
        np.testing.assert_allclose(new.q(new.t_place_done + x), plan.q(plan.t_place_done + x),
                                   atol=1e-9)
        np.testing.assert_allclose(new.v(new.t_place_done + x), plan.v(plan.t_place_done + x),
                                   atol=1e-9)
    retreat = dict((name, (a, b)) for name, a, b, _ in new.segments)["retreat"]
    assert retreat[0] == pytest.approx(new.t_place_done)
    with pytest.raises(ValueError, match="pads open at the place"):
        reseated(plan, plan.t_place_done + 0.01, c)


def test_trajectory_keeps_velocity_and_acceleration_limits(planned):
    plan = planned.plan
    t = np.arange(0.0, plan.duration, 0.002)
    v = np.array([plan.v(ti) for ti in t])
    # The B-spline's bounds hold on its derivatives' control points, hence everywhere, up to the
    # constraint violation the planner accepts from the solver (CONSTRAINT_TOLERANCE, 1e-5).
    assert np.all(np.abs(v) <= IIWA_VELOCITY_LIMITS + CONSTRAINT_TOLERANCE)
    a = np.array([plan.q_traj.EvalDerivative(ti, 2)[:, 0] for ti in t])
    assert np.all(np.abs(a) <= PlannerConfig().free_limits.acceleration + CONSTRAINT_TOLERANCE)
    # The slower straight moves at the object keep their scaled velocity limits.
    c = PlannerConfig()
    for name, t0, t1, _ in plan.segments:
        if name in ("approach", "lift", "descend", "retreat"):
            inside = (t >= t0) & (t <= t1)
            assert np.all(np.abs(v[inside]) <= c.contact_limits.velocity_scale
                          * IIWA_VELOCITY_LIMITS + CONSTRAINT_TOLERANCE), name
    # The velocity output is the derivative of the position output (central differences over
    # 1 ms; 1e-3 rad/s covers the O(h²·jerk) error and the segment joints).
    h = 1e-3
    inner = t[(t > h) & (t < plan.duration - h)][::10]
    fd = np.array([(plan.q(ti + h) - plan.q(ti - h)) / (2 * h) for ti in inner])
    np.testing.assert_allclose(fd, np.array([plan.v(ti) for ti in inner]), atol=1e-3)


def test_trajectory_stays_clear_of_collisions(planned):
    """Each segment, sampled every 5 ms, on a plant built here independently of the planner:
    the free moves keep the arm, gripper and carried box clear of the table and both boxes; the
    moves at the object let the finger pads overlap the target's box (they straddle it)."""
    plan = planned.plan
    c = PlannerConfig()
    X_GO = RigidTransform(np.linalg.inv(SIDE) @ BOX.X_WO)
    other = ("other", RigidTransform(OTHER.X_WO), tuple(OTHER.extents))
    target = ("target", RigidTransform(BOX.X_WO), tuple(BOX.extents))
    placed = ("target", RigidTransform(plan.X_WO_place), tuple(BOX.extents))
    free = make_arm_plant(obstacles=[other, target])
    at_target = make_arm_plant(obstacles=[other, target], finger_contact=["target"])
    carrying = make_arm_plant(obstacles=[other], held=(X_GO, tuple(BOX.extents)))
    at_place = make_arm_plant(obstacles=[other, placed], finger_contact=["target"])
    plants = {"move": (free, c.min_distance), "approach": (at_target, c.contact_min_distance),
              "lift": (at_target, c.contact_min_distance),
              "carry": (carrying, c.min_distance),
              "descend": (carrying, c.contact_min_distance),
              "retreat": (at_place, c.contact_min_distance)}
    assert [s[0] for s in plan.segments] == list(plants)
    for name, t0, t1, reported in plan.segments:
        arm, min_distance = plants[name]
        d = min(clearance(arm, plan.q(t)) for t in np.arange(t0, t1, 0.005))
        # No penetration anywhere; and at least half the required clearance (the planner's
        # dense check), less 1 mm for the planner's own sample spacing (0.01 rad of a joint).
        assert d >= 0.5 * min_distance - 1e-3, (name, d)
        assert reported >= 0.5 * min_distance


def test_place_variants_turn_the_object_about_the_vertical_through_its_centre():
    from tg_drake.planning.planner import _place_variants

    X = RigidTransform(RotationMatrix.MakeXRotation(np.pi / 2), [0.75, -0.3, 0.04]).GetAsMatrix4()
    variants = _place_variants(X, PlannerConfig())
    assert len(variants) == len(PlannerConfig().place_yaws)
    np.testing.assert_allclose(variants[0], X, atol=1e-12)  # the kept orientation first
    for V, yaw in zip(variants, PlannerConfig().place_yaws, strict=False):
        np.testing.assert_allclose(V[:3, 3], X[:3, 3])
        np.testing.assert_allclose(V[2, :3], X[2, :3], atol=1e-12)  # heights of the axes kept
        turn = V[:3, :3] @ X[:3, :3].T
        assert np.degrees(np.arctan2(turn[1, 0], turn[0, 0])) == pytest.approx(yaw, abs=1e-9)


def test_the_retreat_backs_out_along_the_approach_at_the_place():
    """With the object turned about the vertical at the place, the gripper's approach turns with
    it; the retreat follows the approach at the place, not the one at the pick (which dragged a
    bottle over)."""
    from tg_drake.planning.planner import _key_poses, _place_variants

    config = PlannerConfig()
    X_WO = RigidTransform([0.75, 0.1, 0.1]).GetAsMatrix4()
    X_WG = grasp_pose([0.75, 0.1, 0.12], approach_W=[1, 0, 0], closing_W=[0, 1, 0])
    X_WO_place = place_pose(X_WO, [0.07, 0.07, 0.2], (0.6, -0.35))
    for X_place in _place_variants(X_WO_place, config):
        key = _key_poses(None, X_WG, X_WO, X_place, config)
        place, retreat = key.X["place"], key.X["retreat"]
        np.testing.assert_allclose(retreat.translation() - place.translation(),
                                   -config.retreat_distance * place.rotation().col(1), atol=1e-12)
        np.testing.assert_allclose(place.translation() + GRASP_POINT * place.rotation().col(1),
                                   [0.6, -0.35, X_place[2, 3] + 0.02], atol=1e-9)


def test_a_straight_move_onto_another_ik_branch_has_its_start_solved_again(monkeypatch):
    """The grasp's IK (seeded by the pre-grasp's) lands on a flipped wrist: the pre-grasp is
    solved again from the grasp's configuration, so the 10 cm approach is not a wrist flip."""
    from tg_drake.planning import planner
    from tg_drake.planning.ik import IkResult

    flipped = np.array([0.0, 0.3, 0.0, -1.2, -2.6, -2.0, 3.1])
    calls = []

    def fake_ik(arm, X_WG, seeds, **kwargs):
        name = next(n for n, X in key.X.items() if X is X_WG)
        calls.append((name, np.array(seeds[0])))
        if name == "grasp":
            return IkResult(True, flipped.copy(), 0.0)
        return IkResult(True, np.asarray(seeds[0], float) + 0.01, 0.0)  # near its first seed

    class Arms:
        free = grasp = "arm"

        def carry(self, X_GO):
            return "arm"

        def placed(self, X_WO):
            return "arm"

    monkeypatch.setattr(planner, "solve_ik_seeds", fake_ik)
    names = ("pre-grasp", "grasp", "lift", "pre-place", "place", "retreat")
    key = planner._KeyPoses({n: RigidTransform([0.5, 0.0, 0.1 + 0.01 * k])
                             for k, n in enumerate(names)}, RigidTransform(), np.eye(4))
    poses, failure = planner._waypoint_configurations(Arms(), key, [np.zeros(7)],
                                                      PlannerConfig())
    assert failure == ""
    assert [c[0] for c in calls] == ["pre-grasp", "grasp", "pre-grasp", "lift", "pre-place",
                                     "place", "retreat"]
    assert np.max(np.abs(poses["grasp"] - poses["pre-grasp"])) < planner.BRANCH_JUMP
    np.testing.assert_allclose(poses["pre-grasp"], flipped + 0.01)


def test_the_placed_object_is_its_part_shapes_moved_not_its_whole_box():
    """Backing out of a placed object is judged as going into it was: a side grasp on the narrow
    upper part of a wide-based object puts the gripper inside the object's box but clear of its
    parts; at the place the same grasp must be as clear (the whole box there made the retreat of
    rim and upper-part grasps fail)."""
    from tg_drake.planning.planner import _Arms, placed_shapes, target_shapes

    X_WO = np.eye(4)
    X_WO[:3, 3] = [0.70, 0.15, 0.07]
    obj = box_object(X_WO[:3, 3], [0.20, 0.20, 0.14])
    base = np.eye(4)
    base[:3, 3] = [0.70, 0.15, 0.01]
    upper = np.eye(4)
    upper[:3, 3] = [0.70, 0.15, 0.08]
    obj.part_boxes = {"bottom": PartBox(base, np.array([0.10, 0.10, 0.01])),
                      "top": PartBox(upper, np.array([0.015, 0.015, 0.06]))}
    obj.part_probabilities = {"bottom": 1.0, "top": 1.0}
    X_WO_place = np.eye(4)
    X_WO_place[:3, 3] = [0.60, -0.30, 0.07]
    moved = placed_shapes(target_shapes(obj), RigidTransform(X_WO).inverse(), X_WO_place)
    assert [name for name, _, _ in moved] == ["target_placed_bottom", "target_placed_top"]
    np.testing.assert_allclose(moved[1][1].translation(), [0.60, -0.30, 0.08], atol=1e-12)

    arms = _Arms(None, PlannerConfig().open_width, [], target_shapes(obj),
                 obj.extents, X_WO=X_WO)
    X_WG = grasp_pose([0.70, 0.15, 0.10], approach_W=[1, 0, 0], closing_W=[0, 1, 0])
    X_WG_place = X_WO_place @ np.linalg.inv(X_WO) @ X_WG
    for arm, X in ((arms.grasp, X_WG), (arms.placed(X_WO_place), X_WG_place)):
        r = solve_ik_seeds(arm, RigidTransform(X), [np.array(IIWA_HOME)], min_distance=0.003)
        assert r.success, r.reason
        assert clearance(arm, r.q) >= 0.003 - 1e-4
    # The whole box at the place would put the gripper inside it: no such configuration.
    whole = make_arm_plant(obstacles=[("box", RigidTransform(X_WO_place), tuple(obj.extents))],
                           finger_contact=["box"])
    assert not solve_ik_seeds(whole, RigidTransform(X_WG_place), [np.array(IIWA_HOME)],
                              min_distance=0.003).success


def test_a_plan_request_stops_where_its_ik_budget_runs_out():
    """Placed out of the arm's reach, every candidate is picked and fails at the place: without
    a budget all are examined; with a budget of one solve the request ends after the first
    candidate's pick and says why."""
    scene = scene_with_box([0.75, 0.1, 0.10])
    c = ranked([(SIDE, "top"), (TOP, "top"), (SIDE, "middle")])
    far = (0.0, -1.2)  # [m] beyond the arm's reach
    free = plan_task_leg(scene, c, place_xy=far, q_start=IIWA_HOME,
                         config=PlannerConfig(max_ik_solves=None))
    assert free.status == "unreachable" and not free.out_of_budget
    assert "max_ik_solves" not in free.reason
    tight = plan_task_leg(scene, c, place_xy=far, q_start=IIWA_HOME,
                          config=PlannerConfig(max_ik_solves=1))
    assert tight.status == "unreachable" and tight.out_of_budget
    assert "the planning budget of 1 inverse-kinematics solves ran out" in tight.reason
    assert 1 <= tight.ik_solves < free.ik_solves
    assert np.isnan(tight.costs).sum() > np.isnan(free.costs).sum()  # candidates not examined


def test_a_budget_that_suffices_leaves_the_plan_as_it_is():
    scene = scene_with_box([0.75, 0.1, 0.10])
    c = ranked([(SIDE, "top"), (TOP, "top")])
    plans = [plan_task_leg(scene, c, place_xy=PLACE_XY, q_start=IIWA_HOME,
                           config=PlannerConfig(max_ik_solves=n)) for n in (None, 10_000)]
    assert [r.status for r in plans] == ["planned", "planned"]
    assert plans[0].candidate == plans[1].candidate
    assert plans[0].ik_solves > 0  # (the second asks fewer: the answers without clearance
    # constraints are remembered, ik.FREE_IK_MEMO)
    np.testing.assert_array_equal(plans[0].plan.q(plans[0].plan.duration),
                                  plans[1].plan.q(plans[1].plan.duration))


def test_an_ik_budget_below_one_names_its_field():
    from tg_drake.errors import ScenarioError

    with pytest.raises(ScenarioError) as e:
        PlannerConfig(max_ik_solves=0).validate()
    assert e.value.field == "pipeline.planner.max_ik_solves"
    assert "must be >= 1 or null" in str(e.value)
