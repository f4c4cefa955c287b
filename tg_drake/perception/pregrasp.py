"""Pre-grasp hypotheses: two gripper poses per face of each part's bounding box (paper III-B),
and rim grasps on the wide top of an upright open container (ours: a bowl is wider than the WSG
opens, so no box-face grasp fits it).

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
from tg_drake.robot import WSG_GRASP_POINT_G  # the grasp point in G [m]: 0.055 m along +y_G

# Face i (0..5) of a box: outward normal along box axis FACE_AXIS[i] with sign FACE_SIGN[i].
FACE_AXIS = np.array([0, 0, 1, 1, 2, 2])
FACE_SIGN = np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0])
# The two closing directions (box axes) for a face whose normal is along axis i.
OTHER_AXES = np.array([[1, 2], [0, 2], [0, 1]])


def box_pregrasps(X_WB: np.ndarray, half_extents: np.ndarray,
                  cfg: PregraspConfig | None = None) -> np.ndarray:
    """The pre-grasp poses X_WG of boxes: for each of a box's 6 faces, two.

    Args:
        X_WB: 4×4 box pose (centre and axes) in the world, or (B, 4, 4) for B boxes.
        half_extents: (3,) half side lengths along the box axes [m], or (B, 3).

    Returns (12, 4, 4) for one box, (12·B, 4, 4) for B boxes (box by box, face by face).
    """
    cfg = cfg or PregraspConfig()
    X_WB = np.asarray(X_WB, float).reshape(-1, 4, 4)
    h = np.asarray(half_extents, float).reshape(-1, 3)
    B = len(X_WB)
    R = X_WB[:, :3, :3]  # (B, 3, 3), columns = box axes
    normals = np.swapaxes(R[:, :, FACE_AXIS] * FACE_SIGN, 1, 2)  # (B, 6, 3) outward normals
    depth = np.minimum(cfg.grasp_depth, h[:, FACE_AXIS])  # (B, 6)
    p_grasp = X_WB[:, None, :3, 3] + normals * (h[:, FACE_AXIS] - depth)[..., None]
    x_G = np.swapaxes(R, 1, 2)[:, OTHER_AXES[FACE_AXIS]].reshape(12 * B, 3)  # box edge axes
    y_G = np.repeat(-normals.reshape(6 * B, 3), 2, axis=0)  # approach: into the face
    z_G = np.column_stack([x_G[:, 1] * y_G[:, 2] - x_G[:, 2] * y_G[:, 1],  # x_G × y_G
                           x_G[:, 2] * y_G[:, 0] - x_G[:, 0] * y_G[:, 2],
                           x_G[:, 0] * y_G[:, 1] - x_G[:, 1] * y_G[:, 0]])
    X = np.zeros((12 * B, 4, 4))
    X[:, :3, 0], X[:, :3, 1], X[:, :3, 2] = x_G, y_G, z_G
    g = WSG_GRASP_POINT_G  # G's origin = grasp point − R_WG · p_G(grasp point)
    X[:, :3, 3] = (np.repeat(p_grasp.reshape(6 * B, 3), 2, axis=0)
                   - g[0] * x_G - g[1] * y_G - g[2] * z_G)
    X[:, 3, 3] = 1.0
    return X


def rim_pregrasps(X_WB: np.ndarray, half_extents: np.ndarray,
                  cfg: PregraspConfig | None = None) -> np.ndarray:
    """Rim grasps on the top part box of an upright open container: (K, 4, 4) X_WG, or (0, 4, 4)
    when the box does not face up or is narrow enough for the box-face grasps.

    The gripper comes down along the box's −z (the object's axis), its fingers closing radially
    across the wall at `cfg.rim_azimuths` angles, the grasp point `cfg.rim_wall` inside the outer
    radius and `cfg.rim_depth` below the rim. Perception's completion makes the top rotationally
    symmetric, so the outer radius is the box's mean cross half extent.
    """
    cfg = cfg or PregraspConfig()
    X_WB = np.asarray(X_WB, float)
    h = np.asarray(half_extents, float)
    R = X_WB[:3, :3]
    if R[2, 2] < 0.9 or 2.0 * min(h[0], h[1]) < cfg.rim_min_width:
        return np.zeros((0, 4, 4))
    radius = 0.5 * (h[0] + h[1]) - cfg.rim_wall
    y_G = -R[:, 2]
    out = []
    for angle in np.arange(cfg.rim_azimuths) * (2.0 * np.pi / cfg.rim_azimuths):
        u = np.cos(angle) * R[:, 0] + np.sin(angle) * R[:, 1]  # radial: the closing axis
        p_grasp = X_WB[:3, 3] + radius * u + (h[2] - min(cfg.rim_depth, h[2])) * R[:, 2]
        X = np.eye(4)
        X[:3, 0], X[:3, 1], X[:3, 2] = u, y_G, np.cross(u, y_G)
        X[:3, 3] = p_grasp - X[:3, :3] @ WSG_GRASP_POINT_G
        out.append(X)
    return np.array(out)


def along_pregrasps(X_WB: np.ndarray, half_extents: np.ndarray,
                    cfg: PregraspConfig | None = None) -> np.ndarray:
    """Face grasps shifted along a long part box (a handle): for each face parallel to its long
    axis, the pose whose fingers close across that axis, moved along it by ± `along_fraction`
    of the half length. (0, 4, 4) when the box is not long enough (`along_min_length`, twice its
    other sides). Order: face by face, −shift then +shift."""
    cfg = cfg or PregraspConfig()
    h = np.asarray(half_extents, float)
    k = int(np.argmax(h))
    if 2 * h[k] < cfg.along_min_length or h[k] < 2 * np.delete(h, k).max():
        return np.zeros((0, 4, 4))
    X_face = box_pregrasps(X_WB, h, cfg)
    axis = np.asarray(X_WB, float)[:3, k]
    out = []
    for j, X in enumerate(X_face):
        if FACE_AXIS[j // 2] == k or abs(X[:3, 0] @ axis) > 0.5:
            continue  # an end face, or fingers closing along the length
        for sign in (-1.0, 1.0):
            Y = X.copy()
            Y[:3, 3] += sign * cfg.along_fraction * h[k] * axis
            out.append(Y)
    return np.asarray(out).reshape(-1, 4, 4)


def part_pregrasps(boxes: dict[str, tuple[np.ndarray, np.ndarray]], part_index,
                   cfg: PregraspConfig | None = None, *, open_top: bool = True
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Pre-grasps of every part box: ((M, 4, 4) X_WG, (M,) part labels).

    `boxes` maps a part name to (X_WB, half extents); `part_index` maps a name to its label. The
    twelve box-face pre-grasps per part come first, then the rim grasps of a wide upright top,
    then the grasps along long parts (`along_pregrasps`), part by part. A rim grasp puts a
    finger inside the container: `open_top` False (perception saw no inside through the top,
    `interior_seen` 0: a lid closes it) leaves the rim grasps out.
    """
    if not boxes:
        return np.zeros((0, 4, 4)), np.zeros(0, int)
    X = box_pregrasps(np.stack([b[0] for b in boxes.values()]),
                      np.stack([b[1] for b in boxes.values()]), cfg)
    labels = np.repeat([part_index(name) for name in boxes], 12)
    if "top" in boxes and open_top:
        rim = rim_pregrasps(*boxes["top"], cfg)
        X = np.concatenate([X, rim])
        labels = np.concatenate([labels, np.full(len(rim), part_index("top"))])
    for name, (X_WB, h) in boxes.items():
        extra = along_pregrasps(X_WB, h, cfg)
        X = np.concatenate([X, extra])
        labels = np.concatenate([labels, np.full(len(extra), part_index(name))])
    return X, labels
