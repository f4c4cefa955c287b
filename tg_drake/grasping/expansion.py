"""The poses that may be executed for a grasp hypothesis: its approach variants, each moved back
above the table. One rule for the DGI's training data (tg_drake.grasping.dataset) and for
inference (the scoring stage scores exactly these poses; the feasibility stage and the planner
take them as they are), so the DGI scores the pose that is executed.

Poses are WSG grasp frames G in the world (tg_drake.robot: fingers close along ±x_G, approach along
+y_G, the grasp point at y_G = WSG_PAD_CENTRE_Y). For each hypothesis X_WG:

1. variants — X_WG itself; a side grasp (approach within `SIDE_LIMIT` of horizontal) also tilted
   downwards about its closing axis through its grasp point by each of `approach_tilts` (the
   fingers still close across the same part, the wrist rises clear of the table); a steeper grasp
   also tilted back towards the robot (at the world origin) by each of `top_tilts`;
2. retreat — each variant whose gripper (the housing and the open pads, at the grasp pose and at
   the start of its straight approach) would come closer than `table_clearance` to the table top
   is moved back along −y_G just enough to clear it, when at most `max_retreat` suffices (a flat
   object is then grasped with the fingertips just above the table); else it is dropped.

Arrays in, arrays out: no Drake.
"""

from dataclasses import dataclass, field

import numpy as np

from tg_drake.errors import GraspingError, ScenarioError
from tg_drake.robot import WSG_BODY_CENTRE_G, WSG_BODY_SIZE, WSG_PAD_CENTRE_Y, wsg_pad_boxes

SIDE_LIMIT = np.deg2rad(30.0)  # [rad] an approach this close to horizontal is a side grasp.

# The gripper's boxes in G with the pads fully open: (centre, full size) [m].
_BOXES = ((np.array(WSG_BODY_CENTRE_G, float), np.array(WSG_BODY_SIZE, float)),
          *((np.asarray(c, float), np.asarray(s, float)) for c, s in wsg_pad_boxes()))
# Their 24 corners in G.
_CORNERS_G = np.concatenate([c + np.array(np.meshgrid(*[(-0.5, 0.5)] * 3)).reshape(3, -1).T * s
                             for c, s in _BOXES])


@dataclass
class ExpansionConfig:
    """The rule that turns a hypothesis into the poses that may be executed
    (`PipelineConfig.expansion`; the training data's `SamplingConfig.expansion`)."""

    approach_tilts: list[float] = field(default_factory=lambda: [10.0, 20.0, 35.0])  # [deg]
    # a side grasp's downward tilts about its closing axis.
    top_tilts: list[float] = field(default_factory=lambda: [15.0, 30.0])  # [deg] a steep grasp's
    # tilts of the wrist back towards the robot about its closing axis.
    table_clearance: float = 0.004  # [m] the gripper's boxes stay this far above the table top
    # (about twice the D415's depth noise σ on the table, 1.8 mm).
    max_retreat: float = 0.05  # [m] a pose may move this far back along its approach to clear
    # the table; one that needs more is dropped.

    def validate(self, where: str = "expansion") -> None:
        for name in ("approach_tilts", "top_tilts"):
            tilts = getattr(self, name)
            if not all(0.0 < float(t) < 90.0 for t in tilts):
                raise ScenarioError(f"{name} must be angles in (0, 90) degrees, got {tilts}",
                                    field=f"{where}.{name}")
        for name in ("table_clearance", "max_retreat"):
            if not getattr(self, name) >= 0:
                raise ScenarioError(f"{name} must be ≥ 0 [m], got {getattr(self, name)}",
                                    field=f"{where}.{name}")


def lowest_point(X_WG: np.ndarray, approach_distance: float) -> np.ndarray:
    """(M,) the lowest z_W [m] of the gripper's boxes (housing and open pads) at each grasp pose
    and at the start of its approach, `approach_distance` [m] back along −y_G (the approach is a
    straight line: its two ends bound it)."""
    X_WG = np.asarray(X_WG, float).reshape(-1, 4, 4)
    lowest = np.full(len(X_WG), np.inf)
    for back in (0.0, approach_distance):
        q = _CORNERS_G - np.array([0.0, back, 0.0])
        z = np.einsum("mj,nj->mn", X_WG[:, 2, :3], q) + X_WG[:, 2, 3][:, None]
        lowest = np.minimum(lowest, z.min(axis=1))
    return lowest


def retreat_above_table(X_WG: np.ndarray, table_z: float, *, approach_distance: float,
                        config: ExpansionConfig) -> tuple[np.ndarray, np.ndarray]:
    """Each pose moved back along −y_G just enough that the gripper clears the table top at
    height `table_z` by `config.table_clearance` (as `lowest_point`), when that takes at most
    `config.max_retreat`. Returns (the moved poses (M, 4, 4), (M,) bool: it clears now)."""
    X_WG = np.asarray(X_WG, float).reshape(-1, 4, 4).copy()
    short = table_z + config.table_clearance - lowest_point(X_WG, approach_distance)
    rise_per_metre = -X_WG[:, 2, 1]  # moving back along −y_G raises every point by −y_G,z
    with np.errstate(divide="ignore", invalid="ignore"):
        retreat = np.where(short <= 0, 0.0, short / rise_per_metre)
    ok = (short <= 0) | ((rise_per_metre > 1e-6) & (retreat <= config.max_retreat))
    retreat = np.where(ok, retreat, 0.0)
    X_WG[:, :3, 3] -= retreat[:, None] * X_WG[:, :3, 1]
    return X_WG, ok


def tilted(X_WG: np.ndarray, angle: float) -> np.ndarray:
    """X_WG turned about its closing axis x_G through its grasp point by `angle` [rad]."""
    c, s = np.cos(angle), np.sin(angle)
    R = X_WG[:3, :3] @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    X = np.eye(4)
    X[:3, :3] = R
    X[:3, 3] = X_WG[:3, 3] + WSG_PAD_CENTRE_Y * (X_WG[:3, 1] - R[:, 1])
    return X


def approach_variants(X_WG: np.ndarray, config: ExpansionConfig) -> list[np.ndarray]:
    """X_WG (4, 4) itself, then its tilted variants (step 1 of the module docstring)."""
    X_WG = np.asarray(X_WG, float)
    variants = [X_WG]
    y = X_WG[:3, 1]
    if abs(y[2]) > np.sin(SIDE_LIMIT):
        p_grasp = X_WG[:3, 3] + WSG_PAD_CENTRE_Y * y
        towards_robot = -p_grasp[:2] / max(np.linalg.norm(p_grasp[:2]), 1e-9)
        for tilt in np.deg2rad(config.top_tilts):
            # the sign whose body (−y_G) leans most towards the robot
            lean, sign = max(((-tilted(X_WG, s * tilt)[:2, 1] @ towards_robot, s)
                              for s in (1.0, -1.0)), key=lambda v: v[0])
            if lean > 1e-6:
                variants.append(tilted(X_WG, sign * tilt))
    else:
        for tilt in np.deg2rad(config.approach_tilts):
            for sign in (1.0, -1.0):
                X = tilted(X_WG, sign * tilt)
                if X[2, 1] < y[2]:  # the approach points further down
                    variants.append(X)
                    break
    return variants


def executed_poses(X_WG: np.ndarray, table_z: float, *, approach_distance: float,
                   config: ExpansionConfig, variants: bool = True
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The poses that may be executed for hypotheses X_WG (M, 4, 4): each hypothesis' approach
    variants (only the hypothesis itself with `variants=False`), each moved back above the table
    at height `table_z` [m] or dropped (the module docstring). `approach_distance` [m]: how far
    back along −y_G the straight approach starts. Returns (poses (K, 4, 4), source (K,): the
    index of the hypothesis each pose was made from), in hypothesis order."""
    X_WG = np.asarray(X_WG, float)
    if X_WG.size and X_WG.shape[-2:] != (4, 4):
        raise GraspingError(f"grasp hypotheses must be (M, 4, 4) poses, got shape {X_WG.shape}")
    X_WG = X_WG.reshape(-1, 4, 4)
    poses, source = [], []
    for i, X in enumerate(X_WG):
        vs = approach_variants(X, config) if variants else [X]
        poses += vs
        source += [i] * len(vs)
    if not poses:
        return np.zeros((0, 4, 4)), np.zeros(0, int)
    moved, ok = retreat_above_table(np.array(poses), table_z,
                                    approach_distance=approach_distance, config=config)
    return moved[ok], np.array(source, int)[ok]
