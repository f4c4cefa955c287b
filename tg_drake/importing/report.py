"""What an import decided, as one screen of text and a picture of the object in each resting pose.

The pictures colour the parts as every other picture of the project does
(tg_drake.types.PART_COLORS, the paper's Fig. 4) and draw the object's vertices in the table frame
T on the table plane.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tg_drake.importing.collision import ConvexPiece
from tg_drake.importing.mass import MassProperties
from tg_drake.importing.mesh import Placement, RepairedMesh
from tg_drake.importing.poses import StablePose
from tg_drake.importing.source import Source
from tg_drake.types import PART_COLORS, PART_LABELS

MAX_PICTURES = 8  # the most probable resting poses drawn
PICTURE_POINTS = 6000  # vertices drawn per picture (a random subset of a large mesh)


@dataclass(frozen=True)
class Decisions:
    """Everything one import decided (for the report and the pictures)."""

    obj_id: str
    category: str | None
    source: Source
    n_input_vertices: int
    n_input_triangles: int
    n_geometries: int
    placement: Placement
    mesh: RepairedMesh  # in the input's axes (metres, z up)
    vertices_O: np.ndarray  # (V, 3) [m] the repaired mesh in O
    labels: np.ndarray  # (V,) uint8 part label per vertex
    labels_source: str  # "derived" | "given"
    frame_kind: str
    frame_notes: tuple[str, ...]
    mass: MassProperties  # in O
    poses: tuple[StablePose, ...]
    pieces: tuple[ConvexPiece, ...]
    backend: str
    seconds: dict  # stage → wall time [s]


def text(d: Decisions, warnings: tuple[str, ...]) -> str:
    """The one-screen report."""
    m, pl, mp = d.mesh, d.placement, d.mass
    ext = d.vertices_O.max(0) - d.vertices_O.min(0)
    lines = [
        f"{d.obj_id}: {d.category or 'no category'} ({d.frame_kind}) from "
        f"{d.source.given} [{d.source.kind}: {d.source.mesh_file.name}]",
        f"  mesh      {d.n_input_vertices} vertices, {d.n_input_triangles} triangles"
        + (f" in {d.n_geometries} meshes" if d.n_geometries > 1 else "")
        + f" → {len(m.vertices)} vertices, {len(m.faces)} triangles",
        f"  scale     {pl.units} (×{pl.factor:g}"
        + (f", model scale {' '.join(f'{s:g}' for s in d.source.scale)}"
           if d.source.scale != (1.0, 1.0, 1.0) else "")
        + f"): {pl.why}",
        f"  up axis   {pl.up_axis} → z;  size {' × '.join(f'{100 * e:.1f}' for e in ext)} cm "
        "(x × y × z in O)",
        f"  repairs   {'; '.join(m.repairs) or 'none needed'}",
        f"  pieces    {m.n_pieces} connected piece{'s' if m.n_pieces != 1 else ''}, "
        + ("closed" if m.watertight else f"open ({m.n_boundary_edges} boundary edges)"),
        f"  frame     {'; '.join(d.frame_notes) or '-'}",
        f"  labels    {d.labels_source}: " + ", ".join(
            f"{p} {int((d.labels == k).sum())}" for k, p in enumerate(PART_LABELS)
            if (d.labels == k).any()),
        f"  mass      {mp.mass:.4g} kg ({mp.why}); solid: {mp.solid}, {1e6 * mp.volume:.1f} cm³,"
        f" {mp.density:.0f} kg/m³",
        f"  COM       [{', '.join(f'{1000 * c:.1f}' for c in mp.com)}] mm in O",
        "  inertia   about the COM [kg·m²]: "
        + ", ".join(f"{n} {mp.inertia[i, j]:.3e}" for n, (i, j) in
                    zip(("ixx", "iyy", "izz", "ixy", "ixz", "iyz"),
                        ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)), strict=True)),
        f"  poses     {len(d.poses)} stable resting poses (trimesh), most probable first:",
    ]
    for k, s in enumerate(d.poses[:MAX_PICTURES]):
        r = s.resting
        deg = ", ".join(str(round(float(np.degrees(a)))) for a in r.rpy)  # no "-0"
        lines.append(f"    {k}: {s.name or '-':10s} p={s.probability:.2f}  "
                     f"z={1000 * r.xyz[2]:.1f} mm  rpy=[{deg}]°  support "
                     f"margin {1000 * r.support_margin:.1f} mm")
    if len(d.poses) > MAX_PICTURES:
        lines.append(f"    ... {len(d.poses) - MAX_PICTURES} less probable ones")
    n_v = sum(len(p.vertices) for p in d.pieces)
    lines.append(f"  collision {len(d.pieces)} convex pieces ({d.backend}, {n_v} vertices), "
                 "declared convex, rigid hydroelastic")
    lines.append("  time      " + ", ".join(f"{k} {v:.1f} s" for k, v in d.seconds.items()))
    for w in warnings:
        lines.append(f"  warning   {w}")
    return "\n".join(lines)


def pictures(d: Decisions, folder: Path, *, seed: int = 0) -> tuple[Path, ...]:
    """A PNG of the object resting in each of its most probable poses, parts coloured."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    idx = np.random.default_rng(seed).permutation(len(d.vertices_O))[:PICTURE_POINTS]
    colours = np.asarray(PART_COLORS)[d.labels[idx]]
    paths = []
    for k, s in enumerate(d.poses[:MAX_PICTURES]):
        X = s.resting.X_TO
        p_T = d.vertices_O[idx] @ X[:3, :3].T + X[:3, 3]
        fig = plt.figure(figsize=(4, 4))
        ax = fig.add_subplot(projection="3d")
        ax.scatter(*p_T.T, c=colours, s=2, depthshade=False, linewidths=0)
        half = 0.5 * float(np.ptp(p_T, axis=0).max()) * 1.1
        c = 0.5 * (p_T.min(0) + p_T.max(0))
        g = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]]) * half
        ax.plot(c[0] + g[:, 0], c[1] + g[:, 1], 0 * g[:, 0], color="0.6", linewidth=0.8)
        ax.set_xlim(c[0] - half, c[0] + half)
        ax.set_ylim(c[1] - half, c[1] + half)
        ax.set_zlim(0, 2 * half)
        ax.set_box_aspect((1, 1, 1))
        ax.set_xlabel("x_T [m]")
        ax.set_ylabel("y_T [m]")
        ax.set_zlabel("z_T [m]")
        ax.set_title(f"{d.obj_id}: pose {k} {s.name or '(unnamed)'}, p = {s.probability:.2f}",
                     fontsize=8)
        fig.tight_layout()
        path = folder / f"{d.obj_id}_pose_{k}{'_' + s.name if s.name else ''}.png"
        fig.savefig(path, dpi=100)
        plt.close(fig)
        paths.append(path)
    return tuple(paths)
