"""Pictures of perceived objects: the completed cloud coloured by part, as in the paper's Fig. 4.

Observed points are drawn solid, completed (mirrored) ones lighter; the colours are the paper's
(`tg_drake.types.PART_COLORS`: top yellow, middle blue, bottom red, handle green, usable area
magenta). Matplotlib with the Agg backend: no display needed.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

from tg_drake.types import PART_COLORS, PART_LABELS, ObjectDescription  # noqa: E402

# At most this many points are drawn per object (a random subset beyond): the picture stays light.
MAX_POINTS = 6000


def _subset(n: int, seed: int) -> np.ndarray:
    if n <= MAX_POINTS:
        return np.arange(n)
    return np.sort(np.random.default_rng(seed).choice(n, MAX_POINTS, replace=False))


def draw_object(ax, o: ObjectDescription, *, elev: float = 25.0, azim: float = -60.0,
                seed: int = 0) -> None:
    """Draws one object's part-coloured completed cloud on a 3D axis, in the object frame O
    (`seed` picks the subset drawn of a cloud larger than MAX_POINTS)."""
    idx = _subset(len(o.p_W), seed)
    p_O = (o.p_W[idx] - o.X_WO[:3, 3]) @ o.X_WO[:3, :3]
    colours = np.asarray(PART_COLORS)[o.labels[idx]]
    alpha = np.where(o.visible[idx], 1.0, 0.25)
    rgba = np.column_stack([colours, alpha])
    ax.scatter(p_O[:, 0], p_O[:, 1], p_O[:, 2], c=rgba, s=2, depthshade=False, linewidths=0)
    half = 0.5 * float(np.max(o.extents))
    for set_lim in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        set_lim(-half, half)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=elev, azim=azim)
    ax.set_xlabel("x_O [m]")
    ax.set_ylabel("y_O [m]")
    ax.set_zlabel("z_O [m]")
    parts = ", ".join(f"{k} {v:.2f}" for k, v in o.part_probabilities.items())
    ax.set_title(f"{o.name or 'object'}: {o.pose} ({o.pose_likelihood[o.pose]:.2f})\n{parts}",
                 fontsize=8)


def save_object_png(o: ObjectDescription, path: str | Path, *, dpi: int = 120,
                    seed: int = 0) -> Path:
    """Writes a PNG of one object's completed, part-coloured cloud (two views) and returns its
    path (`seed`: see `draw_object`)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig = plt.figure(figsize=(8, 4))
    for i, (elev, azim) in enumerate(((25.0, -60.0), (25.0, 120.0))):
        draw_object(fig.add_subplot(1, 2, i + 1, projection="3d"), o, elev=elev, azim=azim,
                    seed=seed)
    present = sorted(set(np.unique(o.labels)))
    fig.legend(handles=[Patch(color=PART_COLORS[i], label=PART_LABELS[i]) for i in present],
               loc="lower center", ncol=len(present), fontsize=8)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def save_scene_png(objects: list[ObjectDescription], path: str | Path, *, dpi: int = 120,
                   seed: int = 0) -> Path:
    """Writes a PNG with one panel per object of a scene description and returns its path
    (`seed`: see `draw_object`)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    n = max(1, len(objects))
    fig = plt.figure(figsize=(4 * n, 4))
    for i, o in enumerate(objects):
        draw_object(fig.add_subplot(1, n, i + 1, projection="3d"), o, seed=seed)
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
