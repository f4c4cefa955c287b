"""The pass's receiver: its shape-based correction (core), `ReceiverDriver` in a small diagram."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from pydrake.math import RigidTransform
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from tg_drake.planning.handover import (
    Handover,
    ReceiverConfig,
    ReceiverGrasp,
    mount_pose,
    receiver_motion,
)
from tg_drake.receiver import ReceiverDriver, Surface, seen_correction
from tg_drake.systems.plan_messages import PlanState, PlanStatus


def cylinder(handle: bool = False, spacing: float = 0.004):
    """(p_O, n_O): a closed cylinder of radius 35 mm and height 100 mm along z_O, centred on O;
    with `handle`, a 40 × 10 × 60 mm block standing out of its side along +x_O."""
    rng = np.random.default_rng(1)
    n = int(2 * math.pi * 0.035 * 0.1 / spacing ** 2)
    a, z = rng.uniform(0, 2 * math.pi, n), rng.uniform(-0.05, 0.05, n)
    p = np.column_stack([0.035 * np.cos(a), 0.035 * np.sin(a), z])
    normals = np.column_stack([np.cos(a), np.sin(a), np.zeros(n)])
    m = int(math.pi * 0.035 ** 2 / spacing ** 2)
    for sign in (-1.0, 1.0):  # the two end discs
        r, b = 0.035 * np.sqrt(rng.random(m)), rng.uniform(0, 2 * math.pi, m)
        p = np.vstack([p, np.column_stack([r * np.cos(b), r * np.sin(b), np.full(m, 0.05 * sign)])])
        normals = np.vstack([normals, np.tile([0.0, 0.0, sign], (m, 1))])
    if handle:  # the block's two large faces (normals ±y_O) and its outer end (+x_O)
        k = int(0.04 * 0.06 / spacing ** 2)
        for sign in (-1.0, 1.0):
            q = np.column_stack([rng.uniform(0.035, 0.075, k), np.full(k, 0.005 * sign),
                                 rng.uniform(-0.03, 0.03, k)])
            p, normals = np.vstack([p, q]), np.vstack([normals, np.tile([0, sign, 0.0], (k, 1))])
        q = np.column_stack([np.full(k // 4, 0.075), rng.uniform(-0.005, 0.005, k // 4),
                             rng.uniform(-0.03, 0.03, k // 4)])
        p, normals = np.vstack([p, q]), np.vstack([normals, np.tile([1.0, 0, 0], (k // 4, 1))])
    return p, normals


def pose(roll_deg: float = 0.0, shift=(0.0, 0.0, 0.0)) -> np.ndarray:
    """The object lying along x_W at (0.6, 0, 0.3) (z_O along x_W), turned `roll_deg` about its
    own axis and shifted by `shift` [m]."""
    c, s = math.cos(math.radians(roll_deg)), math.sin(math.radians(roll_deg))
    lying = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    X = np.eye(4)
    X[:3, :3] = lying @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    X[:3, 3] = np.add([0.6, 0.0, 0.3], shift)
    return X


def test_a_roll_the_receiver_cannot_see_is_not_followed_a_shift_is():
    p, n = cylinder()
    expected = pose()
    # Rolled 50° about its axis and shifted 8 mm: the same shape 8 mm off.
    C = pose(50.0, (0.0, 0.008, 0.0)) @ np.linalg.inv(expected)
    T = seen_correction(C, expected, Surface(p, n), 0.003)
    assert np.allclose(T[:3, 3] + T[:3, :3] @ [0.6, 0, 0.3] - [0.6, 0, 0.3], [0, 0.008, 0],
                       atol=0.001)
    angle = math.degrees(math.acos(np.clip((np.trace(T[:3, :3]) - 1) / 2, -1, 1)))
    assert angle < 10.0  # the frame turned 50° (what is left is a roll the shape allows) ...
    axis = T[:3, :3] @ [1.0, 0.0, 0.0]  # ... and the axis (x_W) stays where it was
    assert math.degrees(math.acos(min(1.0, axis[0]))) < 1.0


def test_a_turn_that_moves_a_handle_is_followed_by_the_frame():
    p, n = cylinder(handle=True)
    expected = pose()
    C = pose(50.0) @ np.linalg.inv(expected)
    assert np.allclose(seen_correction(C, expected, Surface(p, n), 0.003), C)


HANDOVER = Handover(ReceiverConfig(xy=[0.6, 0.0], height=0.3, yaw=180.0), np.eye(4))


def _run(X_after: np.ndarray, surface) -> np.ndarray:
    """The receiver's commanded mount pose at its grasp (4×4) when the object, standing at
    `pose()` when the plan starts, is at X_after once the robot has arrived (t 1 s)."""
    X_WG_grasp = np.eye(4)  # the robot's grasp (the object carried with it: no move here)
    X_WR = np.eye(4)
    X_WR[:3, :3] = np.column_stack([[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]])
    X_WR[:3, 3] = [0.6, 0.0, 0.3 + 0.055]  # from above, its grasp point on the object's centre
    grasp = ReceiverGrasp(X_WR, "middle", 0, 1.0, 1.0, 1.0, 1.0)
    motion = receiver_motion(HANDOVER, grasp, t_arrive=1.0, X_WG_robot=X_WG_grasp)
    status = PlanStatus(PlanState.executing, t_plan=0.0,
                        plan=SimpleNamespace(handover=motion, X_WG_grasp=X_WG_grasp))
    builder = DiagramBuilder()
    driver = builder.AddSystem(ReceiverDriver(HANDOVER, object_body=0, surface=surface))
    diagram = builder.Build()
    simulator = Simulator(diagram)
    context = driver.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    driver.GetInputPort("plan_status").FixValue(context, status)
    driver.GetInputPort("body_poses").FixValue(context, [RigidTransform(pose())])
    simulator.AdvanceTo(0.5)  # it sees where the object stands
    driver.GetInputPort("body_poses").FixValue(context, [RigidTransform(X_after)])
    simulator.AdvanceTo(motion.times[-1] + 0.1)
    q = driver.GetOutputPort("receiver.mount").Eval(context)[:6]
    return mount_pose(q)


def test_the_receiver_driver_follows_a_shifted_object_in_a_small_diagram():
    surface = Surface(*cylinder())
    plain = _run(pose(), surface)
    shifted = _run(pose(0.0, (0.0, 0.01, 0.0)), surface)
    assert shifted[:3, 3] - plain[:3, 3] == pytest.approx([0.0, 0.01, 0.0], abs=1e-3)
    # Rolled 60° about its axis (the same shape): with the surface it stays; by the frame alone
    # it swings its grasp round the object's axis (60° from above onto the side).
    rolled = _run(pose(60.0), surface)
    assert np.allclose(rolled, plain, atol=2e-3)
    swung = _run(pose(60.0), None)
    assert not np.allclose(swung[:3, 1], plain[:3, 1], atol=0.1)
