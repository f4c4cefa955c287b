"""Grasp feasibility: would the gripper get there clear of everything, and would the grasp hold?

One stage, one model, on the pose that will be executed (the grasp frame G of tg_drake.robot:
fingers close along ±x_G, approach along +y_G, z_G across the pads):

(a) collision — the WSG's boxes (the housing and the two finger pads, `tg_drake.robot`) against
    the perceived points and the table plane: the open gripper swept along its approach from the
    pre-grasp to the grasp, and the pads closing from open onto the target. Signed distances of
    points to boxes (`box_signed_distance`). The other objects' points and the table make a pose
    infeasible; the target's cut of the gripper (it pushes the object as it comes: in physics
    episodes such grasps held as often as not) is a feature of the hold model. At the release
    the pads open around the object in the same relative pose, the object a little above the
    table: the grasp's open-pad and table checks stand for it.
(b) hold margin — contact mechanics: the points between the pads that the closing pads reach
    first are the contact patches (area, extent, centre); the pads' Coulomb friction μ
    (tg_drake.robot.WSG_PAD_FRICTION and the object's), the normal force (the grip, capped by the
    WSG's force limit), the object's mass (its perceived convex-hull volume × a density per
    category — the training objects' mass / hull volume, shipped with the hold model — weighted by
    the logic's category distribution) and the lever of its weight about the closing axis give
    the wrench the patches must carry under the lift and carry
    accelerations and the wrench they can carry: a translational, a torsional and a combined
    margin (elliptic limit surface: margin < 1 slips). A pad presses along x_G, but the object
    pushes back along its own surface normal there: where that normal leans away from x_G (a
    round body pinched past its widest section, by the pads' tips) the grip itself pushes the
    object along the pads' faces, out of the hand — the "squeeze", N tan θ per pad, which
    friction must carry before any load; a squeeze of friction's whole capacity (`squeeze` ≥ 1,
    tan θ ≥ μ: the contact force outside the friction cone) cannot hold whatever the object
    weighs, and such a pose is infeasible.
(c) P(hold | features) — a logistic regression on the margins and patch features, fitted on
    physics episodes of training objects (tools/fit_hold_model.py; tg_drake/data/hold_model.json),
    the squeeze among its inputs; reported, and ranked by with `rank_by_hold`.
(d) geometric refusals — what lies between the open pads, measured on the perceived points
    (`tg_drake.grasping.pads.geometric_refusal`): a part or object that does not fit the opening
    or could not be let go, an open pad coming down on a tool, and grasps that would slip (closing
    along a long part, too little between the pads, a step under them, a tool pressed above its
    widest section or too thin, too long a lever for the weight). Each reason begins with its
    class (`pads.DOES_NOT_FIT`, `COLLISION`, `WOULD_NOT_HOLD`); a part none of whose poses would
    hold is told to the logic as no_hold(Part), not as unreachable.

Arrays in, arrays out: no Drake.
"""


import functools
import json
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

import numpy as np
from scipy.spatial import ConvexHull, QhullError, cKDTree

from tg_drake.errors import ModelError, ScenarioError
from tg_drake.grasping.pads import (
    COLLISION,
    WOULD_NOT_HOLD,
    geometric_refusal,
    in_slab,
)
from tg_drake.robot import (
    WSG_BODY_CENTRE_G,
    WSG_BODY_SIZE,
    WSG_FORCE_LIMIT,
    WSG_GRASP_POINT_G,
    WSG_MAX_OPENING,
    WSG_PAD_FRICTION,
    wsg_pad_boxes,
)
from tg_drake.types import CATEGORIES, PART_LABELS, GraspCandidates, SceneDescription

GRAVITY = 9.81  # [m/s²]
HOLD_MODEL = "hold_model.json"  # in tg_drake/data: the shipped fit (tools/fit_hold_model.py)


@dataclass
class FeasibilityConfig:
    """The physics and the fitted model of grasp feasibility (`PipelineConfig.feasibility`)."""

    opening: float = WSG_MAX_OPENING  # [m] the WSG's opening while it moves (its full stroke).
    point_tolerance: float = 0.002  # [m] a point cuts a box when this deep in it (perception's
    # 1 mm noise per axis, twice).
    min_points: int = 3  # a box's cut is its min_points-th deepest point's (stray points do not
    # count).
    table_clearance: float = 0.0  # [m] the gripper's boxes stay this far above the table top.
    pad_friction: float = WSG_PAD_FRICTION  # Coulomb μ of the WSG's pads (models/wsg_50).
    object_friction: float = 1.0  # Coulomb μ assumed for the object (the shipped library's
    # models/objects/*.sdf); the contact's μ is 2 μ_pad μ_object / (μ_pad + μ_object) (Drake's
    # rule).
    grip_force: float = 60.0  # [N] each pad's normal force on the object, capped by the WSG's
    # force limit (robot.WSG_FORCE_LIMIT, 80 N): the grasp episodes' set point.
    contact_depth: float = 0.003  # [m] points within this of a pad's first contact along x_G
    # form its patch (perception's voxel is 4 mm; the pads' hydroelastic layer yields ~1 mm).
    patch_cell: float = 0.004  # [m] cells of a patch's area (perception's voxel).
    lift_acceleration: float = 2.0  # [m/s²] upwards, at the lift (a design load).
    carry_acceleration: float = 3.0  # [m/s²] horizontal, any direction, while carried.
    default_density: float = 500.0  # [kg/m³] of convex-hull volume, when no category
    # distribution is given (the hold model's per-category densities otherwise).
    min_p_hold: float = 0.5  # a candidate more likely to slip than to hold (P(hold) below this)
    # gets score 0, "would not hold" (with `rank_by_hold`).
    rank_by_hold: bool = True  # multiply the score by P(hold) and refuse below min_p_hold.
    # The shipped model (1,225 episodes of 110 training objects, generated and scan-like, with
    # the 1e7 Pa pads) predicts held-out objects' episodes (Brier 0.145 against the base rate's
    # 0.249, AUC 0.86: tg_drake/data/hold_model.report.json). Ranking by an earlier fit, on the
    # executed generalization suites (254 runs, against the same code not ranking): 4
    # deliveries gained (a squat can by its middle; three pots, two taken by the top instead of
    # a handle that turned in the pads), 1 lost (a spatula by its handle). The default scenario's
    # cup is passed by its middle (P(hold) 0.89).
    # The geometric refusals (`tg_drake.grasping.pads.geometric_refusal`): each compares a
    # measure of the perceived points between the pads with one of these limits. They were
    # set from executed grasps, not fitted; the opening is `opening`.
    width_margin: float = 0.01  # [m] a part must be this much narrower than the opening.
    release_gap: float = 0.013  # [m] an object reaching past both open pads, less this gap
    # (within `release_band` of the grasp point across the pads), could not be let go.
    release_band: float = 0.03  # [m]
    min_pad_depth: float = 0.007  # [m] how far along the pads (the approach) the object must
    # reach between them (seen points).
    min_pad_overlap: float = 0.005  # [m] how far across the pads' 20 mm width the object must
    # span between them: a thin edge pinched between the pads slides out.
    min_contact_share: float = 0.5  # the pads must touch the object's widest section over at
    # least this share of the bands (pads.PAD_BANDS across their width) the object fills between
    # them: a pad landing on a step touches the step only and squeezes the object out.
    min_tool_grip_area: float = 25e-6  # [m²] how much of a pad's face must lie over the lower
    # half of a tool lying on the table (`pads.pad_area_below_middle`): pads pressing only above a
    # rounded handle's widest section squeeze it down and ride up over it.
    min_tool_grip_width: float = 0.008  # [m] a tool lying on the table is at least this thick
    # along the closing axis between the pads (seen points): a thinner shaft rolls out.
    max_pad_cover: float = 1.0 / 3.0  # an open pad may come down over a tool lying on the table
    # on at most this share of its cross-section (`pads.open_pad_cover`): the pad stops on it.
    max_torsion_lever: float = 0.12  # [m] a candidate whose `torsion_lever` (the weight's lever
    # about the closing axis) is longer is refused: the pads resist that turn by friction alone.
    max_length_ratio: float = 2.0  # fingers do not close along a part's length when it is this
    # many times longer than its other extents (squeezed end to end, it slips out).
    model: str = ""  # a hold-model JSON file (tools/fit_hold_model.py); "" = the shipped one.

    def validate(self, where: str = "feasibility") -> None:
        for name in ("opening", "grip_force", "contact_depth", "patch_cell", "pad_friction",
                     "object_friction", "default_density", "max_length_ratio"):
            if not getattr(self, name) > 0:
                raise ScenarioError(f"{name} must be > 0, got {getattr(self, name)}",
                                    field=f"{where}.{name}")
        for name in ("width_margin", "release_gap", "release_band", "min_pad_depth",
                     "min_pad_overlap", "min_tool_grip_area", "min_tool_grip_width",
                     "max_torsion_lever"):
            if not getattr(self, name) >= 0:
                raise ScenarioError(f"{name} must be >= 0, got {getattr(self, name)}",
                                    field=f"{where}.{name}")
        for name in ("min_contact_share", "max_pad_cover"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise ScenarioError(f"{name} must be in [0, 1], got {getattr(self, name)}",
                                    field=f"{where}.{name}")
        if not 0.0 <= self.min_p_hold <= 1.0:
            raise ScenarioError(f"min_p_hold must be in [0, 1], got {self.min_p_hold}",
                                field=f"{where}.min_p_hold")
        if self.model and not Path(self.model).is_file():
            raise ScenarioError(f"no such hold model file {self.model!r}",
                                field=f"{where}.model")

    @property
    def friction(self) -> float:
        """The pad–object contact's μ (Drake's combination of the two materials' μ)."""
        a, b = self.pad_friction, self.object_friction
        return 2 * a * b / (a + b)


# --- (a) collision ------------------------------------------------------------------------------


def box_signed_distance(p_B: np.ndarray, half: np.ndarray) -> np.ndarray:
    """(N,) signed distances [m] of points p_B (N, 3), in the frame of an axis-aligned box centred
    at the origin with half sizes `half`, to the box's surface: negative inside."""
    q = np.abs(p_B) - np.asarray(half, float)
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    inside = np.minimum(q.max(axis=1), 0.0)
    return outside + inside


def gripper_boxes(opening: float, approach: float = 0.0) -> list[tuple[str, np.ndarray,
                                                                     np.ndarray]]:
    """The WSG's boxes in G (name, centre, half size) with its pads `opening` [m] apart, each
    swept `approach` [m] back along −y_G (the volume the box passes through on the approach)."""
    out = [("housing", np.array(WSG_BODY_CENTRE_G, float), np.array(WSG_BODY_SIZE) / 2)]
    for side, (c, size) in zip(("left pad", "right pad"), wsg_pad_boxes(opening), strict=True):
        out.append((side, np.asarray(c, float), np.asarray(size, float) / 2))
    if approach > 0:
        out = [(n, c - [0.0, approach / 2, 0.0], h + [0.0, approach / 2, 0.0])
               for n, c, h in out]
    return out


# The 8 corners of a unit box's half sizes, as signs (x, y, z) (built once: `_box_corners_W` is
# called for every box of every pose).
_CORNER_SIGNS = np.array(np.meshgrid(*[(-1.0, 1.0)] * 3)).reshape(3, -1).T


def _box_corners_W(X_WG: np.ndarray, centre, half) -> np.ndarray:
    """(…, 8, 3) the world corners of boxes (centre, half sizes: (…, 3)) in G, the gripper at
    X_WG (…, 4, 4) (the leading shapes broadcast)."""
    return ((np.expand_dims(centre, -2) + _CORNER_SIGNS * np.expand_dims(half, -2))
            @ np.swapaxes(X_WG[..., :3, :3], -1, -2) + X_WG[..., None, :3, 3])


def _in_G(X_WG: np.ndarray, p_W: np.ndarray) -> np.ndarray:
    """(M, n, 3) the points p_W (n, 3) in the gripper frame of each pose X_WG (M, 4, 4) (one
    product per pose, as for a single pose)."""
    return (p_W - X_WG[:, None, :3, 3]) @ X_WG[:, :3, :3]


def _cuts(p_G: np.ndarray, centre: np.ndarray, half: np.ndarray, k: int,
          present: np.ndarray | None = None) -> np.ndarray:
    """(M, B) how deep [m] the points p_G (M, n, 3), each in its pose's gripper frame, cut each
    of B boxes (centre, half sizes: (B, 3), or (M, B, 3) per pose): the k-th deepest point's
    depth (robust to k − 1 stray points), 0 when fewer than k points are inside some box (only
    those count). `present` (M, B) bool: the boxes each pose has (default: all; 0 for the
    others)."""
    m, n = p_G.shape[:2]
    b = np.shape(centre)[-2]
    per_pose = np.ndim(centre) == 3
    present = np.ones((m, b), bool) if present is None else present
    out = np.zeros((m, b))
    if n < k:
        return out
    lo = np.where(present[..., None], centre - half, np.inf).min(axis=1)
    hi = np.where(present[..., None], centre + half, -np.inf).max(axis=1)
    inside = np.ones((m, n), bool)
    for a in range(3):
        inside &= (p_G[..., a] >= lo[:, a, None]) & (p_G[..., a] <= hi[:, a, None])
    pose, i = np.nonzero(inside)
    q = p_G[pose, i]  # by pose
    for j in range(b):
        c, h = (centre[pose, j], half[pose, j]) if per_pose else (centre[j], half[j])
        # Only a point in the box (depth ≥ 0) makes a cut; one more than 1e-100 m out of it
        # on some axis is out of it (its distance > 0 in `box_signed_distance`).
        near = np.ones(len(q), bool)
        for a in range(3):
            near &= np.abs(q[:, a] - c[..., a]) - h[..., a] <= 1e-100
        depth = -box_signed_distance(q[near] - c[near] if per_pose else q[near] - c,
                                     h[near] if per_pose else h)
        deep = depth >= 0.0
        depth, of = depth[deep], pose[near][deep]
        count = np.bincount(of, minlength=m)
        enough = count >= k
        if enough.any():  # the k-th deepest of each pose's points in the box
            out[enough, j] = depth[np.lexsort((depth, of))][np.cumsum(count)[enough] - k]
    return np.where(present, out, 0.0)


def _named(names, depths: np.ndarray) -> dict[str, float]:
    """Box name → the deepest cut (`_cuts`, one pose's row) of the boxes of that name."""
    out = dict.fromkeys(names, 0.0)
    for name, d in zip(names, depths.tolist(), strict=True):
        out[name] = max(out[name], d)
    return out


def penetration(X_WG: np.ndarray, p_W: np.ndarray, boxes, k: int) -> dict[str, float]:
    """Box name → how deep [m] the points p_W cut it: the k-th deepest point's depth (robust to
    k − 1 stray points), 0 when fewer than k points are inside."""
    p_G = _in_G(np.asarray(X_WG, float)[None], np.asarray(p_W, float).reshape(-1, 3))
    return _named([name for name, _, _ in boxes],
                  _cuts(p_G, np.array([c for _, c, _ in boxes]),
                        np.array([h for _, _, h in boxes]), k)[0])


def boxes_reach(centre: np.ndarray, half: np.ndarray) -> float:
    """[m] the farthest corner of boxes (centres, half sizes: (…, 3)) from their frame's
    origin: no point farther than this from it lies in one."""
    return float(np.linalg.norm(np.abs(centre) + half, axis=-1).max())


def _near_poses(X_WG: np.ndarray, p_W: np.ndarray, reach: float) -> np.ndarray:
    """The points p_W (n, 3) within `reach` [m] of some pose's origin (X_WG (M, 4, 4)): the only
    ones that can lie in a box of that reach (`boxes_reach`) at one of the poses."""
    if not len(p_W) or not len(X_WG):
        return p_W
    return p_W[np.isfinite(cKDTree(X_WG[:, :3, 3]).query(p_W, distance_upper_bound=reach)[0])]


def deepest_cuts(X_WG: np.ndarray, p_W: np.ndarray, boxes, k: int) -> np.ndarray:
    """(M,) how deep [m] the points p_W (n, 3) cut the deepest of the gripper's `boxes` (name,
    centre, half size in G) at each pose X_WG (M, 4, 4): `penetration`'s measure (the k-th
    deepest point of a box; 0 when fewer than k points are inside), many poses at once."""
    X_WG = np.asarray(X_WG, float).reshape(-1, 4, 4)
    centre = np.array([c for _, c, _ in boxes])
    half = np.array([h for _, _, h in boxes])
    p_W = _near_poses(X_WG, np.asarray(p_W, float).reshape(-1, 3), boxes_reach(centre, half))
    step = max(1, _BATCH_POINTS // max(len(p_W), 1))  # poses × points held at once
    return np.concatenate([_cuts(_in_G(X_WG[i:i + step], p_W), centre, half, k).max(axis=1)
                           for i in range(0, len(X_WG), step)]) if len(X_WG) else np.zeros(0)


@dataclass(frozen=True)
class Collision:
    """How the gripper meets what it must not touch (the other objects, the table)."""

    depth: float  # [m] the deepest cut of a box by another object's points (≥ 0)
    box: str  # the box cut most ("" when none)
    what: str  # "other object" | "table" | "" (free)
    table_clearance: float  # [m] the lowest box corner above the table (negative: under it)

    @property
    def free(self) -> bool:
        return not self.what


def closing_sweep(opening: float, closed_width: float) -> list:
    """The pads' boxes swept from `opening` [m] apart to `closed_width` [m] apart (G)."""
    sweep = []
    for (c_o, s), (c_c, _) in zip(wsg_pad_boxes(opening), wsg_pad_boxes(max(closed_width, 0.0)),
                                  strict=True):
        lo = np.minimum(c_o - s / 2, c_c - s / 2)
        hi = np.maximum(c_o + s / 2, c_c + s / 2)
        sweep.append(("closing pad", (lo + hi) / 2, (hi - lo) / 2))
    return sweep


def collision(X_WG: np.ndarray, *, others_p_W: np.ndarray, table_z: float, approach: float,
              config: FeasibilityConfig, closed_width: float | None = None) -> Collision:
    """The open gripper swept from `approach` [m] back along its approach to X_WG, and the pads
    closing from open to `closed_width` [m] (the target's width between them; None: not
    checked), against the other objects' points and the table plane at height `table_z`."""
    return _collisions(np.asarray(X_WG, float)[None], others_p_W=others_p_W, table_z=table_z,
                       approach=approach, config=config, closed_widths=[closed_width])[0]


def _collisions(X_WG: np.ndarray, *, others_p_W: np.ndarray, table_z: float, approach: float,
                config: FeasibilityConfig, closed_widths) -> list[Collision]:
    """`collision` of each pose X_WG (M, 4, 4), its pads closing to closed_widths[i] [m] (None:
    not checked)."""
    boxes = gripper_boxes(config.opening, approach)
    sweeps = [[] if w is None else closing_sweep(config.opening, w) for w in closed_widths]
    extra = max(map(len, sweeps), default=0)
    names = [n for n, _, _ in boxes] + [""] * extra
    centre = np.zeros((len(X_WG), len(names), 3))
    half = np.zeros_like(centre)
    present = np.zeros(centre.shape[:2], bool)
    centre[:, :len(boxes)] = [c for _, c, _ in boxes]
    half[:, :len(boxes)] = [h for _, _, h in boxes]
    present[:, :len(boxes)] = True
    for i, sweep in enumerate(sweeps):
        for j, (name, c, h) in enumerate(sweep, start=len(boxes)):
            names[j], centre[i, j], half[i, j], present[i, j] = name, c, h, True
    p_W = _near_poses(X_WG, np.asarray(others_p_W, float).reshape(-1, 3),
                      boxes_reach(centre[present], half[present]))
    p_G = _in_G(X_WG, p_W)
    cuts = _cuts(p_G, centre, half, config.min_points, present)
    lowest = np.where(present[..., None], _box_corners_W(X_WG[:, None], centre, half)[..., 2],
                      np.inf).min(axis=(1, 2))
    out = []
    for i in range(len(X_WG)):
        cut = _named([n for n, p in zip(names, present[i], strict=True) if p],
                     cuts[i, present[i]])
        name = max(cut, key=cut.get)
        table = lowest[i] - table_z
        if cut[name] > config.point_tolerance:
            out.append(Collision(cut[name], name, "other object", float(table)))
        elif table < config.table_clearance:
            out.append(Collision(float(config.table_clearance - table), "", "table",
                                 float(table)))
        else:
            out.append(Collision(0.0, "", "", float(table)))
    return out


# --- (b) hold margin ----------------------------------------------------------------------------


@dataclass(frozen=True)
class Hold:
    """The contact mechanics of one grasp (all in SI units)."""

    width: float  # [m] the target between the pads along x_G (0: nothing between them)
    n_points: int  # perceived points between the pads
    patch_area: float  # [m²] the smaller of the two pads' contact patches
    patch_extent: float  # [m] the smaller patch's smaller extent across its face
    torsion_radius: float  # [m] mean distance of the patches' cells from their centres
    p_WC: np.ndarray  # (3,) the contact centre (between the patches' centres)
    mass: float  # [kg] estimated
    lever: float  # [m] of the weight about the closing axis through the contact centre
    force_capacity: float  # [N] tangential force the two patches carry (2 μ N)
    torque_capacity: float  # [N·m] torque about x_G they carry by friction
    translational_margin: float  # capacity / the largest tangential load (inf: no load)
    torsional_margin: float  # capacity / the largest torque about x_G
    margin: float  # the combined (elliptic limit surface) margin, the squeeze included: < 1 slips
    pad_cut: float = 0.0  # [m] how deep the target's points cut the open pads' approach sweep
    housing_cut: float = 0.0  # [m] … and the housing's: the gripper pushes the object there
    squeeze: float = 0.0  # the share of the pads' friction their own grip uses up pushing the
    # object along their faces, out of the hand (|Σ tan θ| / 2μ over the two patches' mean
    # surface normals): ≥ 1 squeezes it out at any weight; 0 without normals

    def features(self) -> np.ndarray:
        return hold_feature_vector(self)

    def summary(self) -> dict:
        """The figures result.json reports for the executed grasp (SI units in the names)."""
        def r(x, digits=4):
            return None if not np.isfinite(x) else round(float(x), digits)
        return {"margin": r(self.margin), "squeeze": r(self.squeeze),
                "width_mm": r(self.width * 1e3, 2), "patch_area_mm2": r(self.patch_area * 1e6, 1),
                "lever_mm": r(self.lever * 1e3, 1), "mass_kg": r(self.mass)}


# The model's inputs: the combined margin carries the mass, the friction, the force and the lever
# (the translational and torsional margins, the mass and the lever alone are reported, not fitted:
# collinear with it, they let a small fit give margin the wrong sign).
FEATURES = ("log_margin_shortfall", "log_patch_area_mm2", "patch_extent_mm", "width_fraction",
            "pad_cut_mm", "housing_cut_mm", "squeeze")
_MAX_LOG = 5.0  # log-margins clipped to ±5 (e⁵ ≈ 150: beyond that, more margin says nothing)


def hold_feature_vector(h: Hold) -> np.ndarray:
    def lg(x):
        return float(np.clip(np.log(max(x, 1e-9)), -_MAX_LOG, _MAX_LOG))
    # Margin beyond e (the loads tripled) says nothing more about slipping: log margin ≤ 1.
    # The squeeze beyond 1 is refused outright (outside the friction cone): capped there.
    return np.array([min(lg(h.margin), 1.0), lg(h.patch_area * 1e6 + 1e-3), h.patch_extent * 1e3,
                     h.width / WSG_MAX_OPENING, h.pad_cut * 1e3, h.housing_cut * 1e3,
                     min(h.squeeze, 1.0)])


def mean_density(category: dict[str, float] | None, densities: dict[str, float],
                 default: float) -> float:
    """[kg/m³] the per-category densities (category → kg/m³ of convex-hull volume) weighted by a
    category distribution (name → probability); `default` when none is given or known."""
    if not category:
        return default
    w = np.array([max(float(category.get(c, 0.0)), 0.0) if c in densities else 0.0
                  for c in CATEGORIES])
    if w.sum() <= 0:
        return default
    rho = np.array([densities.get(c, 0.0) for c in CATEGORIES])
    return float(w @ rho / w.sum())


def hull_volume(p_W: np.ndarray) -> float:
    """[m³] of the points' convex hull (0 for fewer than 4 points or a flat set)."""
    if len(p_W) < 4:
        return 0.0
    try:
        return float(ConvexHull(np.asarray(p_W, float)).volume)
    except QhullError:
        return 0.0


NORMAL_NEIGHBOURS = 12  # k of the k-nearest-neighbour normals (perception's completion uses 12)


def point_normals(p: np.ndarray, k: int = NORMAL_NEIGHBOURS) -> np.ndarray:
    """(n, 3) unit surface normals of points p (n, 3), unoriented: the direction of least spread
    of each point's k nearest neighbours (zeros for fewer than 3 points)."""
    p = np.asarray(p, float).reshape(-1, 3)
    if len(p) < 3:
        return np.zeros_like(p)
    _, idx = cKDTree(p).query(p, k=min(k, len(p)))
    q = p[idx] - p[idx].mean(axis=1, keepdims=True)
    _, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", q, q))
    return vectors[:, :, 0]  # eigenvalues ascend: the first is the normal


def squeeze_tangent(n_G: np.ndarray, side: float, weights: np.ndarray | None = None
                    ) -> np.ndarray:
    """(2,) how a pad pressing along side·x_G (−1: the left pad, at the object's −x side) pushes
    the object along the pad's face, per unit of grip: the (y_G, z_G) part of the contact force
    along the `weights`-weighted mean outward surface normal of the patch's points n_G (m, 3),
    scaled to a unit x_G part (magnitude tan θ, θ the normal's lean from x_G). Zero without
    normals."""
    n = np.asarray(n_G, float).reshape(-1, 3)
    w = np.ones(len(n)) if weights is None else np.asarray(weights, float)
    return _squeeze_tangents(n, side, w, np.zeros(len(n), int), 1)[0]


def _squeeze_tangents(n_G: np.ndarray, side: float, weights: np.ndarray, group: np.ndarray,
                      n: int) -> np.ndarray:
    """(n, 2) `squeeze_tangent` of each of n patches: the normals n_G (s, 3) and the weights
    (s,) of its points, `group` (s,) the patch of each point (0 … n − 1, ascending)."""
    n_G = n_G * np.where(n_G[:, 0] * side < 0, -1.0, 1.0)[:, None]  # outward: towards the pad
    count = np.bincount(group, minlength=n)
    end = np.cumsum(count)
    total, mean = np.zeros(n), np.zeros((n, 3))
    for j, (a, b) in enumerate(zip(end - count, end, strict=True)):
        if b > a:  # each patch's sums over its own points, as for one patch alone
            total[j] = weights[a:b].sum()
            mean[j] = weights[a:b] @ n_G[a:b]
    ok = total > 0
    mean[ok] /= total[ok, None]
    ok &= np.abs(mean[:, 0]) >= 1e-9
    out = np.zeros((n, 2))
    # The pad pushes the object along −n; per unit of its x_G part: −n / |n_x|.
    out[ok] = -mean[ok, 1:] / np.abs(mean[ok, 0])[:, None]
    return out


def _patches(q: np.ndarray, group: np.ndarray, n: int, cell: float
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per patch: (area, smaller extent, centre (y, z), mean cell distance from the centre),
    arrays (n,), (n,), (n, 2), (n,), of the patch points q (s, 2) in a pad's face coordinates,
    `group` (s,) the patch of each point (0 … n − 1, ascending, none empty)."""
    ij = np.floor(q / cell).astype(int)
    lo = ij.min(axis=0)
    span = ij.max(axis=0) - lo + 1
    key = (group * span[0] + ij[:, 0] - lo[0]) * span[1] + ij[:, 1] - lo[1]
    _, first = np.unique(key, return_index=True)  # each occupied cell once, by patch, y, z
    cells, of = ij[first], group[first]
    n_cells = np.bincount(of, minlength=n)
    end = np.cumsum(n_cells)
    centres = (cells + 0.5) * cell
    # Each patch's mean cell centre, summed cell after cell (as `ndarray.mean(axis=0)` does).
    padded = np.zeros((n, n_cells.max(), 2))
    padded[of, np.arange(len(of)) - (end - n_cells)[of]] = centres
    centre = padded.cumsum(axis=1)[np.arange(n), n_cells - 1] / n_cells[:, None]
    d = np.linalg.norm(centres - centre[of], axis=1)
    radius = np.array([np.add.reduce(d[e - k:e]) for e, k in zip(end, n_cells, strict=True)]
                      ) / n_cells
    start = np.flatnonzero(np.r_[True, group[1:] != group[:-1]])
    extent = np.where(np.diff(np.r_[start, len(group)]) > 1,
                      (np.maximum.reduceat(q, start) - np.minimum.reduceat(q, start)).min(axis=1),
                      0.0)
    # A single cell still turns about its own extent: at least a cell's mean radius (≈ 0.38 a).
    return n_cells * cell ** 2, extent, centre, np.maximum(radius, 0.38 * cell)


def _between(p_G: np.ndarray, opening: float) -> np.ndarray:
    """(…,) bool: which points p_G (…, 3), in the gripper frame, lie between its pads opened
    `opening` [m] (within the pads' length along y_G and their width along z_G)."""
    return in_slab(p_G.reshape(-1, 3), reach=opening / 2).reshape(p_G.shape[:-1])


def between_pads(X_WG: np.ndarray, p_W: np.ndarray, opening: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(inside (n,) bool, p_G (n, 3)): the points p_W (n, 3) in the gripper frame at X_WG, and
    which of them lie between its pads opened `opening` [m] (within the pads' length along y_G
    and their width along z_G)."""
    p_G = _in_G(np.asarray(X_WG, float)[None], np.asarray(p_W, float).reshape(-1, 3))[0]
    return _between(p_G, opening), p_G


def grip_width(X_WG: np.ndarray, p_W: np.ndarray, opening: float) -> float:
    """[m] how wide the points between the pads (`between_pads`) are along the closing axis
    x_G: where the pads stop as they close on them (0 when fewer than two points)."""
    inside, p_G = between_pads(X_WG, p_W, opening)
    return float(np.ptp(p_G[inside, 0])) if inside.sum() >= 2 else 0.0


def hold(X_WG: np.ndarray, *, target_p_W: np.ndarray, mass: float,
         config: FeasibilityConfig, p_WCoM: np.ndarray | None = None,
         approach: float = 0.0, normals_W: np.ndarray | None = None) -> Hold:
    """The hold of grasp X_WG on the target's points (the completed cloud), an object of `mass`
    [kg] with its centre of mass at p_WCoM (default: the points' centroid); the target's cut of
    the open gripper swept `approach` [m] along its approach (the gripper pushes the object
    there: whether it still holds is the fitted model's to say). `normals_W`: the points' surface
    normals (`point_normals`, any sign) for the squeeze; None: no squeeze."""
    return _holds(np.asarray(X_WG, float)[None], target_p_W=target_p_W, mass=mass,
                  config=config, p_WCoM=p_WCoM, approach=approach, normals_W=normals_W)[0]


def _holds(X_WG: np.ndarray, *, target_p_W: np.ndarray, mass: float,
           config: FeasibilityConfig, p_WCoM: np.ndarray | None = None,
           approach: float = 0.0, normals_W: np.ndarray | None = None) -> list[Hold]:
    """`hold` of each grasp pose X_WG (M, 4, 4)."""
    p_W = np.asarray(target_p_W, float)
    com = p_W.mean(axis=0) if p_WCoM is None and len(p_W) else np.asarray(p_WCoM, float)
    p_G = _in_G(X_WG, p_W.reshape(-1, 3))
    inside = _between(p_G, config.opening)
    N = min(config.grip_force, WSG_FORCE_LIMIT)
    mu = config.friction
    boxes = gripper_boxes(config.opening, approach)
    cut = _cuts(p_G, np.array([c for _, c, _ in boxes]), np.array([h for _, _, h in boxes]),
                config.min_points)
    names = [name for name, _, _ in boxes]
    cuts = []
    for row in cut:
        c = _named(names, row)
        cuts.append(dict(pad_cut=max(c["left pad"], c["right pad"]), housing_cut=c["housing"]))
    count = inside.sum(axis=1)
    out = [None] * len(X_WG)
    for i in np.flatnonzero(count < 2):
        p = X_WG[i, :3, 3] + X_WG[i, :3, :3] @ WSG_GRASP_POINT_G
        out[i] = Hold(0.0, int(count[i]), 0.0, 0.0, 0.0, p, mass, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                      **cuts[i])
    some = np.flatnonzero(count >= 2)  # the poses with points between the pads, k = 0 … K − 1
    if not len(some):
        return out
    # Their points between the pads, pose after pose (k: each point's pose).
    pose, point = np.nonzero(inside[some])
    between = p_G[some[pose], point]
    start = np.cumsum(count[some]) - count[some]
    x = between[:, 0]
    lo, hi = np.minimum.reduceat(x, start), np.maximum.reduceat(x, start)
    on_left = x <= lo[pose] + config.contact_depth
    on_right = x >= hi[pose] - config.contact_depth
    (aL, eL, cL, rL), (aR, eR, cR, rR) = (
        _patches(between[on][:, 1:], pose[on], len(some), config.patch_cell)
        for on in (on_left, on_right))
    X = X_WG[some]
    R, t = X[:, :3, :3], X[:, :3, 3]
    c_G = np.column_stack([(lo + hi) / 2, (cL + cR) / 2])
    p_WC = t + (R @ c_G[:, :, None])[..., 0]
    force_cap = 2 * mu * N
    torque_cap = mu * N * (rL + rR)
    # The squeeze: the pads' own push along their faces (towards the palm it only seats the
    # object against it, so only its part out of the hand, +y_G, and across the pads, ±z_G).
    squeeze_force = np.zeros(len(some))  # [N] friction must carry it before any load
    if normals_W is not None:
        normals_W = np.asarray(normals_W, float)
        n_G = np.concatenate([normals_W[point[a:b]] @ R[k] for k, (a, b) in enumerate(
            zip(start, start + count[some], strict=True))])  # one product per pose
        # Each point weighs as a compliant pad presses it: by how deep the pad reaches past it.
        depth = config.contact_depth
        push = (_squeeze_tangents(n_G[on_left], -1.0, 1.0 - (x[on_left] - lo[pose[on_left]])
                                  / depth, pose[on_left], len(some))
                + _squeeze_tangents(n_G[on_right], 1.0, 1.0 - (hi[pose[on_right]]
                                                               - x[on_right]) / depth,
                                    pose[on_right], len(some)))
        push[:, 0] = np.maximum(push[:, 0], 0.0)
        squeeze_force = N * np.array([float(np.linalg.norm(v)) for v in push])
    # The loads: the patches accelerate the object by a against gravity: f = m (a − g).
    dirs = np.linspace(0.0, 2 * np.pi, 8, endpoint=False)
    accel = np.vstack([[0.0, 0.0, 0.0], [0.0, 0.0, config.lift_acceleration],
                       config.carry_acceleration * np.column_stack(
                           [np.cos(dirs), np.sin(dirs), np.zeros_like(dirs)])])
    f_W = mass * (accel + [0.0, 0.0, GRAVITY])
    r_W = com - p_WC
    tau_W = np.cross(r_W[:, None], f_W)
    x_G = X[:, :3, 0]
    # Across the pads' faces (f_W less its part along x_G).
    f_t = np.linalg.norm(f_W - (f_W @ x_G[..., None]) * x_G[:, None], axis=2)
    tau_x = np.abs((tau_W @ x_G[..., None])[..., 0])
    u = np.sqrt(((f_t + squeeze_force[:, None]) / force_cap) ** 2
                + (tau_x / np.maximum(torque_cap, 1e-12)[:, None]) ** 2)
    lever = np.abs((x_G[:, None] @ np.cross(r_W, [0.0, 0.0, 1.0])[..., None])[:, 0, 0])
    f_max, tau_max, u_max = f_t.max(axis=1), tau_x.max(axis=1), u.max(axis=1)
    for k, i in enumerate(some):
        out[i] = Hold(width=float(hi[k] - lo[k]), n_points=int(count[i]),
                      patch_area=float(min(aL[k], aR[k])),
                      patch_extent=float(min(eL[k], eR[k])),
                      torsion_radius=float((rL[k] + rR[k]) / 2), p_WC=p_WC[k], mass=float(mass),
                      lever=float(lever[k]), force_capacity=force_cap,
                      torque_capacity=float(torque_cap[k]),
                      translational_margin=(float(force_cap / f_max[k]) if f_max[k] > 0
                                            else np.inf),
                      torsional_margin=(float(torque_cap[k] / tau_max[k]) if tau_max[k] > 0
                                        else np.inf),
                      margin=float(1.0 / u_max[k]) if u_max[k] > 0 else np.inf,
                      squeeze=float(squeeze_force[k]) / force_cap, **cuts[i])
    return out


# --- (c) P(hold | features) ---------------------------------------------------------------------


@dataclass(frozen=True)
class HoldModel:
    """A fitted logistic regression: P(hold) = σ(w · (f − mean) / scale + b)."""

    features: tuple[str, ...]
    mean: np.ndarray
    scale: np.ndarray
    weights: np.ndarray
    bias: float
    meta: dict

    @property
    def densities(self) -> dict[str, float]:
        """[kg/m³] per category: the training objects' median mass / convex-hull volume (the
        volume perception can see: the importing prior's mass / enclosed volume is the walls'
        material for an open container's closed-wall mesh, not comparable)."""
        return dict(self.meta.get("hull_density_kg_m3", {}))

    def predict_proba(self, F: np.ndarray) -> np.ndarray:
        """(n,) P(hold) for features F (n, len(features))."""
        z = ((np.atleast_2d(F) - self.mean) / self.scale) @ self.weights + self.bias
        return 1.0 / (1.0 + np.exp(-z))

    def as_dict(self) -> dict:
        return {"features": list(self.features), "mean": self.mean.tolist(),
                "scale": self.scale.tolist(), "weights": self.weights.tolist(),
                "bias": self.bias, **self.meta}


def load_hold_model(path: str | Path | None = None) -> HoldModel:
    """The hold model of a JSON file (tools/fit_hold_model.py); None: the shipped one."""
    src = Path(path) if path else files("tg_drake.data").joinpath(HOLD_MODEL)
    try:
        d = json.loads(src.read_text())
        model = HoldModel(tuple(d["features"]), np.array(d["mean"], float),
                          np.array(d["scale"], float), np.array(d["weights"], float),
                          float(d["bias"]), {k: v for k, v in d.items() if k not in (
                              "features", "mean", "scale", "weights", "bias")})
    except (OSError, KeyError, ValueError, TypeError) as e:
        raise ModelError(f"not a hold model: {e}", file=str(src)) from None
    if model.features != FEATURES:
        raise ModelError(f"hold model features {list(model.features)}; this code computes "
                         f"{list(FEATURES)}: refit it (tools/fit_hold_model.py)", file=str(src))
    return model


@functools.cache
def _shipped_model() -> HoldModel:
    return load_hold_model()


# --- the stage: every candidate -----------------------------------------------------------------


_BATCH_POINTS = 500_000  # poses × points held in the poses' frames at once (12 MB)


@dataclass(frozen=True)
class Feasibility:
    """Per candidate: P(hold), why it is infeasible ("" if it is not), and its mechanics."""

    p_hold: np.ndarray  # (M,)
    reasons: tuple[str, ...]  # (M,)
    holds: tuple[Hold, ...]
    collisions: tuple[Collision, ...]


def collision_reason(c: Collision) -> str:
    """Why a pose that collides (`Collision`, not free) is infeasible."""
    if c.what == "other object":
        return f"{COLLISION}the {c.box} would cut another object by {c.depth * 1000:.1f} mm"
    return (f"{COLLISION}the gripper would reach {-c.table_clearance * 1000:.1f} mm under the "
            "table top")


def others_hit(X_WG: np.ndarray, *, others_p_W: np.ndarray, approach: float,
               config: FeasibilityConfig, closed_widths) -> list[str]:
    """Per pose X_WG (M, 4, 4): why the open gripper swept along its approach or its pads closing
    to closed_widths[i] [m] (None: not checked) would cut the points others_p_W ("" if they
    would not) — `grasp_feasibility`'s collision with other objects, the table left out."""
    hits = _collisions(np.asarray(X_WG, float).reshape(-1, 4, 4), others_p_W=others_p_W,
                       table_z=-np.inf, approach=approach, config=config,
                       closed_widths=closed_widths)
    return [collision_reason(c) if c.what == "other object" else "" for c in hits]


def grasp_feasibility(X_WG: np.ndarray, *, target_p_W: np.ndarray, others_p_W: np.ndarray,
                      table_z: float, approach: float, category: dict[str, float] | None,
                      config: FeasibilityConfig, model: HoldModel | None = None) -> Feasibility:
    """Feasibility of every grasp pose X_WG (M, 4, 4) on the target: collision (a), then the hold
    (b) and its probability (c). A pose that collides gets P(hold) 0 and the reason."""
    model = model or (load_hold_model(config.model) if config.model else _shipped_model())
    target_p_W = np.asarray(target_p_W, float).reshape(-1, 3)
    others_p_W = np.asarray(others_p_W, float).reshape(-1, 3)
    mass = hull_volume(target_p_W) * mean_density(category, model.densities,
                                                  config.default_density)
    normals_W = point_normals(target_p_W)
    X_WG = np.asarray(X_WG, float).reshape(-1, 4, 4)
    holds, hits = [], []
    # The poses a batch at a time, each batch holding the points in every pose's frame.
    step = max(1, _BATCH_POINTS // max(len(target_p_W), len(others_p_W), 1))
    for X in (X_WG[i:i + step] for i in range(0, len(X_WG), step)):
        h = _holds(X, target_p_W=target_p_W, mass=mass, config=config, approach=approach,
                   normals_W=normals_W)
        holds += h
        hits += _collisions(X, others_p_W=others_p_W, table_z=table_z, approach=approach,
                            config=config,
                            closed_widths=[g.width if g.n_points else None for g in h])
    p, reasons = [], []
    for h, c in zip(holds, hits, strict=True):
        if not c.free:
            reasons.append(collision_reason(c))
            p.append(0.0)
            continue
        if h.n_points < 2:
            reasons.append("nothing between the pads")
            p.append(0.0)
            continue
        if h.squeeze >= 1.0:  # the contact force outside the friction cone: no weight holds
            lean, cone = np.degrees(np.arctan([h.squeeze * config.friction, config.friction]))
            reasons.append(f"{WOULD_NOT_HOLD}the grip squeezes it out (its surface under the "
                           f"pads leans {lean:.0f}° from their push; friction holds {cone:.0f}°)")
            p.append(0.0)
            continue
        ph = float(model.predict_proba(h.features())[0])
        p.append(ph)
        reasons.append("" if ph >= config.min_p_hold or not config.rank_by_hold else
                       f"{WOULD_NOT_HOLD}P(hold) {ph:.2f} (margin {h.margin:.2f}, patch "
                       f"{h.patch_area * 1e6:.0f} mm², lever {h.lever * 1000:.0f} mm, "
                       f"mass {h.mass:.2f} kg)")
    return Feasibility(np.array(p), tuple(reasons), tuple(holds), tuple(hits))


# --- the stage on a scene -------------------------------------------------------------------


def assess_candidates(scene: SceneDescription, candidates: GraspCandidates, *,
                      category: dict[str, float] | None, approach: float,
                      config: FeasibilityConfig, model: HoldModel | None = None
                      ) -> GraspCandidates:
    """The candidates (the poses that may be executed: the scoring stage made and scored them,
    `tg_drake.grasping.expansion`), each with P(hold) and the scorer's score (the pipeline's
    P(part | task) · P(grasp | local shape); the Local, one-part and random-part variants score
    otherwise) · P(hold) when `rank_by_hold` (0 with a reason where infeasible), best first; the
    poses are not changed. `category`: the logic's category distribution (the mass's density
    prior); `approach` [m]: the planner's pre-grasp distance (the approach swept for collisions)."""
    m = len(candidates.score)
    if m == 0 or not 0 <= candidates.target < len(scene.objects):
        return GraspCandidates(np.zeros((0, 4, 4)), np.zeros(0, int), np.zeros(0), np.zeros(0),
                               np.zeros(0), candidates.target, p_hold=np.zeros(0),
                               source=np.zeros(0, int))
    target = scene.objects[candidates.target]
    others = [o.p_W for i, o in enumerate(scene.objects) if i != candidates.target]
    others_p_W = np.concatenate(others) if others else np.zeros((0, 3))
    table_z = float(scene.X_WT[2, 3])
    source = (np.arange(m) if candidates.source is None
              else np.asarray(candidates.source, int))
    X_WG = np.asarray(candidates.X_WG, float).reshape(-1, 4, 4)
    f = grasp_feasibility(X_WG, target_p_W=target.p_W, others_p_W=others_p_W, table_z=table_z,
                          approach=approach, category=category, config=config, model=model)
    p_part = np.asarray(candidates.p_part, float)
    p_local = np.asarray(candidates.p_local, float)
    parts = np.asarray(candidates.parts, int)
    # The scorer's score (P(part | task) · P(grasp | local shape) for the pipeline; the Local,
    # one-part and random-part variants score otherwise), pose by pose.
    scored = np.asarray(candidates.score, float)
    # The geometric refusals, on the poses the scorer allows that are clear and would hold so far.
    reasons = list(f.reasons)
    centroid = np.asarray(target.p_W, float).mean(axis=0) if len(target.p_W) else None
    for j in np.flatnonzero(scored > 0):
        if not reasons[j]:
            reasons[j] = geometric_refusal(target, PART_LABELS[parts[j]], X_WG[j], centroid,
                                           config, table_z)
    ok = np.array([not r for r in reasons], bool)
    score = np.where(ok, scored * (f.p_hold if config.rank_by_hold else 1.0), 0.0)
    order = np.argsort(-score, kind="stable")
    # Parts the scorer allows, none of whose poses would hold (not for collisions).
    viable = scored > 0
    unholdable = tuple(
        PART_LABELS[k] for k in np.unique(parts[viable])
        if not ok[viable & (parts == k)].any()
        and any(reasons[j].startswith(WOULD_NOT_HOLD)
                for j in np.flatnonzero(viable & (parts == k))))
    return GraspCandidates(X_WG[order], parts[order], p_part[order], p_local[order],
                           score[order], candidates.target, p_hold=f.p_hold[order],
                           feasibility_reasons=tuple(reasons[j] for j in order),
                           source=source[order], unholdable_parts=unholdable,
                           holds=tuple(f.holds[j] for j in order))


UNSAID = ("P(grasp | local shape) = 0", "scored 0")  # a pose no refusal names: why it scored 0


def why_no_pose(candidates: GraspCandidates, part_probability: dict[str, float], *,
                parts: int = 2) -> str:
    """Why none of the candidates can be tried, for a user: for each of the (at most `parts`)
    parts the logic favours most (P(part | task) ≥ 0.01), its poses and why they were refused,
    counted by class (a reason's text up to its first colon: "does not fit", "collision",
    "would not hold", ...), the most common class quoted once. A pose refused by no reason was
    scored 0 by the scorer. "" when the logic favours no part."""
    labels = np.asarray(candidates.parts, int)
    reasons = candidates.feasibility_reasons or ("",) * len(labels)
    p_local = np.asarray(candidates.p_local, float)
    out = []
    for name, p in sorted(part_probability.items(), key=lambda kv: -kv[1])[:parts]:
        if p < 0.01:
            break
        rows = np.flatnonzero(labels == PART_LABELS.index(name))
        if not len(rows):
            out.append(f"{name} (P(part | task) {p:.2f}): no pose was made on it")
            continue
        by_class: dict[str, list[str]] = {}
        for j in rows:
            r = reasons[j] or UNSAID[int(p_local[j] > 0)]
            by_class.setdefault(r.split(":")[0], []).append(r)
        ranked = sorted(by_class.items(), key=lambda kv: -len(kv[1]))
        counts = ", ".join(f"{cls} {len(rs)}" for cls, rs in ranked)
        # The quote: a refusal's own words where there are any (a score of 0 says nothing more).
        quote = next((rs[0] for cls, rs in ranked if cls not in UNSAID), ranked[0][1][0])
        out.append(f"{name} (P(part | task) {p:.2f}): {len(rows)} poses, none feasible — "
                   f"{counts} (e.g. {quote})")
    return "; ".join(out)
