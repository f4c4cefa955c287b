"""Scan-like meshes made from library objects: what a real scan or a CAD export brings in.

A library object's mesh is small (a few thousand triangles), closed, consistently oriented, in
metres, z up, in its object frame O. A scanned household object is none of that. `scanlike` turns
the one into the other, deterministically for a seed, in this order:

1. **remeshed** to about `n_triangles` triangles by conforming edge bisection: every edge longer
   than a target length is split at its midpoint, each triangle into 2, 3 or 4 by the number of
   its split edges (red–green refinement), until no edge is longer; the target length is adjusted
   (a few passes, count ∝ 1/length²) until the count is within `count_tolerance`. Chosen over
   trimesh's `subdivide_to_size`, which splits only the long triangles and leaves T-junctions
   (cracks the import would have to mend), and over Loop subdivision, which smooths the shape (a
   cup's rim, a knife's edge) and so changes the volume, mass and resting poses that the import
   tests compare with the original. Midpoints lie on the original surface, so before the noise the
   surface is the original one exactly;
2. **surface noise**: each vertex moves along its (area-weighted) normal by a Gaussian of standard
   deviation `noise_sigma`;
3. **holes**: `n_holes` small patches of faces removed, each grown over the surface from a random
   face (area-weighted) to the faces whose centroid is within `hole_radius` of it — along the
   surface, so a hole never goes through a thin wall;
4. **pieces**: the surface cut into `n_pieces` connected regions, each face going to the nearest
   (along the surface) of seeds spread apart; the vertices on a cut are duplicated, so the pieces
   share positions but no vertex (as a scan exported in parts; merging vertices re-joins them).
   Regions rather than planar cuts: a plane at a shallow angle to long thin triangles leaves
   hundreds of one-face islands;
5. **flipped faces**: a fraction `flip_fraction` of the faces has its winding reversed;
6. **zero-area triangles**: `degenerate_fraction` of the face count added, half with a repeated
   vertex (a, b, b), half with three distinct collinear vertices (a, midpoint of ab, b);
7. faces **shuffled**, then the mesh is put in **millimetres, y up** (O's z becomes +y, O's y
   becomes −z) with a random **placement offset** (up to `max_offset` per axis).

Part labels are carried to every vertex from the nearest original vertex (noise-free positions).
A core: numpy, scipy and trimesh only.

    python tools/make_scanlike.py cup_01 glass_01 --out /tmp/scans   # or --all
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import trimesh
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, dijkstra
from scipy.spatial import cKDTree

from tg_drake.errors import ScenarioError, unknown_name
from tg_drake.objects import mesh as library_mesh

FORMATS = ("obj", "stl", "ply")
MM_PER_M = 1000.0  # the scan's unit is the millimetre
# O → scan axes (before scaling): x stays, O's z becomes +y (y up), O's y becomes −z. A rotation.
R_SO = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


@dataclass(frozen=True)
class ScanLikeConfig:
    """What the scan-like mesh gets (SI units; the output is in mm)."""

    n_triangles: int = 50_000  # target triangle count of the remeshed surface (holes not counted)
    count_tolerance: float = 0.05  # relative: the remeshed count lies within ±5 % of n_triangles
    noise_sigma: float = 0.3e-3  # [m] std of the Gaussian displacement along the vertex normal
    n_holes: int = 3  # small patches of faces removed
    hole_radius: float = 4e-3  # [m] along the surface, from a hole's seed face
    n_pieces: int = 3  # planar cuts + 1 (a cut may make more components: a handle cut off)
    flip_fraction: float = 0.02  # of the faces, winding reversed
    degenerate_fraction: float = 0.002  # zero-area triangles added, relative to the face count
    max_offset: float = 0.5  # [m] the placement offset is uniform in ±max_offset per axis

    def __post_init__(self):
        checks = {"n_triangles": self.n_triangles >= 100,
                  "count_tolerance": 0 < self.count_tolerance < 1,
                  "noise_sigma": self.noise_sigma >= 0, "n_holes": self.n_holes >= 0,
                  "hole_radius": self.hole_radius >= 0, "n_pieces": self.n_pieces >= 1,
                  "flip_fraction": 0 <= self.flip_fraction <= 1,
                  "degenerate_fraction": 0 <= self.degenerate_fraction <= 1,
                  "max_offset": self.max_offset >= 0}
        for name, ok in checks.items():
            if not ok:
                raise ScenarioError(f"scan-like {name} out of range: {getattr(self, name)!r}",
                                    field=name)


@dataclass(frozen=True)
class ScanLike:
    """A scan-like mesh (mm, y up) with its per-vertex part labels and what was done."""

    mesh: trimesh.Trimesh  # not processed: duplicates, degenerate and flipped faces kept
    labels: np.ndarray  # (V,) uint8 part label per vertex (index into PART_LABELS)
    X_SO: np.ndarray  # (4, 4) maps O [m] to the scan's coordinates [mm]: p_S = X_SO · p_O
    record: dict = field(default_factory=dict)  # scale, up axis, counts (JSON-serialisable)


# ------------------------------------------------------------------------------------------------
# remeshing


def _face_edges(F: np.ndarray) -> np.ndarray:
    """(F, 3, 2) the edges of each face in winding order: (a, b), (b, c), (c, a)."""
    return np.stack([F, np.roll(F, -1, axis=1)], axis=2)


def _roll_rows(A: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Each row of A (n, 3) rotated left by r[i] places."""
    idx = (np.arange(3)[None, :] + r[:, None]) % 3
    return np.take_along_axis(A, idx, axis=1)


def _unique_edges(F: np.ndarray):
    """(E, 2) unique undirected edges (smaller index first) and, per face edge (F·3,), its row."""
    E = np.sort(_face_edges(F).reshape(-1, 2), axis=1)
    n = int(F.max()) + 1
    uniq, inv = np.unique(E[:, 0] * n + E[:, 1], return_inverse=True)  # integer keys: fast
    return np.stack([uniq // n, uniq % n], axis=1), inv.reshape(-1)


def _split(V: np.ndarray, F: np.ndarray, edges: np.ndarray, inv: np.ndarray, split: np.ndarray):
    """One round: the edges `split` (bool per unique edge) cut at their midpoints, each face by its
    number of split edges: 1 → 2 faces, 2 → 3 (the quad along its shorter diagonal), 3 → 4.
    Conforming (a midpoint is shared by both faces of its edge) and winding-preserving."""
    mid_index = np.full(len(edges), -1, np.int64)
    mid_index[split] = len(V) + np.arange(split.sum())
    V = np.vstack([V, 0.5 * (V[edges[split, 0]] + V[edges[split, 1]])])
    M = mid_index[inv].reshape(-1, 3)  # midpoint of each face edge, −1 when not split
    marked = M >= 0
    count = marked.sum(axis=1)
    out = [F[count == 0]]
    # one split edge: rotate it to (a, b); faces (a, m, c), (m, b, c)
    s = count == 1
    r = np.argmax(marked[s], axis=1)
    f, m = _roll_rows(F[s], r), _roll_rows(M[s], r)
    a, b, c, mab = f[:, 0], f[:, 1], f[:, 2], m[:, 0]
    out += [np.stack([a, mab, c], 1), np.stack([mab, b, c], 1)]
    # two split edges: rotate the unsplit one to (c, a); faces (mab, b, mbc) and the quad
    # a, mab, mbc, c along its shorter diagonal
    s = count == 2
    r = (np.argmin(marked[s], axis=1) + 1) % 3
    f, m = _roll_rows(F[s], r), _roll_rows(M[s], r)
    a, b, c, mab, mbc = f[:, 0], f[:, 1], f[:, 2], m[:, 0], m[:, 1]
    d_a = (np.linalg.norm(V[a] - V[mbc], axis=1) <= np.linalg.norm(V[mab] - V[c], axis=1))[:, None]
    out += [np.stack([mab, b, mbc], 1),
            np.where(d_a, np.stack([a, mab, mbc], 1), np.stack([a, mab, c], 1)),
            np.where(d_a, np.stack([a, mbc, c], 1), np.stack([mab, mbc, c], 1))]
    # three split edges: four faces
    s = count == 3
    f, m = F[s], M[s]
    a, b, c, mab, mbc, mca = f[:, 0], f[:, 1], f[:, 2], m[:, 0], m[:, 1], m[:, 2]
    out += [np.stack([a, mab, mca], 1), np.stack([mab, b, mbc], 1),
            np.stack([mca, mbc, c], 1), np.stack([mab, mbc, mca], 1)]
    return V, np.concatenate(out)


def refine(V: np.ndarray, F: np.ndarray, max_edge: float, *,
           max_rounds: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Conforming edge bisection until no edge is longer than `max_edge` [V's unit]: each round
    splits every longer edge (`_split`)."""
    V, F = np.asarray(V, float), np.asarray(F, np.int64)
    for _ in range(max_rounds):
        edges, inv = _unique_edges(F)
        long_ = np.linalg.norm(V[edges[:, 0]] - V[edges[:, 1]], axis=1) > max_edge
        if not long_.any():
            return V, F
        V, F = _split(V, F, edges, inv, long_)
    raise RuntimeError(f"edge bisection did not reach edges ≤ {max_edge} in {max_rounds} rounds")


def remesh_to_count(V: np.ndarray, F: np.ndarray, n_triangles: int, *,
                    tolerance: float = 0.05, max_passes: int = 8):
    """`refine` with the edge length that gives n_triangles (±tolerance, relative) faces.

    Starts from the equilateral estimate (area per triangle √3/4·L²) and corrects L by
    √(count / n_triangles) each pass, keeping the longest L whose count is not above the target;
    then, when short, one partial round splits the longest edges (each adds about 2 faces). A mesh
    that already has enough faces is returned unchanged. Returns (V, F, max_edge or None).
    """
    V, F = np.asarray(V, float), np.asarray(F, np.int64)
    if len(F) >= n_triangles * (1 - tolerance):
        return V, F, None
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]),
                                axis=1).sum()
    L = np.sqrt(4 * area / (np.sqrt(3) * n_triangles))
    below = None  # (V, F, L) with the most faces not above n_triangles
    for _ in range(max_passes):
        V1, F1 = refine(V, F, L)
        err = len(F1) / n_triangles - 1
        if err <= 0 and (below is None or len(F1) > len(below[1])):
            below = (V1, F1, L)
        if abs(err) <= tolerance:
            return V1, F1, L
        L *= np.sqrt(1 + err) if err > -0.5 else 0.7
    if below is None:
        return V1, F1, L
    V1, F1, L = below
    edges, inv = _unique_edges(F1)
    length = np.linalg.norm(V1[edges[:, 0]] - V1[edges[:, 1]], axis=1)
    k = min(len(edges), (n_triangles - len(F1)) // 2)
    split = np.zeros(len(edges), bool)
    split[np.argsort(-length, kind="stable")[:k]] = True
    V1, F1 = _split(V1, F1, edges, inv, split)
    return V1, F1, L


# ------------------------------------------------------------------------------------------------
# defects


def _vertex_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Area-weighted unit vertex normals (zero-area neighbourhoods get +z; never NaN)."""
    cross = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    N = np.zeros_like(V)
    for k in range(3):
        np.add.at(N, F[:, k], cross)
    norm = np.linalg.norm(N, axis=1, keepdims=True)
    return np.where(norm > 0, N / np.where(norm > 0, norm, 1.0), [0.0, 0.0, 1.0])


def _face_adjacency(F: np.ndarray) -> np.ndarray:
    """(P, 2) pairs of faces that share an edge (by vertex index)."""
    E = np.sort(_face_edges(F).reshape(-1, 2), axis=1)
    key = E[:, 0] * (int(F.max()) + 1) + E[:, 1]
    face = np.repeat(np.arange(len(F)), 3)
    order = np.argsort(key, kind="stable")
    key, face = key[order], face[order]
    same = key[1:] == key[:-1]
    return np.stack([face[:-1][same], face[1:][same]], axis=1)


def _grow_holes(V, F, seeds: np.ndarray, radius: float) -> np.ndarray:
    """Boolean (F,) faces reached from `seeds` over shared edges with centroids within `radius`
    of their seed's centroid."""
    C = V[F].mean(axis=1)
    adj = _face_adjacency(F)
    pairs = np.vstack([adj, adj[:, ::-1]])
    owner = np.full(len(F), -1, np.int64)  # which seed's hole a face belongs to
    owner[seeds] = np.arange(len(seeds))
    frontier = np.zeros(len(F), bool)
    frontier[seeds] = True
    while frontier.any():
        step = pairs[frontier[pairs[:, 0]] & (owner[pairs[:, 1]] < 0)]
        if not len(step):
            break
        src, dst = step[:, 0], step[:, 1]
        near = np.linalg.norm(C[dst] - C[seeds[owner[src]]], axis=1) <= radius
        src, dst = src[near], dst[near]
        dst, first = np.unique(dst, return_index=True)
        owner[dst] = owner[src[first]]
        frontier = np.zeros(len(F), bool)
        frontier[dst] = True
    return owner >= 0


def _regions(V: np.ndarray, F: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    """(F,) region index: the faces cut into `n` connected regions, each face going to the seed
    nearest to it along the surface (Dijkstra over shared edges, centroid to centroid). The seeds
    are spread apart: a random face, then each time the face farthest from those chosen."""
    C = V[F].mean(axis=1)
    seeds = [int(rng.integers(len(F)))]
    d = np.linalg.norm(C - C[seeds[0]], axis=1)
    for _ in range(n - 1):
        seeds.append(int(np.argmax(d)))
        d = np.minimum(d, np.linalg.norm(C - C[seeds[-1]], axis=1))
    adj = _face_adjacency(F)
    w = np.linalg.norm(C[adj[:, 0]] - C[adj[:, 1]], axis=1) + 1e-12  # > 0: csgraph drops zeros
    g = coo_matrix((w, (adj[:, 0], adj[:, 1])), shape=(len(F), len(F))).tocsr()
    _, _, source = dijkstra(g, directed=False, indices=seeds, min_only=True,
                            return_predecessors=True)
    return np.searchsorted(np.array(sorted(seeds)), source) if n > 1 else np.zeros(len(F), int)


def components(F: np.ndarray) -> np.ndarray:
    """(F,) connected-component index of each face, over shared edges (by vertex index)."""
    adj = _face_adjacency(F)
    g = coo_matrix((np.ones(len(adj)), (adj[:, 0], adj[:, 1])), shape=(len(F), len(F)))
    return connected_components(g, directed=False)[1]


def n_components(F: np.ndarray) -> int:
    """Number of connected components of the faces over shared edges (by vertex index)."""
    return int(components(F).max()) + 1 if len(F) else 0


def make_scanlike(obj, *, seed: int = 0, config: ScanLikeConfig | None = None) -> ScanLike:
    """The scan-like version of library object `obj` (an id or a LibraryObject); see the module
    docstring for what is done, in which order. Deterministic for (obj, seed, config)."""
    cfg = config or ScanLikeConfig()
    rng = np.random.default_rng(seed)
    V0, F0, L0 = library_mesh(obj)
    obj_id = obj if isinstance(obj, str) else obj.id

    # 1. remesh; labels from the nearest original vertex on the noise-free surface
    V, F, max_edge = remesh_to_count(V0, F0, cfg.n_triangles, tolerance=cfg.count_tolerance)
    labels = np.asarray(L0, np.uint8)[cKDTree(V0).query(V)[1]]
    n_remeshed = len(F)

    # 2. noise along the normal
    V = V + _vertex_normals(V, F) * rng.normal(0.0, cfg.noise_sigma, (len(V), 1))

    # 3. holes
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]),
                                axis=1)
    seeds = rng.choice(len(F), size=min(cfg.n_holes, len(F)), replace=False, p=area / area.sum())
    removed = _grow_holes(V, F, seeds, cfg.hole_radius) if len(seeds) else np.zeros(len(F), bool)
    F = F[~removed]
    # a hole may leave slivers joined to the rest by a vertex only: dropped, as a scan's cleaning
    # keeps the largest component (the original is one)
    comp = components(F)
    main = comp == np.argmax(np.bincount(comp))
    n_islands = int((~main).sum())
    F = F[main]

    # 4. pieces: surface regions nearest (along the surface) to seeds spread apart; vertices
    # duplicated per (vertex, piece)
    piece = _regions(V, F, cfg.n_pieces, rng)
    key = F * cfg.n_pieces + piece[:, None]
    uniq, inv = np.unique(key.reshape(-1), return_inverse=True)
    V, labels = V[uniq // cfg.n_pieces], labels[uniq // cfg.n_pieces]
    F = inv.reshape(-1, 3).astype(np.int64)

    # 5. flipped faces
    flipped = rng.choice(len(F), size=int(round(cfg.flip_fraction * len(F))), replace=False)
    F[flipped] = F[flipped, ::-1]

    # 6. zero-area triangles: (a, b, b) and (a, midpoint of ab, b)
    n_deg = int(round(cfg.degenerate_fraction * len(F)))
    n_repeat, n_collinear = (n_deg + 1) // 2, n_deg // 2
    host = F[rng.choice(len(F), size=n_deg)]
    repeated = np.stack([host[:n_repeat, 0], host[:n_repeat, 1], host[:n_repeat, 1]], 1)
    a, b = host[n_repeat:, 0], host[n_repeat:, 1]
    mid = len(V) + np.arange(n_collinear)
    V = np.vstack([V, 0.5 * (V[a] + V[b])])
    labels = np.concatenate([labels, labels[a]])
    F = np.concatenate([F, repeated, np.stack([a, mid, b], 1)])

    # 7. shuffled faces; millimetres, y up, placed at a random offset
    F = F[rng.permutation(len(F))]
    X_SO = np.eye(4)
    X_SO[:3, :3] = MM_PER_M * R_SO
    X_SO[:3, 3] = MM_PER_M * rng.uniform(-cfg.max_offset, cfg.max_offset, 3)
    V = V @ X_SO[:3, :3].T + X_SO[:3, 3]

    record = {
        "object": obj_id, "seed": int(seed), "config": asdict(cfg),
        "scale": MM_PER_M, "units": "mm", "up_axis": "y",
        "X_SO": X_SO.tolist(),
        "remesh": {"method": "conforming edge bisection",
                   "max_edge_mm": None if max_edge is None else MM_PER_M * float(max_edge),
                   "original_triangles": int(len(F0)), "triangles": int(n_remeshed)},
        "n_holes": int(len(seeds)), "hole_faces_removed": int(removed.sum()) + n_islands,
        "n_pieces": n_components(F),
        "n_flipped": int(len(flipped)),
        "n_degenerate": int(n_deg), "n_degenerate_repeated": int(n_repeat),
        "n_degenerate_collinear": int(n_collinear),
        "n_vertices": int(len(V)), "n_triangles": int(len(F)),
    }
    m = trimesh.Trimesh(V, F, process=False, validate=False)
    return ScanLike(mesh=m, labels=labels.astype(np.uint8), X_SO=X_SO, record=record)


def write_scanlike(obj_id: str, out_path, fmt: str | None = None, *, seed: int = 0,
                   config: ScanLikeConfig | None = None) -> ScanLike:
    """Writes the scan-like `obj_id` to out_path (format from `fmt` or the file's suffix: obj,
    stl, ply), its record beside it (<stem>_scanlike.json) and, for obj and ply (formats that keep
    vertices), the per-vertex labels (<stem>_parts.npy, in the file's vertex order: load it with
    trimesh's process=False). Returns the ScanLike."""
    out_path = Path(out_path)
    fmt = (fmt or out_path.suffix.lstrip(".")).lower()
    if fmt not in FORMATS:
        raise unknown_name("scan-like format", fmt, FORMATS, error=ScenarioError,
                           file=str(out_path))
    scan = make_scanlike(obj_id, seed=seed, config=config)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    kwargs = {"include_normals": False, "include_texture": False} if fmt == "obj" else {}
    scan.mesh.export(out_path, file_type=fmt, **kwargs)
    stem = out_path.with_suffix("")
    if fmt in ("obj", "ply"):
        np.save(f"{stem}_parts.npy", scan.labels)
    Path(f"{stem}_scanlike.json").write_text(json.dumps(scan.record, indent=1) + "\n")
    return scan
