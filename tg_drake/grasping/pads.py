"""What lies between the open pads: measurements of a grasp pose X_WG on the target's perceived
points, and the geometric refusals of the feasibility stage (`geometric_refusal`).

The grasp frame G of tg_drake.robot: fingers close along ±x_G, approach along +y_G, z_G across
the pads. Each measurement is a length, an area or a share on the perceived points in the slab
the open pads sweep (`slab_points`); `geometric_refusal` compares them with the limits of
`tg_drake.grasping.feasibility.FeasibilityConfig`, whose comments say what each limit stands for.
Arrays in, arrays out: no Drake.
"""

from __future__ import annotations

import numpy as np

from tg_drake.robot import (
    WSG_FINGERTIP_Y,
    WSG_GRASP_POINT_G,
    WSG_MAX_OPENING,
    WSG_PAD_SIZE,
    WSG_PALM_Y,
)
from tg_drake.types import ObjectDescription

GRASP_DEPTH = float(WSG_GRASP_POINT_G[1])  # [m] the grasp point lies this far along +y_G.

# The open finger pads in G (tg_drake.robot: pads 0.012 × 0.082 × 0.02 m centred 0.055 m along
# +y_G, inner faces at x = ±0.055 when open): the 8 outer corners of the pair [m].
PAD_CORNERS_G = np.array([[sx * x, y, sz * WSG_PAD_SIZE[2] / 2] for sx in (-1, 1)
                          for x in (WSG_MAX_OPENING / 2 + WSG_PAD_SIZE[0],)
                          for y in (WSG_PALM_Y, WSG_FINGERTIP_Y) for sz in (-1, 1)])


def part_width(target: ObjectDescription, part: str, X_WG: np.ndarray) -> float:
    """Width [m] of the part's box along the closing direction x_G (0 when no box is known)."""
    box = target.part_boxes.get(part)
    if box is None:
        return 0.0
    x_B = np.asarray(box.X_WB)[:3, :3].T @ X_WG[:3, 0]
    return float(2.0 * np.abs(x_B) @ np.asarray(box.half_extents))


def slab_points(target: ObjectDescription, X_WG: np.ndarray, *, reach: float,
                visible_only: bool = False, band: float | None = None) -> np.ndarray:
    """The target's perceived points in G in the slab the open finger pads sweep: along the
    approach over the pads' length, across their width (or within `band` of the grasp point
    across them), and within `reach` of the grasp point along the closing axis (only the points
    the camera saw, not completed ones, with `visible_only`)."""
    p_W = np.asarray(target.p_W, float)
    visible = np.asarray(target.visible, bool)
    if visible_only and len(visible) == len(p_W):
        p_W = p_W[visible]
    p_G = (p_W - X_WG[:3, 3]) @ X_WG[:3, :3]
    return p_G[in_slab(p_G, reach=reach, band=band)]


def in_slab(p_G: np.ndarray, *, reach: float, band: float | None = None) -> np.ndarray:
    """(N,) bool: which points p_G (N, 3), in the gripper frame G, lie in the slab the open
    pads sweep: along the approach over the pads' length, within `band` of the grasp point
    across the pads (default: their width) and within `reach` of it along the closing axis."""
    lo, hi = PAD_CORNERS_G[:, 1].min(), PAD_CORNERS_G[:, 1].max()
    return ((p_G[:, 1] >= lo) & (p_G[:, 1] <= hi)
            & (np.abs(p_G[:, 2]) <= (PAD_CORNERS_G[:, 2].max() if band is None else band))
            & (np.abs(p_G[:, 0]) <= reach))


def width_between_pads(target: ObjectDescription, X_WG: np.ndarray) -> float:
    """Twice the largest |x_G| of the target's perceived points in the slab the open pads sweep,
    out to their outer faces (a point under a pad counts): the opening the grasp needs. inf when
    no point lies there (nothing to grasp)."""
    p = slab_points(target, X_WG, reach=PAD_CORNERS_G[:, 0].max())
    return float(2.0 * np.abs(p[:, 0]).max()) if len(p) else float("inf")


def extent_along_closing(target: ObjectDescription, X_WG: np.ndarray, band: float
                         ) -> tuple[float, float]:
    """(lowest, highest) x_G [m] of the target's perceived points (completed ones too: the camera
    misses a far end) within the pads' length along the approach and within `band` of the grasp
    point across the pads; (0, 0) when there are none."""
    x = slab_points(target, X_WG, reach=np.inf, band=band)[:, 0]
    return (float(x.min()), float(x.max())) if len(x) else (0.0, 0.0)


def depth_between_pads(target: ObjectDescription, X_WG: np.ndarray, open_width: float,
                       seen: np.ndarray | None = None) -> float:
    """How far along the approach the object reaches between the open pads [m]: from the pads'
    tips back to its nearest point there (inf when perception gave no points: nothing to check).

    Measured on the points the camera saw where there are any: symmetry completion mirrors a
    flat blade about the handle's axis, which makes it look thicker than it is.
    `seen`: those points (`seen_between_pads`) when the caller has them already, as the
    overlap and lower-half checks also take them."""
    if len(target.p_W) == 0:
        return float("inf")
    p = seen_between_pads(target, X_WG, open_width) if seen is None else seen
    return float(PAD_CORNERS_G[:, 1].max() - p[:, 1].min()) if len(p) else 0.0


def _any_visible(target: ObjectDescription) -> bool:
    visible = np.asarray(target.visible, bool)
    return len(visible) == len(target.p_W) and bool(visible.any())


def seen_between_pads(target: ObjectDescription, X_WG: np.ndarray, open_width: float
                      ) -> np.ndarray:
    """The target's points between the open pads (`slab_points`), only those the camera saw when
    it saw any: what the checks of `geometric_refusal` measure (completion mirrors a flat blade
    upwards)."""
    return slab_points(target, X_WG, reach=open_width / 2, visible_only=_any_visible(target))


def overlap_across_pads(target: ObjectDescription, X_WG: np.ndarray, open_width: float,
                        seen: np.ndarray | None = None) -> float:
    """How far across the pads' width (z_G) the object spans between the open pads [m] (inf when
    perception gave no points). Measured on the points the camera saw where there are any, as
    `depth_between_pads`."""
    if len(target.p_W) == 0:
        return float("inf")
    p = seen_between_pads(target, X_WG, open_width) if seen is None else seen
    return float(np.ptp(p[:, 2])) if len(p) else 0.0


PAD_BANDS = 4  # bands across the pads' 20 mm width for `contact_share`
CONTACT_TOLERANCE = 0.004  # [m] a band this close to the widest one touches too (a voxel)


def contact_share(target: ObjectDescription, X_WG: np.ndarray, open_width: float) -> float:
    """Share of the bands across the pads' width that the object fills between the open pads
    (and does not run past them) in which it is about as wide along the closing axis as its
    widest band (within CONTACT_TOLERANCE): where the closing pads touch it first (1 when
    perception gave no points or no band is left). Measured on all points, completed ones too:
    the seen ones alone miss the occluded side of an object lying down."""
    if len(target.p_W) == 0:
        return 1.0
    p = slab_points(target, X_WG, reach=open_width / 2)
    half = PAD_CORNERS_G[:, 2].max()
    band = np.clip(((p[:, 2] + half) / (2 * half) * PAD_BANDS).astype(int), 0, PAD_BANDS - 1)
    # A band where the object reaches out to a pad's inner face runs past that pad (a cup's
    # handle): the pad goes beside it there, and it says nothing about where the pads touch.
    past = open_width / 2 - CONTACT_TOLERANCE
    widths = np.array([np.ptp(p[band == k, 0]) for k in range(PAD_BANDS)
                       if np.count_nonzero(band == k) >= 2
                       and np.abs(p[band == k, 0]).max() < past])
    if len(widths) == 0:
        return 1.0
    return float(np.mean(widths >= widths.max() - CONTACT_TOLERANCE))


def pad_area_below_middle(target: ObjectDescription, X_WG: np.ndarray, open_width: float,
                          table_z: float, cell: float = 0.001, seen: np.ndarray | None = None
                          ) -> float:
    """Area [m²] of a pad's face that lies over the lower half of the object lying between the
    pads: seen along the closing axis, the face's part that is above the table and below half the
    height of the object's top there (its widest section, for a rounded handle), and within
    `cell` × 2.5 of a perceived point across the face. Measured on the points the camera saw where
    there are any (as `depth_between_pads`); inf when perception gave no points or the pads'
    faces do not stand upright enough for a height to mean anything (a closing axis within 30° of
    vertical)."""
    if len(target.p_W) == 0:
        return float("inf")
    up = X_WG[2, 1:3]  # the world's vertical in the faces' (y_G, z_G) coordinates
    if np.linalg.norm(up) < np.cos(np.deg2rad(30.0)):
        return float("inf")
    p = seen_between_pads(target, X_WG, open_width) if seen is None else seen
    if not len(p):
        return 0.0
    across = np.array([-up[1], up[0]]) / np.linalg.norm(up)  # horizontal, in the faces' plane
    y = np.arange(PAD_CORNERS_G[:, 1].min() + cell / 2, PAD_CORNERS_G[:, 1].max(), cell)
    z = np.arange(PAD_CORNERS_G[:, 2].min() + cell / 2, PAD_CORNERS_G[:, 2].max(), cell)
    face = np.stack(np.meshgrid(y, z), axis=-1).reshape(-1, 2)  # cell centres (y_G, z_G)
    height = X_WG[2, 3] + face @ up  # their world heights
    top = X_WG[2, 3] + p[:, 1:3] @ up  # the points' world heights
    near = np.abs((face @ across)[:, None] - (p[:, 1:3] @ across)[None, :]) <= 2.5 * cell
    top_there = np.where(near, top[None, :], -np.inf).max(axis=1)
    below = (height >= table_z) & (height <= table_z + 0.5 * (top_there - table_z))
    return float(below.sum() * cell ** 2)


# [m] the pads' thickness along x_G, outwards from their inner faces
PAD_THICKNESS = WSG_PAD_SIZE[0]
PAD_CELL = 0.004  # [m] cells of a pad's 12 × 20 mm cross-section (3 × 5), perception's voxel


def open_pad_cover(target: ObjectDescription, X_WG: np.ndarray, open_width: float) -> float:
    """The larger, of the two open pads, share of a pad's cross-section across the approach
    (PAD_CELL cells over its thickness and width) under which the camera saw the object within
    the pad's length: where the pad would come down on the object instead of beside it."""
    if len(target.p_W) == 0:
        return 0.0
    p = slab_points(target, X_WG, reach=open_width / 2 + PAD_THICKNESS,
                     visible_only=_any_visible(target))
    half = PAD_CORNERS_G[:, 2].max()
    nx, nz = int(round(PAD_THICKNESS / PAD_CELL)), int(round(2 * half / PAD_CELL))
    cover = 0.0
    for side in (-1.0, 1.0):
        q = p[side * p[:, 0] > open_width / 2]
        if len(q):
            i = np.clip(((side * q[:, 0] - open_width / 2) / PAD_CELL).astype(int), 0, nx - 1)
            k = np.clip(((q[:, 2] + half) / PAD_CELL).astype(int), 0, nz - 1)
            cover = max(cover, np.unique(i * nz + k).size / (nx * nz))
    return cover


DOES_NOT_FIT = "does not fit: "  # how a refusal for the opening or the release begins
WOULD_NOT_HOLD = "would not hold: "  # how a refusal of a grasp that would slip begins
COLLISION = "collision: "  # how a refusal of a gripper that would hit something begins


def geometric_refusal(target: ObjectDescription, part: str, X_WG: np.ndarray, centroid,
                      config, table_z: float = 0.0, *, held: bool = False) -> str:
    """Why the geometry of the grasp X_WG on `part` rules it out ("" if it does not), in three
    classes told by how the reason begins: DOES_NOT_FIT (the part or the object does not fit the
    opening, or could not be let go), COLLISION (an open pad would come down on a tool) and
    WOULD_NOT_HOLD (the fingers would close along a long part, too little of the object reaches
    between the pads, the pads would touch it first in only part of the width it fills or press
    only on the upper half of a tool lying on the table — its top at height `table_z` —, or the
    object's weight would turn it in the pads). `config`: the stage's
    `tg_drake.grasping.feasibility.FeasibilityConfig` (its limits; that module imports this one).
    `centroid`: the object's perceived centroid (None: no points). `held`: the object hangs in
    another gripper (a pass's receiver taking it from the robot): what concerns an object
    standing or lying on the table — letting it go there, an open pad coming down on a tool
    resting on it, a tool squeezed down against it — does not apply; the rest does."""
    opening = config.opening
    width = part_width(target, part, X_WG)
    if width > opening - config.width_margin:
        # The box overstates what lies between the fingers for a grasp across a wall (a rim
        # grasp on a bowl): measure the perceived points there instead.
        width = min(width, width_between_pads(target, X_WG))
    if width > opening - config.width_margin:
        return (f"{DOES_NOT_FIT}{part} is {width:.3f} m across the fingers; the WSG opens "
                f"{opening} m")
    # The part may fit while the object around it does not: an object longer than the opening
    # along the closing axis, held by its ends, stays wedged between the opened fingers at the
    # release. Only an object past both pads is refused: past one (a cup's handle, a bowl's far
    # wall in a rim grasp) the fingers still open clear of it.
    lo, hi = extent_along_closing(target, X_WG, config.release_band)
    half = (opening - config.release_gap) / 2
    if not held and -lo > half and hi > half:
        return (f"{DOES_NOT_FIT}the object reaches past both pads ({hi - lo:.3f} m along the "
                f"closing axis there; its {part} {width:.3f} m): the WSG, open to {opening} m, "
                "could not let go")
    # Tools only: what lies under a pad of a tool lying on the table rests on the table and
    # stops the pad; a container's wall or handle under a pad may yield (`max_pad_cover`).
    cover = open_pad_cover(target, X_WG, opening) if target.is_tool and not held else 0.0
    if cover > config.max_pad_cover:
        return (f"{COLLISION}an open pad would come down on the object (it lies under "
                f"{cover:.0%} of the pad's cross-section, at most {config.max_pad_cover:.0%})")
    along = closes_along_length(target, part, X_WG, config)
    if along:
        return WOULD_NOT_HOLD + along
    seen = seen_between_pads(target, X_WG, opening)  # one selection for the checks
    depth = depth_between_pads(target, X_WG, opening, seen)
    if depth < config.min_pad_depth:
        return (f"{WOULD_NOT_HOLD}only {depth * 1000:.0f} mm of the object reaches between the "
                f"pads (at least {config.min_pad_depth * 1000:.0f} mm): too flat to pick up "
                "from the table")
    overlap = overlap_across_pads(target, X_WG, opening, seen)
    if overlap < config.min_pad_overlap:
        return (f"{WOULD_NOT_HOLD}the object spans only {overlap * 1000:.0f} mm across the pads' "
                f"width between them (at least {config.min_pad_overlap * 1000:.0f} mm): a thin "
                "edge pinched between the pads slides out")
    share = contact_share(target, X_WG, opening)
    if share < config.min_contact_share:
        return (f"{WOULD_NOT_HOLD}the pads would touch the object's widest section over only "
                f"{share:.0%} of the width the object fills between them (at least "
                f"{config.min_contact_share:.0%}): a step or taper under the pads squeezes out")
    if target.is_tool and not held:
        area = pad_area_below_middle(target, X_WG, opening, table_z, seen=seen)
        if area < config.min_tool_grip_area:
            return (f"{WOULD_NOT_HOLD}the pads would press on only {area * 1e6:.0f} mm² of the "
                    f"tool's lower half (at least {config.min_tool_grip_area * 1e6:.0f} mm²): "
                    "pressed above its widest section, it is squeezed out from between them")
        grip = float(np.ptp(seen[:, 0])) if len(seen) else float("inf")
        if grip < config.min_tool_grip_width:
            return (f"{WOULD_NOT_HOLD}the tool is only {grip * 1000:.0f} mm thick between the "
                    f"pads (at least {config.min_tool_grip_width * 1000:.0f} mm): a thin shaft "
                    "rolls out of the squeezing pads")
    if centroid is not None:
        lever = torsion_lever(X_WG, centroid)
        if lever > config.max_torsion_lever:
            return (f"{WOULD_NOT_HOLD}the object's weight would turn it about the closing axis "
                    f"with a {lever:.3f} m lever (at most {config.max_torsion_lever} m): the pads "
                    "resist that turn by friction alone")
    return ""


def torsion_lever(X_WG: np.ndarray, p_WC: np.ndarray) -> float:
    """|x_G · ((p_C − p_grasp) × z_W)| [m]: the lever of a weight at p_WC about the gripper's
    closing axis x_G through the grasp point. The pads resist a turn about x_G by friction over
    their small contact patch only; a turn about the other axes presses on their whole face."""
    p_grasp = X_WG[:3, 3] + GRASP_DEPTH * X_WG[:3, 1]
    return float(abs(X_WG[:3, 0] @ np.cross(np.asarray(p_WC, float) - p_grasp, [0.0, 0.0, 1.0])))


def closes_along_length(target: ObjectDescription, part: str, X_WG: np.ndarray,
                        config) -> str:
    """Why the fingers would close along the length of an elongated part ("" if they do not)."""
    box = target.part_boxes.get(part)
    if box is None:
        return ""
    size = 2.0 * np.asarray(box.half_extents, float)
    k = int(np.argmax(size))
    others = np.delete(size, k)
    axis = np.asarray(box.X_WB, float)[:3, k]
    if size[k] >= config.max_length_ratio * others.max() and abs(axis @ X_WG[:3, 0]) > 0.7:
        return (f"the fingers would close along the {size[k]:.3f} m length of {part}, not "
                "across it")
    return ""
