"""Table plane and object clusters from a depth cloud (the paper's table-top segmentation step).

The table is the largest horizontal plane found by RANSAC (`ransac_plane`, seeded: the same plane on
every run), refitted by least squares on its inliers. The table frame T has its origin at the
inliers' centroid on the plane, z along the plane normal (towards the camera, i.e. up) and x along
the inliers' principal direction. Object points are the points above the plane, inside the table's
extent; they are averaged per voxel and clustered with DBSCAN (Open3D `cluster_dbscan`). Two
clusters that touch in the image with a short depth step between them are one object whose
connection the nearer part hides: a pan's handle whose root hides behind the rim. A cluster with a
pixel on the image border is cut: by default it is dropped, since no completion can recover what the
image does not hold.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import open3d as o3d

from tg_drake.errors import PerceptionError
from tg_drake.perception.config import SegmentationConfig
from tg_drake.perception.geometry import (
    Intrinsics,
    depth_to_points,
    dot3,
    inverse,
    make_transform,
    transform,
    voxel_average,
)

# Fewer valid pixels than this cannot hold a table and an object.
MIN_CLOUD_POINTS = 100


@dataclass
class Segmentation:
    """The table and the object clusters of one depth frame."""

    X_WT: np.ndarray  # 4×4 table frame: origin on the table top, z along its normal.
    table_min_T: np.ndarray  # (2,) lower corner of the table's extent in T (x, y) [m].
    table_max_T: np.ndarray  # (2,) upper corner [m].
    objects_T: list[np.ndarray]  # per object, (M, 3) voxel-averaged points in T [m].
    cut: list[bool]  # per object, True when it touches the image border (kept only when
    # drop_border_objects is False).
    n_dropped_cut: int = 0  # objects dropped because they touch the image border.
    n_points: int = 0  # valid points in the frame.
    plane_tilts_deg: list[float] = field(default_factory=list)  # tilt of every plane tried.


def _fit_plane(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares plane through points: (centroid, unit normal)."""
    c = p.mean(axis=0)
    _, _, vt = np.linalg.svd(p - c, full_matrices=False)
    return c, vt[2]


def ransac_plane(p: np.ndarray, distance: float, iterations: int, rng: np.random.Generator
                 ) -> tuple[np.ndarray, float]:
    """(n, d) of the plane n·p + d = 0 (|n| = 1) through three of the points `p` (N, 3) that has
    the most points within `distance` [m], over `iterations` samples drawn from `rng` (the first
    such plane on a tie). The same generator state gives the same plane on every run: Open3D's
    `segment_plane` spreads its iterations over threads and does not draw the same samples from
    run to run whatever its seed, which on a noisy table moved points across the table's height
    threshold."""
    triples = p[rng.integers(0, len(p), size=(iterations, 3))]
    normals = np.cross(triples[:, 1] - triples[:, 0], triples[:, 2] - triples[:, 0])
    norms = np.linalg.norm(normals, axis=1)
    usable = norms > 1e-12  # three distinct, non-collinear points
    normals[usable] /= norms[usable, None]
    offsets = -np.einsum("ij,ij->i", normals, triples[:, 0])
    counts = np.zeros(iterations, int)
    for k in np.flatnonzero(usable):
        counts[k] = np.count_nonzero(np.abs(dot3(p, normals[k]) + offsets[k]) < distance)
    best = int(np.argmax(counts))
    return normals[best], float(offsets[best])


def find_table(p_W: np.ndarray, p_WC: np.ndarray, cfg: SegmentationConfig
               ) -> tuple[np.ndarray, np.ndarray, list[float]]:
    """The table plane of a world-frame cloud.

    Returns the plane point c_W, its unit normal n_W (towards the camera) and the tilt of every
    plane tried [deg]. Raises PerceptionError when no horizontal plane holds enough points.
    """
    rng = np.random.default_rng(cfg.seed)
    remaining = p_W
    tilts = []
    cos_max = np.cos(np.radians(cfg.max_table_tilt_deg))
    need = cfg.min_table_fraction * len(p_W)
    for _ in range(cfg.max_planes):
        if len(remaining) < max(3, need):
            break
        stride = max(1, len(remaining) // cfg.ransac_points)
        n, d = ransac_plane(remaining[::stride], cfg.plane_distance, cfg.ransac_iterations, rng)
        if n @ p_WC + d < 0:  # point the normal to the camera's side.
            n, d = -n, -d
        inliers = np.abs(dot3(remaining, n) + d) < cfg.plane_distance
        tilts.append(float(np.degrees(np.arccos(np.clip(n[2], -1.0, 1.0)))))
        if n[2] >= cos_max and inliers.sum() >= need:
            stride = max(1, int(inliers.sum()) // cfg.ransac_points)
            c_W, n_W = _fit_plane(remaining[inliers][::stride])
            if n_W @ (p_WC - c_W) < 0:
                n_W = -n_W
            return c_W, n_W, tilts
        remaining = remaining[~inliers]
    tried = ", ".join(f"{t:.0f}°" for t in tilts) or "none"
    raise PerceptionError(
        f"no table plane: no plane within {cfg.max_table_tilt_deg:g}° of horizontal holds "
        f"{cfg.min_table_fraction:.0%} of the {len(p_W)} points (planes tried, tilt: {tried})")


def _merge_occluded(labels_px: np.ndarray, p_px: np.ndarray, rows: np.ndarray, cols: np.ndarray,
                    image_size: tuple[int, int], n: int, max_gap: float) -> np.ndarray:
    """Cluster id → merged cluster id, joining clusters that touch in the image (within 2 px)
    with at most `max_gap` [m] between their points there: one occludes the other's connection
    to it (a pan's handle whose root hides behind the rim)."""
    width, height = image_size
    image = np.full((height + 2, width + 4), -1)
    image[rows, cols + 2] = labels_px
    points = np.zeros((height + 2, width + 4, 3))
    points[rows, cols + 2] = p_px
    pairs = []
    for dr, dc in ((0, 1), (0, 2), (1, -2), (1, -1), (1, 0), (1, 1), (1, 2), (2, 0)):
        a = image[:height, 2:width + 2]
        b = image[dr:dr + height, 2 + dc:2 + dc + width]
        m = (a >= 0) & (b >= 0) & (a != b)
        if m.any():
            gap = np.linalg.norm(points[:height, 2:width + 2][m]
                                 - points[dr:dr + height, 2 + dc:2 + dc + width][m], axis=1)
            close = gap <= max_gap
            pairs.append(np.column_stack([a[m][close], b[m][close]]))
    parent = np.arange(n)
    for i, j in np.unique(np.concatenate(pairs), axis=0) if pairs else []:
        ri, rj = i, j
        while parent[ri] != ri:
            ri = parent[ri]
        while parent[rj] != rj:
            rj = parent[rj]
        parent[max(ri, rj)] = min(ri, rj)
    for i in range(n):  # flatten (parents have smaller ids)
        parent[i] = parent[parent[i]]
    return parent


def segment_cloud(p_W: np.ndarray, pixels: np.ndarray, image_size: tuple[int, int],
                  p_WC: np.ndarray, cfg: SegmentationConfig | None = None) -> Segmentation:
    """Table and object clusters of a world-frame cloud whose points came from image pixels.

    Args:
        p_W: (N, 3) points in the world frame [m].
        pixels: (N, 2) (row, column) of each point.
        image_size: (width, height) of the image [px].
        p_WC: (3,) camera position in the world [m].
        cfg: segmentation parameters.
    """
    cfg = cfg or SegmentationConfig()
    if len(p_W) < MIN_CLOUD_POINTS:
        raise PerceptionError(
            f"empty cloud: the depth image has {len(p_W)} valid pixels (need at least "
            f"{MIN_CLOUD_POINTS}); every pixel is 0 (too close) or +inf (too far)")
    c_W, n_W, tilts = find_table(p_W, p_WC, cfg)

    # Table frame: z = normal, x = principal direction of the plane inliers (sign: world +x).
    height = dot3(p_W, n_W) - c_W @ n_W
    on_table = np.flatnonzero(np.abs(height) < cfg.plane_distance)
    table = p_W[on_table[:: max(1, len(on_table) // cfg.ransac_points)]]
    flat = (table - c_W) - np.outer(dot3(table - c_W, n_W), n_W)
    _, _, vt = np.linalg.svd(flat, full_matrices=False)
    x = vt[0] - (vt[0] @ n_W) * n_W
    x = x / np.linalg.norm(x)
    if x[0] < 0 or (x[0] == 0 and x[1] < 0):
        x = -x
    X_WT = make_transform(np.column_stack([x, np.cross(n_W, x), n_W]), c_W)
    X_TW = inverse(X_WT)
    table_T = transform(X_TW, table)
    # 0.5 % / 99.5 %: the extent ignores stray inliers of other coplanar surfaces.
    lo = np.percentile(table_T[:, :2], 0.5, axis=0) - cfg.table_margin
    hi = np.percentile(table_T[:, :2], 99.5, axis=0) + cfg.table_margin

    # Object points: above the plane, over the table.
    above = np.flatnonzero((height > cfg.min_object_height) & (height < cfg.max_object_height))
    p_T = transform(X_TW, p_W[above])
    inside = np.all(p_T[:, :2] >= lo, axis=1) & np.all(p_T[:, :2] <= hi, axis=1)
    p_T, above = p_T[inside], above[inside]
    width, height_px = image_size
    m = cfg.border_margin_px
    r, c = pixels[above, 0], pixels[above, 1]
    border = (r < m) | (c < m) | (r >= height_px - m) | (c >= width - m)
    objects: list[np.ndarray] = []
    cut: list[bool] = []
    n_dropped = 0
    if len(p_T) >= cfg.min_cluster_points:
        q, voxel = voxel_average(p_T, cfg.voxel_size)
        voxel_cut = np.bincount(voxel, weights=border, minlength=len(q)) > 0
        labels = np.asarray(o3d.geometry.PointCloud(o3d.utility.Vector3dVector(q)).cluster_dbscan(
            cfg.cluster_eps, cfg.cluster_min_points))
        n_clusters = int(labels.max()) + 1
        if n_clusters > 1:
            keep_px = labels[voxel] >= 0
            merged = _merge_occluded(labels[voxel][keep_px], p_T[keep_px], r[keep_px],
                                     c[keep_px], image_size, n_clusters, cfg.merge_max_gap)
            labels = np.where(labels >= 0, merged[labels], -1)
        order = np.argsort(labels, kind="stable")
        bounds = np.searchsorted(labels[order], np.arange(n_clusters + 1))
        clusters = [order[bounds[k]:bounds[k + 1]] for k in range(n_clusters)]
        clusters = [c for c in clusters if len(c) >= cfg.min_cluster_points]
        # Deterministic order: by the cluster's centroid x, then y, in the table frame.
        centroids = np.array([q[c].mean(axis=0) for c in clusters]).reshape(-1, 3)
        for k in np.lexsort((centroids[:, 1], centroids[:, 0])):
            members = clusters[k]
            is_cut = bool(voxel_cut[members].any())
            if is_cut and cfg.drop_border_objects:
                n_dropped += 1
                continue
            objects.append(q[members])
            cut.append(is_cut)
    if not objects and n_dropped:
        raise PerceptionError(
            f"every object on the table ({n_dropped}) is cut by the image border; move the "
            f"camera so the objects are whole in the image, or set drop_border_objects=False")
    return Segmentation(X_WT, lo, hi, objects, cut, n_dropped, len(p_W), tilts)


def segment_depth(depth: np.ndarray, intrinsics: Intrinsics, X_WC: np.ndarray,
                  cfg: SegmentationConfig | None = None) -> Segmentation:
    """Table and object clusters of a depth image seen from camera pose X_WC."""
    p_W, pixels = depth_to_points(depth, intrinsics, X_WC)
    return segment_cloud(p_W, pixels, (intrinsics.width, intrinsics.height),
                         np.asarray(X_WC, float)[:3, 3], cfg)
