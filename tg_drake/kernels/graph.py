"""The labelled k-nn graph of a point cloud (paper section III-C).

Each point is a node; it is joined to its k = 4 nearest points (Euclidean distance in 3D) and the
edge (i, j) weighs w_ij = |n_i · n_j|, so that edges across a crease of the surface count less
than edges along a flat or smoothly curved patch. Node labels are the semantic part labels
(indices into `tg_drake.types.PART_LABELS`).

Everything here is vectorised: one KD-tree query for all points, sparse matrices for the graph.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from tg_drake.errors import KernelError
from tg_drake.types import PART_LABELS

K_NEIGHBOURS = 4  # the paper's four-neighbourhood.


@dataclass(frozen=True)
class LabelledCloud:
    """A validated point cloud with unit normals and integer part labels."""

    points: np.ndarray  # (N, 3) float64 [m].
    normals: np.ndarray  # (N, 3) float64, unit length (orientation does not matter here).
    labels: np.ndarray  # (N,) int64, indices into PART_LABELS.


def validate_cloud(points, normals, labels, *, k: int = K_NEIGHBOURS,
                   n_labels: int = len(PART_LABELS)) -> LabelledCloud:
    """Checks a labelled cloud for the kernel prior and returns it as float64/int64 arrays.

    Raises KernelError naming what is wrong: too few points for a k-nn graph, missing or
    degenerate normals, shapes that do not match, labels outside PART_LABELS.
    """
    if points is None:
        raise KernelError("missing points: the kernel prior needs an (N, 3) point cloud")
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise KernelError(f"points must have shape (N, 3), got {p.shape}")
    n = p.shape[0]
    if n < k + 1:
        raise KernelError(
            f"a cloud of {n} point(s) is too small: the k-nn graph with k = {k} needs at least "
            f"{k + 1} points")
    if not np.all(np.isfinite(p)):
        raise KernelError("points contain NaN or infinite coordinates")
    if normals is None:
        raise KernelError("missing normals: the edge weights |n_i · n_j| need one unit normal "
                          "per point")
    nrm = np.asarray(normals, dtype=np.float64)
    if nrm.shape != p.shape:
        raise KernelError(f"normals must have the shape of the points {p.shape}, got {nrm.shape}")
    length = np.linalg.norm(nrm, axis=1)
    # 1e-6: a normal this short carries no direction (estimators return zeros when they fail).
    bad = ~np.isfinite(length) | (length < 1e-6)
    if np.any(bad):
        raise KernelError(
            f"missing normals: {int(bad.sum())} of {n} normals are zero or not finite "
            f"(first at point {int(np.flatnonzero(bad)[0])})")
    if labels is None:
        raise KernelError("missing labels: the kernel prior needs one part label per point")
    lab = np.asarray(labels)
    if lab.shape != (n,):
        raise KernelError(f"labels must have shape ({n},), got {lab.shape}")
    if lab.dtype.kind not in "iu":
        raise KernelError(f"labels must be integers (indices into PART_LABELS), got {lab.dtype}")
    unknown = np.unique(lab[(lab < 0) | (lab >= n_labels)])
    if unknown.size:
        allowed = ", ".join(f"{i} ({name})" for i, name in enumerate(PART_LABELS[:n_labels]))
        raise KernelError(f"unknown part label(s) {unknown.tolist()}; allowed: {allowed}")
    return LabelledCloud(p, nrm / length[:, None], lab.astype(np.int64))


def knn_graph(points: np.ndarray, normals: np.ndarray, *, k: int = K_NEIGHBOURS) -> sp.csr_matrix:
    """The symmetric weighted k-nn adjacency matrix A, A_ij = |n_i · n_j|.

    i and j are joined when j is among the k nearest points of i or i among those of j (the
    union, so the graph is undirected). `points` and `normals` must be validated
    (`validate_cloud`); normals need not be oriented consistently.
    """
    n = points.shape[0]
    _, idx = cKDTree(points).query(points, k=k + 1)
    # Drop each point itself from its neighbour list. With duplicate points the point need not
    # come first, so keep the first k entries that are not the point (stable order).
    not_self = idx != np.arange(n)[:, None]
    order = np.argsort(~not_self, axis=1, kind="stable")[:, :k]
    nbr = np.take_along_axis(idx, order, axis=1)
    rows = np.repeat(np.arange(n), k)
    cols = nbr.ravel()
    weights = np.abs(np.einsum("ij,ij->i", normals[rows], normals[cols]))
    directed = sp.csr_matrix((weights, (rows, cols)), shape=(n, n))
    return directed.maximum(directed.T).tocsr()


def transition_matrix(adjacency: sp.spmatrix) -> sp.csr_matrix:
    """The row-normalised adjacency D⁻¹A of the label diffusion L_t = D⁻¹A L_(t−1).

    A node whose edges all weigh zero (every neighbour's normal is perpendicular to its own)
    has D_ii = 0; it keeps its label distribution (its row is the unit row), so every row of
    the result sums to 1 and distributions stay distributions.
    """
    a = sp.csr_matrix(adjacency, dtype=np.float64)
    degree = np.asarray(a.sum(axis=1)).ravel()
    isolated = degree <= 0.0
    inv = np.where(isolated, 0.0, 1.0 / np.where(isolated, 1.0, degree))
    return (sp.diags(inv) @ a + sp.diags(isolated.astype(np.float64))).tocsr()


def cloud_transition(cloud: LabelledCloud, *, k: int = K_NEIGHBOURS) -> sp.csr_matrix:
    """D⁻¹A of the weighted k-nn graph of a validated cloud."""
    return transition_matrix(knn_graph(cloud.points, cloud.normals, k=k))


def object_size(points: np.ndarray) -> float:
    """The cloud's largest extent along its principal axes [m]: a size that does not change when
    the cloud is turned, so a turned or moved object gets the same scale."""
    centred = points - points.mean(axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    extents = np.ptp(centred @ axes.T, axis=0)
    return float(extents.max())


def size_normalised(cloud: LabelledCloud) -> LabelledCloud:
    """The cloud scaled to a largest principal extent of 1 (normals and labels unchanged).

    The paper normalises the kernel, K̂_ij = K_ij / sqrt(K_ii K_jj), to be independent of the
    number of points "and hence of the scale of the objects". With clouds resampled at one metric
    spacing that does not hold: T diffusion steps then span the same distance on a 6 cm bowl and
    on a 14 cm glass, and the graph's label bands measure the object's size, not its shape. Scaled
    to unit size first and resampled at a spacing relative to it, every object has about the same
    number of points per part band, and the kernel compares shapes.
    """
    size = object_size(cloud.points)
    if not size > 0:
        raise KernelError("a cloud with no extent (all points at one place) has no size to "
                          "normalise")
    return LabelledCloud(cloud.points / size, cloud.normals, cloud.labels)


def voxel_resample(cloud: LabelledCloud, spacing: float, *,
                   offset: np.ndarray | None = None) -> LabelledCloud:
    """One point per occupied cube of side `spacing` [m] (the point nearest the cube centre).

    Brings clouds of any density to the density of the database, so that T diffusion steps
    span the same surface distance in the query and in the database. The kept points are real
    points, so their normals and labels are kept unchanged. The grid starts at the cloud's lowest
    corner, so a moved cloud resamples the same; `offset` [m] shifts the grid from there (the
    database tool varies it to get different samplings of one object).
    """
    if not spacing > 0:
        raise KernelError(f"voxel spacing must be positive, got {spacing}")
    shift = np.zeros(3) if offset is None else np.asarray(offset, dtype=np.float64)
    scaled = (cloud.points - cloud.points.min(axis=0) + shift) / spacing
    cell = np.floor(scaled).astype(np.int64)
    dist = np.sum((scaled - cell - 0.5) ** 2, axis=1)
    # Sort by cell, then by distance to the cell centre; the first of each cell is kept.
    order = np.lexsort((dist, cell[:, 2], cell[:, 1], cell[:, 0]))
    sorted_cells = cell[order]
    first = np.ones(len(order), dtype=bool)
    first[1:] = np.any(sorted_cells[1:] != sorted_cells[:-1], axis=1)
    keep = np.sort(order[first])
    return LabelledCloud(cloud.points[keep], cloud.normals[keep], cloud.labels[keep])
