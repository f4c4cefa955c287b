"""Collision-free joint trajectories between two arm configurations (kinematic trajectory
optimisation).

One segment is a B-spline path q(t) on the arm plant (`tg_drake.planning.ik.ArmPlant`) found by
pydrake's `KinematicTrajectoryOptimization` (SNOPT): its duration is minimised subject to

- the end configurations, at rest (zero velocity) at both ends;
- the joint position limits of the plant, the iiwa's velocity limits (scaled by a factor ≤ 1) and
  acceleration limits (`SegmentLimits`);
- minimum-distance constraints between every unfiltered pair of collision geometries at
  `collision_samples` evenly spaced interior path parameters;
- for a straight-line move of the gripper (approach, lift, descent, retreat), the gripper origin
  within `line_tolerance` of the line between its end positions and the gripper orientation
  within `angle_tolerance` of the start orientation, at interior samples.

Constraints at samples say nothing about the path between them, so the solution is then checked
densely (at times no joint moves more than `check_step` between). Where the clearance falls below
`check_fraction` · `min_distance`, a minimum-distance constraint is added at that path parameter
and the problem is solved again from the previous solution, up to `max_refinements` times.

The WSG's two finger joints are part of the arm plant's positions; they are held at the arm
plant's opening (equal lower and upper bounds) and dropped from the returned trajectory, which
has the 7 iiwa joints as its rows.
"""


import time
from dataclasses import dataclass, field

import numpy as np
from pydrake.math import BsplineBasis, RigidTransform
from pydrake.multibody.inverse_kinematics import (
    MinimumDistanceLowerBoundConstraint,
    OrientationConstraint,
    PointToLineDistanceConstraint,
)
from pydrake.planning import KinematicTrajectoryOptimization
from pydrake.solvers import Solve
from pydrake.trajectories import BsplineTrajectory

from tg_drake.planning.ik import ArmPlant, clearance, satisfies_constraints
from tg_drake.robot import IIWA_VELOCITY_LIMITS  # [rad/s], joints 1–7 (the models' too)


@dataclass
class SegmentLimits:
    """Limits for one trajectory segment."""

    velocity: np.ndarray = field(default_factory=lambda: IIWA_VELOCITY_LIMITS.copy())
    # [rad/s] per iiwa joint.
    acceleration: np.ndarray = field(default_factory=lambda: np.full(7, 2.0))
    # [rad/s²] per iiwa joint. Our choice, well under the iiwa's capability: the station drives
    # the arm by joint PD (kp 2000 N·m/rad) without an acceleration feed-forward, so the tracking
    # error grows with the torque an acceleration needs (about M·a / kp: a few mrad at 2 rad/s²).
    velocity_scale: float = 1.0  # the velocity limits are multiplied by this (≤ 1).
    min_duration: float = 0.2  # [s] a segment never runs faster than this.
    max_duration: float = 20.0  # [s]


@dataclass
class SegmentConfig:
    """How a segment is optimised and checked."""

    num_control_points: int = 12  # of the B-spline path (order 4: cubic).
    collision_samples: int = 12  # minimum-distance constraints at this many path parameters.
    influence_distance: float = 0.05  # [m] pairs farther than min_distance + this are ignored.
    line_samples: int = 6  # interior samples of the straight-line constraints.
    line_tolerance: float = 0.01  # [m] allowed distance of the gripper origin from its line.
    angle_tolerance: float = 0.05  # [rad] allowed gripper rotation along a straight move.
    check_step: float = 0.01  # [rad] the dense check's spacing: the most any joint moves
    # between two checked configurations (about 1 cm at the gripper for the shoulder joints).
    check_fraction: float = 0.5  # the dense check accepts clearance ≥ this · min_distance.
    max_refinements: int = 3  # re-solves with constraints added where the check failed.


@dataclass
class Segment:
    """A solved segment, with time from 0 to `duration`."""

    success: bool
    trajectory: BsplineTrajectory | None  # rows: the 7 iiwa joints [rad]
    duration: float  # [s]
    min_clearance: float  # [m] smallest signed distance found by the dense check
    reason: str = ""
    solve_time: float = 0.0  # [s] wall time of the optimisation(s)


@dataclass
class StraightLine:
    """A straight move of the gripper origin from p_W0 to p_W1 at a fixed orientation R_WG."""

    p_W0: np.ndarray
    p_W1: np.ndarray
    R_WG: object  # pydrake.math.RotationMatrix


def plan_segment(arm: ArmPlant, q0, q1, *, min_distance: float, limits: SegmentLimits,
                 config: SegmentConfig | None = None, line: StraightLine | None = None,
                 via=()) -> Segment:
    """A time-minimal, collision-free trajectory from iiwa configuration q0 to q1 at rest.

    `via`: iiwa configurations to try as intermediate points of the initial guess when the
    straight joint-space guess does not lead to a solution (e.g. a raised posture to pass over
    obstacles). Returns `Segment(success=False, reason=...)` when no guess works.
    """
    config = config or SegmentConfig()
    q0, q1 = np.asarray(q0, float), np.asarray(q1, float)
    t_start = time.perf_counter()
    guesses = [[q0, q1]] + [[q0, np.asarray(v, float), q1] for v in via]
    reason = ""
    for knots in guesses:
        segment = _solve_with_refinement(arm, q0, q1, knots, min_distance=min_distance,
                                         limits=limits, config=config, line=line)
        if segment.success:
            segment.solve_time = time.perf_counter() - t_start
            return segment
        reason = segment.reason
    # The optimiser can stop at its iteration limit on short moves that a plain interpolation
    # does well: accept the smooth joint-space interpolation when it passes every check.
    segment = interpolated_segment(arm, q0, q1, min_distance=min_distance, limits=limits,
                                   config=config, line=line)
    if segment.success:
        segment.solve_time = time.perf_counter() - t_start
        return segment
    return Segment(False, None, np.inf, -np.inf, f"{reason}; {segment.reason}",
                   time.perf_counter() - t_start)


# The quintic rest-to-rest profile s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ (zero velocity and acceleration at
# both ends): its peak speed is 15/8 and its peak acceleration 10/√3 (for a unit move in unit time).
QUINTIC_PEAK_SPEED = 15.0 / 8.0
QUINTIC_PEAK_ACCELERATION = 10.0 / np.sqrt(3.0)


def interpolated_segment(arm: ArmPlant, q0, q1, *, min_distance: float,
                         limits: SegmentLimits, config: SegmentConfig,
                         line: StraightLine | None = None) -> Segment:
    """The straight joint-space move q0 → q1 on the quintic rest-to-rest profile, timed for the
    velocity and acceleration limits, if it passes the dense clearance check and (for a straight
    move) keeps the gripper within the line and angle tolerances; else a failed Segment."""
    q0, q1 = np.asarray(q0, float), np.asarray(q1, float)
    delta = np.abs(q1 - q0)
    v = np.asarray(limits.velocity) * limits.velocity_scale
    a = np.asarray(limits.acceleration)
    duration = float(np.clip(max(np.max(QUINTIC_PEAK_SPEED * delta / v),
                                 np.sqrt(np.max(QUINTIC_PEAK_ACCELERATION * delta / a))),
                             limits.min_duration, limits.max_duration))
    # A degree-5 Bézier with its end points tripled is exactly the quintic profile.
    basis = BsplineBasis(6, 6, initial_parameter_value=0.0, final_parameter_value=duration)
    path = BsplineTrajectory(basis, [q.reshape(-1, 1) for q in (q0, q0, q0, q1, q1, q1)])
    ts = check_times(path, config.check_step)
    d = np.array([clearance(arm, path.value(t)[:, 0]) for t in ts])
    if d.min() < config.check_fraction * min_distance:
        return Segment(False, None, np.inf, float(d.min()),
                       f"the interpolated move comes within {d.min():.4f} m of a collision")
    if line is not None:
        p0, p1 = np.asarray(line.p_W0, float), np.asarray(line.p_W1, float)
        u = (p1 - p0) / max(np.linalg.norm(p1 - p0), 1e-9)
        R_ref = line.R_WG.matrix()
        for t in ts:
            arm.plant.SetPositions(arm.plant_context, arm.full_q(path.value(t)[:, 0]))
            X = arm.G.CalcPoseInWorld(arm.plant_context)
            r = X.translation() - p0
            off_line = np.linalg.norm(r - np.dot(r, u) * u)
            angle = np.arccos(np.clip((np.trace(R_ref.T @ X.rotation().matrix()) - 1) / 2, -1, 1))
            if off_line > config.line_tolerance or angle > config.angle_tolerance:
                return Segment(False, None, np.inf, float(d.min()),
                               f"the interpolated move leaves the straight line by "
                               f"{off_line * 1000:.0f} mm / {np.rad2deg(angle):.1f}°")
    return Segment(True, path, duration, float(d.min()))


def _solve_with_refinement(arm, q0, q1, guess_knots, *, min_distance, limits, config, line
                           ) -> Segment:
    # Interior samples: the end configurations are fixed and were checked by the IK (whose
    # accepted solutions may sit a fraction of a millimetre inside the bound).
    samples = list(np.linspace(0.0, 1.0, config.collision_samples + 2)[1:-1])
    guess = _guess(arm, guess_knots, config.num_control_points, limits)
    for _ in range(config.max_refinements + 1):
        trajopt, result = _solve(arm, q0, q1, samples, guess, min_distance=min_distance,
                                 limits=limits, config=config, line=line)
        if not satisfies_constraints(result, trajopt.prog()):
            return Segment(False, None, np.inf, -np.inf,
                           f"trajectory optimisation failed ({result.get_solver_id().name()}: "
                           f"{result.get_solution_result().name})")
        path = trajopt.ReconstructTrajectory(result)
        duration = path.end_time() - path.start_time()
        ts = check_times(path, config.check_step)
        d = np.array([clearance(arm, path.value(t)[arm.iiwa_indices, 0]) for t in ts])
        bad = d < config.check_fraction * min_distance
        if not bad.any():
            return Segment(True, _iiwa_rows(path, arm.iiwa_indices), duration, float(d.min()))
        # Constrain the worst point of each run of violations, then solve again from here.
        s_bad = (ts[bad] - path.start_time()) / duration
        samples = sorted(set(samples) | {float(s) for s in s_bad[_run_minima(d[bad], bad)]})
        guess = path
    return Segment(False, None, np.inf, float(d.min()),
                   f"the path still comes within {d.min():.4f} m of a collision after "
                   f"{config.max_refinements} refinements")


def check_times(path, step: float) -> np.ndarray:
    """Times along `path` at which no joint moves more than `step` between neighbours (from
    the B-spline's control points: the path stays inside their convex hull, and its speed is
    bounded by that of the control polygon of its derivative)."""
    v = path.MakeDerivative()
    v_max = np.max(np.abs(np.hstack(v.control_points())))
    n = max(2, int(np.ceil(v_max * (path.end_time() - path.start_time()) / step)) + 1)
    return np.linspace(path.start_time(), path.end_time(), n)


def _run_minima(d_bad, bad) -> np.ndarray:
    """Indices into d_bad of the smallest value of each contiguous run of True in `bad`."""
    run_id = np.cumsum(np.diff(np.r_[0, bad.astype(int)]) == 1)[bad]
    return np.array([np.flatnonzero(run_id == r)[np.argmin(d_bad[run_id == r])]
                     for r in np.unique(run_id)], int)


def _solve(arm, q0, q1, samples, guess, *, min_distance, limits, config, line):
    plant = arm.plant
    nq = plant.num_positions()
    idx = arm.iiwa_indices
    q0_full, q1_full = arm.full_q(q0), arm.full_q(q1)
    trajopt = KinematicTrajectoryOptimization(nq, config.num_control_points, 4)
    prog = trajopt.get_mutable_prog()
    trajopt.AddDurationCost(1.0)
    trajopt.AddDurationConstraint(limits.min_duration, limits.max_duration)
    # Joint limits; the fingers stay where the arm plant holds them.
    lower, upper = arm.q_fingers.copy(), arm.q_fingers.copy()
    lower[idx] = plant.GetPositionLowerLimits()[idx]
    upper[idx] = plant.GetPositionUpperLimits()[idx]
    trajopt.AddPositionBounds(lower, upper)
    v_max, a_max = np.ones(nq), np.ones(nq)  # the fixed fingers: any finite bound.
    v_max[idx] = np.asarray(limits.velocity) * limits.velocity_scale
    a_max[idx] = limits.acceleration
    trajopt.AddVelocityBounds(-v_max, v_max)
    trajopt.AddAccelerationBounds(-a_max, a_max)
    # Start and end configurations, at rest.
    zero = np.zeros(nq)
    trajopt.AddPathPositionConstraint(q0_full, q0_full, 0.0)
    trajopt.AddPathPositionConstraint(q1_full, q1_full, 1.0)
    trajopt.AddPathVelocityConstraint(zero, zero, 0.0)
    trajopt.AddPathVelocityConstraint(zero, zero, 1.0)
    # Collision avoidance at samples of the path parameter.
    for s in samples:
        trajopt.AddPathPositionConstraint(MinimumDistanceLowerBoundConstraint(
            plant, min_distance, arm.plant_context, None, config.influence_distance), s)
    if line is not None:
        direction = np.asarray(line.p_W1, float) - np.asarray(line.p_W0, float)
        for s in np.linspace(0.0, 1.0, config.line_samples + 2)[1:-1]:
            trajopt.AddPathPositionConstraint(PointToLineDistanceConstraint(
                plant, arm.G, np.zeros(3), plant.world_frame(), np.asarray(line.p_W0, float),
                direction, 0.0, config.line_tolerance, arm.plant_context), s)
            trajopt.AddPathPositionConstraint(OrientationConstraint(
                plant, plant.world_frame(), line.R_WG, arm.G, RigidTransform().rotation(),
                config.angle_tolerance, arm.plant_context), s)
    trajopt.SetInitialGuess(guess)
    return trajopt, Solve(prog)


def _guess(arm, knots_iiwa, num_control_points, limits) -> BsplineTrajectory:
    """A B-spline through the given iiwa configurations (piecewise linear in the control points),
    lasting long enough for the velocity limits."""
    knots = np.array([arm.full_q(q) for q in knots_iiwa])
    legs = np.linalg.norm(np.diff(knots, axis=0), axis=1)
    arc = np.r_[0.0, np.cumsum(legs)] / max(legs.sum(), 1e-9)
    s = np.linspace(0.0, 1.0, num_control_points)
    control_points = np.column_stack([np.interp(s, arc, knots[:, j])
                                      for j in range(knots.shape[1])])
    v = np.asarray(limits.velocity) * limits.velocity_scale
    step = np.abs(np.diff(knots[:, arm.iiwa_indices], axis=0)).sum(axis=0)
    duration = float(np.clip(2.0 * np.max(step / v), limits.min_duration, limits.max_duration))
    basis = BsplineBasis(4, num_control_points, initial_parameter_value=0.0,
                         final_parameter_value=duration)
    return BsplineTrajectory(basis, [c.reshape(-1, 1) for c in control_points])


def _iiwa_rows(path: BsplineTrajectory, rows) -> BsplineTrajectory:
    """The same B-spline restricted to the given rows."""
    return BsplineTrajectory(path.basis(), [c[rows, :] for c in path.control_points()])


def shifted(trajectory: BsplineTrajectory, t0: float) -> BsplineTrajectory:
    """The trajectory delayed to start at t0 (same shape)."""
    basis = trajectory.basis()
    knots = np.asarray(basis.knots()) - trajectory.start_time() + t0
    return BsplineTrajectory(BsplineBasis(basis.order(), list(knots)),
                             trajectory.control_points())
