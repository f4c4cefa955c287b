"""Helpers shared by the tests (importable as `grasp_helpers`: pyproject sets pythonpath): gripper
poses built from a grasp point, a box scene with part boxes, ranked candidates, a box object."""

from __future__ import annotations

import numpy as np

from tg_drake.robot import WSG_GRASP_POINT_G
from tg_drake.types import (
    PART_LABELS,
    GraspCandidates,
    ObjectDescription,
    PartBox,
    SceneDescription,
)

GRASP_POINT = float(WSG_GRASP_POINT_G[1])  # [m] the grasp point along +y_G from the WSG body origin


def top_down(p_grasp):
    """A top-down grasp with its grasp point at p_grasp: x_G = x_W (closing), y_G = −z_W
    (approach down), z_G = y_W."""
    X = np.eye(4)
    X[:3, :3] = np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]], float)
    X[:3, 3] = np.asarray(p_grasp, float) - X[:3, 1] * WSG_GRASP_POINT_G[1]
    return X


def grasp_pose(p_W_grasp, approach_W, closing_W) -> np.ndarray:
    """X_WG (4×4) with the grasp point at p_W_grasp, approach +y_G, fingers closing along x_G."""
    y = np.asarray(approach_W, float) / np.linalg.norm(approach_W)
    x = np.asarray(closing_W, float) / np.linalg.norm(closing_W)
    X = np.eye(4)
    X[:3, :3] = np.column_stack([x, y, np.cross(x, y)])
    X[:3, 3] = np.asarray(p_W_grasp, float) - GRASP_POINT * y
    return X


def scene_with_box(p_W_center, extents=(0.07, 0.07, 0.20)) -> SceneDescription:
    """One upright box on the table, bottom / middle / top thirds as its parts (`box_object`)."""
    return SceneDescription(objects=[box_object(p_W_center, extents)], X_WT=np.eye(4), target=0)


def ranked(poses_and_parts, scores=None) -> GraspCandidates:
    """Candidates (X_WG, part name) scored `scores` (default: 0.9 falling to 0.5, in order)."""
    X = np.array([X for X, _ in poses_and_parts])
    parts = np.array([PART_LABELS.index(p) for _, p in poses_and_parts])
    score = np.linspace(0.9, 0.5, len(parts)) if scores is None else np.asarray(scores, float)
    return GraspCandidates(X_WG=X, parts=parts, p_part=score, p_local=np.ones(len(parts)),
                           score=score)


def box_object(p_W_center, extents, parts=("bottom", "middle", "top")) -> ObjectDescription:
    """An upright box on the table, its height split evenly into the given parts (bottom up), with
    no perceived points (set `p_W`, `visible` for checks that measure them)."""
    extents = np.asarray(extents, float)
    X_WO = np.eye(4)
    X_WO[:3, 3] = p_W_center
    boxes = {}
    for k, name in enumerate(parts):
        X_WB = X_WO.copy()
        X_WB[2, 3] += -extents[2] / 2 + extents[2] * (k + 0.5) / len(parts)
        boxes[name] = PartBox(X_WB, np.array([extents[0], extents[1], extents[2] / len(parts)]) / 2)
    return ObjectDescription(
        p_W=np.zeros((0, 3)), n_W=np.zeros((0, 3)), labels=np.zeros(0, int),
        visible=np.zeros(0, bool), X_WO=X_WO, extents=extents, pose="upright",
        pose_likelihood={"upright": 1.0}, part_probabilities=dict.fromkeys(parts, 1.0),
        part_boxes=boxes, pregrasp_X_WG=np.zeros((0, 4, 4)), pregrasp_parts=np.zeros(0, int))
