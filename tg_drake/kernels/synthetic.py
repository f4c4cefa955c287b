"""Parametric labelled clouds (cylinders, boxes, mugs, tools) for tests and benchmarks.

Points are spread uniformly over the surface (each primitive gets a share proportional to its
area), normals point outwards, and labels follow the paper's part scheme: containers split into
top / middle / bottom thirds along z, plus a handle; tools are a handle and a usable area.
"""

from __future__ import annotations

import numpy as np

from tg_drake.kernels.graph import LabelledCloud
from tg_drake.types import part_index

TOP, MIDDLE, BOTTOM, HANDLE, USABLE = (part_index(n) for n in
                                       ("top", "middle", "bottom", "handle", "usable_area"))


def _thirds(z: np.ndarray, height: float) -> np.ndarray:
    """Part labels of points on a container of the given height by z (0 at the bottom)."""
    return np.where(z < height / 3, BOTTOM, np.where(z < 2 * height / 3, MIDDLE, TOP))


def _cylinder_side(radius, z0, z1, n, rng):
    phi = rng.uniform(0, 2 * np.pi, n)
    z = rng.uniform(z0, z1, n)
    nrm = np.column_stack([np.cos(phi), np.sin(phi), np.zeros(n)])
    return np.column_stack([radius * nrm[:, :2], z]), nrm


def _disc(radius, z, up, n, rng):
    r = radius * np.sqrt(rng.random(n))
    phi = rng.uniform(0, 2 * np.pi, n)
    p = np.column_stack([r * np.cos(phi), r * np.sin(phi), np.full(n, z)])
    nrm = np.tile([0.0, 0.0, 1.0 if up else -1.0], (n, 1))
    return p, nrm


def _split(n: int, areas) -> list[int]:
    areas = np.asarray(areas, dtype=float)
    counts = np.floor(n * areas / areas.sum()).astype(int)
    counts[0] += n - counts.sum()
    return counts.tolist()


def cylinder(*, radius: float, height: float, n: int, rng: np.random.Generator,
             open_top: bool = False) -> LabelledCloud:
    """A closed (can, bottle-like) or open-topped (glass, bowl-like) cylinder on z = 0."""
    areas = [2 * np.pi * radius * height, np.pi * radius ** 2] + \
        ([] if open_top else [np.pi * radius ** 2])
    counts = _split(n, areas)
    parts = [_cylinder_side(radius, 0.0, height, counts[0], rng),
             _disc(radius, 0.0, False, counts[1], rng)]
    if not open_top:
        parts.append(_disc(radius, height, True, counts[2], rng))
    p = np.concatenate([q for q, _ in parts])
    nrm = np.concatenate([m for _, m in parts])
    return LabelledCloud(p, nrm, _thirds(p[:, 2], height))


def box(*, size, n: int, rng: np.random.Generator) -> LabelledCloud:
    """A closed box with its bottom face on z = 0, size (x, y, z) [m]."""
    sx, sy, sz = size
    areas = np.array([sy * sz, sy * sz, sx * sz, sx * sz, sx * sy, sx * sy])
    face = rng.choice(6, size=n, p=areas / areas.sum())
    u = rng.random((n, 3)) * np.array([sx, sy, sz])
    axis = face // 2
    side = face % 2
    extent = np.array([sx, sy, sz])
    u[np.arange(n), axis] = side * extent[axis]
    nrm = np.zeros((n, 3))
    nrm[np.arange(n), axis] = np.where(side == 1, 1.0, -1.0)
    p = u - np.array([sx / 2, sy / 2, 0.0])
    return LabelledCloud(p, nrm, _thirds(p[:, 2], sz))


def mug(*, radius: float, height: float, n: int, rng: np.random.Generator,
        handle_radius: float = 0.025, tube: float = 0.006) -> LabelledCloud:
    """An open cylinder with a half-torus handle on its +x side, labelled handle."""
    n_handle = max(int(n * 0.15), 8)
    body = cylinder(radius=radius, height=height, n=n - n_handle, rng=rng, open_top=True)
    theta = rng.uniform(-np.pi / 2, np.pi / 2, n_handle)  # half ring outside the body.
    psi = rng.uniform(0, 2 * np.pi, n_handle)
    centre = np.array([radius, 0.0, height / 2])
    ring = np.column_stack([np.cos(theta), np.zeros(n_handle), np.sin(theta)])
    nrm = np.cos(psi)[:, None] * ring + np.sin(psi)[:, None] * np.array([0.0, 1.0, 0.0])
    p = centre + handle_radius * ring + tube * nrm
    return LabelledCloud(np.concatenate([body.points, p]), np.concatenate([body.normals, nrm]),
                         np.concatenate([body.labels, np.full(n_handle, HANDLE)]))


def tool(*, handle_length: float, handle_radius: float, head_size, n: int,
         rng: np.random.Generator) -> LabelledCloud:
    """A lying tool: a cylindrical handle along x and a box head (usable area) beyond it."""
    hx, hy, hz = head_size
    a_handle = 2 * np.pi * handle_radius * handle_length
    a_head = 2 * (hx * hy + hy * hz + hx * hz)
    n_handle, n_head = _split(n, [a_handle, a_head])
    side, nrm = _cylinder_side(handle_radius, 0.0, handle_length, n_handle, rng)
    # The cylinder's axis is z; lay it along x.
    handle_p = side[:, [2, 1, 0]] * np.array([1.0, 1.0, -1.0])
    handle_n = nrm[:, [2, 1, 0]] * np.array([1.0, 1.0, -1.0])
    head = box(size=head_size, n=n_head, rng=rng)
    head_p = head.points + np.array([handle_length + hx / 2, 0.0, -hz / 2])
    return LabelledCloud(np.concatenate([handle_p, head_p]),
                         np.concatenate([handle_n, head.normals]),
                         np.concatenate([np.full(n_handle, HANDLE), np.full(n_head, USABLE)]))
