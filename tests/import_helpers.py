"""Test meshes for the import tests, made here from the shipped library (never third-party ones):
a library object's mesh as a scan would come — in mm, y up, some triangles flipped, zero-area
triangles added, optionally holes cut."""

from __future__ import annotations

import numpy as np

from tg_drake.objects import mesh

# file coordinates of a y-up mesh: (x, z, -y) of the object's; "y" up turns them back.
Y_UP = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])


def scan_like(obj_id: str, *, holes: int = 0, seed: int = 0):
    """(vertices [mm], faces) of the library object `obj_id` in mm, y up, every 7th triangle
    flipped, three zero-area triangles added (a repeated vertex, a collinear one, a sliver), and
    `holes` triangles removed (each with its neighbours, a small hole)."""
    V, F, _ = mesh(obj_id)
    V = 1000.0 * np.asarray(V) @ Y_UP.T
    F = np.array(F)
    rng = np.random.default_rng(seed)
    if holes:
        drop = set()
        for f in rng.choice(len(F), holes, replace=False):
            drop |= set(np.flatnonzero(np.isin(F, F[f]).any(axis=1)).tolist())
        F = F[np.setdiff1d(np.arange(len(F)), list(drop))]
    F[::7] = F[::7, ::-1]
    a, b = F[0, 0], F[0, 1]
    mid = len(V)
    V = np.vstack([V, 0.5 * (V[a] + V[b])])  # a vertex on the edge a-b: a collinear triangle
    F = np.vstack([F, [[a, a, b], [a, mid, b], [b, b, b]]])
    return V, F


def write_obj(path, V, F) -> None:
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in V.tolist()]
    lines += [f"f {a} {b} {c}" for a, b, c in (np.asarray(F) + 1).tolist()]
    path.write_text("\n".join(lines) + "\n")


def read_obj(path):
    """(V, F) from the `v` and `f` lines, as tg_drake.objects.mesh reads them."""
    lines = path.read_text().splitlines()
    V = np.array([ln.split()[1:4] for ln in lines if ln.startswith("v ")], float)
    F = np.array([[t.split("/")[0] for t in ln.split()[1:4]] for ln in lines
                  if ln.startswith("f ")], np.int64) - 1
    return V, F
