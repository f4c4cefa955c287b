"""Depth gradient image (DGI) features of the volume a WSG 50 closes on (paper, section V-A).

For a gripper pose ``X_WG`` and an object point cloud ``p_W`` the feature is computed in four steps:

1. the points inside the gripper's *closing volume* (a box fixed in the gripper frame G);
2. their *depth*, "the z-component of the distance from the gripper base to the object point"
   (paper); for the WSG that component is along the approach axis +y_G, measured from the palm;
3. the depth image DI(u, v): the volume is cut into cells of 7 × 7 mm across the approach axis and
   each pixel holds the minimum depth of the points in its cell, −1 where the cell is empty
   (paper eq. 3: an orthogonal projection of the closest point to the gripper base);
4. the depth gradient image by central differences on the interior pixels (paper eqs. 4–6):
   DGI(u, v) = sqrt((DI(u+1, v) − DI(u−1, v))² + (DI(u, v+1) − DI(u, v−1))²);
5. the feature vector: DI and DGI pixels, with depths rescaled so that an RBF kernel weighs depth
   differences against empty pixels (`feature_depth_images`).

Everything is vectorised over many hypotheses (M gripper poses) and points (N): no Python loop
over points or poses.

Gripper frame G is the WSG body frame of models/wsg_50/wsg_50.urdf: the fingers close along ±x_G,
the approach direction is +y_G, z_G is across the finger pads. The pads' geometry below comes from
tg_drake.robot, which the model file is written from (a test checks that they still agree).

The paper names its cells "7x7x15 (mm)" without tying the third figure to an axis. Here a cell is
7 mm along x_G (u) by 7 mm along z_G (v) and spans the whole depth of the closing volume, since DI
stores a continuous depth per pixel; the third figure is not used as a cell size.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tg_drake.errors import GraspingError
from tg_drake.robot import (
    WSG_FINGERTIP_Y,
    WSG_MAX_OPENING,
    WSG_PAD_CENTRE_Y,
    WSG_PAD_SIZE,
    WSG_PALM_Y,
)

# --- WSG 50 geometry in the gripper frame G [m] (tg_drake.robot) -------------------------------
CLOSING_AXIS = 0  # index of x_G: the fingers close along ±x_G.
APPROACH_AXIS = 1  # index of y_G: the gripper approaches the object along +y_G.
PAD_WIDTH_AXIS = 2  # index of z_G: across the finger pads.
MAX_OPENING = WSG_MAX_OPENING  # distance between the pads' inner faces when fully open.
PAD_SIZE = WSG_PAD_SIZE  # finger pad box along x_G, y_G, z_G.
PAD_CENTER_Y = WSG_PAD_CENTRE_Y  # y_G of the pads' centres (the grasp point).
GRIPPER_BASE_Y = WSG_PALM_Y  # 0.014: the palm, where the pads start.
FINGERTIP_Y = WSG_FINGERTIP_Y  # 0.096: the pads' tips.

# --- DGI sampling (paper: 7 mm cells) -----------------------------------------------------------
CELL_SIZE = 0.007  # pixel side across the approach axis [m] (paper).
EMPTY_DEPTH = -1.0  # DI of a pixel whose cell holds no point (paper eq. 3).


@dataclass(frozen=True)
class DgiConfig:
    """The closing volume and its pixel grid, in the gripper frame G.

    The volume is the box swept by the pads as they close, pads included: x_G over the full
    opening plus the pads' thickness, y_G from just behind the palm to the fingertips (the depth
    axis, depth = y_G − base_y), z_G over the pad width. The pixel grid covers it with `n_u` × `n_v`
    square cells of side `cell_size`, centred on x_G = z_G = 0.
    """

    cell_size: float = CELL_SIZE  # pixel side [m].
    n_u: int = 20  # pixels along x_G: 20 × 7 mm = 140 mm ⊇ the 134 mm from the outer face of
    # one open pad to the other's, so that the DI also shows what the pads land on.
    n_v: int = 3  # pixels along z_G: 3 × 7 mm = 21 mm ⊇ the 20 mm pad width.
    base_y: float = GRIPPER_BASE_Y  # y_G of the gripper base (depth 0) [m].
    palm_margin: float = 0.021  # the volume starts this far behind the base (3 cells) [m]: an
    # object that reaches into the palm shows as a negative depth (−0.021 to 0), the gripper
    # body hitting it. 0 gives the paper's volume, from the base to the fingertips.
    depth_scale: float = 25.0  # feature units per metre of depth (see `dgi_features`) [1/m].
    tip_y: float = FINGERTIP_Y  # y_G of the fingertips (largest depth) [m].

    def __post_init__(self):
        if not (self.cell_size > 0 and self.tip_y > self.base_y and 0 <= self.palm_margin < 1):
            raise GraspingError(
                f"bad DgiConfig: need cell_size {self.cell_size} > 0, tip_y {self.tip_y} > "
                f"base_y {self.base_y}, 0 ≤ palm_margin {self.palm_margin} < 1 m (depths must "
                "stay above the empty value −1)")
        if not self.depth_scale > 0:
            raise GraspingError(f"bad DgiConfig: depth_scale {self.depth_scale} must be > 0")
        if self.n_u < 3 or self.n_v < 3:
            raise GraspingError(
                f"bad DgiConfig: n_u = {self.n_u} and n_v = {self.n_v} must be ≥ 3 for central "
                "differences")

    @property
    def half_extent_x(self) -> float:
        """Half size of the volume along x_G [m]."""
        return 0.5 * self.n_u * self.cell_size

    @property
    def half_extent_z(self) -> float:
        """Half size of the volume along z_G [m]."""
        return 0.5 * self.n_v * self.cell_size

    @property
    def depth_range(self) -> float:
        """Length of the volume along the approach axis [m]."""
        return self.tip_y - self.base_y

    @property
    def n_features(self) -> int:
        """Length of the feature vector: DI pixels then interior DGI pixels."""
        return self.n_u * self.n_v + (self.n_u - 2) * (self.n_v - 2)


def _check_inputs(p_W: np.ndarray, X_WG: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    p_W = np.asarray(p_W, dtype=float)
    X_WG = np.asarray(X_WG, dtype=float)
    if p_W.ndim != 2 or p_W.shape[1] != 3:
        raise GraspingError(f"point cloud must be (N, 3), got shape {p_W.shape}")
    if not np.all(np.isfinite(p_W)):
        raise GraspingError("point cloud holds NaN or infinite coordinates")
    if X_WG.ndim == 2:
        X_WG = X_WG[None]
    if X_WG.ndim != 3 or X_WG.shape[1:] != (4, 4):
        raise GraspingError(f"gripper poses X_WG must be (4, 4) or (M, 4, 4), got {X_WG.shape}")
    if not np.all(np.isfinite(X_WG)):
        raise GraspingError("gripper poses X_WG hold NaN or infinite entries")
    R = X_WG[:, :3, :3]
    # 1e-6: a rotation written out to six decimals (YAML, JSON) still passes.
    err = np.abs(np.einsum("mji,mjk->mik", R, R) - np.eye(3)).max(axis=(1, 2))
    if np.any(err > 1e-6):
        bad = int(np.argmax(err))
        raise GraspingError(
            f"gripper pose X_WG[{bad}] has a rotation that is not orthonormal "
            f"(error {err[bad]:.2g})")
    return p_W, X_WG


def points_in_gripper_frame(p_W: np.ndarray, X_WG: np.ndarray) -> np.ndarray:
    """The cloud expressed in each gripper frame: (M, N, 3) array p_G = R_WGᵀ (p_W − p_WG)."""
    p_W, X_WG = _check_inputs(p_W, X_WG)
    R_WG = X_WG[:, :3, :3]
    p_WG = X_WG[:, :3, 3]
    # p_G[m, n, j] = Σ_i (p_W[n, i] − p_WG[m, i]) R_WG[m, i, j]: one matrix product for all poses
    # (N × 3 by 3 × 3M), computed point-major and returned as an (M, N, 3) view.
    M = len(X_WG)
    p_G = (p_W @ R_WG.transpose(1, 0, 2).reshape(3, 3 * M)).reshape(len(p_W), M, 3)
    p_G -= np.einsum("mi,mij->mj", p_WG, R_WG)[None]
    return p_G.transpose(1, 0, 2)


def closing_volume_mask(p_G: np.ndarray, config: DgiConfig = DgiConfig()) -> np.ndarray:
    """Boolean mask (…, N) of the points (expressed in G) inside the closing volume.

    Half-open intervals on every axis, so that a point on a cell boundary belongs to one cell.
    """
    x = p_G[..., CLOSING_AXIS]
    y = p_G[..., APPROACH_AXIS]
    z = p_G[..., PAD_WIDTH_AXIS]
    return ((x >= -config.half_extent_x) & (x < config.half_extent_x)
            & (z >= -config.half_extent_z) & (z < config.half_extent_z)
            & (y >= config.base_y - config.palm_margin) & (y < config.tip_y))


def depth_images(p_W: np.ndarray, X_WG: np.ndarray, config: DgiConfig = DgiConfig()) -> np.ndarray:
    """DI for every gripper pose: (M, n_u, n_v) minimum depth per cell [m], EMPTY_DEPTH if empty.

    Pixel u runs along +x_G, pixel v along +z_G; depth = y_G − base_y ∈ [−palm_margin,
    depth_range).
    """
    p_G = points_in_gripper_frame(p_W, X_WG).transpose(1, 0, 2)  # (N, M, 3), contiguous
    M = p_G.shape[1]
    inside = closing_volume_mask(p_G, config)
    n_idx, m_idx = np.nonzero(inside)
    q = p_G[n_idx, m_idx]
    u = np.floor((q[:, CLOSING_AXIS] + config.half_extent_x) / config.cell_size).astype(np.intp)
    v = np.floor((q[:, PAD_WIDTH_AXIS] + config.half_extent_z) / config.cell_size).astype(np.intp)
    # Rounding at the far boundary can give n_u (or n_v) for a point just inside; clip it back.
    np.clip(u, 0, config.n_u - 1, out=u)
    np.clip(v, 0, config.n_v - 1, out=v)
    depth = q[:, APPROACH_AXIS] - config.base_y
    di = np.full(M * config.n_u * config.n_v, np.inf)
    np.minimum.at(di, (m_idx * config.n_u + u) * config.n_v + v, depth)
    di[np.isinf(di)] = EMPTY_DEPTH
    return di.reshape(M, config.n_u, config.n_v)


def depth_gradient_images(di: np.ndarray) -> np.ndarray:
    """DGI of depth images (…, n_u, n_v) → (…, n_u − 2, n_v − 2), central differences (paper)."""
    di = np.asarray(di, dtype=float)
    if di.ndim < 2 or di.shape[-1] < 3 or di.shape[-2] < 3:
        raise GraspingError(f"depth images must be (…, n_u ≥ 3, n_v ≥ 3), got shape {di.shape}")
    di_u = di[..., 2:, 1:-1] - di[..., :-2, 1:-1]
    di_v = di[..., 1:-1, 2:] - di[..., 1:-1, :-2]
    return np.sqrt(di_u**2 + di_v**2)


def feature_depth_images(di: np.ndarray, config: DgiConfig = DgiConfig()) -> np.ndarray:
    """DI in feature units: depth measured from the volume's back face, times `depth_scale`;
    empty pixels stay at EMPTY_DEPTH.

    In metres, the empty value −1 lies a metre below every depth, so that an RBF kernel on raw DIs
    sees whether pixels are empty and hardly how deep they are. Here the volume spans
    [0, (palm_margin + depth_range) · depth_scale) = [0, 2.6) units at the defaults, and empty
    is one unit (4 cm) below its back face.
    """
    di = np.asarray(di, dtype=float)
    return np.where(di == EMPTY_DEPTH, EMPTY_DEPTH, (di + config.palm_margin) * config.depth_scale)


def dgi_features(p_W: np.ndarray, X_WG: np.ndarray, config: DgiConfig = DgiConfig()) -> np.ndarray:
    """Feature vectors (M, config.n_features): the DI pixels then the DGI pixels, row-major, both
    in feature units (`feature_depth_images`; the DGI is taken of the scaled DI)."""
    di = feature_depth_images(depth_images(p_W, X_WG, config), config)
    dgi = depth_gradient_images(di)
    M = di.shape[0]
    return np.concatenate([di.reshape(M, -1), dgi.reshape(M, -1)], axis=1)
