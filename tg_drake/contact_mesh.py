"""The contact geometry of a generated object: its mesh with as few triangles as keep its shape.

Hydroelastic contact between a rigid mesh and a compliant body (the table top, the finger pads)
costs per triangle of the mesh inside the compliant body: a can's rounded rim resting on the table
crosses hundreds of them, and that contact, not the arm, is most of a simulation step (measured
with the station: 0.2 ms per 5 ms step without an object, 1.9 ms with a can standing on the table).
The visual mesh keeps every triangle (the renderer and the perception see it); the collision mesh is
the same surface decimated (open3d's quadric decimation) to the fewest triangles whose surface
stays within `CONTACT_TOLERANCE` of the visual one, both ways.
"""

from __future__ import annotations

import numpy as np
import open3d
import trimesh

# [m] the largest distance allowed between the collision surface and the visual one (either way):
# half a millimetre, a quarter of the thinnest blade the libraries hold (2 mm) and under the depth
# sensor's error at the table (the D415 model: z²·0.08 px / (f·b), about 2 mm RMS at 1 m, output in
# 1 mm steps), so neither a grasp nor a resting pose moves by more than the camera can tell.
# Measured with it: docs/design.md, "Simulation settings".
CONTACT_TOLERANCE = 0.5e-3
SAMPLES = 20_000  # surface points per side of the two-sided distance estimate (seeded).
MIN_TRIANGLES = 16  # the decimation's search starts here.


def surface_distance(V_a, F_a, V_b, F_b, *, samples: int = SAMPLES, seed: int = 0) -> float:
    """[m] an estimate of the two-sided Hausdorff distance between two triangle surfaces: the
    largest distance from any of `samples` area-uniform points (and every vertex) of either
    surface to the other one."""
    largest = 0.0
    for (V1, F1), (V2, F2) in (((V_a, F_a), (V_b, F_b)), ((V_b, F_b), (V_a, F_a))):
        points, _ = trimesh.sample.sample_surface(trimesh.Trimesh(V1, F1, process=False),
                                                  samples, seed=seed)
        scene = open3d.t.geometry.RaycastingScene()
        scene.add_triangles(open3d.core.Tensor(np.asarray(V2, np.float32)),
                            open3d.core.Tensor(np.asarray(F2, np.uint32)))
        query = open3d.core.Tensor(np.vstack([points, V1]).astype(np.float32))
        largest = max(largest, float(scene.compute_distance(query).numpy().max()))
    return largest


def contact_mesh(V: np.ndarray, F: np.ndarray, *, tolerance: float = CONTACT_TOLERANCE
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3) [m], triangles (m, 3)): the fewest-triangle quadric decimation of the
    mesh (V, F) found by bisection on the target count (to 2 % of it) whose surface lies within
    `tolerance` [m] of the mesh's (`surface_distance`); the mesh itself when no decimation does.
    Deterministic: the same mesh gives the same result."""
    source = open3d.geometry.TriangleMesh(open3d.utility.Vector3dVector(np.array(V, float)),
                                          open3d.utility.Vector3iVector(np.array(F, np.int32)))
    best = (np.asarray(V, float), np.asarray(F, np.int64))
    low, high = MIN_TRIANGLES, len(F)  # `high` triangles always fit (the mesh itself)
    while high - low > max(8, high // 50):
        middle = (low + high) // 2
        decimated = source.simplify_quadric_decimation(middle)
        decimated.remove_degenerate_triangles()
        decimated.remove_unreferenced_vertices()
        V_d, F_d = np.asarray(decimated.vertices), np.asarray(decimated.triangles, np.int64)
        if len(F_d) and surface_distance(V, F, V_d, F_d) <= tolerance:
            high, best = middle, (V_d, F_d)
        else:
            low = middle
    return best
