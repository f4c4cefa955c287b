"""Grasp hypotheses for collecting DGI training data: on part boxes, perturbed, and random.

Poses are WSG body frames G in the world (see dgi.py: fingers close along ±x_G, approach +y_G, the
grasp point at y_G = PAD_CENTER_Y). All functions are vectorised and take their randomness as `rng`.

- `box_grasps`: the paper's pre-grasp hypotheses of a part box (section III-B: "two pre-grasp poses
  for each face of a box"): for each of the 6 faces, the gripper approaches along the face's inward
  normal with its fingers closing along one or the other of the face's two axes.
- `perturb_grasps`: hypotheses moved and turned a little, as an imprecise perception would.
- `surface_grasps`: random hypotheses at random surface points, approaching roughly against the
  normal, turned at random about it.

The table is not theirs to judge: `tg_drake.grasping.expansion.executed_poses` turns a hypothesis
into the poses that may be executed (approach variants, moved back above the table), for the
training data and for inference alike.
"""

from __future__ import annotations

import numpy as np

from tg_drake.errors import GraspingError
from tg_drake.grasping.dgi import PAD_CENTER_Y

# How far behind the face the grasp point goes on a part thicker than the pads reach [m]:
# the pads then overlap the part by 0.041 + 0.025 = 66 mm of their 82 mm length.
GRASP_INSET = 0.025


def _frames(x: np.ndarray, y: np.ndarray, p: np.ndarray) -> np.ndarray:
    """(M, 4, 4) poses with x_G, y_G given (orthonormal) and z_G = x_G × y_G, origin p."""
    X = np.zeros((len(p), 4, 4))
    X[:, :3, 0] = x
    X[:, :3, 1] = y
    X[:, :3, 2] = np.cross(x, y)
    X[:, :3, 3] = p
    X[:, 3, 3] = 1.0
    return X


def box_grasps(X_WB: np.ndarray, half_extents: np.ndarray) -> np.ndarray:
    """(12, 4, 4): two hypotheses per face of the box with pose X_WB and half sizes `half_extents`.

    The grasp point lies on the line through the face centre along the face normal, at the box
    centre when the box is at most GRASP_INSET deep along the approach, else GRASP_INSET behind the
    face. Order: faces +x, −x, +y, −y, +z, −z of the box; per face, closing along the first then
    the second of the face's other two axes (in cyclic order).
    """
    X_WB = np.asarray(X_WB, dtype=float)
    h = np.asarray(half_extents, dtype=float)
    if X_WB.shape != (4, 4) or h.shape != (3,) or np.any(h < 0):
        raise GraspingError(f"a part box needs a (4, 4) pose and 3 half extents ≥ 0; got "
                            f"{X_WB.shape} and {h.shape}")
    R = X_WB[:3, :3]
    xs, ys, ps = [], [], []
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = sign * R[:, axis]  # outward normal of the face
            inset = min(h[axis], GRASP_INSET)
            grasp_point = X_WB[:3, 3] + n * (h[axis] - inset)
            for other in ((axis + 1) % 3, (axis + 2) % 3):
                xs.append(R[:, other])
                ys.append(-n)
                ps.append(grasp_point + n * PAD_CENTER_Y)
    return _frames(np.array(xs), np.array(ys), np.array(ps))


def _rotations(axis_angle: np.ndarray) -> np.ndarray:
    """(M, 3, 3) rotation matrices from (M, 3) axis-angle vectors (Rodrigues)."""
    theta = np.linalg.norm(axis_angle, axis=1)
    k = axis_angle / np.maximum(theta, 1e-12)[:, None]
    K = np.zeros((len(k), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    K = K - K.transpose(0, 2, 1)
    s, c = np.sin(theta)[:, None, None], np.cos(theta)[:, None, None]
    return np.eye(3) + s * K + (1 - c) * K @ K


def perturb_grasps(X_WG: np.ndarray, rng: np.random.Generator, *, position_std: float = 0.01,
                   angle_std: float = 0.2) -> np.ndarray:
    """Each pose moved by N(0, position_std²) per axis [m] and turned about its grasp point by a
    rotation of N(0, angle_std²) per axis-angle component [rad]."""
    X_WG = np.asarray(X_WG, dtype=float).reshape(-1, 4, 4)
    M = len(X_WG)
    R = _rotations(rng.normal(scale=angle_std, size=(M, 3))) @ X_WG[:, :3, :3]
    grasp_point = X_WG[:, :3, 3] + PAD_CENTER_Y * X_WG[:, :3, 1]
    grasp_point = grasp_point + rng.normal(scale=position_std, size=(M, 3))
    return _frames(R[:, :, 0], R[:, :, 1], grasp_point - PAD_CENTER_Y * R[:, :, 1])


def surface_grasps(p_W: np.ndarray, n_W: np.ndarray, count: int, rng: np.random.Generator, *,
                   max_tilt: float = 0.6, max_depth: float = 0.04) -> np.ndarray:
    """`count` random hypotheses: each approaches a random surface point against its normal,
    tilted by up to `max_tilt` [rad], turned at random about the approach axis, with the grasp
    point up to `max_depth` [m] behind the surface point."""
    p_W = np.asarray(p_W, dtype=float)
    n_W = np.asarray(n_W, dtype=float)
    if p_W.ndim != 2 or p_W.shape[1] != 3 or n_W.shape != p_W.shape or len(p_W) == 0:
        raise GraspingError(f"need (N, 3) points and normals, N > 0; got {p_W.shape}, {n_W.shape}")
    i = rng.integers(len(p_W), size=count)
    y = -n_W[i] / np.linalg.norm(n_W[i], axis=1, keepdims=True)
    # A random unit vector orthogonal to y, then tilt y about it.
    a = rng.normal(size=(count, 3))
    a -= np.sum(a * y, axis=1, keepdims=True) * y
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    tilt = rng.uniform(0, max_tilt, size=count)
    y = _rotations(a * tilt[:, None])[:, :, :] @ y[:, :, None]
    y = y[:, :, 0]
    # x: a random unit vector orthogonal to the tilted y.
    x = rng.normal(size=(count, 3))
    x -= np.sum(x * y, axis=1, keepdims=True) * y
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    grasp_point = p_W[i] + y * rng.uniform(0, max_depth, size=count)[:, None]
    return _frames(x, y, grasp_point - PAD_CENTER_Y * y)
