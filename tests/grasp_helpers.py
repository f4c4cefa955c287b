"""Helpers shared by the tests (importable as `grasp_helpers`: pyproject sets pythonpath): gripper
poses built from a grasp point."""

from __future__ import annotations

import numpy as np

from tg_drake.robot import WSG_GRASP_POINT_G

GRASP_POINT = float(WSG_GRASP_POINT_G[1])  # [m] the grasp point along +y_G from the WSG body origin


def grasp_pose(p_W_grasp, approach_W, closing_W) -> np.ndarray:
    """X_WG (4×4) with the grasp point at p_W_grasp, approach +y_G, fingers closing along x_G."""
    y = np.asarray(approach_W, float) / np.linalg.norm(approach_W)
    x = np.asarray(closing_W, float) / np.linalg.norm(closing_W)
    X = np.eye(4)
    X[:3, :3] = np.column_stack([x, y, np.cross(x, y)])
    X[:3, 3] = np.asarray(p_W_grasp, float) - GRASP_POINT * y
    return X
