"""The pass: the robot carries the object to a hand-over pose, a second gripper takes it.

    handover = Handover(config=ReceiverConfig(), X_WT=X_WT)
    X_WO_handover = handover.object_pose(X_WO)            # the object's box centre at the point
    grasp = choose_receiver_grasp(candidates, target=obj, X_WO=X_WO, X_WO_handover=X,
                                  X_WG_robot=X_WG_place, receiver_parts={"handle": 0.9, ...},
                                  handover=handover, table_z=z)
    motion = receiver_motion(handover, grasp.X_WR, t_start=t_arrive)

The receiver is a WSG 50 (its frame R is the WSG frame G of tg_drake.robot: fingers close along
±x_R, it approaches along +y_R) on a kinematic mount (tg_drake.receiver): three prismatic joints
along the world's axes and three revolute joints, so that X_WR = translation(x, y, z) ·
Rz(yaw) · Ry(pitch) · Rx(roll) (`mount_pose`, `mount_configuration`).

Geometry (`ReceiverConfig`, the scenario's `receiver` block, table frame): the hand-over point
(`xy`, `height` above the table top) is where the object's box centre is handed over, its
orientation as picked (the planner's place yaws turn it about the vertical). The receiver comes
along the horizontal direction `yaw` (0: the table's +x, away from the robot; 180: towards the
robot) and waits, before and while the robot carries, `standoff` back along that direction and
`rise` above the point (out of the camera's view and above perception's height band, so that the
scene it perceives is the table's). Its mount reaches at most `reach` from where it waits.

The receiver's grasp (`choose_receiver_grasp`): the grasp candidates on the parts the logic names
for a receiver (`tg_drake.logic.receive.receiver_parts`, given the part the robot holds), moved
along the object's axis onto its observed length (`onto_observed_length`: the part boxes come from
the completed cloud, whose ends may lie past the object's), carried with the object into its
hand-over pose, each also turned ±90° about its pads' width axis (`turned_about_width`: from the
sides the table closed); those whose approach is within `max_approach_angle` of the receiver's
direction and within its reach are checked by the feasibility core
(`tg_drake.grasping.feasibility.grasp_feasibility`): clear of the robot's gripper by `clearance`
(the planner's clearance near the target) — its housing and its pads open, swept back along the
robot's retreat, and the band its pads pass through from holding the object to open —, of the robot
arm's links where the arm stands at the hand-over (the planner's IK) and of the table, with
something between the pads, and its housing and open pads clear of the object on the approach
(`_pushes`: held by the robot, the object would be pushed round in its grip). Chosen: the best
P(part) · P(grasp | local shape) · P(hold) among those whose contact mechanics carry the weight
(combined margin ≥ 1), else among all.

The receiver's motion (`receiver_motion`, mount joint space, smooth in time): once the robot has
arrived, from where it waits to its pre-grasp (`approach` back along +y_R from the grasp), a
straight approach, the fingers close as the robot's do, and it holds; the robot opens and
retreats meanwhile (the planner).

Arrays in, arrays out: no Drake.
"""



import math
from dataclasses import dataclass, field

import numpy as np

from tg_drake.errors import ScenarioError
from tg_drake.grasping.feasibility import (
    FeasibilityConfig,
    boxes_reach,
    closing_sweep,
    deepest_cuts,
    grasp_feasibility,
    grip_width,
    gripper_boxes,
    others_hit,
)
from tg_drake.grasping.pads import (
    GRASP_DEPTH,  # [m] the grasp point along +y_G
    geometric_refusal,
)
from tg_drake.robot import WSG_GRASP_POINT_G, WSG_MAX_OPENING, WSG_PAD_SIZE, wrist_reach_margin
from tg_drake.tasks.judge import PASS_HOLD_DURATION
from tg_drake.types import PART_LABELS, GraspCandidates, ObjectDescription, moved_rigidly

UP = np.array([0.0, 0.0, 1.0])


@dataclass
class ReceiverConfig:
    """The receiver of a pass (the scenario's `receiver` block; lengths in the table frame)."""

    xy: list[float] = field(default_factory=lambda: [-0.15, 0.0])  # [m] the hand-over point on
    # the table (the object's box centre is handed over above it); default: 0.6 m in front of the
    # robot's base, where the arm carries comfortably
    height: float = 0.3  # [m] of the hand-over point above the table top
    yaw: float = 180.0  # [deg] about the table normal: the direction the receiver moves in to
    # take the object (0: the table's +x, away from the robot; 180: towards the robot, a person
    # across the table)
    standoff: float = 0.3  # [m] it waits this far back along its direction from the point ...
    rise: float = 0.45  # [m] ... and this far above it
    reach: float = 0.8  # [m] its mount moves at most this far from where it waits
    approach: float = 0.1  # [m] its pre-grasp stands this far back along −y_R from its grasp
    offsets: list[list[float]] = field(default_factory=lambda: [
        [0.0, 0.0], [0.1, 0.0], [0.2, 0.0], [0.1, 0.1], [-0.1, 0.0]])  # [m] (out, up): the
    # hand-over points tried in order (`handover_object_poses`), moved `out` horizontally away
    # from the robot's base and `up` from `xy`/`height`, for a grasp whose wrist cannot reach
    # the configured one (a side grasp from the robot's side puts the wrist inside the arm's
    # folded reach; the receiver's reach still bounds its grasp there)
    max_approach_angle: float = 90.0  # [deg] its approach +y_R at most this far from its
    # direction (90: any approach from its side of the object, from above included)
    clearance: float = 0.0  # [m] how far its gripper keeps from the robot's (exact geometry,
    # checked without the perceived points' tolerance) beyond not touching it. 3 mm (the
    # planner's clearance near the target) measured over S_GRASP's and S_ROBOT's 48 pass cases:
    # 2 hand-overs gained, 1 lost to "no receiver grasp clear", and none left in
    # scenarios/default.yaml
    max_grasps: int = 48  # of those, the best by P(part) · P(grasp | local shape) checked by the
    # feasibility core per hand-over pose (each check ~10 ms of a 2-core machine's time)
    speed: float = 0.5  # [m/s] moving to its pre-grasp once the robot has arrived with the
    # object (peak: 1.875 × the mean) ...
    turn_speed: float = 1.5  # [rad/s] ... and turning (each mount angle)
    approach_speed: float = 0.1  # [m/s] the straight approach (peak: 1.875 × the mean)
    look: float = 0.3  # [s] at its pre-grasp after the robot has arrived, before approaching:
    # where the object is in the robot's hand is seen then (tg_drake.receiver.ReceiverDriver)
    see_tolerance: float = 0.003  # [m] what the receiver tells apart when it compares the
    # object's shape where it is with where the plan carries it (95th percentile of the surface
    # distance; about a D415's depth noise at half a metre): a turn of the object it cannot see
    # (a lying glass rolled about its axis) is not followed (tg_drake.receiver.seen_correction)
    close_duration: float = 0.8  # [s] open → 0 (then → closed_width over squeeze_duration), as
    # the robot's gripper closes (PlannerConfig)
    squeeze_duration: float = 0.1  # [s]
    settle_duration: float = 0.4  # [s] held closed before the robot opens
    closed_width: float = -0.04  # [m] commanded past closed, as the robot's (PlannerConfig)
    hold_duration: float = PASS_HOLD_DURATION  # [s] after the robot's release, the receiver must
    # hold it alone this long (the task's success test, tg_drake.tasks.judge.judge_pass)
    kp: float = 20000.0  # [N/m] the mount's prismatic PD gains (the receiver and a held object
    kd: float = 1000.0  # [N·s/m] of 1 kg sag mg/kp = 0.5 mm)
    kp_rotation: float = 500.0  # [N·m/rad] the revolute joints' (0.3 kg·m weight at 0.1 m: 2 mrad)
    kd_rotation: float = 20.0  # [N·m·s/rad]
    force_limit: float = 400.0  # [N] of each prismatic actuator (and [N·m] of each revolute)

    def validate(self, where: str = "receiver") -> None:
        """ScenarioError naming the field."""
        if len(self.xy) != 2 or not all(math.isfinite(v) for v in self.xy):
            raise ScenarioError(f"xy must be two finite numbers [m], got {self.xy}",
                                field=f"{where}.xy")
        if not self.offsets or any(len(o) != 2 or not all(math.isfinite(v) for v in o)
                                   for o in self.offsets):
            raise ScenarioError(f"offsets must be a non-empty list of [out, up] pairs of finite "
                                f"numbers [m], got {self.offsets}", field=f"{where}.offsets")
        checks = (("height", self.height > 0.0, "> 0 m"), ("yaw", math.isfinite(self.yaw),
                                                           "a finite angle [deg]"),
                  ("standoff", self.standoff >= 0.0, ">= 0 m"), ("rise", self.rise >= 0.0,
                                                                 ">= 0 m"),
                  ("reach", self.reach > 0.0, "> 0 m"), ("approach", self.approach >= 0.0,
                                                         ">= 0 m"),
                  ("max_approach_angle", 0.0 < self.max_approach_angle <= 180.0,
                   "in (0, 180] deg"),
                  ("clearance", self.clearance >= 0.0, ">= 0 m"),
                  ("max_grasps", self.max_grasps >= 1, ">= 1"),
                  ("look", self.look >= 0.0, ">= 0 s"),
                  ("see_tolerance", self.see_tolerance > 0.0, "> 0 m"),
                  ("speed", self.speed > 0.0, "> 0 m/s"),
                  ("turn_speed", self.turn_speed > 0.0, "> 0 rad/s"),
                  ("approach_speed", self.approach_speed > 0.0, "> 0 m/s"),
                  ("close_duration", self.close_duration > 0.0, "> 0 s"),
                  ("squeeze_duration", self.squeeze_duration >= 0.0, ">= 0 s"),
                  ("settle_duration", self.settle_duration >= 0.0, ">= 0 s"),
                  ("closed_width", self.closed_width < WSG_MAX_OPENING, "< the WSG's opening"),
                  ("hold_duration", self.hold_duration > 0.0, "> 0 s"),
                  ("kp", self.kp > 0.0, "> 0"), ("kd", self.kd >= 0.0, ">= 0"),
                  ("kp_rotation", self.kp_rotation > 0.0, "> 0"),
                  ("kd_rotation", self.kd_rotation >= 0.0, ">= 0"),
                  ("force_limit", self.force_limit > 0.0, "> 0"))
        for name, ok, allowed in checks:
            value = getattr(self, name)
            if not (ok and math.isfinite(value)):
                raise ScenarioError(f"must be {allowed}, got {value}", field=f"{where}.{name}")


# --- the mount ---------------------------------------------------------------------------------


def _rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _ry(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def mount_pose(q) -> np.ndarray:
    """4×4 X_WR of the mount's configuration q = (x, y, z [m], yaw, pitch, roll [rad])."""
    q = np.asarray(q, float)
    X = np.eye(4)
    X[:3, :3] = _rz(q[3]) @ _ry(q[4]) @ _rx(q[5])
    X[:3, 3] = q[:3]
    return X


def mount_configuration(X_WR: np.ndarray, near=None) -> np.ndarray:
    """The mount's q (6,) of pose X_WR (the inverse of `mount_pose`); angles unwrapped to lie
    within π of `near`'s (a q) when given."""
    R = np.asarray(X_WR, float)[:3, :3]
    pitch = math.asin(-max(-1.0, min(1.0, R[2, 0])))
    if abs(math.cos(pitch)) > 1e-9:
        yaw, roll = math.atan2(R[1, 0], R[0, 0]), math.atan2(R[2, 1], R[2, 2])
    else:  # the closing axis vertical: yaw and roll turn about the same axis
        yaw, roll = math.atan2(-R[0, 1], R[1, 1]), 0.0
    q = np.array([*np.asarray(X_WR, float)[:3, 3], yaw, pitch, roll])
    if near is None:
        return q
    # Of the two angle triples of one rotation, (yaw, pitch, roll) and (yaw + π, π − pitch,
    # roll + π), each unwrapped to within π of `near`'s, the nearer one.
    near = np.asarray(near, float)
    best = None
    for angles in (q[3:], np.array([yaw + np.pi, np.pi - pitch, roll + np.pi])):
        a = near[3:] + (angles - near[3:] + np.pi) % (2 * np.pi) - np.pi
        if best is None or np.abs(a - near[3:]).max() < np.abs(best - near[3:]).max():
            best = a
    q[3:] = best
    return q


# --- the hand-over geometry --------------------------------------------------------------------


@dataclass(frozen=True)
class Handover:
    """A pass's receiver in the world: the scenario's `ReceiverConfig` and the table frame."""

    config: ReceiverConfig
    X_WT: np.ndarray  # 4×4 table frame

    @property
    def point(self) -> np.ndarray:
        """(3,) world position of the hand-over point."""
        c = self.config
        return (np.asarray(self.X_WT, float) @ np.array([c.xy[0], c.xy[1], c.height, 1.0]))[:3]

    @property
    def direction(self) -> np.ndarray:
        """(3,) unit world direction the receiver moves in (horizontal)."""
        a = math.radians(self.config.yaw)
        d = np.asarray(self.X_WT, float)[:3, :3] @ np.array([math.cos(a), math.sin(a), 0.0])
        d[2] = 0.0
        return d / np.linalg.norm(d)

    @property
    def X_WR_wait(self) -> np.ndarray:
        """4×4 where the receiver waits: `standoff` back along its direction and `rise` above the
        point, approaching along its direction (+y_R), its pads' width (z_R) vertical."""
        y = self.direction
        x = np.cross(y, UP)
        X = np.eye(4)
        X[:3, :3] = np.column_stack([x, y, UP])
        X[:3, 3] = self.point - self.config.standoff * y + self.config.rise * UP
        return X

    def object_pose(self, X_WO: np.ndarray) -> np.ndarray:
        """The perceived object frame (origin at its box centre) moved to the hand-over point,
        its orientation kept."""
        X = np.array(X_WO, float)
        X[:3, 3] = self.point
        return X


def handover_object_poses(handover: "Handover", X_WO: np.ndarray, X_WG: np.ndarray, *,
                          yaws_deg, lift: float, retreat: float) -> list[np.ndarray]:
    """The object's poses at the hand-over to plan for grasp X_WG (picked with the object at X_WO):
    its box centre at each of the receiver's `offsets` from the configured point (out: along the
    horizontal from the robot's base through it), its orientation turned about the vertical by
    each of `yaws_deg` [deg] (the planner's place yaws), in that order (the configured point's
    yaws first); those whose gripper pose there, `lift` [m] above it (the pre-place) or `retreat`
    [m] back along −y_G (the retreat) would put the wrist outside the arm's reach
    (`wrist_reach_margin` < 0) left out: the IK cannot find them."""
    X_WO = np.asarray(X_WO, float)
    X_OG = np.linalg.inv(X_WO) @ np.asarray(X_WG, float)
    point = handover.point
    out_dir = np.array([point[0], point[1], 0.0])
    norm = float(np.linalg.norm(out_dir))
    out_dir = out_dir / norm if norm > 1e-9 else handover.direction * -1.0
    poses = []
    for out, up in handover.config.offsets:
        p = point + out * out_dir + up * UP
        for yaw in np.deg2rad(np.asarray(yaws_deg, float)):
            X = X_WO.copy()
            X[:3, :3] = _rz(float(yaw)) @ X_WO[:3, :3]
            X[:3, 3] = p
            G = X @ X_OG
            pre, back = G.copy(), G.copy()
            pre[2, 3] += lift
            back[:3, 3] -= retreat * G[:3, 1]
            if min(wrist_reach_margin(V) for V in (G, pre, back)) >= 0.0:
                poses.append(X)
    return poses


def robot_gripper_points(X_WG: np.ndarray, *, retreat: float, closed_width: float | None = None,
                         grow: float = 0.0, spacing: float = 0.005) -> np.ndarray:
    """(N, 3) world points of the robot's WSG at X_WG that the receiver's gripper must stay
    clear of, `spacing` [m] apart (about perception's voxel): the surfaces of its housing and of
    its pads open (as they open at the release) swept `retreat` [m] back along −y_G (its
    retreat) — a box of the receiver's that cuts one of these contains some of its surface —,
    and, given the robot's grip width `closed_width` [m], the whole volume its pads pass through
    from holding (that width apart) to open: the receiver closes while the robot still holds,
    and the robot opens with the receiver's fingers in place, so a receiver's pad may lie
    wholly inside that band. Every box grown by `grow` [m] on each side (a clearance)."""
    out = []
    for _, centre, half in gripper_boxes(WSG_MAX_OPENING, retreat):
        grid = _box_grid(centre, half + grow, spacing)
        out.append(grid[np.any(np.isclose(np.abs(grid - centre), half + grow, rtol=0,
                                          atol=1e-9), axis=1)])
    if closed_width is not None:
        out += [_box_grid(centre, half + grow, spacing)
                for _, centre, half in closing_sweep(WSG_MAX_OPENING, closed_width)]
    p_G = np.concatenate(out)
    return p_G @ np.asarray(X_WG, float)[:3, :3].T + np.asarray(X_WG, float)[:3, 3]


def _box_grid(centre: np.ndarray, half: np.ndarray, spacing: float) -> np.ndarray:
    """(N, 3) a grid filling the box (centre, half sizes) at most `spacing` [m] apart, its faces
    included."""
    axes = [np.linspace(c - h, c + h, max(2, int(np.ceil(2 * h / spacing)) + 1))
            for c, h in zip(centre, half, strict=True)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


@dataclass(frozen=True)
class ReceiverGrasp:
    """The receiver's chosen grasp at the hand-over."""

    X_WR: np.ndarray  # 4×4 its grasp pose
    part: str
    candidate: int  # index into the GraspCandidates
    p_part: float  # P(the receiver takes this part) (tg_drake.logic.receive)
    p_local: float
    p_hold: float
    score: float  # p_part · p_local · p_hold
    margin: float = float("inf")  # the contact mechanics' combined hold margin (< 1 slips)


def choose_receiver_grasp(candidates: GraspCandidates, *, target: ObjectDescription,
                          X_WO: np.ndarray, X_WO_handover: np.ndarray, X_WG_robot: np.ndarray,
                          receiver_parts: dict, handover: Handover, table_z: float,
                          retreat: float, feasibility: FeasibilityConfig | None = None,
                          category: dict | None = None, cache: dict | None = None,
                          arm_p_W: np.ndarray | None = None
                          ) -> tuple[ReceiverGrasp | None, str]:
    """The receiver's best grasp at the hand-over (module doc), or (None, why there is none).

    `X_WO`: the object's perceived pose, where the candidates were made; `X_WO_handover`: its pose
    handed over; `X_WG_robot`: the robot's gripper there; `receiver_parts`: part → P(the receiver
    takes it); `retreat` [m]: how far the robot backs out along −y_G after opening. `cache`: a
    dict kept across the hand-over poses of one planning call: the feasibility of the receiver's
    poses relative to the object and the robot's gripper does not change when the three are
    turned together about the vertical (the planner's place yaws), so it is computed once per
    robot grasp and set of poses. `arm_p_W`: (N, 3) points on the robot arm's links at the
    hand-over (`tg_drake.planning.ik.arm_surface_points`), kept clear of as its gripper is.
    The robot's gripper is exact geometry: its boxes are grown by the feasibility's tolerance
    for perceived points (`point_tolerance`), which would otherwise let the receiver's cut
    them, and by the receiver's `clearance`."""
    config = handover.config
    feasibility = feasibility or FeasibilityConfig()
    parts = np.asarray(candidates.parts, int)
    names = [PART_LABELS[k] for k in parts]
    p_recv = np.array([float(receiver_parts.get(n, 0.0)) for n in names])
    on_part = np.flatnonzero(p_recv > 0)
    wanted = ", ".join(p for p, v in receiver_parts.items() if v > 0) or "none"
    if not len(on_part):
        return None, (f"hand-over: no receiver grasp candidate on the parts a receiver takes "
                      f"({wanted})")
    # The candidates moved onto the object's observed length (`onto_observed_length`), carried
    # with the object (X_WR = X_WO_handover · X_WO⁻¹ · X_WG), each also turned about its pads'
    # width axis (`turned_about_width`).
    moved = np.asarray(X_WO_handover, float) @ np.linalg.inv(np.asarray(X_WO, float))
    on_object = onto_observed_length(np.asarray(candidates.X_WG, float)[on_part], target)
    carried = np.einsum("ij,njk->nik", moved, on_object)
    X_WR = np.array([V for X in carried for V in (X, *turned_about_width(X))])
    on_part = np.repeat(on_part, 1 + len(TURNS))
    # A container not end to end along gravity: a receiver closing along the vertical and along
    # its axis (a glass from rim to base) holds it on its lower pad, and when the robot lets go it
    # drops by the error of the perceived extent's centre between the pads (15-57 mm in S_ROBOT's
    # glass hand-overs). "Along": closer to it than to square (45°). (A tool's frame z is not its
    # axis; its handle is squeezed from above and below on purpose: `turned_about_width`. So is a
    # container's handle — a pan's, standing out sideways — the pads across the handle alone.)
    if not target.is_tool:
        x_R = X_WR[:, :3, 0]
        z_O = np.asarray(X_WO_handover, float)[:3, 2]
        square = math.cos(math.radians(45.0))
        body = np.array([names[k] != "handle" for k in on_part], bool)
        end_to_end = (np.abs(x_R[:, 2]) > square) & (np.abs(x_R @ z_O) > square) & body
        X_WR, on_part = X_WR[~end_to_end], on_part[~end_to_end]
        if not len(X_WR):
            return None, (f"hand-over: every receiver grasp on {wanted} would squeeze the object "
                          f"end to end along gravity")
    cos_max = math.cos(math.radians(config.max_approach_angle))
    toward = X_WR[:, :3, 1] @ handover.direction >= cos_max - 1e-9
    wait = handover.X_WR_wait[:3, 3]
    far = np.linalg.norm(X_WR[:, :3, 3] - wait, axis=1)
    within = far <= config.reach
    if not toward.any():
        return None, (f"hand-over: no receiver grasp on {wanted} approaches within "
                      f"{config.max_approach_angle:.0f}° of the receiver's direction")
    if not (toward & within).any():
        return None, (f"hand-over: the receiver cannot reach: its nearest grasp on {wanted} is "
                      f"{far[toward].min():.2f} m from where it waits (reach {config.reach} m)")
    keep = np.flatnonzero(toward & within)
    prior = p_recv[on_part[keep]] * np.asarray(candidates.p_local, float)[on_part[keep]]
    keep = keep[np.argsort(-prior, kind="stable")[:config.max_grasps]]
    X_OG = np.linalg.inv(np.asarray(X_WO_handover, float)) @ np.asarray(X_WG_robot, float)
    arm = np.zeros((0, 3)) if arm_p_W is None else np.asarray(arm_p_W, float).reshape(-1, 3)
    key = (np.round(X_OG, 6).tobytes(), round(float(X_WO_handover[2, 3]) - table_z, 6),
           keep.tobytes())
    target_p_W = np.asarray(target.p_W, float) @ moved[:3, :3].T + moved[:3, 3]
    if cache is None or key not in cache:
        carried_target = moved_rigidly(target, moved)
        grip = grip_width(X_WG_robot, target_p_W, WSG_MAX_OPENING)
        robot = robot_gripper_points(X_WG_robot, retreat=retreat, closed_width=grip,
                                     grow=config.clearance + feasibility.point_tolerance)
        f = grasp_feasibility(X_WR[keep], target_p_W=target_p_W, others_p_W=robot,
                              table_z=table_z, approach=config.approach, category=category,
                              config=feasibility)
        # The object hangs in the robot's grip: a receiver whose housing or open pads, coming
        # in along its approach, cut it would push it round in that grip (a gripper on an object
        # on the table may push it onto the table: the hold model weighs that there, not here).
        # Then the geometric refusals of the robot's own grasps (pads.geometric_refusal), less
        # those of an object on the table: fingers closing along a long part, too little of the
        # object between the pads, a step under them, a weight that would turn it in them.
        centroid = target_p_W.mean(axis=0) if len(target_p_W) else None
        reasons = []
        for j, (r, h) in enumerate(zip(f.reasons, f.holds, strict=True)):
            r = r or _pushes(h, feasibility.point_tolerance)
            reasons.append(r or geometric_refusal(
                carried_target, names[on_part[keep[j]]], X_WR[keep[j]], centroid, feasibility,
                table_z, held=True))
        if cache is not None:
            cache[key] = (f, reasons)
    else:
        f, reasons = cache[key]
    # The robot's arm, which is where it is for this hand-over pose alone (the rest above is
    # the same for every pose of the object, the robot's gripper and the receiver's turned
    # together about the vertical: the cache's key), clear of the gripper as the rest is.
    free = [j for j, r in enumerate(reasons) if not r]
    if len(arm) and free:
        reasons = list(reasons)
        hits = others_hit(X_WR[keep[free]], others_p_W=arm, approach=config.approach,
                          config=feasibility, closed_widths=[
                              f.holds[j].width if f.holds[j].n_points else None for j in free])
        for j, why in zip(free, hits, strict=True):
            reasons[j] = why
    ok = np.array([not r for r in reasons], bool)
    if not ok.any():
        first = next((r for r in reasons if r), "")
        return None, (f"hand-over: no receiver grasp on {wanted} clear of the robot's gripper, "
                      f"its arm and the table, and of the object ({len(keep)} tried; first: "
                      f"{first})")
    idx = on_part[keep]
    p_local = np.asarray(candidates.p_local, float)[idx]
    score = np.where(ok, p_recv[idx] * p_local * f.p_hold, -1.0)
    # Poses whose contact mechanics hold the weight (margin ≥ 1) first, then by score.
    margin = np.array([h.margin >= 1.0 for h in f.holds], bool) & ok
    # The first of them whose transit, from where the receiver waits to its pre-grasp, keeps
    # clear of the robot's arm (links 1-7: the robot stands still at the hand-over while the
    # receiver comes) and of the object: a receiver passing through the arm strikes it, and the
    # arm, held by its joints' controllers, gives way and lets the object go. (Near the robot's
    # gripper the receiver's approach and grasp are checked above; on the way a graze of its
    # housing was seen to do no harm.)
    obstacles = np.concatenate([arm, target_p_W])
    best, blocked = None, 0
    for j in np.argsort(-(score + 2.0 * margin), kind="stable"):  # scores lie in [0, 1]
        if not ok[j]:
            break
        cut = transit_cut(handover, X_WR[keep[j]], obstacles, feasibility.min_points)
        if cut <= feasibility.point_tolerance:
            best = int(j)
            break
        blocked += 1
    if best is None:
        return None, (f"hand-over: the receiver's way from where it waits to each of its "
                      f"{blocked} grasps on {wanted} clear at the hand-over would cross the "
                      f"robot's arm or the object")
    i = int(idx[best])
    return ReceiverGrasp(X_WR[keep][best], names[i], i, float(p_recv[i]), float(p_local[best]),
                         float(f.p_hold[best]), float(score[best]),
                         float(f.holds[best].margin)), ""


def _pushes(h, tolerance: float) -> str:
    """Why a receiver's grasp would push the object held by the robot (its housing or its open
    pads, swept along the approach, cut by the object's points more than `tolerance` [m]), or
    ""."""
    box, depth = max((("housing", h.housing_cut), ("pads", h.pad_cut)), key=lambda b: b[1])
    if depth <= tolerance:
        return ""
    return (f"would push the object in the robot's grip: the receiver's {box} cut it by "
            f"{depth * 1000:.1f} mm on the approach")


# [fraction] of the observed points left out at each end of the object's axis when its observed
# length is measured (`observed_length`). Fitted on the pass cases of S_GRASP with the objects
# lying (cans, bottles, glasses and cups, D415): a few stray points (the end face's rim spread
# along a perceived axis up to 10° off the true one, the sensor's noise at the silhouette) reach
# up to 4.3 cm past the real end, and the part boxes built from the completed cloud with them;
# the 1st and 99th percentiles lie within 0.5 cm of both real ends on 6 of the 9 objects
# measured, within 1.4 cm on all.
OBSERVED_TRIM = 0.01


def observed_length(target: ObjectDescription) -> tuple[float, float] | None:
    """(lo, hi) [m]: where the object's observed points lie along its axis z_O (coordinates from
    its frame's origin), trimmed of OBSERVED_TRIM at each end; None with fewer than two observed
    points."""
    X_WO = np.asarray(target.X_WO, float)
    p_W = np.asarray(target.p_W, float).reshape(-1, 3)
    visible = np.asarray(target.visible, bool).reshape(-1)
    if len(visible) != len(p_W) or visible.sum() < 2:
        return None
    s = (p_W[visible] - X_WO[:3, 3]) @ X_WO[:3, 2]
    lo, hi = np.quantile(s, [OBSERVED_TRIM, 1.0 - OBSERVED_TRIM])
    return float(lo), float(hi)


def onto_observed_length(X_WG: np.ndarray, target: ObjectDescription) -> np.ndarray:
    """The grasps X_WG (N, 4, 4), each moved along the object's axis z_O just far enough that its
    pads' width along that axis lies within the observed length (`observed_length`): the part
    boxes the candidates were made on come from the completed cloud, whose ends may lie past the
    object's (a 12.9 cm can lying perceived 15 cm long), and a receiver grasping there closes on
    air. A pad's half width reaches |z_G · z_O| · WSG_PAD_SIZE[2] / 2 along the axis (a grasp
    whose pads close across the axis: 1 cm; one approaching the object's end along the axis: 0,
    its grasp point kept within the observed end). A length shorter than the pads centres them
    on it. Orientations are kept; the candidates' scores are those of the original poses."""
    X_WG = np.array(X_WG, float).reshape(-1, 4, 4)
    extent = observed_length(target)
    if extent is None or not len(X_WG):
        return X_WG
    lo, hi = extent
    X_WO = np.asarray(target.X_WO, float)
    axis = X_WO[:3, 2]
    p_grasp = X_WG[:, :3, 3] + X_WG[:, :3, :3] @ WSG_GRASP_POINT_G
    s = (p_grasp - X_WO[:3, 3]) @ axis
    reach = np.abs(X_WG[:, :3, 2] @ axis) * WSG_PAD_SIZE[2] / 2
    low, high = lo + reach, hi - reach
    target_s = np.where(low <= high, np.clip(s, low, high), (lo + hi) / 2)
    X_WG[:, :3, 3] += (target_s - s)[:, None] * axis
    return X_WG


TURNS = (np.pi / 2, -np.pi / 2)  # [rad] the turns of `turned_about_width`


def turned_about_width(X_WG: np.ndarray) -> list[np.ndarray]:
    """X_WG turned about its pads' width axis z_G through its grasp point by each of TURNS: the
    pads still close across the same section of the part, from another side. In the air the
    receiver may come from the sides the table closed to the robot (under a tool lying on it), and
    a tool held horizontally is best squeezed from above and below: its weight's lever about a
    vertical closing axis is nil."""
    out = []
    p_grasp = X_WG[:3, 3] + GRASP_DEPTH * X_WG[:3, 1]
    for a in TURNS:
        c, s_ = math.cos(a), math.sin(a)
        R = X_WG[:3, :3] @ np.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]])
        X = np.eye(4)
        X[:3, :3] = R
        X[:3, 3] = p_grasp - GRASP_DEPTH * R[:, 1]
        out.append(X)
    return out


# --- the receiver's motion ---------------------------------------------------------------------


@dataclass(frozen=True)
class HandoverMotion:
    """The receiver's commanded mount configuration and finger opening over plan time: knots
    joined by quintic time scalings (zero velocity and acceleration at each knot)."""

    times: tuple  # (K,) [s] increasing
    q: np.ndarray  # (K, 6) mount configurations at the knots
    width_times: tuple  # (L,) [s]
    widths: tuple  # (L,) commanded opening [m], linear between the knots
    t_closed: float  # [s] the receiver's fingers have closed and settled
    X_WR_grasp: np.ndarray  # 4×4 its grasp pose
    part: str = ""  # the part it takes
    hold_duration: float = PASS_HOLD_DURATION  # [s] it must hold it alone after the release
    X_WG_robot: np.ndarray | None = None  # 4×4 the robot's gripper at the hand-over pose
    t_arrive: float = 0.0  # [s] the robot has arrived there

    def _segment(self, t: float):
        times = self.times
        if t <= times[0]:
            return 0, 0.0, 0.0
        if t >= times[-1]:
            return len(times) - 2, 1.0, 0.0
        k = int(np.searchsorted(times, t, side="right") - 1)
        d = times[k + 1] - times[k]
        return k, (t - times[k]) / d, d

    def configuration(self, t: float) -> np.ndarray:
        """(6,) mount q at plan time t."""
        k, u, _ = self._segment(t)
        s = u ** 3 * (10 - 15 * u + 6 * u * u)
        return self.q[k] + s * (self.q[k + 1] - self.q[k])

    def velocity(self, t: float) -> np.ndarray:
        """(6,) its time derivative."""
        k, u, d = self._segment(t)
        if d == 0.0:
            return np.zeros(6)
        ds = 30 * u * u * (1 - u) ** 2 / d
        return ds * (self.q[k + 1] - self.q[k])

    def width(self, t: float) -> float:
        return float(np.interp(t, self.width_times, self.widths))


def _duration(q_a: np.ndarray, q_b: np.ndarray, speed: float, turn_speed: float,
              minimum: float) -> float:
    """[s] a quintic move between two mount configurations, its peak speed (1.875 × the mean) at
    most `speed` [m/s] and `turn_speed` [rad/s]."""
    d = max(float(np.linalg.norm(q_b[:3] - q_a[:3])) / speed,
            float(np.abs(q_b[3:] - q_a[3:]).max()) / turn_speed)
    return max(minimum, 1.875 * d)


def _transit(handover: Handover, X_WR: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The mount's q where the receiver waits and at its pre-grasp for grasp X_WR (`approach`
    back along its approach, −y_R): its transit runs straight from one to the other in q."""
    q_wait = mount_configuration(handover.X_WR_wait)
    X_pre = np.array(X_WR, float)
    X_pre[:3, 3] -= handover.config.approach * X_pre[:3, 1]
    return q_wait, mount_configuration(X_pre, near=q_wait)


# [m] the farthest any point of the receiver's open gripper moves between two of its transit's
# poses that are checked (`transit_poses`): under the thickness of a pad (12 mm), so that no
# box of it steps over a wall of points.
TRANSIT_STEP = 0.01


def transit_poses(handover: Handover, X_WR: np.ndarray) -> np.ndarray:
    """(n, 4, 4) the receiver's poses along its transit from where it waits to its pre-grasp for
    grasp X_WR (`receiver_motion`: a straight line in the mount's q), no two more than
    TRANSIT_STEP apart at any point of its open gripper, both ends included."""
    q_wait, q_pre = _transit(handover, X_WR)
    boxes = gripper_boxes(WSG_MAX_OPENING)
    radius = boxes_reach(np.array([c for _, c, _ in boxes]), np.array([h for _, _, h in boxes]))
    d = q_pre - q_wait
    reach = float(np.linalg.norm(d[:3])) + radius * float(np.abs(d[3:]).sum())
    s = np.linspace(0.0, 1.0, 2 + int(math.ceil(reach / TRANSIT_STEP)))
    return np.array([mount_pose(q_wait + v * d) for v in s])


def transit_cut(handover: Handover, X_WR: np.ndarray, points_W: np.ndarray, k: int) -> float:
    """[m] how deep the points points_W (n, 3) cut the receiver's open gripper (its housing and
    pads, `gripper_boxes`) anywhere along its transit to the pre-grasp of grasp X_WR (the k-th
    deepest point at each pose, robust to k − 1 stray points; 0: clear)."""
    cuts = deepest_cuts(transit_poses(handover, X_WR), points_W, gripper_boxes(WSG_MAX_OPENING),
                        k)
    return float(cuts.max()) if len(cuts) else 0.0


def receiver_motion(handover: Handover, grasp: ReceiverGrasp, *, t_arrive: float,
                    t_earliest: float = 0.0, X_WG_robot: np.ndarray | None = None
                    ) -> HandoverMotion:
    """From where it waits to its pre-grasp once the robot has arrived at the hand-over pose
    (`t_arrive`, plan time; not before `t_earliest`: the object lifted), held there `look`
    seconds, the straight approach, closing, held to the end. It does not move in while the
    robot carries and descends: the arm's links sweep through the space around the hand-over
    pose then (on the lying can, bottle and glass passes of S_GRASP the receiver, there early,
    was struck by links 5-7 with 130-830 N)."""
    c = handover.config
    q_wait, q_pre = _transit(handover, grasp.X_WR)
    q_grasp = mount_configuration(grasp.X_WR, near=q_pre)
    move = _duration(q_wait, q_pre, c.speed, c.turn_speed, 1.0)
    t_start = max(t_earliest, t_arrive)
    t_pre = t_start + move
    t_look = max(t_pre, t_arrive) + c.look
    t_at = t_look + max(0.5, 1.875 * c.approach / c.approach_speed)
    t_zero = t_at + c.close_duration
    t_squeezed = t_zero + c.squeeze_duration
    t_closed = t_squeezed + c.settle_duration
    return HandoverMotion(
        times=(0.0, t_start, t_pre, t_look, t_at),
        q=np.array([q_wait, q_wait, q_pre, q_pre, q_grasp]),
        width_times=(0.0, t_at, t_zero, t_squeezed),
        widths=(WSG_MAX_OPENING, WSG_MAX_OPENING, 0.0, c.closed_width),
        t_closed=t_closed, X_WR_grasp=np.array(grasp.X_WR, float), part=grasp.part,
        hold_duration=c.hold_duration,
        X_WG_robot=None if X_WG_robot is None else np.asarray(X_WG_robot, float),
        t_arrive=float(t_arrive))
