"""The perception stage end to end: depth image → SceneDescription (paper section III-A/B).

`describe_scene` segments a depth frame into the table and object clusters, and
`describe_object` turns one object's visible points into an ObjectDescription: normals towards
the camera, symmetry completion, pose, parts, part boxes and pre-grasp hypotheses.
"""

from __future__ import annotations

import numpy as np

from tg_drake.errors import PerceptionError
from tg_drake.perception.completion import complete
from tg_drake.perception.config import PerceptionConfig
from tg_drake.perception.geometry import (
    Intrinsics,
    check_transform,
    estimate_normals,
    inverse,
    make_transform,
    rotate,
    transform,
    voxel_average,
)
from tg_drake.perception.parts import segment_parts
from tg_drake.perception.pose import estimate_pose, interior_seen, tool_pose
from tg_drake.perception.pregrasp import part_pregrasps
from tg_drake.perception.segmentation import segment_depth
from tg_drake.types import ObjectDescription, PartBox, SceneDescription, part_index

# An object needs this many visible points (after voxel averaging) to be described.
MIN_OBJECT_POINTS = 20
# Points this far below the table plane are an error, not noise [m] (well above depth noise).
BELOW_TABLE_TOLERANCE = 0.01


def describe_object(p_T: np.ndarray, X_WT: np.ndarray, p_TC: np.ndarray,
                    cfg: PerceptionConfig | None = None, occluders_T: np.ndarray | None = None
                    ) -> ObjectDescription:
    """Describes one object from its visible points.

    Args:
        p_T: (N, 3) visible points of the object in the table frame T (z = height above the
            table top) [m].
        X_WT: 4×4 table frame in the world.
        p_TC: (3,) camera position in T [m] (normals are oriented towards it).
        cfg: perception parameters.
        occluders_T: (K, 3) the other objects' visible points in T [m] (they may hide parts of
            this one from the camera: the completion keeps what is behind them).
    """
    cfg = cfg or PerceptionConfig()
    p_T = np.asarray(p_T, float)
    if p_T.ndim != 2 or p_T.shape[1] != 3:
        raise PerceptionError(f"object points must be an (N, 3) array, got shape {p_T.shape}")
    if not np.all(np.isfinite(p_T)):
        raise PerceptionError("object points contain NaN or inf")
    if len(p_T) < MIN_OBJECT_POINTS:
        raise PerceptionError(
            f"an object needs at least {MIN_OBJECT_POINTS} visible points, got {len(p_T)}")
    if p_T[:, 2].min() < -BELOW_TABLE_TOLERANCE:
        raise PerceptionError(
            f"object points lie {-p_T[:, 2].min():.3f} m below the table plane (tolerance "
            f"{BELOW_TABLE_TOLERANCE} m): wrong table frame?")
    if len(p_T) > cfg.segmentation.max_object_points:
        # A large object (a pan) is averaged again on a coarser grid: its shape is as clear
        # and every later step (and the kernel prior's graph) stays fast.
        grid = cfg.segmentation.voxel_size * np.sqrt(len(p_T) / cfg.segmentation.max_object_points)
        p_T, _ = voxel_average(p_T, grid)
    n_T = estimate_normals(p_T, np.asarray(p_TC, float), cfg.completion.normal_neighbours)
    c = complete(p_T, n_T, cfg.completion, p_TC=p_TC, occluders_T=occluders_T)
    pose = estimate_pose(c, n_T, p_TC, cfg.pose)
    parts = segment_parts(c, pose.top_sign, cfg.parts)
    if parts.is_tool:
        pose = tool_pose(c, cfg.pose)

    X_WO = X_WT @ make_transform(parts.R_TO, parts.p_TO)
    boxes = {name: PartBox(X_WT @ make_transform(parts.R_TO, centre), half)
             for name, (centre, half) in parts.boxes.items()}
    seen = interior_seen(pose, parts.is_tool, cfg.pose)  # perception looked: 1 − seen is hidden
    X_WG, grasp_parts = part_pregrasps(
        {name: (b.X_WB, b.half_extents) for name, b in boxes.items()}, part_index, cfg.pregrasp,
        open_top=seen > 0.0)
    return ObjectDescription(
        p_W=transform(X_WT, c.p_T), n_W=rotate(X_WT, c.n_T), labels=parts.labels,
        visible=c.visible, X_WO=X_WO, extents=parts.extents, pose=pose.pose,
        pose_likelihood=pose.likelihood, pose_cue=pose.cue,
        pose_end=None if pose.end is None else (
            pose.end.recess, pose.end.dome, pose.end.rise, pose.end.rise_error,
            *((np.nan, np.nan) if pose.wall is None else (pose.wall.narrowing, pose.wall.error)),
            float(pose.narrower_top)),
        part_probabilities=parts.probabilities, part_boxes=boxes,
        pregrasp_X_WG=X_WG, pregrasp_parts=grasp_parts, containment=None, is_tool=parts.is_tool,
        interior_seen=seen, interior_hidden=1.0 - seen)


def describe_cloud(p_W: np.ndarray, X_WT: np.ndarray, p_WC: np.ndarray,
                   cfg: PerceptionConfig | None = None) -> ObjectDescription:
    """Describes one object from visible world-frame points, averaged per voxel first."""
    cfg = cfg or PerceptionConfig()
    X_WT = check_transform(X_WT, "X_WT")
    p_W = np.asarray(p_W, float)
    if p_W.ndim != 2 or p_W.shape[1] != 3 or len(p_W) == 0:
        raise PerceptionError(f"object points must be a non-empty (N, 3) array, got {p_W.shape}")
    if not np.all(np.isfinite(p_W)):
        raise PerceptionError("object points contain NaN or inf")
    X_TW = inverse(X_WT)
    q, _ = voxel_average(transform(X_TW, p_W), cfg.segmentation.voxel_size)
    return describe_object(q, X_WT, transform(X_TW, np.asarray(p_WC, float)[None])[0], cfg)


def describe_scene(depth: np.ndarray, intrinsics: Intrinsics, X_WC: np.ndarray,
                   cfg: PerceptionConfig | None = None) -> SceneDescription:
    """Scene description of a depth frame: one ObjectDescription per object on the table.

    Objects are ordered by their position along the table frame's x, then y.
    """
    cfg = cfg or PerceptionConfig()
    seg = segment_depth(depth, intrinsics, X_WC, cfg.segmentation)
    p_TC = transform(inverse(seg.X_WT), np.asarray(X_WC, float)[:3, 3][None])[0]
    # Every object's points, each object's own span: the others of an object are the rest.
    every = np.concatenate([np.zeros((0, 3)), *seg.objects_T])
    ends = np.cumsum([len(q) for q in seg.objects_T])
    objects = [describe_object(q, seg.X_WT, p_TC, cfg,
                               occluders_T=np.delete(every, np.s_[end - len(q):end], axis=0))
               for q, end in zip(seg.objects_T, ends, strict=True)]
    return SceneDescription(objects=objects, X_WT=seg.X_WT)
