"""Semantic parts of a completed object (paper section III-B).

Two kinds of object, as in the paper:

- **Tools** have a *handle* and a *usable area*. A tool's symmetry axis is parallel to the table
  and its visible cross-section is thin (both its sides below `tool_max_thickness`) over a good
  part of its length (`tool_thin_fraction`): the handle of a hammer or a ladle, all of a knife; a
  bottle lying down is thin only at its neck. We split the axis where the cross-section changes
  most: the two-segment piecewise-constant fit of the cross-section's width and height along the
  axis with the least squared error. The usable area is the flatter segment (a hammer's head, a
  knife's blade, a spatula's blade: their cross-section is much wider than thick); when both
  segments are about as flat, the thicker one is the handle (a screwdriver's grip). Both
  probabilities are 0.5 + 0.5·(share of the profile's variance the split explains): a clear
  change of cross-section is a sure split. A round body with a handle longer than
  `tool_handle_ratio` times its diameter is a long-handled tool lying on its head (a ladle on its
  bowl): the body is its usable area; the circle test's confidence is both parts' probability.
- **Other objects**: points outside the fitted circle are the *handle* (paper: "a circle fitted
  in the projected points W with a large confidence; the points lying outside of the circle are
  labeled as handle"); the rest is divided along the axis into *bottom*, *middle* and *top* (the
  top end given by the pose cue). A part's probability is the share of its length along the axis
  covered by visible points (a part seen end to end is sure; one seen only through the symmetry
  completion is not). The handle's probability is the circle test's confidence, lowered when the
  handle has few visible points.

The object frame O has its origin at the completed cloud's box centroid, z along the symmetry
axis towards the top (for a tool: from the handle to the usable area), x towards the handle when
there is one, else along the first box direction (upright) or up (lying).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tg_drake.perception.completion import Completion
from tg_drake.perception.config import PartConfig
from tg_drake.types import PART_LABELS

TOP, MIDDLE, BOTTOM, HANDLE, USABLE = (PART_LABELS.index(p) for p in
                                       ("top", "middle", "bottom", "handle", "usable_area"))
# Two tool segments count as equally flat when their width/height ratios are within this factor.
EQUAL_FLATNESS = 1.5
# A handle seen with this many points (of 4 mm voxels: a 3 cm × 1.5 cm strip) is fully supported;
# fewer points lower its probability towards half the circle test's confidence.
HANDLE_SUPPORT_POINTS = 30


@dataclass
class Parts:
    labels: np.ndarray  # (N,) int part labels, indices into PART_LABELS.
    probabilities: dict[str, float]  # detected part → probability.
    is_tool: bool
    R_TO: np.ndarray  # 3×3 object frame axes in T (columns x, y, z).
    p_TO: np.ndarray  # (3,) object frame origin (box centroid) in T [m].
    extents: np.ndarray  # (3,) full box sides along O's axes [m].
    boxes: dict[str, tuple[np.ndarray, np.ndarray]]  # part → (centre in T, half extents in O).


def _long_handle(c: Completion, cfg: PartConfig) -> bool:
    """A vertical body with a handle longer than `tool_handle_ratio` body diameters: a ladle
    lying on its bowl. (A pan's handle is about as long as the pan is wide.)"""
    if not c.vertical or c.circle is None or not c.handle.any():
        return False
    d = c.p_T[c.handle] - c.p_TA
    reach = np.linalg.norm(d - np.outer(d @ c.axis_T, c.axis_T), axis=1).max() - c.circle.radius
    return reach > cfg.tool_handle_ratio * 2 * c.circle.radius


def _object_frame(c: Completion, top_sign: float, long_handle: bool = False) -> np.ndarray:
    if long_handle:  # z from the handle to the head (the body), x up.
        z = -c.handle_direction_T / np.linalg.norm(c.handle_direction_T)
        x = np.array([0.0, 0.0, 1.0])
        return np.column_stack([x, np.cross(z, x), z])
    z = top_sign * c.axis_T
    if np.linalg.norm(c.handle_direction_T) > 0:
        x = c.handle_direction_T - (c.handle_direction_T @ z) * z
    elif c.vertical:
        x = c.R_TB[:, 0].copy()
    else:  # up, made orthogonal to a tilted axis
        x = np.array([0.0, 0.0, 1.0]) - z[2] * z
    x = x / np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _best_split(f: np.ndarray) -> tuple[int, float]:
    """Two-segment piecewise-constant fit of rows of f: (first index of the second segment,
    share of the total squared deviation the split explains)."""
    n = len(f)
    csum = np.cumsum(f, axis=0)
    csq = np.cumsum((f ** 2).sum(axis=1))
    k = np.arange(1, n)  # left segment = rows [0, k)
    left = csq[k - 1] - (csum[k - 1] ** 2).sum(axis=1) / k
    right_sum = csum[-1] - csum[k - 1]
    right = (csq[-1] - csq[k - 1]) - (right_sum ** 2).sum(axis=1) / (n - k)
    sse = left + right
    total = csq[-1] - (csum[-1] ** 2).sum() / n
    best = int(np.argmin(sse))
    explained = 1.0 - sse[best] / total if total > 0 else 0.0
    return int(k[best]), float(np.clip(explained, 0.0, 1.0))


def _tool_profile(q: np.ndarray, bins: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cross-section width (along x) and height (along y) per bin of z for points q in O.

    Returns the bin edges, the occupied bins' indices and their (B, 2) extents.
    """
    s = q[:, 2]
    edges = np.linspace(s.min(), s.max(), bins + 1)
    k = np.clip(np.searchsorted(edges, s, side="right") - 1, 0, bins - 1)
    hi = np.full((bins, 2), -np.inf)
    lo = np.full((bins, 2), np.inf)
    np.maximum.at(hi, k, q[:, :2])
    np.minimum.at(lo, k, q[:, :2])
    occupied = np.flatnonzero(np.isfinite(hi[:, 0]))
    return edges, occupied, (hi - lo)[occupied]


def _coverage(s_visible: np.ndarray, lo: float, hi: float, bins: int) -> float:
    """Share of `bins` equal sub-intervals of [lo, hi] holding at least one visible point."""
    if hi <= lo:
        return 0.0
    inside = s_visible[(s_visible >= lo) & (s_visible <= hi)]
    k = np.clip(((inside - lo) / (hi - lo) * bins).astype(int), 0, bins - 1)
    return float(np.unique(k).size / bins)


def segment_parts(c: Completion, top_sign: float, cfg: PartConfig | None = None) -> Parts:
    """Part labels, probabilities, object frame and part boxes of a completed object."""
    cfg = cfg or PartConfig()
    long_handle = _long_handle(c, cfg)
    R_TO = _object_frame(c, top_sign, long_handle)
    q = (c.p_T - c.p_TA) @ R_TO  # points in O's axes, origin on the axis.
    is_tool = False
    if not c.vertical:
        # The visible points' profile: a tool lying on the table need not be symmetric about
        # the axis (a ladle's handle rises from its bowl), and the completion would mirror it.
        edges, occupied, profile = _tool_profile(q[c.visible], cfg.profile_bins)
        thin = profile.max(axis=1) < cfg.tool_max_thickness
        is_tool = len(occupied) > 0 and thin.mean() >= cfg.tool_thin_fraction
    labels = np.empty(len(q), int)
    probabilities: dict[str, float] = {}
    if long_handle:
        is_tool = True
        labels[:] = USABLE
        labels[c.handle] = HANDLE
        p = c.circle.confidence
        probabilities = {"handle": p, "usable_area": p}
    elif is_tool:
        if len(occupied) >= 2:
            k, explained = _best_split(profile)
        else:
            k, explained = 1, 0.0
        split = edges[occupied[min(k, len(occupied) - 1)]]
        first, second = profile[:k].mean(axis=0), profile[k:].mean(axis=0)
        flat1 = first.max() / max(first.min(), 1e-9)
        flat2 = second.max() / max(second.min(), 1e-9)
        if max(flat1, flat2) > EQUAL_FLATNESS * min(flat1, flat2):
            usable_first = flat1 > flat2
        else:
            usable_first = first.prod() < second.prod()  # the thicker segment is the handle
        usable = (q[:, 2] < split) if usable_first else (q[:, 2] >= split)
        labels[:] = HANDLE
        labels[usable] = USABLE
        if usable_first:  # z from the handle to the usable area: turn O by 180° about x.
            R_TO = R_TO * np.array([1.0, -1.0, -1.0])
            q = q * np.array([1.0, -1.0, -1.0])
        p = 0.5 + 0.5 * explained
        probabilities = {"handle": p, "usable_area": p}
    else:
        body = ~c.handle
        s = q[:, 2]
        s_lo, s_hi = s[body].min(), s[body].max()
        length = s_hi - s_lo
        t_top = s_hi - cfg.top_fraction * length
        t_bottom = s_lo + cfg.bottom_fraction * length
        labels[:] = MIDDLE
        labels[s >= t_top] = TOP
        labels[s <= t_bottom] = BOTTOM
        labels[c.handle] = HANDLE
        s_vis = s[c.visible & body]
        for name, a, b in (("top", t_top, s_hi), ("middle", t_bottom, t_top),
                           ("bottom", s_lo, t_bottom)):
            p = _coverage(s_vis, a, b, cfg.coverage_bins)
            if p > 0:
                probabilities[name] = p
        n_handle = int(c.handle.sum())
        if n_handle and c.circle is not None:
            support = min(1.0, n_handle / HANDLE_SUPPORT_POINTS)
            probabilities["handle"] = c.circle.confidence * (0.5 + 0.5 * support)
    boxes: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for label in np.unique(labels):
        m = labels == label
        b_lo, b_hi = q[m].min(axis=0), q[m].max(axis=0)
        boxes[PART_LABELS[label]] = (c.p_TA + R_TO @ (0.5 * (b_lo + b_hi)), 0.5 * (b_hi - b_lo))
    lo, hi = q.min(axis=0), q.max(axis=0)
    return Parts(labels, probabilities, is_tool, R_TO, c.p_TA + R_TO @ (0.5 * (lo + hi)),
                 hi - lo, boxes)
