"""Synthetic objects and depth images with known answers, for tests, benchmarks and evaluation.

Meshes are Open3D triangle meshes in an object frame whose origin is on the table under the
object (z up). Depth images are ray cast with Open3D's RaycastingScene through Drake's pinhole
model (`Intrinsics`, camera frame X right, Y down, Z forward), +inf where no ray hits, as Drake's
renderer reports no return.
"""

from __future__ import annotations

import numpy as np
import open3d as o3d

from tg_drake.perception.geometry import Intrinsics, frame_from_z, make_transform, rotate, transform


def lathe(profile: np.ndarray, segments: int = 64) -> o3d.geometry.TriangleMesh:
    """Surface of revolution about z of a polyline profile of (r, z) rows [m]."""
    profile = np.asarray(profile, float)
    k = len(profile)
    phi = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    r, z = profile[:, 0], profile[:, 1]
    vertices = np.stack([np.outer(np.cos(phi), r), np.outer(np.sin(phi), r),
                         np.tile(z, (segments, 1))], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(segments), np.arange(k - 1), indexing="ij")
    i, j = i.ravel(), j.ravel()
    i1 = (i + 1) % segments
    a, b, c, d = i * k + j, i1 * k + j, i1 * k + j + 1, i * k + j + 1
    triangles = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(vertices),
                                     o3d.utility.Vector3iVector(triangles))
    mesh.compute_triangle_normals()
    return mesh


def cylinder(radius: float, height: float) -> o3d.geometry.TriangleMesh:
    """A closed cylinder (a can) standing on the table."""
    return lathe([[0, 0], [radius, 0], [radius, height], [0, height]])


def cup(radius: float, height: float, wall: float = 0.004, base: float = 0.006
        ) -> o3d.geometry.TriangleMesh:
    """An open cylindrical cup (or glass), opening up."""
    return lathe([[0, 0], [radius, 0], [radius, height], [radius - wall, height],
                  [radius - wall, base], [0, base]])


def glass(bottom_radius: float, top_radius: float, height: float, wall: float = 0.003
          ) -> o3d.geometry.TriangleMesh:
    """An open tapered glass (or a bowl, when wide and low), opening up."""
    return lathe([[0, 0], [bottom_radius, 0], [top_radius, height], [top_radius - wall, height],
                  [bottom_radius - wall, wall], [0, wall]])


def upside_down(mesh: o3d.geometry.TriangleMesh, height: float) -> o3d.geometry.TriangleMesh:
    """A standing mesh of the given height turned upside down (about x) onto the table."""
    return placed(mesh, make_transform(np.diag([1.0, -1.0, -1.0]), [0.0, 0.0, height]))


def bottle(radius: float, height: float, neck_radius: float) -> o3d.geometry.TriangleMesh:
    """A closed bottle: body, shoulder and neck."""
    return lathe([[0, 0], [radius, 0], [radius, 0.6 * height], [neck_radius, 0.8 * height],
                  [neck_radius, height], [0, height]])


def mug(radius: float, height: float, handle_reach: float = 0.03, handle_thickness: float = 0.012
        ) -> o3d.geometry.TriangleMesh:
    """An open cup with a ring handle on its +x side."""
    body = cup(radius, height)
    ring = 0.5 * (0.6 * height)  # the handle spans the middle 60 % of the height.
    handle = o3d.geometry.TriangleMesh.create_torus(
        torus_radius=max(ring, handle_reach - 0.5 * handle_thickness),
        tube_radius=0.5 * handle_thickness, radial_resolution=40, tubular_resolution=12)
    # Torus ring in the xz-plane, centred so that it reaches handle_reach beyond the wall.
    R = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])
    handle.rotate(R, center=(0, 0, 0))
    ring_r = max(ring, handle_reach - 0.5 * handle_thickness)
    handle.translate((radius + handle_reach - 0.5 * handle_thickness - ring_r, 0, 0.5 * height))
    # Keep only the half outside the cup.
    keep = np.asarray(handle.vertices)[:, 0] >= radius - 0.002
    handle.remove_vertices_by_mask(~keep)
    return body + handle


def box(size: tuple[float, float, float]) -> o3d.geometry.TriangleMesh:
    """A box standing on the table, centred on the origin in x and y."""
    mesh = o3d.geometry.TriangleMesh.create_box(*size)
    mesh.translate((-0.5 * size[0], -0.5 * size[1], 0.0))
    return mesh


def hammer(handle_length: float = 0.28, handle_radius: float = 0.012,
           head_length: float = 0.1, head_width: float = 0.03, head_height: float = 0.03
           ) -> o3d.geometry.TriangleMesh:
    """A hammer lying on the table: handle along +x from the origin, head across it at the end."""
    handle = o3d.geometry.TriangleMesh.create_cylinder(handle_radius, handle_length, 32, 4)
    handle.rotate(np.array([[0, 0, 1.0], [0, 1.0, 0], [-1.0, 0, 0]]), center=(0, 0, 0))
    handle.translate((0.5 * handle_length, 0.0, handle_radius))
    head = o3d.geometry.TriangleMesh.create_box(head_width, head_length, head_height)
    head.translate((handle_length - head_width, -0.5 * head_length,
                    handle_radius - 0.5 * head_height if head_height < 2 * handle_radius
                    else 0.0))
    return handle + head


def pan(radius: float = 0.12, height: float = 0.05, handle_length: float = 0.18
        ) -> o3d.geometry.TriangleMesh:
    """A shallow open pan with a flat handle on its +x side, at rim height."""
    body = cup(radius, height, wall=0.004, base=0.005)
    handle = o3d.geometry.TriangleMesh.create_box(handle_length, 0.03, 0.012)
    handle.translate((radius - 0.005, -0.015, height - 0.014))
    return body + handle


def lying(mesh: o3d.geometry.TriangleMesh, radius: float, roll: float = np.pi / 2
          ) -> o3d.geometry.TriangleMesh:
    """A standing round mesh laid on its side, its side on the table: its axis (z) along world
    +x; its x axis (a mug's handle) turned to (0, cos roll, sin roll), so roll = π/2 is up."""
    R = np.column_stack([[0.0, np.cos(roll), np.sin(roll)], [0.0, -np.sin(roll), np.cos(roll)],
                         [1.0, 0.0, 0.0]])
    out = o3d.geometry.TriangleMesh(mesh)
    out.rotate(R, center=(0, 0, 0))
    out.translate((0, 0, radius))
    return out


def placed(mesh: o3d.geometry.TriangleMesh, X_WO: np.ndarray) -> o3d.geometry.TriangleMesh:
    """A copy of a mesh moved to pose X_WO."""
    out = o3d.geometry.TriangleMesh(mesh)
    out.transform(X_WO)
    return out


def look_at(p_WE: np.ndarray, p_WT: np.ndarray) -> np.ndarray:
    """Camera pose X_WC at eye p_WE looking at target p_WT (Drake: Z forward, Y down, X right;
    the image's up is world +z)."""
    z = np.asarray(p_WT, float) - np.asarray(p_WE, float)
    z = z / np.linalg.norm(z)
    R = frame_from_z(z, np.cross(z, [0.0, 0.0, 1.0]) if abs(z[2]) < 0.999 else [1.0, 0, 0])
    # frame_from_z gives (x, y = z × x, z); x = z × up points right, so y points down.
    return make_transform(R, p_WE)


def render_depth(meshes: list[o3d.geometry.TriangleMesh], intrinsics: Intrinsics,
                 X_WC: np.ndarray) -> np.ndarray:
    """(H, W) float32 depth image [m] of world-frame meshes; +inf where no ray hits."""
    scene = o3d.t.geometry.RaycastingScene()
    for mesh in meshes:
        scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    d_C = intrinsics.ray_directions_C().reshape(-1, 3)
    d_W = rotate(X_WC, d_C)
    origin = np.broadcast_to(X_WC[:3, 3], d_W.shape)
    rays = o3d.core.Tensor(np.hstack([origin, d_W]).astype(np.float32))
    t = scene.cast_rays(rays)["t_hit"].numpy()  # in units of |d|: d has unit z in C → depth.
    return t.reshape(intrinsics.height, intrinsics.width).astype(np.float32)


def table_mesh(size: tuple[float, float] = (1.2, 0.9), thickness: float = 0.03
               ) -> o3d.geometry.TriangleMesh:
    """A table top whose upper surface is the plane z = 0, centred on the origin."""
    mesh = o3d.geometry.TriangleMesh.create_box(size[0], size[1], thickness)
    mesh.translate((-0.5 * size[0], -0.5 * size[1], -thickness))
    return mesh


# ---- point clouds sampled with numpy (analytic surfaces) ----

def cylinder_points(radius: float, height: float, n: int, rng: np.random.Generator
                    ) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) points and outward normals uniformly on a closed cylinder standing at the origin."""
    side = 2 * np.pi * radius * height
    cap = np.pi * radius ** 2
    u = rng.uniform(0, side + 2 * cap, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    rr = radius * np.sqrt(rng.uniform(0, 1, n))
    on_side = u < side
    on_top = (u >= side) & (u < side + cap)
    r = np.where(on_side, radius, rr)
    z = np.where(on_side, rng.uniform(0, height, n), np.where(on_top, height, 0.0))
    p = np.column_stack([r * np.cos(phi), r * np.sin(phi), z])
    normal = np.where(on_side[:, None], np.column_stack([np.cos(phi), np.sin(phi), 0 * phi]),
                      np.where(on_top[:, None], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]))
    return p, normal


def box_points(size: tuple[float, float, float], n: int, rng: np.random.Generator
               ) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) points and outward normals uniformly on a box standing centred at the origin."""
    sx, sy, sz = size
    areas = np.array([sy * sz, sy * sz, sx * sz, sx * sz, sx * sy, sx * sy])
    face = rng.choice(6, n, p=areas / areas.sum())
    u = rng.uniform(-0.5, 0.5, (n, 3)) * np.array(size)
    axis = face // 2
    sign = np.where(face % 2 == 0, 1.0, -1.0)
    u[np.arange(n), axis] = sign * 0.5 * np.array(size)[axis]
    normal = np.zeros((n, 3))
    normal[np.arange(n), axis] = sign
    return u + np.array([0.0, 0.0, 0.5 * sz]), normal


def facing(p: np.ndarray, normal: np.ndarray, p_eye: np.ndarray) -> np.ndarray:
    """(N,) bool: the surface faces the eye (back-face culling; exact for convex shapes)."""
    return np.einsum("ij,ij->i", normal, p_eye - p) > 0


def partial_view(p_O: np.ndarray, n_O: np.ndarray, X_WO: np.ndarray, p_WE: np.ndarray,
                 noise: float, rng: np.random.Generator) -> np.ndarray:
    """World-frame points of an object that face the eye, with Gaussian noise (std `noise` [m])."""
    p_W, n_W = transform(X_WO, p_O), rotate(X_WO, n_O)
    seen = facing(p_W, n_W, p_WE)
    return p_W[seen] + rng.normal(0.0, noise, (int(seen.sum()), 3))
