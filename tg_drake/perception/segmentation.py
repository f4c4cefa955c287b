"""Table plane and object clusters from a depth cloud (the paper's table-top segmentation step).

The table is the largest horizontal plane found by RANSAC (`ransac_plane`, seeded: the same plane on
every run), refitted by least squares on its inliers. The table frame T has its origin at the
inliers' centroid on the plane, z along the plane normal (towards the camera, i.e. up) and x along
the inliers' principal direction. Object points are the points above the plane, inside the table's
extent; they are averaged per voxel and clustered with DBSCAN (Open3D `cluster_dbscan`). Two
clusters that touch in the image with a short depth step between them are one object whose
connection the nearer part hides: a pan's handle whose root hides behind the rim. A cluster with a
pixel on the image border is cut: by default it is dropped, since no completion can recover what the
image does not hold. Last, the table's noise that crossed the height threshold at an object's foot
and joined its cluster is taken off it (`foot_noise`): low voxels out from the footprint of what
stands above the noise band, on table that is not raised.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import open3d as o3d
from scipy.spatial import cKDTree

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


def table_noise_scale(height: np.ndarray, range_m: np.ndarray, table: np.ndarray) -> float:
    """a [1/m] of the table's height noise σ = a·range² (a triangulating camera's axial noise
    grows with range², sensor_model.StructuredLight.axial_rms): 1.4826·MAD of height/range² over
    the table inliers (`table`: their mask), whatever the camera."""
    u = height[table] / range_m[table] ** 2
    return 1.4826 * float(np.median(np.abs(u - np.median(u))))


def _raised_discs(centres: np.ndarray, xy: np.ndarray, h: np.ndarray, r2: np.ndarray, a: float,
                  cfg: SegmentationConfig) -> np.ndarray:
    """(M,) bool: is the table raised around each of `centres` (M, 2)? The points (xy (N, 2),
    heights h (N,), squared camera ranges r2 (N,)) within the disc of a `thin_cell` square's area
    of a centre: at least `thin_min_cell_points` of them, their median height above
    `thin_min_height` and above `thin_significance` of its standard error, 1.2533·a·mean(r2)/√n
    (the table's noise σ = a·range², `table_noise_scale`)."""
    hood = cKDTree(xy).query_ball_point(centres, cfg.thin_cell / np.sqrt(np.pi))
    n = np.array([len(nb) for nb in hood], int)
    if not n.any():
        return np.zeros(len(centres), bool)
    owner = np.repeat(np.arange(len(centres)), n)
    nb = np.concatenate(hood).astype(int)
    by = np.lexsort((h[nb], owner))  # each disc's heights in order
    first = np.r_[0, np.cumsum(n)[:-1]]
    hs = h[nb][by]
    has = np.flatnonzero(n)
    m = np.zeros(len(centres))
    m[has] = 0.5 * (hs[first[has] + (n[has] - 1) // 2] + hs[first[has] + n[has] // 2])
    k = np.maximum(n, 1)
    error = 1.2533 * a * np.bincount(owner, weights=r2[nb], minlength=len(centres)) / k / np.sqrt(k)
    return ((n >= cfg.thin_min_cell_points) & (m > cfg.thin_min_height)
            & (m > cfg.thin_significance * error))


def foot_noise(q: np.ndarray, p_T: np.ndarray, height: np.ndarray, range_q: np.ndarray,
               range_m: np.ndarray, a: float, cfg: SegmentationConfig) -> np.ndarray:
    """(M,) bool: the voxels q (M, 3, in T) of one object that are the table's noise at its foot.

    DBSCAN joins a voxel of table noise that crosses the height threshold within `cluster_eps` of
    an object's foot; a few of them, 10–30 mm out from the wall, stretch the object's box, and
    the completion's 180° turn doubles the stretch on the far side (measured on the training
    objects' perceived views: half had a horizontal box side 10 mm or more too long, a quarter
    25 mm). A voxel is such noise when (1) its height is within `foot_noise_sigmas` of the
    table's noise σ = a·range² (`table_noise_scale`; q's camera ranges `range_q`), (2) it lies
    more than a voxel out from the footprint of the object's voxels above that band, and (3) the
    cloud around it on the table (every point of p_T with its `height` and camera range
    `range_m` below the band, within the disc of a `thin_cell` square's area) is not raised — the
    test of `raised_cells`: the median height within `thin_significance` standard errors of the
    table's or under `thin_min_height`. A blade lying flat beside a raised handle is raised all
    along, a noise voxel has table around it. An object with too few voxels above the band to
    have a footprint (a blade alone) keeps all of its own."""
    out = np.zeros(len(q), bool)
    band = cfg.foot_noise_sigmas * a * range_q ** 2
    low = q[:, 2] <= band
    above = ~low
    if not low.any() or above.sum() < cfg.cluster_min_points:
        return out
    d, _ = cKDTree(q[above, :2]).query(q[low, :2])
    outside = np.flatnonzero(low)[d > cfg.voxel_size]
    if len(outside) == 0:
        return out
    lo_xy = q[outside, :2].min(axis=0) - cfg.thin_cell
    hi_xy = q[outside, :2].max(axis=0) + cfg.thin_cell
    near = np.flatnonzero(np.all(p_T[:, :2] >= lo_xy, axis=1) & np.all(p_T[:, :2] <= hi_xy, axis=1)
                          & (height > -cfg.plane_distance)
                          & (height <= cfg.foot_noise_sigmas * a * range_m ** 2))
    if len(near) == 0:
        return out
    raised = _raised_discs(q[outside, :2], p_T[near, :2], height[near], range_m[near] ** 2, a,
                           cfg)
    out[outside[~raised]] = True
    return out


def raised_cells(p_T: np.ndarray, height: np.ndarray, range_m: np.ndarray,
                 table: np.ndarray, cfg: SegmentationConfig) -> np.ndarray:
    """(N,) bool: the low points (−plane_distance < height ≤ min_object_height) that lie in a
    raised cell of the table — an object thinner than the height threshold (a blade lying flat).

    A point's height says little about a 2–4 mm object: the table's own noise is about as large
    (σ ≈ 2 mm at 1 m through the D415). The median height of the points in a `thin_cell` square
    has a far smaller error, 1.253·σ/√n. The noise is the table's own: a triangulating camera's
    axial noise grows with range² (sensor_model.StructuredLight.axial_rms), so σ = a·range²
    with a from the table inliers' heights (`table`: their mask; 1.4826·MAD of height/range²),
    whatever the camera. A cell is raised when its median exceeds `thin_significance` of those
    errors and `thin_min_height`; a lone raised cell of noise is dropped later (too few voxels
    for a cluster).

    Args:
        p_T: (N, 3) points in the table frame [m]; height: (N,) their heights [m];
        range_m: (N,) their distances from the camera [m]; table: (N,) bool, the plane's inliers.
    """
    low = np.flatnonzero((height <= cfg.min_object_height) & (height > -cfg.plane_distance))
    out = np.zeros(len(p_T), bool)
    if len(low) == 0 or not table.any():
        return out
    a = table_noise_scale(height, range_m, table)
    ij = np.floor(p_T[low, :2] / cfg.thin_cell).astype(np.int64)
    ij -= ij.min(axis=0)
    cell = ij[:, 0] * (int(ij[:, 1].max()) + 1) + ij[:, 1]
    order = np.lexsort((height[low], cell))
    cell_sorted = cell[order]
    starts = np.flatnonzero(np.r_[True, cell_sorted[1:] != cell_sorted[:-1]])
    counts = np.diff(np.r_[starts, len(order)])
    median = height[low][order][starts + (counts - 1) // 2]
    mean_r2 = np.add.reduceat(range_m[low][order] ** 2, starts) / counts
    error = 1.2533 * a * mean_r2 / np.sqrt(counts)
    raised = ((counts >= cfg.thin_min_cell_points) & (median > cfg.thin_min_height)
              & (median > cfg.thin_significance * error))
    if not raised.any():
        return out
    # The object's outline within a cell: each low point of a raised cell or of a cell next to
    # one is tested on the disc of the cell's area centred on it (a point off the object's edge
    # has mostly table around it), so that no cell's table part joins the object.
    cells = cell_sorted[starts]
    width = int(ij[:, 1].max()) + 1
    near = np.zeros(len(cells), bool)
    raised_ids = cells[raised]
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            near |= np.isin(cells, raised_ids + di * width + dj)
    cand = order[np.repeat(near, counts)]
    xy = p_T[low[cand], :2]
    keep = _raised_discs(xy, xy, height[low[cand]], range_m[low[cand]] ** 2, a, cfg)
    out[low[cand[keep]]] = True
    return out


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
    return _joined(n, np.unique(np.concatenate(pairs), axis=0) if pairs else [])


def _joined(n: int, pairs) -> np.ndarray:
    """Cluster id → the smallest id of its group, the groups joined by `pairs` (i, j)."""
    parent = np.arange(n)
    for i, j in pairs:
        ri, rj = i, j
        while parent[ri] != ri:
            ri = parent[ri]
        while parent[rj] != rj:
            rj = parent[rj]
        parent[max(ri, rj)] = min(ri, rj)
    for i in range(n):  # flatten (parents have smaller ids)
        parent[i] = parent[parent[i]]
    return parent


def _merge_through_lost(labels_px: np.ndarray, rows: np.ndarray, cols: np.ndarray,
                        valid: np.ndarray, q: np.ndarray, labels_q: np.ndarray, n: int,
                        bridge_px: int, max_gap: float) -> np.ndarray:
    """Cluster id → merged cluster id, joining clusters that meet in the image when each grows,
    one pixel per step for `bridge_px` steps, into the pixels the sensor lost (`valid`: (H, W)
    True where the frame has a depth), and whose nearest points (q (M, 3) voxel points with
    their cluster `labels_q`) are at most `max_gap` [m] apart. A pixel with a depth (the table,
    another object) stops the growth: what the camera saw between two clusters keeps them
    apart."""
    height, width = valid.shape
    image = np.full((height + 2, width + 2), -1)
    image[rows + 1, cols + 1] = labels_px
    lost = np.zeros((height + 2, width + 2), bool)
    lost[1:-1, 1:-1] = ~valid
    lost[rows + 1, cols + 1] = False
    shifts = ((0, 1), (0, -1), (1, 0), (-1, 0))
    for _ in range(bridge_px):
        grown = image.copy()
        for dr, dc in shifts:
            src = np.roll(image, (dr, dc), axis=(0, 1))
            take = (grown < 0) & lost & (src >= 0)
            grown[take] = src[take]
        if np.array_equal(grown, image):
            break
        image = grown
    pairs = set()
    for dr, dc in ((0, 1), (1, -1), (1, 0), (1, 1)):
        a = image[1:-1, 1:-1]
        b = np.roll(image, (-dr, -dc), axis=(0, 1))[1:-1, 1:-1]
        m = (a >= 0) & (b >= 0) & (a != b)
        pairs.update(map(tuple, np.unique(np.sort(np.column_stack([a[m], b[m]]), axis=1),
                                          axis=0).tolist()))
    near = [(i, j) for i, j in sorted(pairs)
            if cKDTree(q[labels_q == i]).query(q[labels_q == j], k=1)[0].min() <= max_gap]
    return _joined(n, near)


def fit_circle(xy: np.ndarray) -> tuple[np.ndarray, float, float]:
    """(centre (2,), radius, RMS distance to the circle) [m] of the least-squares (Kåsa) circle
    through points xy (N, 2), N ≥ 3."""
    A = np.column_stack([2 * xy, np.ones(len(xy))])
    b = (xy ** 2).sum(axis=1)
    (cx, cy, k), *_ = np.linalg.lstsq(A, b, rcond=None)
    centre = np.array([cx, cy])
    radius = float(np.sqrt(max(k + cx * cx + cy * cy, 0.0)))
    rms = float(np.sqrt(np.mean((np.linalg.norm(xy - centre, axis=1) - radius) ** 2)))
    return centre, radius, rms


def _circle_radii(stats: np.ndarray) -> np.ndarray:
    """Radii [m] of the least-squares (Kåsa) circles whose normal equations are `stats` (..., 3,
    4): [AᵀA | Aᵀb] summed over points, A = [2x, 2y, 1], b = x² + y² (fit_circle's system). NaN
    where the system is too ill-conditioned for the normal equations (the caller then fits)."""
    M, v = stats[..., :3], stats[..., 3]
    out = np.full(M.shape[:-2], np.nan)
    ok = np.linalg.cond(M) < 1e10 if len(M) else np.zeros(0, bool)
    if ok.any():
        cx, cy, k = np.moveaxis(np.linalg.solve(M[ok], v[ok][..., None])[..., 0], -1, 0)
        out[ok] = np.sqrt(np.maximum(k + cx * cx + cy * cy, 0.0))
    return out


def _merge_shared_rims(q: np.ndarray, labels: np.ndarray, n: int, cfg: SegmentationConfig
                       ) -> np.ndarray:
    """Cluster id → merged cluster id, joining two clusters whose tops lie on one circle: the
    near and the far wall of an open container whose rim between them the camera lost (a wide
    pot seen from above: the inside's floor hidden, the rim's sides thinner than the sensor's
    edge losses). q: (M, 3) voxel points in T [m]; labels (M,) their cluster (−1: noise).

    A pair needs the circle's radius at most each top's longest side (each top an arc of it, not
    a blob beside it); that radius comes for every pair at once from the normal equations, which
    add over the two tops, and only pairs within 1 % of it are fitted point by point
    (fit_circle)."""
    order = np.argsort(labels, kind="stable")
    bounds = np.searchsorted(labels[order], np.arange(n + 1))
    origin = q[:, :2].mean(axis=0) if len(q) else np.zeros(2)  # the fit does not depend on it
    tops, z_top, side = [], np.full(n, np.nan), np.zeros(n)
    stats = np.zeros((n, 3, 4))
    for k in range(n):
        pts = q[order[bounds[k]:bounds[k + 1]]]
        top = pts[pts[:, 2] >= pts[:, 2].max() - cfg.rim_band] if len(pts) else pts
        tops.append(top)
        if len(top) >= 3:
            z_top[k] = pts[:, 2].max()
            side[k] = np.ptp(top[:, :2], axis=0).max()
            xy = top[:, :2] - origin
            A = np.column_stack([2 * xy, np.ones(len(xy))])
            stats[k] = A.T @ np.column_stack([A, (xy ** 2).sum(axis=1)])
    i, j = np.triu_indices(n, 1)
    pair = np.abs(z_top[i] - z_top[j]) <= cfg.rim_band  # NaN (under 3 top points): False
    i, j = i[pair], j[pair]
    radius = _circle_radii(stats[i] + stats[j])
    maybe = ~(radius > 1.01 * np.minimum(side[i], side[j]) + 1e-6)  # NaN: fit it
    parent = np.arange(n)
    for a, b in zip(i[maybe].tolist(), j[maybe].tolist(), strict=True):
        ta, tb = tops[a], tops[b]
        _, radius, rms = fit_circle(np.concatenate([ta[:, :2], tb[:, :2]]))
        if rms <= cfg.rim_fit_rms and radius > 0 and min(side[a], side[b]) >= radius:
            ra, rb = parent[a], parent[b]
            parent[parent == max(ra, rb)] = min(ra, rb)
    return parent


def _clusters(idx: np.ndarray, p_T: np.ndarray, pixels: np.ndarray,
              image_size: tuple[int, int], cfg: SegmentationConfig,
              valid: np.ndarray) -> list[tuple[np.ndarray, bool, np.ndarray]]:
    """The object clusters of the points `idx` (indices into p_T (N, 3) [m] and their image
    pixels (N, 2); `valid` (H, W): the frame's pixels with a depth): per cluster (its
    voxel-averaged points, whether it touches the image border, the indices of its points)."""
    if len(idx) < cfg.min_cluster_points:
        return []
    p = p_T[idx]
    width, height_px = image_size
    m = cfg.border_margin_px
    r, c = pixels[idx, 0], pixels[idx, 1]
    border = (r < m) | (c < m) | (r >= height_px - m) | (c >= width - m)
    q, voxel = voxel_average(p, cfg.voxel_size)
    voxel_cut = np.bincount(voxel, weights=border, minlength=len(q)) > 0
    labels = np.asarray(o3d.geometry.PointCloud(o3d.utility.Vector3dVector(q)).cluster_dbscan(
        cfg.cluster_eps, cfg.cluster_min_points))
    n_clusters = int(labels.max()) + 1
    if n_clusters > 1:
        keep_px = labels[voxel] >= 0
        merged = _merge_occluded(labels[voxel][keep_px], p[keep_px], r[keep_px], c[keep_px],
                                 image_size, n_clusters, cfg.merge_max_gap)
        labels = np.where(labels >= 0, merged[labels], -1)
        rims = _merge_shared_rims(q, labels, n_clusters, cfg)
        labels = np.where(labels >= 0, rims[np.maximum(labels, 0)], -1)
        if cfg.lost_bridge_px > 0:  # (the merges keep which voxels are noise: keep_px holds)
            kept = labels >= 0
            lost = _merge_through_lost(labels[voxel][keep_px], r[keep_px], c[keep_px], valid,
                                       q[kept], labels[kept], n_clusters,
                                       cfg.lost_bridge_px, cfg.merge_max_gap)
            labels = np.where(labels >= 0, lost[np.maximum(labels, 0)], -1)
    order = np.argsort(labels, kind="stable")
    bounds = np.searchsorted(labels[order], np.arange(n_clusters + 1))
    out = []
    for k in range(n_clusters):
        members = order[bounds[k]:bounds[k + 1]]
        if len(members) >= cfg.min_cluster_points:
            out.append((q[members], bool(voxel_cut[members].any()),
                        idx[np.isin(voxel, members)]))
    return out


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

    # Object points: above the plane, over the table; then the objects thinner than the height
    # threshold (`raised_cells`), as objects of their own: a raised cell's points never join an
    # object the threshold sees (its lowest band stays cut, as the kernel database's views and
    # the pose calibration saw it: the table's mixed pixels at its foot are not the object).
    p_T_all = transform(X_TW, p_W)
    inside = np.all(p_T_all[:, :2] >= lo, axis=1) & np.all(p_T_all[:, :2] <= hi, axis=1)
    regular = inside & (height > cfg.min_object_height) & (height < cfg.max_object_height)
    valid = np.zeros((image_size[1], image_size[0]), bool)  # pixels with a depth
    valid[pixels[:, 0], pixels[:, 1]] = True
    found = _clusters(np.flatnonzero(regular), p_T_all, pixels, image_size, cfg, valid)
    range_all = np.linalg.norm(p_W - p_WC, axis=1)
    on_plane = np.abs(height) < cfg.plane_distance
    thin = inside & raised_cells(p_T_all, height, range_all, on_plane, cfg)
    if thin.any():
        # A found object lying within thin_max_height of the table (its threshold-crossing
        # points a thin object's noise) is clustered again with the raised cells' points.
        flat = np.zeros(len(p_W), bool)
        for q, _, members in found:
            flat[members] = np.median(q[:, 2]) <= cfg.thin_max_height
        found = [f for f in found if not flat[f[2][0]]]
        taken = np.zeros(len(p_W), bool)
        for _, _, members in found:
            taken[members] = True
        rest = np.flatnonzero((regular & ~taken) | thin)
        if taken.any() and len(rest):  # nothing within a cluster's reach of a found object
            d, _ = cKDTree(p_T_all[taken]).query(p_T_all[rest],
                                                 distance_upper_bound=cfg.cluster_eps)
            rest = rest[~np.isfinite(d)]
        found += [f for f in _clusters(rest, p_T_all, pixels, image_size, cfg, valid)
                  if (thin | flat)[f[2]].any()]
    if found and cfg.foot_noise_sigmas > 0:
        a = table_noise_scale(height, range_all, on_plane)
        p_CT = transform(X_TW, np.asarray(p_WC, float)[None])[0]
        cleaned = []
        for q, is_cut, members in found:
            noise = foot_noise(q, p_T_all, height, np.linalg.norm(q - p_CT, axis=1),
                               range_all, a, cfg)
            cleaned.append((q[~noise], is_cut, members))
        found = cleaned
    objects: list[np.ndarray] = []
    cut: list[bool] = []
    n_dropped = 0
    # Deterministic order: by the cluster's centroid x, then y, in the table frame.
    centroids = np.array([q.mean(axis=0) for q, _, _ in found]).reshape(-1, 3)
    for k in np.lexsort((centroids[:, 1], centroids[:, 0])):
        q, is_cut, _ = found[k]
        if is_cut and cfg.drop_border_objects:
            n_dropped += 1
            continue
        objects.append(q)
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
