"""One trajectory segment: the dense collision check and its refinement, straight-line moves."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.math import RigidTransform

from tg_drake.planning.ik import CONSTRAINT_TOLERANCE, clearance, make_arm_plant, solve_ik
from tg_drake.planning.trajectory import (
    IIWA_VELOCITY_LIMITS,
    SegmentConfig,
    SegmentLimits,
    StraightLine,
    plan_segment,
    shifted,
)

# The arm reaching forward and low, turned 0.7 rad to either side; a post between the two
# postures, in the way of the gripper (at about 0.39 m height) when it swings across.
LOW = np.array([0.0, 0.6, 0.0, -1.3, 0.0, 1.0, 0.0])
Q0, Q1 = LOW.copy(), LOW.copy()
Q0[0], Q1[0] = -0.7, 0.7
MIN_DISTANCE = 0.01  # [m]


@pytest.fixture(scope="module")
def arm_with_post():
    return make_arm_plant(obstacles=[("post", RigidTransform([0.72, 0.0, 0.3]), (0.1, 0.1, 0.6))])


def dense_clearance(arm, trajectory, dt=0.002):
    return min(clearance(arm, trajectory.value(t)[:, 0])
               for t in np.arange(trajectory.start_time(), trajectory.end_time(), dt))


def test_the_post_is_in_the_way(arm_with_post):
    assert clearance(arm_with_post, Q0) > MIN_DISTANCE
    assert clearance(arm_with_post, Q1) > MIN_DISTANCE
    assert clearance(arm_with_post, LOW) < 0  # half-way along the straight joint path


def test_dense_check_rejects_what_one_sample_misses(arm_with_post):
    one_sample = SegmentConfig(collision_samples=1, max_refinements=0)
    segment = plan_segment(arm_with_post, Q0, Q1, min_distance=MIN_DISTANCE,
                           limits=SegmentLimits(), config=one_sample)
    assert not segment.success
    assert "after 0 refinements" in segment.reason


def test_refinement_adds_constraints_until_the_path_is_clear(arm_with_post):
    config = SegmentConfig(collision_samples=1, max_refinements=3)
    segment = plan_segment(arm_with_post, Q0, Q1, min_distance=MIN_DISTANCE,
                           limits=SegmentLimits(), config=config)
    assert segment.success, segment.reason
    traj = segment.trajectory
    assert traj.rows() == 7
    np.testing.assert_allclose(traj.value(traj.start_time())[:, 0], Q0, atol=1e-6)
    np.testing.assert_allclose(traj.value(traj.end_time())[:, 0], Q1, atol=1e-6)
    # Checked here every 2 ms: clear by at least the planner's accepted half of min_distance,
    # less 1 mm for the planner's own check spacing (0.01 rad of a joint between checks).
    d = dense_clearance(arm_with_post, traj)
    assert d >= config.check_fraction * MIN_DISTANCE - 1e-3
    assert segment.min_clearance >= config.check_fraction * MIN_DISTANCE
    v = traj.MakeDerivative()
    for t in np.linspace(traj.start_time(), traj.end_time(), 200):
        assert np.all(np.abs(v.value(t)[:, 0]) <= IIWA_VELOCITY_LIMITS + CONSTRAINT_TOLERANCE)
    np.testing.assert_allclose(v.value(traj.start_time())[:, 0], 0.0, atol=1e-6)  # at rest
    np.testing.assert_allclose(v.value(traj.end_time())[:, 0], 0.0, atol=1e-6)


def test_straight_line_keeps_the_gripper_on_its_line():
    """A 0.15 m vertical move of the gripper. Unconstrained, the time-optimal joint path strays
    about 12 mm from the line and turns the gripper 0.03 rad; with the line constraint (3 mm) it
    does not."""
    arm = make_arm_plant()
    arm.plant.SetPositions(arm.plant_context, arm.full_q(LOW))
    X0 = arm.G.CalcPoseInWorld(arm.plant_context)
    X1 = RigidTransform(X0.rotation(), X0.translation() + [0.0, 0.0, -0.15])
    q1 = solve_ik(arm, X1, q_seed=LOW, min_distance=None)  # within 0.02 rad of X1's rotation
    assert q1.success
    config = SegmentConfig(line_tolerance=0.003, angle_tolerance=0.01)
    line = StraightLine(X0.translation(), X1.translation(), X0.rotation())
    segment = plan_segment(arm, LOW, q1.q, min_distance=0.003,
                           limits=SegmentLimits(velocity_scale=0.25), config=config, line=line)
    assert segment.success, segment.reason
    traj = segment.trajectory
    for t in np.linspace(traj.start_time(), traj.end_time(), 100):
        arm.plant.SetPositions(arm.plant_context, arm.full_q(traj.value(t)[:, 0]))
        X = arm.G.CalcPoseInWorld(arm.plant_context)
        off_line = np.linalg.norm(X.translation()[:2] - X0.translation()[:2])
        # The constraint holds at 6 interior samples; between them the smooth path bends by
        # well under 1 mm.
        assert off_line <= config.line_tolerance + 0.001
        # The end itself is only as close to X1's rotation as the IK made it (0.02 rad, and the
        # accepted constraint violation: 3e-4 rad).
        angle = (X.rotation().inverse() @ X0.rotation()).ToAngleAxis().angle()
        assert angle <= 0.02 + 3e-4


def test_shifted_delays_a_trajectory():
    arm = make_arm_plant()
    segment = plan_segment(arm, Q0, LOW, min_distance=MIN_DISTANCE, limits=SegmentLimits())
    assert segment.success, segment.reason
    late = shifted(segment.trajectory, 2.5)
    assert late.start_time() == pytest.approx(2.5, abs=1e-12)
    assert late.end_time() == pytest.approx(2.5 + segment.duration, abs=1e-12)
    for s in (0.0, 0.3, segment.duration):
        np.testing.assert_allclose(late.value(2.5 + s), segment.trajectory.value(s), atol=1e-12)
