"""Collision geometry of an imported object: a convex decomposition of its mesh.

A 50k-triangle scan as one rigid-hydroelastic mesh makes contact slow (and Drake takes a mesh's
convex hull for point contact anyway); convex pieces declared convex (<drake:declare_convex/>) cost
about what a library object costs. Backends: CoACD (`coacd`, collision-aware, keeps a cup's cavity
open) and V-HACD (`vhacdx`, voxel based, faster). Their parameters live in BACKENDS.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import open3d
import trimesh
import vhacdx

# isort: split
import coacd  # after open3d: open3d fails to load (std::bad_cast) in a process that loaded coacd

from tg_drake.errors import ModelError
from tg_drake.importing.mesh import boundary_edges, closed_with_caps
from tg_drake.objects import obj_text

# Parameters of each backend, in its own units.
BACKENDS: dict[str, dict] = {
    "coacd": {
        "threshold": 0.05,  # concavity allowed per piece, a fraction of the bounding-box diagonal
        "max_convex_hull": 16,  # pieces at most (contact cost grows with them)
        # remeshing to a manifold first (preprocess_mode) is chosen per mesh: "off" when the
        # capped mesh is closed but for OPEN_EDGES of its edges (CoACD's own "auto" remeshes for
        # the two open edges a decimation leaves: 46 s instead of 11 s for a 50k-triangle scan)
        "preprocess_resolution": 30,  # voxels per bounding-box side of that remeshing
        "resolution": 1000,  # surface samples per concavity evaluation
        "mcts_iterations": 30, "mcts_max_depth": 2, "mcts_nodes": 10,  # cutting-plane search
        "decimate": True, "max_ch_vertex": 64,  # vertices per piece at most
        "seed": 0,
    },
    "vhacd": {
        "maxConvexHulls": 16,  # pieces at most
        "resolution": 100_000,  # voxels in the bounding box
        "minimumVolumePercentErrorAllowed": 1.0,  # [%] of the hull volume
        "maxNumVerticesPerCH": 64,  # vertices per piece
    },
}
OPEN_EDGES = 1e-3  # fraction of a closed-enough mesh's edges that may be open (see above)
MIN_PIECE_VOLUME = 1e-9  # [m³] (1 mm³) a smaller piece adds no contact: dropped.
# The decomposition works on the mesh with its holes capped (an open mesh sends CoACD through its
# slow manifold remeshing), decimated to this many triangles (quadric error, open3d): CoACD's time
# grows with the triangle count, and 4000 triangles keep a household object's shape to well
# under a millimetre. The pieces are convex hulls: they cover the decimated surface.
DECOMPOSITION_TRIANGLES = 4000


@dataclass(frozen=True)
class ConvexPiece:
    vertices: np.ndarray  # (n, 3) [m] in O
    faces: np.ndarray  # (m, 3) outward triangles of its convex hull


def decompose(V: np.ndarray, F: np.ndarray, backend: str = "coacd") -> list[ConvexPiece]:
    """Convex pieces covering the mesh (V, F) [m]; ModelError for an unknown backend."""
    if backend not in BACKENDS:
        raise ModelError(f"unknown collision backend {backend!r}; allowed: "
                         f"{', '.join(BACKENDS)}", field="collision")
    params = BACKENDS[backend]
    Vd, Fd = decomposition_input(np.asarray(V, float), np.asarray(F, np.int64))
    if backend == "coacd":
        coacd.set_log_level("error")
        closed = len(boundary_edges(Fd)) <= OPEN_EDGES * 1.5 * len(Fd)  # 1.5 edges a triangle
        raw = coacd.run_coacd(coacd.Mesh(Vd, Fd), preprocess_mode="off" if closed else "on",
                              **params)
    else:
        raw = vhacdx.compute_vhacd(Vd, Fd.astype(np.uint32), **params)
    pieces = []
    for v, _ in raw:
        hull = _hull(np.asarray(v, float))
        if hull is not None:
            pieces.append(hull)
    if not pieces:  # nothing usable (a thin or tiny object): its convex hull
        hull = _hull(np.asarray(V, float))
        if hull is None:
            raise ModelError("no convex collision piece could be made (a flat object)")
        pieces = [hull]
    return pieces


def decomposition_input(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The mesh the decomposition sees: holes capped, at most DECOMPOSITION_TRIANGLES."""
    V, F = closed_with_caps(V, F)
    if len(F) > DECOMPOSITION_TRIANGLES:
        m = open3d.geometry.TriangleMesh(open3d.utility.Vector3dVector(V),
                                         open3d.utility.Vector3iVector(F.astype(np.int32)))
        m = m.simplify_quadric_decimation(DECOMPOSITION_TRIANGLES)
        m.remove_degenerate_triangles()
        m.remove_unreferenced_vertices()
        V, F = closed_with_caps(np.asarray(m.vertices, float),
                                np.asarray(m.triangles, np.int64))  # decimation's own slits
    return V, F


def _hull(points: np.ndarray) -> ConvexPiece | None:
    if len(points) < 4:
        return None
    # a flat piece's hull has no volume: trimesh's centre of mass divides by it (a warning)
    with np.errstate(divide="ignore", invalid="ignore"):
        try:
            h = trimesh.convex.convex_hull(points)
        except Exception:  # noqa: BLE001 - qhull on flat input
            return None
        if not h.is_volume or h.volume < MIN_PIECE_VOLUME:
            return None
    return ConvexPiece(np.asarray(h.vertices, float), np.asarray(h.faces, np.int64))


def piece_obj_text(piece: ConvexPiece, name: str) -> str:
    """Wavefront OBJ of a piece (metres, O; 1 nm: a hull's near-coplanar facets stay convex when
    read back)."""
    return obj_text(piece.vertices, piece.faces, name=name,
                    comment="convex collision piece (metres, object frame O)")


def collision_sdf(uris: list[str], *, mu: float = 1.0) -> str:
    """The SDF <collision> elements of the pieces: declared convex, rigid hydroelastic, friction
    mu (static and dynamic, the shipped library's 1.0)."""
    out = []
    for k, uri in enumerate(uris):
        out.append(f"""      <collision name="collision_{k}">
        <geometry>
          <mesh><uri>{uri}</uri><drake:declare_convex/></mesh>
        </geometry>
        <drake:proximity_properties>
          <drake:rigid_hydroelastic/>
          <drake:mu_dynamic>{mu}</drake:mu_dynamic>
          <drake:mu_static>{mu}</drake:mu_static>
        </drake:proximity_properties>
      </collision>""")
    return "\n".join(out)
