"""Camera model, back-projection, rigid transforms and normals on arrays.

Drake's conventions: a depth image is float32 metres, +inf where the return is too far and 0 where
it is too close; the camera frame C has X right, Y down, Z forward (the optical axis), and pixel
(u, v) (column, row) sees the ray ((u − cx)/fx, (v − cy)/fy, 1) in C, as in Drake's
DepthImageToPointCloud.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import open3d as o3d

from tg_drake.errors import PerceptionError


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics of a depth camera (Drake's CameraInfo, without pydrake)."""

    width: int  # [px]
    height: int  # [px]
    fx: float  # focal length along u [px]
    fy: float  # focal length along v [px]
    cx: float  # principal point u [px]
    cy: float  # principal point v [px]

    @staticmethod
    def from_camera_info(info) -> Intrinsics:
        """From a pydrake.systems.sensors.CameraInfo (duck-typed: no pydrake import here)."""
        return Intrinsics(int(info.width()), int(info.height()), float(info.focal_x()),
                          float(info.focal_y()), float(info.center_x()), float(info.center_y()))

    @staticmethod
    def from_fov(width: int, height: int, fov_y: float) -> Intrinsics:
        """Square pixels, centred principal point, vertical field of view fov_y [rad] (Drake's
        CameraInfo(width, height, fov_y) convention)."""
        f = 0.5 * height / np.tan(0.5 * fov_y)
        return Intrinsics(width, height, f, f, width / 2 - 0.5, height / 2 - 0.5)

    def ray_directions_C(self) -> np.ndarray:
        """(H, W, 3) ray directions in C with unit z: depth × direction = point in C."""
        u = (np.arange(self.width) - self.cx) / self.fx
        v = (np.arange(self.height) - self.cy) / self.fy
        d = np.empty((self.height, self.width, 3))
        d[..., 0] = u[None, :]
        d[..., 1] = v[:, None]
        d[..., 2] = 1.0
        return d


def check_transform(X: np.ndarray, name: str) -> np.ndarray:
    """A 4×4 rigid transform as float array, or PerceptionError naming `name`."""
    X = np.asarray(X, dtype=float)
    if X.shape != (4, 4) or not np.all(np.isfinite(X)):
        raise PerceptionError(f"{name} must be a finite 4×4 rigid transform, got shape {X.shape}")
    R = X[:3, :3]
    if not np.allclose(R.T @ R, np.eye(3), atol=1e-6) or np.linalg.det(R) < 0:
        # 1e-6: float32 round trips of a rotation matrix stay well inside this.
        raise PerceptionError(f"{name} has a rotation block that is not a proper rotation")
    return X


def rotate(X_AB: np.ndarray, v_B: np.ndarray) -> np.ndarray:
    """Vectors (N, 3) in B → in A.

    Written column by column: for tall (N, 3) arrays this is several times faster than a BLAS
    matrix product, which spends its time starting threads.
    """
    R = X_AB[:3, :3]
    return v_B[:, 0:1] * R[:, 0] + v_B[:, 1:2] * R[:, 1] + v_B[:, 2:3] * R[:, 2]


def transform(X_AB: np.ndarray, p_B: np.ndarray) -> np.ndarray:
    """Points (N, 3) in B → in A."""
    return rotate(X_AB, p_B) + X_AB[:3, 3]


def dot3(p: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(N,) p_i · v for (N, 3) p and a (3,) v, without BLAS (see `rotate`)."""
    return p[:, 0] * v[0] + p[:, 1] * v[1] + p[:, 2] * v[2]


def inverse(X_AB: np.ndarray) -> np.ndarray:
    X_BA = np.eye(4)
    X_BA[:3, :3] = X_AB[:3, :3].T
    X_BA[:3, 3] = -X_AB[:3, :3].T @ X_AB[:3, 3]
    return X_BA


def make_transform(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    X = np.eye(4)
    X[:3, :3] = R
    X[:3, 3] = p
    return X


def frame_from_z(z: np.ndarray, x_hint: np.ndarray) -> np.ndarray:
    """A rotation matrix with columns (x, y, z): z given, x the part of x_hint orthogonal to z."""
    z = z / np.linalg.norm(z)
    x = x_hint - (x_hint @ z) * z
    if np.linalg.norm(x) < 1e-9:  # x_hint parallel to z: take any orthogonal direction.
        x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x = x / np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def depth_to_points(depth: np.ndarray, intrinsics: Intrinsics, X_WC: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Back-projects every valid pixel of a depth image into the world frame.

    Args:
        depth: (H, W) or (H, W, 1) depth along the optical axis [m]; +inf, 0 and NaN mean no
            return and are skipped.
        intrinsics: the camera's Intrinsics (image size must match `depth`).
        X_WC: 4×4 pose of the camera frame C in the world W.

    Returns:
        p_W: (N, 3) points in the world frame [m].
        pixels: (N, 2) int (row, column) of each point.
    """
    depth = np.asarray(depth)
    if depth.ndim == 3 and depth.shape[2] == 1:
        depth = depth[..., 0]
    if depth.shape != (intrinsics.height, intrinsics.width):
        raise PerceptionError(
            f"depth image is {depth.shape[::-1]} (width, height) but the camera info says "
            f"({intrinsics.width}, {intrinsics.height})")
    X_WC = check_transform(X_WC, "X_WC")
    valid = np.isfinite(depth) & (depth > 0)
    rows, cols = np.nonzero(valid)
    z = depth[rows, cols].astype(float)
    x = (cols - intrinsics.cx) * (z / intrinsics.fx)
    y = (rows - intrinsics.cy) * (z / intrinsics.fy)
    R, t = X_WC[:3, :3], X_WC[:3, 3]
    p_W = np.empty((len(z), 3))
    for i in range(3):  # the three world coordinates, each a vectorised expression.
        p_W[:, i] = R[i, 0] * x + R[i, 1] * y + R[i, 2] * z + t[i]
    return p_W, np.column_stack([rows, cols])


def estimate_normals(p: np.ndarray, p_view: np.ndarray, k: int) -> np.ndarray:
    """Unit normals by k-nn PCA (Open3D), oriented towards the viewpoint p_view (same frame)."""
    if len(p) < 3:
        raise PerceptionError(f"need at least 3 points to estimate normals, got {len(p)}")
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(p))
    cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(min(k, len(p))))
    n = np.asarray(cloud.normals).copy()
    flip = np.einsum("ij,ij->i", n, p_view - p) < 0
    n[flip] *= -1
    return n


def voxel_average(p: np.ndarray, size: float) -> tuple[np.ndarray, np.ndarray]:
    """Averages points per cubic voxel of side `size`.

    Returns the (M, 3) voxel means and the (N,) index of each input point's voxel.
    """
    keys = np.floor(p / size).astype(np.int64)
    keys -= keys.min(axis=0)
    span = keys.max(axis=0) + 1
    flat = (keys[:, 0] * span[1] + keys[:, 1]) * span[2] + keys[:, 2]
    _, inverse_index, counts = np.unique(flat, return_inverse=True, return_counts=True)
    sums = np.column_stack([np.bincount(inverse_index, weights=p[:, j], minlength=len(counts))
                            for j in range(3)])
    return sums / counts[:, None], inverse_index
