"""Perfect perception from the object library's labels (the paper's synthetic scenario S_SYN).

"The object points are distributed uniformly on the object surface according to their size ...
point normals are correctly oriented, the object pose and its parts are manually labeled": here
the surface is sampled from the library mesh (`tg_drake.objects.sample_surface`) with its part
labels, placed at the object's true world pose. Only the synthetic evaluation uses this; the
pipeline's perception never reads ground truth.
"""

from __future__ import annotations

import functools

import numpy as np

from tg_drake.errors import PerceptionError
from tg_drake.objects import get_object, sample_surface
from tg_drake.perception.config import PregraspConfig
from tg_drake.perception.geometry import check_transform, make_transform, rotate, transform
from tg_drake.perception.pregrasp import part_pregrasps
from tg_drake.types import (
    CONTAINMENTS,
    PART_LABELS,
    POSES,
    ObjectDescription,
    PartBox,
    part_index,
)

# An object's symmetry axis within acos(0.7) ≈ 46° of the table normal is upright (or upside down).
UPRIGHT_COSINE = 0.7


def pose_from_transform(X_WO: np.ndarray, X_WT: np.ndarray, is_tool: bool) -> str:
    """The discrete pose of a library object at X_WO on the table X_WT: its symmetry axis (the
    library's z for a container) along the table normal is upright, against it upside down,
    else sideways; a tool lying on the table is always sideways."""
    if is_tool:
        return "sideways"
    c = X_WO[:3, 2] @ X_WT[:3, 2]
    return "upright" if c > UPRIGHT_COSINE else ("upsidedown" if c < -UPRIGHT_COSINE
                                                 else "sideways")


# A wide opening: the surface within half the body's radius of its axis lies at least this share
# of the body's height below its top. Sampled library meshes: cans 0.03–0.04 (a lid 4 mm down),
# bottles 0 (the neck), every glass, cup, bowl, pot and pan 0.88–0.98.
OPEN_TOP_DEPTH = 0.25


def open_top(p_O: np.ndarray, labels: np.ndarray) -> bool:
    """Whether a container's surface points (its library frame: z along the symmetry axis
    towards the top) show a wide open top: the surface near the axis lies deep below the rim."""
    body = np.asarray(labels) != part_index("handle")
    q = np.asarray(p_O, float)[body]
    if len(q) == 0:
        return False
    rho = np.linalg.norm(q[:, :2], axis=1)
    central = rho < 0.5 * rho.max()
    top, height = q[:, 2].max(), np.ptp(q[:, 2])
    if not central.any() or height <= 0:
        return False
    return bool(top - q[central, 2].max() >= OPEN_TOP_DEPTH * height)


@functools.cache
def library_open_top(obj_id: str, seed: int = 0) -> bool:
    """`open_top` of a library object, on a sampling of 4,000 surface points drawn with `seed`
    (a property of the object, not of a run: the default sampling is the one the labels use)."""
    p_O, _, labels = sample_surface(get_object(obj_id), n=4000,
                                    rng=np.random.default_rng(seed))
    return open_top(p_O, labels)


def interior_visible(obj_id: str, pose: str) -> float:
    """The perfect `interior_seen` observation of a library object in a pose: 1 for an open
    container unless it stands upside down (its opening on the table, out of any camera's sight),
    else 0 (tools too)."""
    if get_object(obj_id).is_tool or pose == "upsidedown":
        return 0.0
    return float(library_open_top(obj_id))


def describe_library_object(obj_id: str, X_WO: np.ndarray, X_WT: np.ndarray, *,
                            spacing: float = 0.004, rng: np.random.Generator,
                            pose: str | None = None, containment: str | None = None,
                            pregrasp: PregraspConfig | None = None) -> ObjectDescription:
    """The ObjectDescription of library object `obj_id` at world pose X_WO (library frame O).

    Args:
        obj_id: a library object id.
        X_WO: 4×4 pose of the library object frame in the world.
        X_WT: 4×4 table frame (for the pose label when `pose` is None).
        spacing: surface sampling spacing [m] (n = area / spacing²).
        rng: random generator of the surface samples.
        pose: the true pose label; None derives it from X_WO.
        containment: "empty", "full" or None.

    The description's object frame follows perception's convention: origin at the box centroid,
    z along the symmetry axis towards the top (a tool: from the handle to the usable area, the
    library's x), x towards the handle (a tool: the library's z, up).
    """
    obj = get_object(obj_id)
    X_WO = check_transform(X_WO, "X_WO")
    X_WT = check_transform(X_WT, "X_WT")
    if pose is None:
        pose = pose_from_transform(X_WO, X_WT, obj.is_tool)
    elif pose not in POSES:
        raise PerceptionError(f"unknown pose {pose!r}; allowed: {', '.join(POSES)}")
    if containment is not None and containment not in CONTAINMENTS:
        raise PerceptionError(
            f"unknown containment {containment!r}; allowed: {', '.join(CONTAINMENTS)}")
    p_O, n_O, labels = sample_surface(obj, spacing=spacing, rng=rng)
    # Perception's object axes in the library frame: a tool's axis is the library's x.
    R_OP = (np.column_stack([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])
            if obj.is_tool else np.eye(3))
    q = p_O @ R_OP  # points in perception's axes, library origin
    lo, hi = q.min(axis=0), q.max(axis=0)
    X_OP = make_transform(R_OP, R_OP @ (0.5 * (lo + hi)))
    X_WP = X_WO @ X_OP
    boxes = {}
    for label in np.unique(labels):
        m = labels == label
        b_lo, b_hi = q[m].min(axis=0), q[m].max(axis=0)
        centre_O = R_OP @ (0.5 * (b_lo + b_hi))
        boxes[PART_LABELS[label]] = PartBox(X_WO @ make_transform(R_OP, centre_O),
                                            0.5 * (b_hi - b_lo))
    X_WG, grasp_parts = part_pregrasps({k: (b.X_WB, b.half_extents) for k, b in boxes.items()},
                                       part_index, pregrasp,
                                       open_top=not obj.is_tool and library_open_top(obj_id))
    return ObjectDescription(
        p_W=transform(X_WO, p_O), n_W=rotate(X_WO, n_O), labels=labels,
        visible=np.ones(len(p_O), bool), X_WO=X_WP, extents=hi - lo, pose=pose,
        pose_likelihood={p: float(p == pose) for p in POSES},
        part_probabilities={name: 1.0 for name in boxes}, part_boxes=boxes,
        pregrasp_X_WG=X_WG, pregrasp_parts=grasp_parts, containment=containment,
        is_tool=obj.is_tool, name=obj_id,
        interior_seen=interior_visible(obj_id, pose),
        interior_hidden=1.0 - interior_visible(obj_id, pose))
