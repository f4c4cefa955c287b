"""Pre-grasp hypotheses: two gripper poses per face of each part's bounding box (paper III-B).

For the face of a part box with outward normal f, the gripper approaches along −f; the two poses
close the fingers along one or the other of the face's two edge directions. The grasp point (the
point midway between the fingertips) lies on the face's centre line, `grasp_depth` inside the
face (at most half the box's depth), so that the fingers straddle the part's outer layer; the
planner adds its own stand-off for the approach.

Gripper frame G (the WSG 50 body frame of tg_drake's model): the fingers close along ±x_G, the
approach direction is +y_G, and the grasp point is `WSG_GRASP_POINT_G` in G.
"""

from __future__ import annotations

import numpy as np

from tg_drake.perception.config import PregraspConfig

# The grasp point (between the fingertips) in the WSG body frame G [m]: 0.055 m along +y_G, the
# approach direction. Change it here if the gripper model changes.
WSG_GRASP_POINT_G = np.array([0.0, 0.055, 0.0])

# Face i (0..5) of a box: outward normal along box axis FACE_AXIS[i] with sign FACE_SIGN[i].
FACE_AXIS = np.array([0, 0, 1, 1, 2, 2])
FACE_SIGN = np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0])
# The two closing directions (box axes) for a face whose normal is along axis i.
OTHER_AXES = np.array([[1, 2], [0, 2], [0, 1]])


def box_pregrasps(X_WB: np.ndarray, half_extents: np.ndarray,
                  cfg: PregraspConfig | None = None) -> np.ndarray:
    """The 12 pre-grasp poses X_WG (12, 4, 4) of one box: for each of its 6 faces, two.

    Args:
        X_WB: 4×4 box pose (centre and axes) in the world.
        half_extents: (3,) half side lengths along the box axes [m].
    """
    cfg = cfg or PregraspConfig()
    R = X_WB[:3, :3]
    h = np.asarray(half_extents, float)
    normals = (R[:, FACE_AXIS] * FACE_SIGN).T  # (6, 3) outward face normals in W.
    depth = np.minimum(cfg.grasp_depth, h[FACE_AXIS])
    p_grasp = X_WB[:3, 3] + normals * (h[FACE_AXIS] - depth)[:, None]  # (6, 3)
    x_G = R.T[OTHER_AXES[FACE_AXIS]].reshape(12, 3)  # (6, 2, 3) → (12, 3): box edge axes.
    y_G = np.repeat(-normals, 2, axis=0)  # approach: into the face.
    z_G = np.column_stack([x_G[:, 1] * y_G[:, 2] - x_G[:, 2] * y_G[:, 1],  # x_G × y_G
                           x_G[:, 2] * y_G[:, 0] - x_G[:, 0] * y_G[:, 2],
                           x_G[:, 0] * y_G[:, 1] - x_G[:, 1] * y_G[:, 0]])
    X = np.zeros((12, 4, 4))
    X[:, :3, 0], X[:, :3, 1], X[:, :3, 2] = x_G, y_G, z_G
    X[:, :3, 3] = np.repeat(p_grasp, 2, axis=0) - np.einsum("nij,j->ni", X[:, :3, :3],
                                                            WSG_GRASP_POINT_G)
    X[:, 3, 3] = 1.0
    return X


def part_pregrasps(boxes: dict[str, tuple[np.ndarray, np.ndarray]], part_index,
                   cfg: PregraspConfig | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Pre-grasps of every part box: ((M, 4, 4) X_WG, (M,) part labels).

    `boxes` maps a part name to (X_WB, half extents); `part_index` maps a name to its label.
    """
    poses, labels = [], []
    for name, (X_WB, half) in boxes.items():
        poses.append(box_pregrasps(X_WB, half, cfg))
        labels.append(np.full(12, part_index(name)))
    if not poses:
        return np.zeros((0, 4, 4)), np.zeros(0, int)
    return np.concatenate(poses), np.concatenate(labels)
