"""The pass on arrays: the receiver's mount and hand-over geometry, its grasp chosen clear of the
robot's gripper, the part the logic names for it, and the judge of its hold."""

import dataclasses

import numpy as np
import pytest

import tg_drake.planning.handover as handover_module
from tg_drake.errors import ScenarioError
from tg_drake.grasping.feasibility import grip_width
from tg_drake.logic.receive import receiver_parts
from tg_drake.outcome import HandContact
from tg_drake.planning.handover import (
    Handover,
    ReceiverConfig,
    choose_receiver_grasp,
    handover_object_poses,
    mount_configuration,
    mount_pose,
    receiver_motion,
    robot_gripper_points,
)
from tg_drake.robot import wrist_reach_margin
from tg_drake.tasks.judge import PASS_HEIGHT_TOLERANCE, judge_pass
from tg_drake.types import PART_LABELS, GraspCandidates, ObjectDescription

# A top grasp: approach −z_W, fingers closing along y_W (across a bar lying along x_W).
R_TOP = np.column_stack([[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]])
GRASP_DEPTH = 0.055  # [m] the grasp point along +y_G (tg_drake.robot)


def top_grasp(x: float, z: float) -> np.ndarray:
    """The WSG frame whose grasp point is (x, 0, z)."""
    X = np.eye(4)
    X[:3, :3] = R_TOP
    X[:3, 3] = [x, 0.0, z + GRASP_DEPTH]
    return X


def bar(height: float) -> ObjectDescription:
    """A 240 × 25 × 25 mm bar along x_W centred at (0, 0, height): its x < 0 half the handle, the
    rest the usable area (4 mm points through its volume)."""
    g = np.arange(-0.12, 0.1201, 0.004)
    h = np.arange(-0.0125, 0.01251, 0.004)
    p = np.stack(np.meshgrid(g, h, h, indexing="ij"), axis=-1).reshape(-1, 3) + [0, 0, height]
    labels = np.where(p[:, 0] < 0, PART_LABELS.index("handle"), PART_LABELS.index("usable_area"))
    X_WO = np.eye(4)
    X_WO[2, 3] = height
    return ObjectDescription(p_W=p, n_W=np.zeros_like(p), labels=labels,
                             visible=np.ones(len(p), bool), X_WO=X_WO,
                             extents=np.array([0.24, 0.025, 0.025]), pose="sideways",
                             pose_likelihood={"sideways": 1.0}, part_probabilities={},
                             part_boxes={}, pregrasp_X_WG=np.zeros((0, 4, 4)),
                             pregrasp_parts=np.zeros(0, int), is_tool=True)


def candidates(xs) -> GraspCandidates:
    X = np.array([top_grasp(x, 0.3) for x in xs])
    parts = np.array([PART_LABELS.index("handle" if x < 0 else "usable_area") for x in xs])
    n = len(xs)
    return GraspCandidates(X_WG=X, parts=parts, p_part=np.ones(n), p_local=np.full(n, 0.5),
                           score=np.full(n, 0.5))


HANDOVER = Handover(ReceiverConfig(xy=[0.0, 0.0], height=0.3, yaw=180.0), np.eye(4))


def choose(xs, *, handover=HANDOVER, robot_x=0.07, parts=None):
    target = bar(0.3)
    return choose_receiver_grasp(
        candidates(xs), target=target, X_WO=target.X_WO, X_WO_handover=target.X_WO,
        X_WG_robot=top_grasp(robot_x, 0.3),
        receiver_parts=parts or {"handle": 0.9, "usable_area": 0.1}, handover=handover,
        table_z=0.0, retreat=0.1)


def test_the_receiver_takes_the_handle_clear_of_the_robots_gripper():
    grasp, why = choose([-0.07, 0.04, 0.09])
    assert why == "" and grasp is not None
    assert grasp.part == "handle" and grasp.candidate == 0
    # The candidate itself or one of its turns about its pads' width (the same grasp point,
    # approaching from a side), whichever P(hold) ranks first.
    from tg_drake.planning.handover import turned_about_width
    X = top_grasp(-0.07, 0.3)
    assert any(np.allclose(grasp.X_WR, V) for V in [X, *turned_about_width(X)])
    assert 0.0 < grasp.p_hold <= 1.0 and grasp.score == pytest.approx(
        0.9 * 0.5 * grasp.p_hold)


def test_no_receiver_grasp_clear_of_the_robots_fingers_is_said_so():
    # Both candidates lie where the robot's housing and pads are (x 0.045 … 0.095 m).
    grasp, why = choose([0.06, 0.08], parts={"usable_area": 1.0})
    assert grasp is None
    assert "clear of the robot's gripper" in why and "other object" in why


def test_a_receiver_grasp_that_would_push_the_held_object_is_refused(monkeypatch):
    # The grasp point 35 mm under the bar's axis: the housing's face (39.9 mm above the grasp
    # point) reaches 7.6 mm into the 25 mm bar, which hangs in the robot's grip. (Its axis z_O
    # along the bar, x_W: the receiver's grasps keep their height.)
    target = bar(0.3)
    X_WO = target.X_WO.copy()
    X_WO[:3, :3] = np.column_stack([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    target = dataclasses.replace(target, X_WO=X_WO)
    deep = GraspCandidates(X_WG=np.array([top_grasp(-0.07, 0.265)]),
                           parts=np.array([PART_LABELS.index("handle")]), p_part=np.ones(1),
                           p_local=np.full(1, 0.5), score=np.full(1, 0.5))

    def receive():
        return choose_receiver_grasp(
            deep, target=target, X_WO=target.X_WO, X_WO_handover=target.X_WO,
            X_WG_robot=top_grasp(0.07, 0.3), receiver_parts={"handle": 1.0},
            handover=HANDOVER, table_z=0.0, retreat=0.1)

    # Turned about its pads' width axis it comes in from the side, its housing clear: taken so.
    grasp, why = receive()
    assert grasp is not None and abs(grasp.X_WR[2, 1]) < 1e-9, why
    # Not turned, nothing is left.
    monkeypatch.setattr(handover_module, "TURNS", ())
    grasp, why = receive()
    assert grasp is None
    assert "would push the object in the robot's grip" in why and "housing" in why


def test_the_receiver_keeps_its_clearance_from_the_robots_gripper():
    # The robot's housing spans x 0.045 … 0.095 m (its grasp at x 0.07, the housing 50 mm along
    # the pads' width, x_W here); a receiver's at x 0.018 m ends at 0.043 m: 2 mm from it. (The
    # receiver waits on the −x side, its way in clear of the robot's gripper.)
    target = bar(0.3)

    def receive(clearance):
        handover = Handover(ReceiverConfig(xy=[0.0, 0.0], height=0.3, yaw=0.0,
                                           clearance=clearance), np.eye(4))
        return choose_receiver_grasp(
            candidates([0.018]), target=target, X_WO=target.X_WO, X_WO_handover=target.X_WO,
            X_WG_robot=top_grasp(0.07, 0.3), receiver_parts={"usable_area": 1.0},
            handover=handover, table_z=0.0, retreat=0.1)

    assert receive(0.0)[0] is not None
    grasp, why = receive(0.003)
    assert grasp is None and "clear of the robot's gripper" in why
    # 1 mm into the robot's housing: refused at no clearance too (its geometry is exact: the
    # perceived points' 2 mm tolerance does not apply).
    handover = Handover(ReceiverConfig(xy=[0.0, 0.0], height=0.3, yaw=0.0), np.eye(4))
    grasp, why = choose_receiver_grasp(
        candidates([0.021]), target=target, X_WO=target.X_WO, X_WO_handover=target.X_WO,
        X_WG_robot=top_grasp(0.07, 0.3), receiver_parts={"usable_area": 1.0},
        handover=handover, table_z=0.0, retreat=0.1)
    assert grasp is None and "clear of the robot's gripper" in why


def test_a_receiver_that_cannot_reach_is_said_so():
    short = Handover(ReceiverConfig(xy=[0.0, 0.0], height=0.3, yaw=180.0, reach=0.3), np.eye(4))
    grasp, why = choose([-0.07], handover=short)
    assert grasp is None and "cannot reach" in why and "reach 0.3 m" in why


def test_a_receiver_approaching_only_from_its_side_refuses_top_grasps():
    side = Handover(ReceiverConfig(xy=[0.0, 0.0], height=0.3, yaw=180.0,
                                   max_approach_angle=45.0), np.eye(4))
    grasp, why = choose([-0.07], handover=side)
    assert grasp is None and "within 45°" in why


def test_the_robots_gripper_points_fill_the_band_its_pads_open_through():
    # Holding the 25 mm bar, the pads' inner faces are ±12.5 mm from the grasp point (along y_W
    # here); they open to ±55 mm. A receiver's pad placed between (y 30 mm, at the grasp point)
    # would be struck as the robot opens: the band is filled only given the grip width.
    probe = np.array([0.0, 0.03, 0.3])
    open_only = robot_gripper_points(top_grasp(0.0, 0.3), retreat=0.1)
    holding = robot_gripper_points(top_grasp(0.0, 0.3), retreat=0.1, closed_width=0.025)
    assert np.linalg.norm(open_only - probe, axis=1).min() > 0.02
    assert np.linalg.norm(holding - probe, axis=1).min() <= 0.005
    # Nothing of the band lies between the holding pads, where the object is.
    inner = holding[(np.abs(holding[:, 1]) < 0.0125 - 1e-9) & (np.abs(holding[:, 2] - 0.3) < 0.04)]
    assert len(inner) == 0


def test_the_grip_width_is_the_span_of_the_points_between_the_pads():
    target = bar(0.3)  # its points 4 mm apart across its 25 mm: −12.5 … +11.5 mm
    assert grip_width(top_grasp(0.07, 0.3), target.p_W, 0.11) == pytest.approx(0.024, abs=1e-9)
    assert grip_width(top_grasp(0.5, 0.3), target.p_W, 0.11) == 0.0  # past its end


def test_the_robots_gripper_points_fill_its_housing_and_open_pads_swept_back():
    p = robot_gripper_points(top_grasp(0.0, 0.3), retreat=0.1)
    # The housing is 146 mm along the closing axis (y_W here); the pads open to 110 mm, their
    # outer faces at ±(0.055 + 0.012) m, within it.
    assert np.abs(p[:, 1]).max() == pytest.approx(0.073, abs=1e-6)
    grown = robot_gripper_points(top_grasp(0.0, 0.3), retreat=0.1, grow=0.005)
    assert np.abs(grown[:, 1]).max() == pytest.approx(0.078, abs=1e-6)
    below = p[p[:, 2] < 0.3 + GRASP_DEPTH - 0.0151]  # under the housing: the pads only
    assert np.abs(below[:, 1]).max() == pytest.approx(0.067, abs=1e-6)
    # The retreat sweeps it 0.1 m up (−y_G = +z_W); the fingertips reach the grasp point's
    # −0.041 m below it.
    assert p[:, 2].min() == pytest.approx(0.3 + GRASP_DEPTH - 0.096, abs=1e-6)
    # The housing's back face 0.0213 + 0.0725 / 2 m behind G (tg_drake.robot).
    assert p[:, 2].max() == pytest.approx(0.3 + GRASP_DEPTH + 0.05755 + 0.1, abs=1e-6)


@pytest.mark.parametrize("seed", range(5))
def test_the_mount_configuration_inverts_the_mount_pose(seed):
    rng = np.random.default_rng(seed)
    q = np.concatenate([rng.uniform(-1, 1, 3), rng.uniform(-3, 3, 1), rng.uniform(-1.4, 1.4, 1),
                        rng.uniform(-3, 3, 1)])
    assert np.allclose(mount_pose(mount_configuration(mount_pose(q))), mount_pose(q))
    assert np.allclose(mount_configuration(mount_pose(q), near=q), q)


def test_the_receiver_waits_back_and_above_the_hand_over_point():
    X_WT = np.eye(4)
    X_WT[:3, 3] = [0.75, 0.0, 0.0]
    h = Handover(ReceiverConfig(xy=[-0.15, 0.0], height=0.3, yaw=90.0), X_WT)
    assert np.allclose(h.point, [0.6, 0.0, 0.3])
    assert np.allclose(h.direction, [0.0, 1.0, 0.0], atol=1e-12)
    X = h.X_WR_wait
    assert np.allclose(X[:3, 3], [0.6, -0.3, 0.75])
    assert np.allclose(X[:3, 1], h.direction) and np.allclose(X[:3, :3].T @ X[:3, :3], np.eye(3))
    assert np.allclose(h.object_pose(np.eye(4))[:3, 3], h.point)


def test_the_receivers_motion_reaches_its_grasp_then_closes():
    grasp, _ = choose([-0.07])
    motion = receiver_motion(HANDOVER, grasp, t_arrive=20.0, t_earliest=5.0)
    q_wait = mount_configuration(HANDOVER.X_WR_wait)
    # It waits while the robot carries (the arm moving past), and leaves once it has arrived.
    for t in (5.0, 19.9, 20.0):
        assert np.allclose(motion.configuration(t), q_wait)
    assert np.allclose(motion.velocity(5.0), 0.0)
    assert np.allclose(mount_pose(motion.configuration(motion.times[-1] + 1)), grasp.X_WR)
    t_pre = motion.times[2]
    assert motion.times[1] == pytest.approx(20.0) and t_pre > 20.5 and motion.t_arrive == 20.0
    assert motion.times[3] == pytest.approx(t_pre + HANDOVER.config.look)
    X_pre = mount_pose(motion.configuration(t_pre))
    assert np.allclose(X_pre[:3, 3], grasp.X_WR[:3, 3] - 0.1 * grasp.X_WR[:3, 1])
    assert motion.width(t_pre) == pytest.approx(0.11)
    assert motion.width(motion.t_closed) == pytest.approx(-0.04)
    assert motion.t_closed > motion.times[-1]


def test_a_receiver_with_a_bad_field_is_refused_naming_it():
    with pytest.raises(ScenarioError, match="receiver.max_approach_angle"):
        ReceiverConfig(max_approach_angle=0.0).validate()
    with pytest.raises(ScenarioError, match="receiver.xy"):
        ReceiverConfig(xy=[0.0, float("nan")]).validate()


def test_the_logic_names_the_handle_of_a_tool_for_the_receiver():
    parts = receiver_parts({"knife": 1.0}, held="usable_area", parts=("handle", "usable_area"))
    assert list(parts) == ["handle", "usable_area"] and parts["handle"] == pytest.approx(0.9)
    held = receiver_parts({"knife": 1.0}, held="handle", parts=("handle", "usable_area"))
    assert held == pytest.approx({"handle": 0.7, "usable_area": 0.3})
    # Category probabilities whose rounding would sum above 1 are accepted.
    near = receiver_parts({"knife": 0.5000005, "hammer": 0.4999995}, held="usable_area",
                          parts=("handle", "usable_area"))
    assert near["handle"] == pytest.approx(0.9)
    # A cup held by its middle is taken by its middle's other side first.
    cup = receiver_parts({"cup": 1.0}, held="middle", parts=("top", "middle", "bottom"))
    assert max(cup, key=cup.get) == "middle" and sum(cup.values()) == pytest.approx(1.0)


def judged(**changes):
    """judge_pass of a receiver squeezing the object with 40 N per pad, 20 mm apart, unless
    `changes` say otherwise (the receiver's fields by their HandContact names)."""
    receiver = dict(opening=0.02, left=True, right=True, hydroelastic=2, squeeze_left=40.0,
                    squeeze_right=40.0)
    receiver.update({k: changes.pop(k) for k in list(changes) if k in receiver})
    args = dict(receiver=HandContact(**receiver), robot_touches=False, on_table=False,
                z_W=[0.3, 0.2995, 0.2992], held_for=1.0)
    args.update(changes)
    return judge_pass(**args)


def test_judge_pass_success_is_the_receivers_steady_hold_alone():
    ok = judged()
    assert ok.task == "pass" and ok.success, ok
    assert ok.measure["height_change_m"] == pytest.approx(0.0008)
    assert ok.measure["receiver_held"] is True
    # A thin blade squeezed by the compliant pads leaves the fingers at their closed limit: held.
    assert judged(opening=0.0, squeeze_left=12.0, squeeze_right=12.0).success
    # The check's time is a sum of the plan's segment times: a hold of exactly the duration,
    # measured a rounding short of it, is the whole hold (a run measured 1 s − 2e-15 s).
    assert judged(held_for=1.0 - 2e-15).success
    assert not judged(held_for=1.0 - 1e-3).success


@pytest.mark.parametrize("change, words", [
    (dict(right=False, squeeze_right=0.0), "right pad not touching"),
    # Fingers at their closed limit, the object pressing on a pad's outside (pushing it inwards).
    (dict(opening=0.0, squeeze_left=-5.0), "closed on air"),
    (dict(squeeze_right=0.3), "does not push both pads apart"),
    (dict(robot_touches=True), "robot's pads"),
    (dict(on_table=True), "touches the table"),
    (dict(held_for=0.5), "only 0.50 s"),
    (dict(z_W=[0.3, 0.3 - 2 * PASS_HEIGHT_TOLERANCE]), "slipped"),
])
def test_judge_pass_failures_say_why(change, words):
    outcome = judged(**change)
    assert not outcome.success and words in outcome.detail, outcome


def test_a_turned_receiver_grasp_keeps_its_grasp_point_and_closes_across_the_approach():
    from tg_drake.planning.handover import turned_about_width

    X = top_grasp(-0.07, 0.3)
    for V in turned_about_width(X):
        assert np.allclose(V[:3, 3] + GRASP_DEPTH * V[:3, 1], [-0.07, 0.0, 0.3])
        assert np.allclose(V[:3, 2], X[:3, 2])  # the pads' width axis kept
        assert abs(V[:3, 0] @ X[:3, 1]) == pytest.approx(1.0)  # closes along the old approach


def side_grasp(p, approach) -> np.ndarray:
    """A WSG frame at p approaching horizontally along `approach` (fingers closing across it, the
    pads' width vertical)."""
    y = np.asarray(approach, float) / np.linalg.norm(approach)
    z = np.array([0.0, 0.0, 1.0])
    X = np.eye(4)
    X[:3, :3] = np.column_stack([np.cross(y, z), y, z])
    X[:3, 3] = p
    return X


def test_the_wrist_reach_margin_is_the_distance_inside_the_arms_shell():
    # The shoulder at 0.36 m above the base; the wrist centre 0.195 m behind G; the elbow's
    # ±120° range leaves the wrist 0.41–0.82 m from the shoulder.
    far = side_grasp([0.6 + 0.195, 0.0, 0.36], [1.0, 0.0, 0.0])  # wrist 0.6 m out
    assert wrist_reach_margin(far) == pytest.approx(0.6 - 0.4104, abs=1e-3)  # the nearer bound
    folded = side_grasp([0.3 + 0.195, 0.0, 0.36], [1.0, 0.0, 0.0])  # wrist 0.3 m out
    assert wrist_reach_margin(folded) == pytest.approx(0.3 - 0.4104, abs=1e-3)
    stretched = side_grasp([0.9 + 0.195, 0.0, 0.36], [1.0, 0.0, 0.0])
    assert wrist_reach_margin(stretched) == pytest.approx(0.82 - 0.9, abs=1e-3)


def test_hand_over_points_out_of_the_arms_reach_for_the_grasp_are_left_out():
    # An upright can held from the robot's side (approach +x) at the default hand-over point
    # (0.6 m out, 0.3 m up): the wrist 0.25 m from the shoulder, inside the folded arm's reach;
    # the point moved out and turned yaws that bring the wrist out of the fold remain.
    handover = Handover(ReceiverConfig(), np.array([[1, 0, 0, 0.75], [0, 1, 0, 0],
                                                    [0, 0, 1, 0], [0, 0, 0, 1.0]]))
    X_WO = np.eye(4)
    X_WO[:3, 3] = [0.7, 0.0, 0.06]
    X_WG = side_grasp([0.7 - 0.055, 0.0, 0.07], [1.0, 0.0, 0.0])
    poses = handover_object_poses(handover, X_WO, X_WG, yaws_deg=[0.0, 60.0, 180.0], lift=0.15,
                                  retreat=0.1)
    assert poses
    for X in poses:
        G = X @ np.linalg.inv(X_WO) @ X_WG
        assert wrist_reach_margin(G) >= 0.0
    at_point = [X for X in poses if np.allclose(X[:3, 3], handover.point)]
    yawed_0 = [X for X in at_point if np.allclose(X[:3, :3], np.eye(3))]
    assert not yawed_0  # held from the robot's side, straight at the point: too folded
    assert wrist_reach_margin(handover.object_pose(X_WO) @ np.linalg.inv(X_WO) @ X_WG) < 0.0
    # Some pose of the list lies out along the robot's radial direction from the point.
    assert any(X[0, 3] > handover.point[0] + 0.05 for X in poses)


def lying_can(stray: int = 3) -> ObjectDescription:
    """A can lying along x_W (its axis z_O = x_W), 10 cm long, radius 3.5 cm, centred at the
    origin: its upper half observed, the lower half completed, and the completed cloud pushed
    2 cm past each end (invisible points); `stray` observed points 2 cm past the +x end."""
    s = np.linspace(-0.05, 0.05, 101)
    a = np.linspace(0.0, np.pi, 19)
    S, A = np.meshgrid(s, a, indexing="ij")
    seen = np.column_stack([S.ravel(), 0.035 * np.cos(A.ravel()), 0.035 * np.sin(A.ravel())])
    far = np.column_stack([np.linspace(-0.07, 0.07, 141), np.zeros(141), np.full(141, -0.035)])
    odd = np.tile([0.07, 0.0, 0.035], (stray, 1))
    p = np.concatenate([seen, far, odd])
    visible = np.concatenate([np.ones(len(seen), bool), np.zeros(len(far), bool),
                              np.ones(stray, bool)])
    X_WO = np.eye(4)
    X_WO[:3, :3] = np.column_stack([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    return ObjectDescription(p_W=p, n_W=np.zeros_like(p), labels=np.zeros(len(p), int),
                             visible=visible, X_WO=X_WO, extents=np.array([0.07, 0.07, 0.14]),
                             pose="sideways", pose_likelihood={"sideways": 1.0},
                             part_probabilities={}, part_boxes={},
                             pregrasp_X_WG=np.zeros((0, 4, 4)), pregrasp_parts=np.zeros(0, int))


def test_receiver_grasps_are_moved_onto_the_objects_observed_length():
    from tg_drake.planning.handover import observed_length, onto_observed_length

    can = lying_can()
    lo, hi = observed_length(can)
    assert lo == pytest.approx(-0.05, abs=0.002) and hi == pytest.approx(0.05, abs=0.002)
    # A top grasp closing across the axis at the completed end (x = 6.5 cm): its pads (2 cm wide
    # along the axis) end within the observed end; one at the middle stays; an end grasp
    # approaching along the axis keeps its grasp point at the observed end.
    across = top_grasp(0.065, 0.0)  # its pads' width axis z_G along −x_W: the can's axis
    middle = top_grasp(0.0, 0.0)
    end = side_grasp([0.09, 0.0, 0.0], [-1.0, 0.0, 0.0])  # grasp point at 9 - 5.5 = 3.5 cm
    end_far = side_grasp([0.12, 0.0, 0.0], [-1.0, 0.0, 0.0])  # grasp point at 6.5 cm
    moved = onto_observed_length(np.array([across, middle, end, end_far]), can)
    point = moved[:, :3, 3] + GRASP_DEPTH * moved[:, :3, 1]
    assert point[0] == pytest.approx([hi - 0.01, 0.0, 0.0], abs=1e-9)
    assert np.allclose(moved[1], middle) and np.allclose(moved[2], end)
    assert point[3] == pytest.approx([hi, 0.0, 0.0], abs=1e-9)
    assert np.allclose(moved[:, :3, :3], np.array([across, middle, end, end_far])[:, :3, :3])


def test_the_receiver_keeps_clear_of_the_robots_arm():
    # Free of the robot's gripper, the handle grasp at x = −0.07 is taken; with an arm link's
    # points where its pads would be, it is refused and the one at −0.10 taken instead.
    grasp, _ = choose([-0.07, -0.10])
    assert grasp is not None and grasp.candidate == 0
    target = bar(0.3)
    link = np.array([[-0.07, y, 0.3 + dz] for y in np.linspace(-0.06, 0.06, 25)
                     for dz in np.linspace(0.02, 0.06, 9)])  # a wall above the handle at −7 cm
    grasp, _ = choose_receiver_grasp(
        candidates([-0.07, -0.10]), target=target, X_WO=target.X_WO, X_WO_handover=target.X_WO,
        X_WG_robot=top_grasp(0.07, 0.3), receiver_parts={"handle": 0.9, "usable_area": 0.1},
        handover=HANDOVER, table_z=0.0, retreat=0.1, arm_p_W=link)
    assert grasp is not None and grasp.candidate == 1


def test_the_part_touched_is_read_off_the_labelled_mesh_in_the_objects_frame():
    from tg_drake.outcome import part_touched

    # Two labelled vertices along the object's x: a handle at −0.1 m, a usable area at +0.1 m.
    V = np.array([[-0.1, 0.0, 0.0], [0.1, 0.0, 0.0]])
    handle, blade = PART_LABELS.index("handle"), PART_LABELS.index("usable_area")
    labels = np.array([handle, blade])
    X_WO = np.eye(4)
    X_WO[:3, :3] = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]  # 90° about z
    X_WO[:3, 3] = [0.5, 0.0, 0.3]
    # Pads touching at world (0.5, −0.09, 0.3) ± 1 cm: the object's x = −0.09 m, its handle.
    points = [np.array([0.5, -0.09, 0.31]), np.array([0.5, -0.09, 0.29])]
    assert part_touched(points, X_WO, V, labels) == handle
    assert part_touched([np.array([0.5, 0.08, 0.3])], X_WO, V, labels) == blade
    assert part_touched([], X_WO, V, labels) is None
    assert part_touched(points, X_WO, None, None) is None


def test_judge_pass_reports_the_part_the_receiver_holds():
    ok = judged(received_part="handle")
    assert ok.success and ok.measure["received_part"] == "handle"
    assert "by its handle" in ok.detail
    assert judged().measure["received_part"] == ""


def test_a_container_is_not_squeezed_end_to_end_along_gravity_by_the_receiver():
    """The bar seen as a container standing on its axis (not a tool, its frame's z vertical): the
    turns of the top grasps on its body (here its middle) that would close along the vertical,
    its axis, are not taken; as a tool the same turns are allowed (a handle squeezed from above
    and below), and so they are on a container's handle (a pan's, standing out sideways: the pads
    across the handle alone)."""
    import dataclasses

    container = dataclasses.replace(bar(0.3), is_tool=False)
    body = candidates([-0.07, -0.10])
    body = dataclasses.replace(body, parts=np.full(2, PART_LABELS.index("middle")))
    kept = {}
    for name, target, cands, parts in (
            ("container body", container, body, {"middle": 1.0}),
            ("container handle", container, candidates([-0.07, -0.10]), {"handle": 1.0}),
            ("tool handle", bar(0.3), candidates([-0.07, -0.10]), {"handle": 1.0})):
        grasp, why = choose_receiver_grasp(
            cands, target=target, X_WO=target.X_WO, X_WO_handover=target.X_WO,
            X_WG_robot=top_grasp(0.07, 0.3), receiver_parts=parts, handover=HANDOVER,
            table_z=0.0, retreat=0.1)
        assert grasp is not None, why
        kept[name] = grasp.X_WR
    # The container's receiver closes across, not along, the vertical on its body ...
    assert abs(kept["container body"][2, 0]) < 0.5
    # ... and as on a tool's on its handle, where it takes the vertical closing.
    assert np.allclose(kept["container handle"], kept["tool handle"])
    assert abs(kept["tool handle"][2, 0]) > 0.9


def test_the_receiver_is_refused_what_the_robot_would_be_refused(monkeypatch):
    """The geometric refusals of the robot's grasps apply to the receiver's (those of an object
    on the table aside): here fingers closing along an 80 mm rod, 12 mm thick, held in the air.
    Without the refusal the same pose would be taken."""
    from tg_drake.types import PartBox

    g = np.arange(-0.04, 0.0401, 0.003)
    h = np.arange(-0.006, 0.00601, 0.003)
    p = np.stack(np.meshgrid(g, h, h, indexing="ij"), axis=-1).reshape(-1, 3) + [0, 0, 0.3]
    X_WO = np.eye(4)
    X_WO[2, 3] = 0.3
    X_WB = X_WO.copy()
    rod = ObjectDescription(
        p_W=p, n_W=np.zeros_like(p), labels=np.full(len(p), PART_LABELS.index("handle")),
        visible=np.ones(len(p), bool), X_WO=X_WO, extents=np.array([0.08, 0.012, 0.012]),
        pose="sideways", pose_likelihood={"sideways": 1.0}, part_probabilities={"handle": 1.0},
        part_boxes={"handle": PartBox(X_WB, np.array([0.04, 0.006, 0.006]))},
        pregrasp_X_WG=np.zeros((0, 4, 4)), pregrasp_parts=np.zeros(0, int), is_tool=True)
    along = np.eye(4)  # from above, closing along x_W (the rod's length)
    along[:3, :3] = np.column_stack([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    along[:3, 3] = [0.0, 0.0, 0.3 + GRASP_DEPTH]
    cands = GraspCandidates(X_WG=along[None], parts=np.array([PART_LABELS.index("handle")]),
                            p_part=np.ones(1), p_local=np.full(1, 0.5), score=np.full(1, 0.5))
    monkeypatch.setattr(handover_module, "TURNS", ())

    def receive():
        return choose_receiver_grasp(
            cands, target=rod, X_WO=X_WO, X_WO_handover=X_WO, X_WG_robot=top_grasp(0.4, 0.3),
            receiver_parts={"handle": 1.0}, handover=HANDOVER, table_z=0.0, retreat=0.1)

    grasp, why = receive()
    assert grasp is None and "close along the 0.080 m" in why, why
    monkeypatch.setattr(handover_module, "geometric_refusal", lambda *a, **k: "")
    grasp, why = receive()
    assert grasp is not None, why


def test_a_receiver_whose_way_in_crosses_the_robots_arm_is_refused():
    """An arm link stands as a wall of points at x 0.15 m (y ±0.1 m, z 0.35 … 0.8 m): waiting on
    the +x side (yaw 180°: it moves along −x) the receiver would pass through it on its way to a
    grasp at x 0.018 m; from the −x side (yaw 0°) the same grasp is taken. The transit's poses
    run from where it waits to the pre-grasp, no point of its open gripper moving more than
    TRANSIT_STEP between two."""
    from tg_drake.grasping.feasibility import gripper_boxes
    from tg_drake.planning.handover import TRANSIT_STEP, transit_poses

    target = bar(0.3)
    g = np.arange(-0.1, 0.1001, 0.005)
    h = np.arange(0.35, 0.8001, 0.005)
    wall = np.stack(np.meshgrid([0.15], g, h, indexing="ij"), axis=-1).reshape(-1, 3)
    outcome = {}
    for yaw in (180.0, 0.0):
        handover = Handover(ReceiverConfig(xy=[0.0, 0.0], height=0.3, yaw=yaw), np.eye(4))
        outcome[yaw] = choose_receiver_grasp(
            candidates([0.018]), target=target, X_WO=target.X_WO, X_WO_handover=target.X_WO,
            X_WG_robot=top_grasp(0.07, 0.3), receiver_parts={"usable_area": 1.0},
            handover=handover, table_z=0.0, retreat=0.1, arm_p_W=wall)
        X = transit_poses(handover, top_grasp(0.018, 0.3))
        assert np.allclose(X[0], handover.X_WR_wait)
        pre = top_grasp(0.018, 0.3)
        pre[:3, 3] -= handover.config.approach * pre[:3, 1]
        assert np.allclose(X[-1], pre, atol=1e-9)
        corners = np.array([c + s * h for _, c, h in gripper_boxes(0.11)
                            for s in np.array(np.meshgrid(*[(-1, 1)] * 3)).reshape(3, -1).T])
        p = np.einsum("nij,kj->nki", X[:, :3, :3], corners) + X[:, None, :3, 3]
        assert np.linalg.norm(np.diff(p, axis=0), axis=2).max() <= TRANSIT_STEP + 1e-9
    grasp, why = outcome[180.0]
    assert grasp is None and "would cross the robot's arm" in why
    assert outcome[0.0][0] is not None, outcome[0.0][1]
