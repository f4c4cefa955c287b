"""Loading and repairing a user's mesh with trimesh: units, up axis, repair, pieces and holes.

`load` reads any format trimesh reads (a scene's meshes are concatenated into one), `to_metres_z_up`
scales it (given or inferred units) and turns its up axis to z, `repair` merges vertices, drops
zero-area and duplicate triangles, makes the winding consistent and outward, fills small holes, and
says what it did. The result never has a zero-area triangle, so no normal is NaN.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import trimesh
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import breadth_first_order, connected_components
from scipy.spatial import cKDTree

from tg_drake.errors import ModelError

# Length of one file unit [m].
UNITS: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001, "inch": 0.0254}
# units "auto": tried in this order, the first that makes the longest side of the bounding box a
# household object's size [m] (a 2 cm cap to a 1 m pan with its handle) wins.
AUTO_ORDER: tuple[str, ...] = ("m", "mm", "cm", "inch")
HOUSEHOLD_SIZE = (0.02, 1.0)  # [m] longest bounding-box side of a graspable household object
# [m] outside this an object is no table-top object whatever the units (a 0.1 mm speck, a 100 m
# building): an error.
PLAUSIBLE_SIZE = (0.002, 3.0)
# up axis of the file → rotation taking it to +z (right-handed, proper rotations).
UP_AXES: dict[str, np.ndarray] = {
    "z": np.eye(3),
    "-z": np.diag([1.0, -1.0, -1.0]),
    "y": np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]]),  # +90° about x: y → z
    "-y": np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]]),
    "x": np.array([[0, 0, -1.0], [0, 1.0, 0], [1.0, 0, 0]]),  # -90° about y: x → z
    "-x": np.array([[0, 0, 1.0], [0, 1.0, 0], [-1.0, 0, 0]]),
}
MERGE_DIGITS = 6  # vertices equal to 1 µm (in metres) are one vertex.
MIN_AREA = 1e-12  # [m²] a triangle smaller than 1 µm × 2 µm is degenerate: dropped.
# A "soup": more than this fraction of the triangles share no edge with another one (nothing to
# take a surface, a volume or a resting pose from).
SOUP_FRACTION = 0.5


@dataclass(frozen=True)
class LoadedMesh:
    vertices: np.ndarray  # (V, 3) in file units, file axes
    faces: np.ndarray  # (F, 3) int64
    n_geometries: int  # meshes of the file (a scene's are concatenated)
    textured: object = None  # the file's one mesh as trimesh loaded it, when it carries a texture
    # image and its coordinates (a scan's colours: kept for the illustration), else None


@dataclass(frozen=True)
class Placement:
    units: str  # the units used: one of UNITS
    factor: float  # [m per file unit]
    why: str  # how the units were decided (for the report)
    up_axis: str
    size: float  # [m] longest side of the bounding box after scaling
    warnings: tuple[str, ...]


@dataclass(frozen=True)
class RepairedMesh:
    vertices: np.ndarray  # (V, 3) [m], z up
    faces: np.ndarray  # (F, 3) int64, consistently wound, outward where a piece is closed
    vertex_normals: np.ndarray  # (V, 3) unit, finite
    source_vertex: np.ndarray  # (V,) index of the nearest vertex of the mesh given to repair
    repairs: tuple[str, ...]  # what was done, for the report ("merged 1204 duplicate vertices")
    n_pieces: int  # connected components
    watertight: bool
    n_boundary_edges: int  # edges with one triangle (an open mesh has some)

    @property
    def is_open(self) -> bool:
        return not self.watertight


def load(path, *, file_for_errors: str | None = None) -> LoadedMesh:
    """Vertices and triangles of a mesh file (trimesh); a scene's meshes are concatenated.

    ModelError naming the file for an unreadable, empty or non-triangle file.
    """
    name = file_for_errors or str(path)
    try:
        obj = trimesh.load(str(path), process=False)
    except ImportError as e:
        raise ModelError(f"reading this format needs a package that is not installed: {e}",
                         file=name) from None
    except Exception as e:  # noqa: BLE001 - trimesh raises many kinds on a malformed file
        raise ModelError(f"cannot read the mesh: {type(e).__name__}: {e}", file=name) from None
    if isinstance(obj, trimesh.Scene):
        geoms = [g for g in obj.dump() if isinstance(g, trimesh.Trimesh)]
    elif isinstance(obj, trimesh.Trimesh):
        geoms = [obj]
    else:
        geoms = []
    geoms = [g for g in geoms if len(g.faces)]
    if not geoms:
        raise ModelError(f"the file holds no triangles ({type(obj).__name__}); allowed: a "
                         "triangle or polygon mesh", file=name)
    V, F, off = [], [], 0
    for g in geoms:
        V.append(np.asarray(g.vertices, float))
        F.append(np.asarray(g.faces, np.int64) + off)
        off += len(g.vertices)
    V, F = np.concatenate(V), np.concatenate(F)
    if not np.isfinite(V).all():
        raise ModelError("the mesh has non-finite vertex coordinates", file=name)
    return LoadedMesh(V, F, len(geoms), textured=_textured(geoms))


def _textured(geoms: list) -> trimesh.Trimesh | None:
    """The one mesh when it has texture coordinates and an image (PBR materials simplified to a
    diffuse map), else None: a scene of several meshes keeps no texture."""
    if len(geoms) != 1 or not isinstance(geoms[0].visual, trimesh.visual.TextureVisuals):
        return None
    visual = geoms[0].visual
    if visual.uv is None or len(visual.uv) != len(geoms[0].vertices):
        return None
    material = visual.material
    if isinstance(material, trimesh.visual.material.PBRMaterial):
        material = material.to_simple()
    if getattr(material, "image", None) is None:
        return None
    return geoms[0]


def infer_units(size: float) -> tuple[str, str]:
    """(units, why) for a mesh whose longest bounding-box side is `size` file units."""
    for u in AUTO_ORDER:
        if HOUSEHOLD_SIZE[0] <= size * UNITS[u] <= HOUSEHOLD_SIZE[1]:
            return u, (f"{size:.4g} file units across: {u} makes it {100 * size * UNITS[u]:.1f} "
                       f"cm, a household object's size ({100 * HOUSEHOLD_SIZE[0]:.0f}–"
                       f"{100 * HOUSEHOLD_SIZE[1]:.0f} cm); tried {', '.join(AUTO_ORDER)}")
    # none fits: the units whose size is nearest the range (the plausibility check then decides)
    centre = math.sqrt(HOUSEHOLD_SIZE[0] * HOUSEHOLD_SIZE[1])
    u = min(AUTO_ORDER, key=lambda u: abs(math.log(size * UNITS[u] / centre)))
    return u, (f"{size:.4g} file units across: no unit among {', '.join(AUTO_ORDER)} makes it "
               f"{100 * HOUSEHOLD_SIZE[0]:.0f}–{100 * HOUSEHOLD_SIZE[1]:.0f} cm; nearest: {u}")


def to_metres_z_up(V: np.ndarray, *, units: str, up_axis: str,
                   scale=(1.0, 1.0, 1.0), file: str | None = None) -> tuple[np.ndarray, Placement]:
    """V scaled to metres (model-file `scale` times the units) and turned so `up_axis` is +z."""
    if units != "auto" and units not in UNITS:
        raise ModelError(f"unknown units {units!r}; allowed: auto, {', '.join(UNITS)}",
                         file=file, field="units")
    if up_axis not in UP_AXES:
        raise ModelError(f"unknown up axis {up_axis!r}; allowed: {', '.join(UP_AXES)}",
                         file=file, field="up_axis")
    Vs = V * np.asarray(scale, float)
    size = float((Vs.max(0) - Vs.min(0)).max())
    if not size > 0:
        raise ModelError("the mesh has no extent (all its vertices coincide)", file=file)
    warnings = []
    if units == "auto":
        units, why = infer_units(size)
        if units != "m":
            warnings.append(f"units auto: read as {units} (factor {UNITS[units]:g} m per file "
                            f"unit, {size:.4g} → {size * UNITS[units]:.4g} m across); give "
                            "--units to override")
    else:
        why = f"given ({units})"
    factor = UNITS[units]
    metres = size * factor
    if not PLAUSIBLE_SIZE[0] <= metres <= PLAUSIBLE_SIZE[1]:
        raise ModelError(
            f"the mesh is {metres:.4g} m across in {units} ({size:.4g} file units); allowed: a "
            f"table-top object {1000 * PLAUSIBLE_SIZE[0]:.0f} mm to {PLAUSIBLE_SIZE[1]:.0f} m "
            f"across — give the right units (auto, {', '.join(UNITS)})", file=file, field="units")
    V_m = (Vs * factor) @ UP_AXES[up_axis].T
    return V_m, Placement(units, factor, why, up_axis, metres, tuple(warnings))


def _areas(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]),
                                axis=1)


def boundary_edges(F: np.ndarray) -> np.ndarray:
    """(B, 2) directed edges (as wound in their triangle) that no other triangle shares."""
    E = F[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    key = np.sort(E, axis=1)
    _, inv, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return E[counts[inv.ravel()] == 1]


def repair(V: np.ndarray, F: np.ndarray, *, file: str | None = None) -> RepairedMesh:
    """The mesh (metres) repaired with trimesh; ModelError for a mesh nothing can be made of."""
    repairs = []
    m = trimesh.Trimesh(V, F, process=False)
    n_v = len(m.vertices)
    m.merge_vertices(merge_tex=True, merge_norm=True, digits_vertex=MERGE_DIGITS)
    if len(m.vertices) < n_v:
        repairs.append(f"merged {n_v - len(m.vertices)} duplicate vertices (1 µm)")
    n_f = len(m.faces)
    keep = _areas(m.vertices, m.faces) > MIN_AREA
    m.update_faces(keep)
    if len(m.faces) < n_f:
        repairs.append(f"removed {n_f - len(m.faces)} zero-area triangles")
    n_f = len(m.faces)
    m.update_faces(m.unique_faces())
    if len(m.faces) < n_f:
        repairs.append(f"removed {n_f - len(m.faces)} duplicate triangles")
    m.remove_unreferenced_vertices()
    if len(m.faces) < 4:
        raise ModelError(f"the mesh has {len(m.faces)} usable triangles after removing "
                         "degenerate ones; allowed: a surface mesh", file=file)
    lonely = _isolated_fraction(m)
    if lonely > SOUP_FRACTION:
        raise ModelError(f"{100 * lonely:.0f} % of the triangles share no edge with another (a "
                         "triangle soup, not a surface); allowed: a connected surface mesh",
                         file=file)
    before = _face_normals(m.vertices, m.faces)
    m.faces = consistent_winding(np.asarray(m.faces, np.int64), m.face_adjacency,
                                 m.face_adjacency_edges)
    _orient_outward(m)
    flipped = int((np.einsum("ij,ij->i", before, _face_normals(m.vertices, m.faces)) < 0).sum())
    if flipped:
        repairs.append(f"re-wound {flipped} triangles (consistent with their neighbours, "
                       "outward)")
    n_f = len(m.faces)
    if not m.is_watertight:
        trimesh.repair.fill_holes(m)  # fills triangle and quad holes only: the small ones
        if len(m.faces) > n_f:
            repairs.append(f"filled small holes with {len(m.faces) - n_f} triangles")
    keep = _areas(m.vertices, m.faces) > MIN_AREA
    if not keep.all():
        m.update_faces(keep)
        m.remove_unreferenced_vertices()
    Vr, Fr = np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)
    normals = vertex_normals(Vr, Fr)
    pieces = len(trimesh.graph.connected_components(m.face_adjacency, nodes=np.arange(len(Fr)),
                                                    min_len=1))
    n_boundary = len(boundary_edges(Fr))
    src = cKDTree(V).query(Vr)[1]
    return RepairedMesh(Vr, Fr, normals, np.asarray(src, np.int64), tuple(repairs), pieces,
                        bool(m.is_watertight), n_boundary)


def consistent_winding(F: np.ndarray, adjacency: np.ndarray, shared: np.ndarray) -> np.ndarray:
    """F with triangles flipped so that neighbours traverse their shared edge in opposite
    directions (trimesh.repair.fix_winding's result, vectorised: its per-triangle loop takes
    seconds on a scan). `adjacency` (A, 2) pairs of neighbouring triangles, `shared` (A, 2) the
    vertices of their shared edge (trimesh's face_adjacency, face_adjacency_edges). Each
    connected piece keeps its first triangle's winding; flips propagate along a breadth-first
    spanning tree."""
    if len(adjacency) == 0:
        return F
    def forward(f, u, v):  # whether triangle f goes u → v
        k = np.argmax(F[f] == u[:, None], axis=1)
        return F[f, (k + 1) % 3] == v
    a, b = adjacency[:, 0], adjacency[:, 1]
    u, v = shared[:, 0], shared[:, 1]
    flip_edge = (forward(a, u, v) == forward(b, u, v)).astype(np.int8)  # same way: one flips
    n = len(F)
    g = coo_matrix((np.ones(len(a)), (a, b)), shape=(n, n)).tocsr()
    g = g + g.T
    edge_of = {}
    for i, j, x in zip(a.tolist(), b.tolist(), flip_edge.tolist(), strict=True):
        edge_of[(i, j)] = edge_of[(j, i)] = x
    _, comp = connected_components(g, directed=False)
    flip = np.zeros(n, bool)
    seen = np.zeros(comp.max() + 1, bool)
    for root in range(n):
        if seen[comp[root]]:
            continue
        seen[comp[root]] = True
        order, pred = breadth_first_order(g, root, directed=False)
        for node in order[1:].tolist():
            p = int(pred[node])
            flip[node] = flip[p] ^ bool(edge_of[(p, node)])
    out = F.copy()
    out[flip] = out[flip][:, ::-1]
    return out


def _face_normals(V, F):
    return np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])


def _isolated_fraction(m: trimesh.Trimesh) -> float:
    has_neighbour = np.zeros(len(m.faces), bool)
    adj = m.face_adjacency
    has_neighbour[adj.ravel()] = True
    return float(1.0 - has_neighbour.mean())


def _orient_outward(m: trimesh.Trimesh) -> None:
    """Flips every connected piece whose signed volume (its holes closed by fans,
    `capped_moments`) is negative: its triangles then face outwards."""
    comps = trimesh.graph.connected_components(m.face_adjacency, nodes=np.arange(len(m.faces)),
                                               min_len=1)
    faces = m.faces.copy()
    changed = False
    for c in comps:
        if capped_moments(m.vertices, faces[c])[0] < 0:
            faces[c] = faces[c][:, ::-1]
            changed = True
    if changed:
        m.faces = faces


def vertex_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(V, 3) unit area-weighted vertex normals; a vertex without a triangle of area gets +z."""
    fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])  # length = 2 × area
    acc = np.zeros_like(V)
    for k in range(3):
        np.add.at(acc, F[:, k], fn)
    n = np.linalg.norm(acc, axis=1, keepdims=True)
    out = np.where(n > 0, acc / np.where(n > 0, n, 1.0), np.array([0.0, 0.0, 1.0]))
    return out


def closed_with_caps(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(V', F') the mesh with every hole closed: each boundary loop (a connected set of boundary
    edges) fanned from its vertices' centroid (a vertex appended to V), wound against the
    boundary edges so that the surface with its caps is closed. F' = F followed by the caps. Loops
    of two pieces that meet at a seam give caps that cancel in any surface integral."""
    B = boundary_edges(F)
    if len(B) == 0:
        return V, F
    ids, inv = np.unique(B, return_inverse=True)
    inv = inv.reshape(B.shape)
    n = len(ids)
    g = coo_matrix((np.ones(len(B)), (inv[:, 0], inv[:, 1])), shape=(n, n))
    _, comp = connected_components(g, directed=False)
    counts = np.bincount(comp)
    centre = np.zeros((comp.max() + 1, 3))
    np.add.at(centre, comp, V[ids])
    centre /= counts[:, None]
    caps = np.stack([len(V) + comp[inv[:, 0]], B[:, 1], B[:, 0]], axis=1)
    return np.vstack([V, centre]), np.vstack([F, caps])


def hole_caps(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(C, 3, 3) the triangles `closed_with_caps` adds."""
    V2, F2 = closed_with_caps(V, F)
    return V2[F2[len(F):]]


def capped_moments(V: np.ndarray, F: np.ndarray):
    """(volume [m³], first moment (3,), second moment ∫ x xᵀ dV (3, 3), cap area [m²]) of the
    solid that (V, F) bounds once its holes are closed by `hole_caps` (unit density; the signed
    divergence-theorem sums over tetrahedra from the origin)."""
    T = np.concatenate([V[F], hole_caps(V, F)]) if len(F) else np.zeros((0, 3, 3))
    caps = T[len(F):]
    a, b, c = T[:, 0], T[:, 1], T[:, 2]
    v = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    s = a + b + c
    first = (v[:, None] * s).sum(0) / 4.0
    outer = (np.einsum("ni,nj->nij", a, a) + np.einsum("ni,nj->nij", b, b)
             + np.einsum("ni,nj->nij", c, c) + np.einsum("ni,nj->nij", s, s))
    second = (v[:, None, None] * outer).sum(0) / 20.0
    cap_area = float(0.5 * np.linalg.norm(
        np.cross(caps[:, 1] - caps[:, 0], caps[:, 2] - caps[:, 0]), axis=1).sum())
    return float(v.sum()), first, second, cap_area
