"""The support hull: a convex hull with fewer faces, the only geometry of an object that touches
the table.

An object at rest on a flat table, or sliding on it, touches it only where its convex hull does,
so the table needs nothing of the mesh but its hull. The hydroelastic contact between a rigid
mesh and the compliant table costs per triangle of the mesh inside the table's volume, and SAP
solves one contact point per polygon: a library can standing on the table made 272 contact
polygons with its 2,160-triangle mesh. The station gives every object both geometries, the mesh
against everything but the table and its surfaces, the support hull against those only
(tg_drake.station); the fingers, the contents and other objects still meet the mesh.

`support_hull` decimates the mesh's convex hull (quadric decimation, Open3D) to the fewest
faces of `FACE_COUNTS` whose hull stays within `tolerance` of the full hull both ways (each
full-hull vertex outside it, each of its vertices outside the full hull, measured to the other's
face planes), else keeps the full hull.
"""

from __future__ import annotations

import numpy as np
import open3d as o3d
from scipy.spatial import ConvexHull

# [m] the support hull's largest departure from the convex hull: a lying object may rest up to
# this much lower than on its mesh (the perceived points are trusted to 2 mm as well).
SUPPORT_TOLERANCE = 0.002
FACE_COUNTS = (32, 48, 64, 96, 128, 192, 256)  # [1] decimation targets, tried in order


def _outside(points: np.ndarray, hull: ConvexHull) -> float:
    """[m] how far the farthest of `points` lies outside `hull`'s face planes (0 if none)."""
    planes = hull.equations  # (F, 4): unit outward normal, offset; n·p + offset > 0 outside
    s = points @ planes[:, :3].T + planes[:, 3]
    return float(max(0.0, s.max(axis=1).max()))


def support_hull(vertices: np.ndarray, *, tolerance: float = SUPPORT_TOLERANCE) -> np.ndarray:
    """(N, 3) points whose convex hull is the support hull of a mesh with `vertices` (M, 3) [m]:
    its convex hull decimated to the fewest faces of `FACE_COUNTS` within `tolerance` [m] of the
    full hull, or the full hull's vertices when no decimation is within it (or the hull has no
    more faces than the target)."""
    V = np.asarray(vertices, float).reshape(-1, 3)
    full = ConvexHull(V)
    V_full = V[full.vertices]
    index = np.full(len(V), -1)
    index[full.vertices] = np.arange(len(full.vertices))
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(V_full),
                                     o3d.utility.Vector3iVector(index[full.simplices]))
    for faces in FACE_COUNTS:
        if faces >= len(full.simplices):
            break
        P = np.asarray(mesh.simplify_quadric_decimation(faces)
                       .remove_unreferenced_vertices().vertices)
        if len(P) < 4:
            continue
        try:
            coarse = ConvexHull(P)
        except Exception:  # noqa: BLE001 — a flat decimation (qhull refuses it): more faces
            continue
        if max(_outside(V_full, coarse), _outside(P, full)) <= tolerance:
            return P[coarse.vertices]
    return V_full
