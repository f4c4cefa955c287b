"""The task motions of the planner: where and how the object goes for the given task.

    placing = task_placing("p&pInUpsidedown", place_xy=xy, table_z=z, config=cfg)
    for R_turn, X_WO_place in placing.place_poses(X_WO, X_WG, extents, is_tool=False,
                                                  release_height=0.01, place_pose=place_pose):
        ...  # plan the pick-and-place with the object released at X_WO_place

- p&pInUpright / p&pInSideways / p&pInUpsidedown: the place pose turns the object into the task's
  resting pose, the grasp kept (X_WG_place = X_WO_place · X_OG): the turn is a rotation of the
  object about its box centre, about the horizontal part of the gripper's approach axis first
  (a turn of the wrist alone) then about that of its closing axis, else the smallest turn. The
  perceived object frame has z along the symmetry axis towards the top, so upright is z up,
  upside down z down, sideways z level. A turn that leaves the gripper's closing axis nearer
  vertical than level is not placed (`lets_go_onto_support`: the lower finger would carry it).
  A tool only lies "sideways" (flat): any other pose is refused.
- p&pOn: the object goes to the centre of the surface (`SurfaceConfig`), its box's lowest corner
  `release_height` above the surface's top; the surfaces are obstacles of every motion.
- pourOut: carried upright over the bowl (`task.pour_into`, the perceived object nearest the
  bowl's position), its opening's edge above the bowl's centre; tilted `pour_tilt` about a
  horizontal axis through that edge (the horizontal part of the gripper's approach first: a turn
  of the wrist, then its closing axis) and lowered until its lowest corner is `pour_drop` above
  the bowl's top, held `pour_hold`, tilted back, then placed as usual.
- pourIn: carried upright under the dispenser (`fill_at`), its box `fill_clearance` under the
  hopper's gate; held there `fill_open` with the dispenser open (the supervisor's
  ``dispenser_command``) and `fill_settle` more, then placed as usual.
- pourOut and pourIn are judged at the pour: when the place target is out of reach for a grasp,
  the container goes back where it was picked (reachable by that grasp: it was picked there).
- every other task: the pick-and-place, the object's orientation kept.

Each place pose is also turned about the vertical by `PlannerConfig.place_yaws`.
"""


import functools
from dataclasses import dataclass, field

import numpy as np

from tg_drake.errors import ScenarioError
from tg_drake.perception.ground_truth import pose_from_transform
from tg_drake.tasks.judge import REST_POSE_OF_TASK

UP = np.array([0.0, 0.0, 1.0])
# [1] a turn axis is taken as perpendicular to the object's axis when their cosine is below this.
PERPENDICULAR = 0.15
# [1] a turned object is released only where the gripper's closing axis x_G is nearer level than
# vertical (|x_G · z_W| at most cos 45°): nearer vertical, the lower finger lies between the object
# and the table, and opening lowers the object onto that finger instead of setting it down.
MAX_CLOSING_RISE = float(np.cos(np.pi / 4))


@dataclass
class TaskMotionConfig:
    """The task motions' settings (`pipeline.tasks`)."""

    reorient: bool = True  # p&pIn*: turn the object into the task's resting pose (False: place
    # it as picked, the task then judged on that)
    turned_release_heights: list[float] = field(default_factory=lambda: [0.01, 0.03, 0.05])
    # [m] gaps under a turned object's box at release, tried in order: turned upside down, a
    # side grasp's approach points up, and the wrist stays clear of the table only higher up
    pour_tilt: float = 135.0  # [deg] pourOut: the container's axis turned this far from up.
    # The contents are spheres with friction 0.3 (friction angle 17°): at 110° the wall slopes
    # 20° to the opening and, on the training objects of tasks_pour_out (6 runs), 14 of 60
    # spheres stayed in (42 in the bowl); at 135° and 150° none did (with `pour_drop` 0.03 m:
    # 59 and 60 of 60 in the bowl; without it, from the upright container's height, 30 and 40:
    # the rest bounced off the bowl onto the table)
    pour_hold: float = 1.5  # [s] pourOut: held tilted over the bowl
    pour_clearance: float = 0.05  # [m] pourOut: the upright container's box above the bowl's
    pour_drop: float = 0.03  # [m] pourOut: the tilted container's lowest corner above the bowl's
    # top (how far the contents fall to the rim's height)
    pour_yaws: list[float] = field(default_factory=lambda: [0.0, 90.0, -90.0, 180.0])  # [deg]
    # pourOut: the pour turned about the bowl's vertical axis, tried in order; pourIn: the
    # container turned about the dispenser's vertical axis
    fill_clearance: float = 0.02  # [m] pourIn: the container's box under the dispenser's gate
    fill_open: float = 1.5  # [s] pourIn: the dispenser is open while the container is held
    fill_settle: float = 1.0  # [s] pourIn: held on after the dispenser closes
    regrasp_yaws: list[float] = field(default_factory=lambda: [90.0, -90.0, 180.0, 45.0, -45.0])
    # [deg] p&pIn* place-and-regrasp: turns of the object about the vertical tried for the
    # intermediate resting pose, in order (tg_drake.planning.regrasp)
    regrasp_spots: list[float] = field(default_factory=lambda: [0.0, 0.5, 1.0])  # [1]
    # p&pIn* place-and-regrasp: where the intermediate pose is tried, in order, as fractions of
    # the way from where the object is (0) to the place target (1)
    regrasp_max_poses: int = 16  # p&pIn* place-and-regrasp: intermediate poses examined (the
    # second leg's reach checked) at most, before giving up
    regrasp_max_legs: int = 3  # p&pIn* place-and-regrasp: intermediate poses whose second leg
    # is reachable that the first leg's full motion planning is tried for, before giving up

    def validate(self, where: str = "pipeline.tasks") -> None:
        checks = (("turned_release_heights", all(h >= 0.0 for h in self.turned_release_heights)
                   and len(self.turned_release_heights) > 0, "a non-empty list of heights >= 0 m"),
                  ("pour_tilt", 0.0 < self.pour_tilt <= 180.0, "in (0, 180] deg"),
                  ("pour_hold", self.pour_hold >= 0.0, ">= 0 s"),
                  ("pour_clearance", self.pour_clearance >= 0.0, ">= 0 m"),
                  ("pour_drop", self.pour_drop >= 0.0, ">= 0 m"),
                  ("fill_clearance", self.fill_clearance >= 0.0, ">= 0 m"),
                  ("fill_open", self.fill_open > 0.0, "> 0 s"),
                  ("fill_settle", self.fill_settle >= 0.0, ">= 0 s"),
                  ("regrasp_spots", all(0.0 <= f <= 1.0 for f in self.regrasp_spots),
                   "fractions in [0, 1]"),
                  ("regrasp_max_poses", self.regrasp_max_poses >= 1, ">= 1"),
                  ("regrasp_max_legs", self.regrasp_max_legs >= 1, ">= 1"))
        for name, ok, allowed in checks:
            if not ok:
                raise ScenarioError(f"must be {allowed}, got {getattr(self, name)}",
                                    field=f"{where}.{name}")


def perceived_pose(R_WO: np.ndarray, *, is_tool: bool) -> str:
    """The discrete pose of a perceived object frame (z towards the top) on a level table: the
    library's rule (`tg_drake.perception.ground_truth.pose_from_transform`)."""
    X = np.eye(4)
    X[:3, :3] = R_WO
    return pose_from_transform(X, np.eye(4), is_tool)


def axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    """3×3 rotation by `angle` [rad] about unit `axis` (Rodrigues)."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def _horizontal(v: np.ndarray) -> np.ndarray | None:
    h = np.array([v[0], v[1], 0.0])
    n = np.linalg.norm(h)
    return h / n if n > 1e-6 else None


def turns_to_pose(R_WO: np.ndarray, R_WG: np.ndarray, pose: str, *, is_tool: bool
                  ) -> list[np.ndarray]:
    """World-frame rotations that turn an object of orientation R_WO, held by a gripper at
    R_WG, into resting pose `pose`, most wrist-like first: [I] when it is in that pose already,
    [] when it cannot rest so (a tool other than "sideways")."""
    if perceived_pose(R_WO, is_tool=is_tool) == pose:
        return [np.eye(3)]
    if is_tool:
        return []
    z = np.asarray(R_WO, float)[:, 2]
    axes = [a for a in (_horizontal(R_WG[:, 1]), _horizontal(R_WG[:, 0])) if a is not None]
    turns = []
    if pose in ("upright", "upsidedown"):
        d = UP if pose == "upright" else -UP
        for a in axes:
            if abs(a @ z) < PERPENDICULAR:
                zp = z - (a @ z) * a  # z in the plane the turn keeps
                angle = np.arctan2(np.cross(zp, d) @ a, zp @ d)
                turns.append(axis_angle(a, angle))
        cross = np.cross(z, d)
        if np.linalg.norm(cross) > 1e-6:  # the smallest turn
            turns.append(axis_angle(cross, np.arccos(np.clip(z @ d, -1.0, 1.0))))
        else:
            turns.append(axis_angle(axes[0] if axes else np.array([1.0, 0, 0]), np.pi))
    else:  # sideways: z level, either way along the plane the turn keeps
        for a in axes:
            if abs(a @ z) < PERPENDICULAR:
                level = np.cross(a, UP)
                for d in (level, -level):
                    zp = z - (a @ z) * a
                    angle = np.arctan2(np.cross(zp, d) @ a, zp @ d)
                    turns.append(axis_angle(a, angle))
        h = _horizontal(z)
        if h is not None:  # the smallest turn: tip over towards where the axis leans
            turns.append(axis_angle(np.cross(z, h), np.arccos(np.clip(z @ h, -1.0, 1.0))))
    unique = []
    for R in turns:
        if not any(np.allclose(R, U, atol=1e-6) for U in unique):
            unique.append(R)
    return unique


def smallest_turn(R_WO: np.ndarray, pose: str, *, is_tool: bool) -> np.ndarray | None:
    """The world rotation that turns an object of orientation R_WO into resting pose `pose` by
    the smallest tip-over, whatever holds it (I when it rests so already); None when it cannot
    rest so (`turns_to_pose`)."""
    turns = turns_to_pose(R_WO, np.eye(3), pose, is_tool=is_tool)
    return turns[-1] if turns else None


def lets_go_onto_support(R_turn: np.ndarray, R_WG: np.ndarray) -> bool:
    """Can a gripper at R_WG that turns its object by the world rotation R_turn (the grasp kept,
    so the gripper turns with it) set it down by opening? Its fingers open along its closing
    axis x_G; with x_G nearer vertical than level at the place (`MAX_CLOSING_RISE`) the lower
    finger stays under the object, which then rests on the finger, not on the table. A turn
    about the vertical does not change this, so the place's yaw variants share the answer."""
    x_place = np.asarray(R_turn, float) @ np.asarray(R_WG, float)[:, 0]
    return abs(float(x_place @ UP)) <= MAX_CLOSING_RISE + 1e-9


def turned_retreat(y_WG: np.ndarray) -> np.ndarray:
    """The unit direction a gripper backs away in after releasing an object it turned: back along
    its approach (−y_G), but never down (a turned object's approach may point up, and backing
    along it would drive the wrist into the table): the downward part is dropped, straight up
    when nothing is left."""
    r = -np.asarray(y_WG, float)
    r[2] = max(r[2], 0.0)
    n = np.linalg.norm(r)
    return r / n if n > 0.3 else UP.copy()


def turned(X_WO: np.ndarray, R: np.ndarray) -> np.ndarray:
    """X_WO turned by the world rotation R about its own origin (the box centre)."""
    X = np.asarray(X_WO, float).copy()
    X[:3, :3] = R @ X[:3, :3]
    return X


@dataclass(frozen=True)
class Surface:
    """A box on the table in the world frame: its name, centre xy and top height [m], and the
    box (name, 4×4 X_WB of its centre, size) the planner's plants weld."""

    name: str
    xy: tuple
    top_z: float
    X_WB: np.ndarray = field(repr=False)
    size: tuple = ()


def surfaces_in_world(surfaces, X_WT: np.ndarray) -> list[Surface]:
    """The scenario's surfaces (`SurfaceConfig`: xy and size in the table frame T) in the world."""
    X_WT = np.asarray(X_WT, float)
    out = []
    for s in surfaces:
        sx, sy, sz = (float(v) for v in s.size)
        X_TB = np.eye(4)
        X_TB[:3, 3] = [float(s.xy[0]), float(s.xy[1]), sz / 2]
        X_WB = X_WT @ X_TB
        top = X_WT @ np.array([float(s.xy[0]), float(s.xy[1]), sz, 1.0])
        out.append(Surface(s.name, (float(top[0]), float(top[1])), float(top[2]), X_WB,
                           (sx, sy, sz)))
    return out


@dataclass(frozen=True)
class TaskPlacing:
    """Where the object goes for a task: the resting pose to turn it into (None: kept) and the
    place target (world xy of the box centre, the support's height)."""

    task: str
    pose: str | None  # an entry of POSES, or None to keep the orientation
    place_xy: tuple
    support_z: float  # [m] world height of what the object is released onto
    surface: str = ""
    turned_release_heights: tuple = (0.01,)  # [m] (TaskMotionConfig)
    pour_at: tuple | None = None  # pourOut: world xy of the bowl's centre [m]; None: no pour
    pour_tilt: float = np.deg2rad(135.0)  # [rad]
    pour_hold: float = 1.5  # [s]
    pour_clearance: float = 0.05  # [m]
    pour_drop: float = 0.03  # [m]
    pour_yaws: tuple = (0.0,)  # [rad]
    fill_at: tuple | None = None  # pourIn: world (x, y, z) of the dispenser's gate [m]; None:
    # no fill
    fill_clearance: float = 0.02  # [m]
    fill_open: float = 1.5  # [s]
    fill_settle: float = 1.0  # [s]
    R_place: tuple | None = None  # 3×3 (nested tuples): the object's exact world orientation at
    # release (a place-and-regrasp's intermediate resting pose, tg_drake.planning.regrasp); None:
    # turned into `pose` by the grasp's wrist turns
    regrasp_yaws: tuple = ()  # [rad] (TaskMotionConfig.regrasp_yaws)
    regrasp_spots: tuple = (0.0,)  # [1] (TaskMotionConfig)
    regrasp_max_poses: int = 16  # (TaskMotionConfig)
    regrasp_max_legs: int = 3  # (TaskMotionConfig)

    @property
    def pours(self) -> bool:
        """Does the task pour out (over a bowl) or fill (under a dispenser)?"""
        return self.pour_at is not None or self.fill_at is not None

    @property
    def hold(self) -> float:
        """[s] how long the container is held at the pour (tilted) or under the dispenser."""
        return self.fill_open + self.fill_settle if self.fill_at is not None else self.pour_hold

    def place_poses(self, X_WO: np.ndarray, X_WG: np.ndarray, extents, *, is_tool: bool,
                    release_height: float, place_pose, X_OB=None) -> list[tuple]:
        """(R_turn or None, X_WO_place) for the grasp X_WG, before the yaw variants; [] when the
        object cannot be turned into the pose. `place_pose` is the planner's
        (`tg_drake.planning.planner.place_pose`), `extents` and `X_OB` the box it sets down."""
        place_pose = functools.partial(place_pose, X_OB=X_OB)
        X_WO = np.asarray(X_WO, float)
        R_WG = np.asarray(X_WG, float)[:3, :3]
        if self.R_place is not None:  # an exact orientation: one turn, each release height
            R = np.asarray(self.R_place, float) @ X_WO[:3, :3].T
            if np.allclose(R, np.eye(3), atol=1e-9):
                return [(None, place_pose(X_WO, extents, self.place_xy, table_z=self.support_z,
                                          release_height=release_height))]
            if not lets_go_onto_support(R, R_WG):
                return []
            return [(R, place_pose(turned(X_WO, R), extents, self.place_xy,
                                   table_z=self.support_z, release_height=height))
                    for height in self.turned_release_heights]
        if self.pose is None:
            out = [(None, place_pose(X_WO, extents, self.place_xy, table_z=self.support_z,
                                     release_height=release_height))]
            if self.pours and not np.allclose(X_WO[:2, 3], self.place_xy, atol=1e-6):
                # A pour is judged at the bowl or the dispenser, not where the container ends:
                # when the place target is out of this grasp's reach it goes back where it was
                # picked, which the same grasp reached (the pick's own pose, raised
                # `release_height`).
                out.append((None, place_pose(X_WO, extents, X_WO[:2, 3], table_z=self.support_z,
                                             release_height=release_height)))
            return out
        out = []
        for R in turns_to_pose(X_WO[:3, :3], R_WG, self.pose, is_tool=is_tool):
            if np.allclose(R, np.eye(3)):
                out.append((None, place_pose(X_WO, extents, self.place_xy,
                                             table_z=self.support_z,
                                             release_height=release_height)))
                continue
            if not lets_go_onto_support(R, R_WG):  # it would rest on the lower finger
                continue
            for height in self.turned_release_heights:
                out.append((R, place_pose(turned(X_WO, R), extents, self.place_xy,
                                          table_z=self.support_z, release_height=height)))
        return out


def task_placing(task: str, *, place_xy, table_z: float, surface: Surface | None = None,
                 pour_at=None, fill_at=None,
                 config: TaskMotionConfig | None = None) -> TaskPlacing:
    """The placing of `task` (module doc): the resting pose of p&pIn* (when `config.reorient`),
    the surface's centre and top for p&pOn (when the scenario has one), else the place target
    on the table with the orientation kept; pourOut pours over `pour_at` (world xy of the bowl)
    first, when given; pourIn is filled under `fill_at` (world xyz of the dispenser's gate)."""
    config = config or TaskMotionConfig()
    pose = REST_POSE_OF_TASK.get(task) if config.reorient else None
    if task == "p&pOn" and surface is not None:
        return TaskPlacing(task, None, tuple(surface.xy), surface.top_z, surface.name)
    pour = {}
    if task == "pourOut" and pour_at is not None:
        pour = dict(pour_at=(float(pour_at[0]), float(pour_at[1])),
                    pour_tilt=float(np.deg2rad(config.pour_tilt)),
                    pour_hold=float(config.pour_hold), pour_clearance=float(config.pour_clearance),
                    pour_drop=float(config.pour_drop),
                    pour_yaws=tuple(float(v) for v in np.deg2rad(config.pour_yaws)))
    if task == "pourIn" and fill_at is not None:
        pour = dict(fill_at=tuple(float(v) for v in fill_at),
                    fill_clearance=float(config.fill_clearance),
                    fill_open=float(config.fill_open), fill_settle=float(config.fill_settle),
                    pour_yaws=tuple(float(v) for v in np.deg2rad(config.pour_yaws)))
    return TaskPlacing(task, pose, tuple(float(v) for v in place_xy), float(table_z),
                       turned_release_heights=tuple(config.turned_release_heights),
                       regrasp_yaws=tuple(float(v) for v in np.deg2rad(config.regrasp_yaws)),
                       regrasp_spots=tuple(float(f) for f in config.regrasp_spots),
                       regrasp_max_poses=int(config.regrasp_max_poses),
                       regrasp_max_legs=int(config.regrasp_max_legs), **pour)


def bowl_of(obstacles, pour_at) -> int | None:
    """Index of the perceived object (`ObjectDescription`) nearest the bowl's xy `pour_at`."""
    if not len(obstacles):
        return None
    d = [np.linalg.norm(np.asarray(o.X_WO)[:2, 3] - np.asarray(pour_at)) for o in obstacles]
    return int(np.argmin(d))


def _box_heights(X_WO: np.ndarray, extents) -> np.ndarray:
    """[m] world heights of the 8 corners of a box (frame X_WO at its centre, sides `extents`)."""
    corners = np.array(np.meshgrid(*[(-0.5, 0.5)] * 3)).reshape(3, -1).T * np.asarray(extents)
    return (np.asarray(X_WO)[:3, :3] @ corners.T)[2] + np.asarray(X_WO)[2, 3]


def box_top(X_WO: np.ndarray, extents) -> float:
    """[m] world height of the highest corner of a box."""
    return float(np.max(_box_heights(X_WO, extents)))


def box_bottom(X_WO: np.ndarray, extents) -> float:
    """[m] world height of the lowest corner of a box."""
    return float(np.min(_box_heights(X_WO, extents)))


def pour_poses(X_WO: np.ndarray, extents, X_WG: np.ndarray, *, bowl_xy, bowl_top: float,
               tilt: float, clearance: float, drop: float | None = None,
               yaws=(0.0,)) -> list[tuple]:
    """(X_WO_pour, X_WO_tilted) pairs for pouring a container (perceived frame X_WO, z towards
    its opening; box `extents`) held by a gripper at X_WG into a bowl whose top is at
    `bowl_top` over world xy `bowl_xy`: the upright container's opening edge above the bowl's
    centre, its box `clearance` above the bowl's top; then turned by `tilt` [rad] about the
    horizontal axis through that edge and lowered (or raised) until its box's lowest corner is
    `drop` [m] above the bowl's top (None: not moved, the edge stays where it was), so that the
    contents fall from just above the rim. Tilt axes: the horizontal parts of the gripper's
    approach (a turn of the wrist) and closing axes, each way; each turned about the bowl's
    vertical by `yaws` [rad]. [] when the container is not upright."""
    X_WO = np.asarray(X_WO, float)
    if perceived_pose(X_WO[:3, :3], is_tool=False) != "upright":
        return []
    h = float(extents[2])
    r = 0.5 * max(float(extents[0]), float(extents[1]))
    R_WG = np.asarray(X_WG, float)[:3, :3]
    axes = []
    for a in (_horizontal(R_WG[:, 1]), _horizontal(R_WG[:, 0])):
        if a is not None:
            axes += [a, -a]
    z = X_WO[:3, 2]
    lowest = -0.5 * abs(z @ UP) * h  # the box's bottom below its centre (upright, near level)
    out = []
    for yaw in yaws:
        Rz = axis_angle(UP, yaw)
        for a0 in axes:
            a = Rz @ a0
            d = np.cross(a, UP)  # where the opening leans as it turns
            lip = np.array([bowl_xy[0], bowl_xy[1], bowl_top + clearance - lowest + h / 2])
            centre = lip - h / 2 * z - r * d
            X_pour = np.eye(4)
            X_pour[:3, :3] = Rz @ X_WO[:3, :3]
            X_pour[:3, 3] = centre
            R = axis_angle(a, tilt)
            X_tilted = np.eye(4)
            X_tilted[:3, :3] = R @ X_pour[:3, :3]
            X_tilted[:3, 3] = lip + R @ (centre - lip)
            if drop is not None:
                X_tilted[2, 3] += bowl_top + drop - box_bottom(X_tilted, extents)
            out.append((X_pour, X_tilted))
    return out


def fill_poses(X_WO: np.ndarray, extents, *, gate: tuple, clearance: float,
               yaws=(0.0,)) -> list[tuple]:
    """(X_WO_fill, None) for holding an upright container (perceived frame X_WO, box `extents`)
    under a dispenser's gate at world `gate` (x, y, z): its box centred under the gate, its top
    `clearance` below it, turned about the vertical by `yaws` [rad]; [] when not upright."""
    X_WO = np.asarray(X_WO, float)
    if perceived_pose(X_WO[:3, :3], is_tool=False) != "upright":
        return []
    top = 0.5 * abs(X_WO[:3, 2] @ UP) * float(extents[2])  # the box's top above its centre
    out = []
    for yaw in yaws:
        X = np.eye(4)
        X[:3, :3] = axis_angle(UP, yaw) @ X_WO[:3, :3]
        X[:3, 3] = [gate[0], gate[1], gate[2] - clearance - top]
        out.append((X, None))
    return out


def dispenser_obstacle(X_WH: np.ndarray, *, side: float, below: float, above: float) -> Surface:
    """The dispenser as an obstacle box: `side` square about the hopper frame H (the centre of
    the gate's top, table axes; world pose X_WH), from `below` under H to `above` over it [m]."""
    X_WB = np.asarray(X_WH, float).copy()
    X_WB[:3, 3] += X_WB[:3, 2] * (above - below) / 2
    top = np.asarray(X_WH, float)[:3, 3]
    return Surface("dispenser", (float(top[0]), float(top[1])), float(top[2] + above), X_WB,
                   (float(side), float(side), float(above + below)))
