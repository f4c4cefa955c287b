"""Symmetry-based shape completion (paper section III-A) and the circle test (III-B).

Works in the table frame T (origin on the table top, z up along the table normal). Following the
paper:

- the vertical box direction is the table normal and its length the largest height, d_z;
- the horizontal box directions are the PCA eigenvectors of W, the visible points projected
  onto the table plane;
- the xy-centroid c_xy is the centroid of the top region, the points higher than σ·d_z (their
  projection is symmetric about the axis when the top is seen, Fig. 3 of the paper);
- the symmetry axis s is the box direction left over by the pair of box directions whose
  dimensions are the closest (the cross product of that pair); it passes through the box centroid;
- the visible points P are rotated 180° about s and added to P.

Two additions, both built on the paper's own circle test for handles ("a circle fitted in the
projected points W with a large confidence; the points lying outside it are handle"):

1. The circle test is run for every candidate axis on the points projected along it (for the
   vertical axis that is W, the paper's case). A rotationally symmetric object has a circular
   cross-section about its axis and about no other box direction, so when exactly one candidate
   passes, it is the axis (when none passes, the clearly surest one whose circle explains the
   box: SUREST_MIN); otherwise the paper's closest-dimensions rule decides. This keeps a
   mug or a pan upright although its handle stretches one horizontal dimension of the box, and
   the closest-dimensions rule alone would call it sideways.
2. Handle points (outside the circle) are not rotated: the handle is the part that breaks the
   rotational symmetry, and rotating it would add a second, phantom handle.
3. Given the camera, a rotated point is kept only where the camera could not have seen it
   (`seen_free`): one axis rotates the whole object, so where a part is thinner than the axis is
   high (the shaft of a screwdriver lying on the table, tilted from its thick handle to its tip;
   a knife's flat blade) its copy floats above it, in space the camera looked through.

The test works on the outline of the folded cross-section: the 180° rotation about the axis maps
polar angle θ to θ + π, so the completed outline radius in direction θ is the largest radius
seen at θ or θ + π. A circle is an outline of constant radius R, except for at most one run of
directions where a handle reaches beyond it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import minimum_filter

from tg_drake.errors import PerceptionError
from tg_drake.perception.config import CompletionConfig
from tg_drake.perception.geometry import frame_from_z

# Normals within acos(0.5) = 60° of an axis estimate are on end faces, not the side wall.
SIDE_WALL_COSINE = 0.5
# Circle tests whose confidences differ by less than this are equally sure.
CONFIDENCE_TIE = 0.05
# When no circle test passes, the surest one still decides when it is surer than every other by
# more than CONFIDENCE_TIE, at least this share of its outline bins is on its circle, and its
# circle explains the box (the box's sides across the axis differ by less than the circle's
# diameter: a handle's reach, not a long tool's): a cup whose handle or a lost far rim keeps it
# just under `min_circle_fraction` is still far rounder about its vertical axis than about any
# lying one. Fitted on the training objects' perceived views (D415 model, every resting pose,
# yaws 0/120/240, tools included; 80 views where no test passed): the 28 views the rule decides
# from 0.6 up were all the right axis; the wrong surest candidates there are lying tools read
# vertical, one within the tie and four whose box sides differ by 3.5–18 diameters.
SUREST_MIN = 0.6
# The top region is a ridge along a lying object's axis when its principal variance is this many
# times its secondary one (a strip at least twice as long as wide).
RIDGE_EIGEN_RATIO = 4.0


@dataclass
class CircleFit:
    """Result of the circle test on points projected along a candidate axis."""

    ok: bool  # a circle (with at most one handle) fits with confidence ≥ min_circle_fraction.
    radius: float  # R [m].
    confidence: float  # share of the non-handle outline bins on the circle.
    handle: np.ndarray  # (N,) bool: points outside the circle, in the handle's directions.
    handle_direction: np.ndarray  # (2,) unit direction of the handle in the plane, or zeros.
    rim: np.ndarray  # (M,) int indices of the outline points on the circle.
    spread: float = np.inf  # relative standard deviation of the outline radius on the circle.


@dataclass
class Completion:
    """A completed object in the table frame T."""

    p_T: np.ndarray  # (N, 3) visible points followed by the rotated ones [m].
    n_T: np.ndarray  # (N, 3) unit normals, outwards from the symmetry axis.
    visible: np.ndarray  # (N,) bool: observed points.
    handle: np.ndarray  # (N,) bool: handle points (observed only; never rotated).
    p_TA: np.ndarray  # (3,) a point on the symmetry axis (the body's box centroid) [m].
    axis_T: np.ndarray  # (3,) unit symmetry axis direction (up when vertical).
    vertical: bool  # the axis is the table normal.
    R_TB: np.ndarray  # 3×3 box directions as columns: (e1, e2, up) in the table plane.
    box_dims: np.ndarray  # (3,) visible box dimensions along R_TB's columns [m].
    circle: CircleFit | None  # the circle test about the chosen axis (None if it failed).
    handle_direction_T: np.ndarray  # (3,) unit direction from the axis to the handle, or zeros.
    axis_margin: float  # confidence in the axis decision, in [0.5, 1].
    d_z: float  # height of the highest point [m].


def _largest_cyclic_run(mask: np.ndarray) -> np.ndarray:
    """Boolean mask of the longest run of True in a cyclic boolean array."""
    n = len(mask)
    if mask.all():
        return mask.copy()
    doubled = np.concatenate([mask, mask])
    idx = np.arange(2 * n)
    last_false = np.maximum.accumulate(np.where(doubled, -1, idx))
    length = idx - last_false
    end = int(np.argmax(length))
    run = np.zeros(n, bool)
    if length[end] > 0:
        run[np.arange(end - length[end] + 1, end + 1) % n] = True
    return run


def _median(x: np.ndarray) -> float:
    """Median of a short vector (np.median's generality costs more than the sort)."""
    x = np.sort(x)
    n = len(x)
    return float(0.5 * (x[(n - 1) // 2] + x[n // 2]))


def circle_test(q: np.ndarray, cfg: CompletionConfig) -> CircleFit:
    """Circle test on (N, 2) points q centred on a candidate symmetry axis (the axis at 0)."""
    n_bins = max(4, cfg.circle_bins // 2)
    rho = np.hypot(q[:, 0], q[:, 1])
    theta = np.mod(np.arctan2(q[:, 1], q[:, 0]), np.pi)
    k = np.minimum((theta / (np.pi / n_bins)).astype(int), n_bins - 1)
    outline = np.zeros(n_bins)
    np.maximum.at(outline, k, rho)
    occupied = outline > 0
    fail = CircleFit(False, 0.0, 0.0, np.zeros(len(q), bool), np.zeros(2), np.zeros(0, int))
    if occupied.mean() < cfg.min_circle_coverage:
        return fail
    radius = _median(outline[occupied])
    if radius <= 0:
        return fail
    outside = occupied & (outline > (1 + cfg.circle_tolerance) * radius)
    run = _largest_cyclic_run(outside)
    is_handle = (run.any() and run.sum() <= cfg.max_handle_fraction * n_bins
                 and outline[run].max() >= max((1 + cfg.handle_min_protrusion) * radius,
                                               radius + cfg.handle_min_reach))
    handle_bins = run if is_handle else np.zeros(n_bins, bool)
    rest = occupied & ~handle_bins
    on_circle = rest & (np.abs(outline - radius) <= cfg.circle_tolerance * radius)
    radius = _median(outline[on_circle]) if on_circle.any() else radius
    confidence = float(on_circle.sum() / max(rest.sum(), 1))
    handle = handle_bins[k] & (rho > (1 + cfg.circle_tolerance) * radius)
    direction = np.zeros(2)
    if handle.sum() >= cfg.min_handle_points:
        mean = q[handle].mean(axis=0)
        direction = mean / max(np.linalg.norm(mean), 1e-12)
    else:
        handle[:] = False
    rim = np.flatnonzero((rho == outline[k]) & on_circle[k])
    spread = float(np.std(outline[on_circle]) / radius) if on_circle.any() else np.inf
    return CircleFit(confidence >= cfg.min_circle_fraction, radius, confidence, handle,
                     direction, rim, spread)


def _rotate_180(p: np.ndarray, p_A: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Rotates points (or, with p_A = 0, vectors) by 180° about the axis through p_A along a."""
    d = p - p_A
    return p_A + 2.0 * np.outer(d @ a, a) - d


def seen_free(q: np.ndarray, p_seen: np.ndarray, p_C: np.ndarray, *, radius: float,
              margin: float, occluders: np.ndarray | None = None) -> np.ndarray:
    """(M,) bool: which points q (M, 3) lie in space the camera at p_C saw through: no observed
    point p_seen (N, 3) within `radius` [m] of q's line of sight is nearer the camera than
    `margin` [m] behind q (the camera saw past q, to a surface farther away or to none of the
    object's: the table), and no point of `occluders` (K, 3; other objects) lies in front of q
    there. All in one frame.

    Works on a z-buffer of the observed points in a pinhole image about their mean direction,
    pixels radius / 2 wide at their mean range, each pixel's nearest range spread over the
    pixels within `radius` (a 5×5 minimum)."""
    q = np.asarray(q, float).reshape(-1, 3)
    p_seen = np.asarray(p_seen, float).reshape(-1, 3)
    free = np.zeros(len(q), bool)
    if not len(q) or not len(p_seen) or radius <= 0:
        return free
    P = p_seen - p_C
    ahead = P.mean(axis=0)  # the image's axis; its rows level with the table
    u, v, w = frame_from_z(ahead, np.cross(ahead, [0.0, 0.0, 1.0])).T
    pixel = 0.5 * radius / float(np.linalg.norm(P, axis=1).mean())

    def image(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        depth = x @ w  # > 0: in front of the camera
        ok = depth > 1e-6
        safe = np.where(ok, depth, 1.0)
        ij = np.floor(np.column_stack([x @ u, x @ v]) / (safe[:, None] * pixel)).astype(np.int64)
        return ij, np.linalg.norm(x, axis=1), ok

    def visible(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ij, r, ok = image(x)
        return ij[ok], r[ok]

    ij_p, r_p = visible(P)
    ij_q, r_q, ok_q = image(q - p_C)
    others = (None if occluders is None or not len(occluders)
              else visible(np.asarray(occluders, float).reshape(-1, 3) - p_C))
    # The image spans what was observed (the object and the others): a point beyond it is in
    # front of the table the camera saw there, whatever its depth.
    both = ij_p if others is None else np.vstack([ij_p, others[0]])
    lo = both.min(axis=0) - 2
    shape = both.max(axis=0) - lo + 3
    k_q = ij_q - lo
    inside = ok_q & np.all((k_q >= 0) & (k_q < shape), axis=1)
    k_q = tuple(k_q[inside].T)

    def nearest(ij: np.ndarray, r: np.ndarray) -> np.ndarray:
        """Each pixel's nearest range among the points (ij, r) within 2 pixels (inf: none)."""
        buffer = np.full(tuple(shape), np.inf)
        np.minimum.at(buffer, tuple((ij - lo).T), r)
        return minimum_filter(buffer, size=5, mode="constant", cval=np.inf)

    seen = np.full(len(q), np.inf)
    seen[inside] = nearest(ij_p, r_p)[k_q]
    free = ok_q & (seen > r_q + margin)
    if others is not None and free.any():
        in_front = np.full(len(q), np.inf)
        in_front[inside] = nearest(*others)[k_q]
        free &= ~(in_front < r_q)  # another object between the camera and q hides q
    return free


def complete(p_T: np.ndarray, n_T: np.ndarray, cfg: CompletionConfig | None = None,
             p_TC: np.ndarray | None = None, occluders_T: np.ndarray | None = None
             ) -> Completion:
    """Completes the visible points P of one object by the paper's line-reflection symmetry.

    Args:
        p_T: (N, 3) visible points in the table frame (z = height above the table) [m].
        n_T: (N, 3) their unit normals, oriented towards the camera.
        cfg: completion parameters.
        p_TC: (3,) the camera's position in T [m]: rotated points where the camera saw through
            are dropped (`seen_free`); None: all are kept.
        occluders_T: (K, 3) other objects' visible points in T [m], which may hide this one's.
    """
    cfg = cfg or CompletionConfig()
    p_T = np.asarray(p_T, float)
    n_T = np.asarray(n_T, float)
    if p_T.ndim != 2 or p_T.shape[1] != 3 or n_T.shape != p_T.shape:
        raise PerceptionError(
            f"completion needs (N, 3) points and normals, got {p_T.shape} and {n_T.shape}")
    if len(p_T) < 10:
        raise PerceptionError(f"completion needs at least 10 visible points, got {len(p_T)}")
    if not np.all(np.isfinite(p_T)) or not np.all(np.isfinite(n_T)):
        raise PerceptionError("completion got non-finite points or normals")
    z = p_T[:, 2]
    d_z = float(z.max())
    if d_z <= 0:
        raise PerceptionError(
            f"the object's points are not above the table (highest point {d_z:.4f} m)")
    W = p_T[:, :2]

    # Horizontal box directions: PCA of W (sign fixed so that e1 has x ≥ 0 in T).
    _, evecs = np.linalg.eigh(np.cov(W.T))
    e1 = evecs[:, 1] * (1.0 if evecs[0, 1] >= 0 else -1.0)
    e2 = np.array([-e1[1], e1[0]])

    # Candidate axes: the vertical, the two horizontal box directions and, when the top region
    # is a ridge (a lying object's top), the ridge's direction: W's PCA is a poor guide to the
    # axis when W is nearly square (a short lying mug), its top ridge is not.
    top = z > cfg.sigma * d_z
    c_top = W[top].mean(axis=0)
    directions = [e1, e2]
    if top.sum() >= 10:
        evals_t, evecs_t = np.linalg.eigh(np.cov(W[top].T))
        if evals_t[1] > RIDGE_EIGEN_RATIO * max(evals_t[0], 1e-12):
            directions.append(evecs_t[:, 1] * (1.0 if evecs_t[0, 1] >= 0 else -1.0))
    # And the axis the normals give (`_normal_axis`): a squat pot lying down shows W neither
    # along nor across its axis, and its circle test passes about wrong horizontal axes too.
    for start in (e1, e2):
        normal_axis = _normal_axis(n_T, np.append(start, 0.0))
        if normal_axis is not None and np.linalg.norm(normal_axis[:2]) > 0:
            d_n = normal_axis[:2] / np.linalg.norm(normal_axis[:2])
            directions.append(d_n * (1.0 if d_n[0] >= 0 else -1.0))
    candidates = [_vertical_candidate(W, top, c_top, d_z, e1, e2, cfg)]
    # A tilted lying axis is tried along W's long direction and the top ridge only.
    # (Not when the vertical circle is already perfect: a tilted one could at best tie.)
    tilt_normals = n_T if candidates[0].fit.confidence < 1.0 else None
    candidates += [_horizontal_candidate(W, z, c_top, d_z, d, cfg,
                                         tilt_normals if i != 1 else None)
                   for i, d in enumerate(directions)]

    # Choose: the candidate whose cross-section is most surely a circle; between candidates as
    # sure as each other, or when none passes and none is surer than the others by a clear
    # margin (SUREST_MIN), the paper's rule (the axis is the box direction not in the pair
    # of closest dimensions: a handle stretches the box, so it is the last resort).
    passing = [c for c in candidates if c.fit.ok]
    if not passing:
        surest = sorted(candidates, key=lambda c: c.fit.confidence, reverse=True)
        best = surest[0].fit.confidence
        if best >= SUREST_MIN and surest[0].gap < 2 * surest[0].fit.radius and (
                len(surest) == 1 or best > surest[1].fit.confidence + CONFIDENCE_TIE):
            passing = surest[:1]
    if passing:
        best = max(c.fit.confidence for c in passing)
        passing = [c for c in passing if c.fit.confidence >= best - CONFIDENCE_TIE]
    if len(passing) > 1 and all(not c.vertical for c in passing):
        # Lying axes as sure as each other: the one about which the surface is most nearly
        # a surface of revolution (its normals meet the axis).
        passing = [min(passing, key=lambda c: _revolution_residual(p_T, n_T, c))]
    if len(passing) == 1:
        chosen, margin = passing[0], passing[0].fit.confidence
    else:
        ranked = sorted(passing or candidates[:3], key=lambda c: c.gap)
        chosen = ranked[0]
        g0, g1 = ranked[0].gap, (ranked[1].gap if len(ranked) > 1 else np.inf)
        margin = 1.0 - g0 / max(g0 + g1, 1e-12) if np.isfinite(g1) else 1.0
    fit = chosen.fit if chosen.fit.ok else None
    handle = fit.handle if fit is not None else np.zeros(len(W), bool)
    p_TA, a = chosen.p_TA, chosen.a
    if fit is None:
        handle_direction = np.zeros(3)
    else:  # the handle's direction in the circle test's plane, in T.
        handle_direction = fit.handle_direction[0] * chosen.u + fit.handle_direction[1] * chosen.v
    dims = np.array([2 * np.abs((W - p_TA[:2]) @ e1).max(),
                     2 * np.abs((W - p_TA[:2]) @ e2).max(), d_z])

    # Rotate the body (not the handle) 180° about the axis.
    body = ~handle
    p_rot = _rotate_180(p_T[body], p_TA, a)
    n_rot = _rotate_180(n_T[body], np.zeros(3), a)
    if p_TC is not None:
        hidden = ~seen_free(p_rot, p_T, np.asarray(p_TC, float), radius=cfg.free_space_radius,
                            margin=cfg.free_space_margin, occluders=occluders_T)
        p_rot, n_rot = p_rot[hidden], n_rot[hidden]
    p_all = np.concatenate([p_T, p_rot])
    n_all = np.concatenate([n_T, n_rot])
    # Outwards: away from the axis point (radially for walls, along the axis for end faces).
    flip = np.einsum("ij,ij->i", n_all, p_all - p_TA) < 0
    n_all[flip] *= -1
    visible = np.concatenate([np.ones(len(p_T), bool), np.zeros(len(p_rot), bool)])
    handle_all = np.concatenate([handle, np.zeros(len(p_rot), bool)])
    R_TB = np.column_stack([np.append(e1, 0.0), np.append(e2, 0.0), [0.0, 0.0, 1.0]])
    return Completion(p_all, n_all, visible, handle_all, p_TA, a, chosen.vertical, R_TB, dims,
                      fit, handle_direction, float(np.clip(margin, 0.5, 1.0)), d_z)


@dataclass
class _Candidate:
    """A candidate symmetry axis and its circle test."""

    vertical: bool
    a: np.ndarray  # (3,) unit axis direction in T.
    u: np.ndarray  # (3,) first axis of the circle test's plane (orthogonal to a).
    v: np.ndarray  # (3,) second axis of the circle test's plane.
    fit: CircleFit
    p_TA: np.ndarray  # (3,) axis point in T.
    gap: float  # the paper's rule: difference of the two box dimensions across the axis [m].


def _vertical_candidate(W: np.ndarray, top: np.ndarray, c_top: np.ndarray, d_z: float,
                        e1: np.ndarray, e2: np.ndarray, cfg: CompletionConfig) -> _Candidate:
    """The vertical axis through the top region's centroid (paper), at half the height."""
    fit, c = _vertical_fit(W, top, c_top, cfg)
    if not fit.ok:
        # A handle at rim height (a pan's) pulls the top region's centroid towards it and
        # stretches W along the handle. Across the handle (e2) W spans the body's diameter
        # 2R; along it, the body's centre is R in from the end of W without the handle.
        # Try both ends and keep the best circle test.
        s1, s2 = W @ e1, W @ e2
        radius = 0.5 * (s2.max() - s2.min())
        mid2 = 0.5 * (s2.max() + s2.min())
        for s1_c in (s1.min() + radius, s1.max() - radius):
            fit2, c2 = _vertical_fit(W, top, s1_c * e1 + mid2 * e2, cfg)
            if fit2.confidence > fit.confidence:
                fit, c = fit2, c2
    if not fit.ok:  # no circle: the paper's top-region centroid.
        c = c_top
    body = ~fit.handle if fit.ok else np.ones(len(W), bool)
    gap = abs(2 * np.abs((W[body] - c) @ e1).max() - 2 * np.abs((W[body] - c) @ e2).max())
    return _Candidate(True, np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]),
                      np.array([0.0, 1.0, 0.0]), fit, np.array([c[0], c[1], 0.5 * d_z]), gap)


def _horizontal_candidate(W: np.ndarray, z: np.ndarray, c_top: np.ndarray, d_z: float,
                          a: np.ndarray, cfg: CompletionConfig, n: np.ndarray | None = None
                          ) -> _Candidate:
    """A horizontal axis along a through the top region's centroid across it (paper).

    Along the axis its point is the middle of the visible extent; its height is d_z / 2 (the
    box centroid) or, when that fits the circle better, the radius of a round body lying on
    the table: a handle sticking up raises d_z but not the body's axis. Given the normals n,
    an axis found from them, possibly tilted from the table, is tried when the horizontal one
    fails (`_tilted_candidate`).
    """
    b = np.array([-a[1], a[0]])
    s_a = W @ a
    across = (W - c_top) @ b
    best: tuple[CircleFit, float] | None = None
    for height in (0.5 * d_z, 0.5 * (across.max() - across.min())):
        fit = circle_test(np.column_stack([across, z - height]), cfg)
        if best is None or (fit.ok, fit.confidence) > (best[0].ok, best[0].confidence):
            best = (fit, height)
        if fit.ok:
            break
    fit, height = best
    if not fit.ok:  # no circle: the paper's box centroid.
        height = 0.5 * d_z
    p_xy = 0.5 * (s_a.min() + s_a.max()) * a + (c_top @ b) * b
    gap = abs(2 * np.abs(across[~fit.handle] if fit.ok else across).max() - d_z)
    up = np.array([0.0, 0.0, 1.0])
    candidate = _Candidate(False, np.append(a, 0.0), np.append(b, 0.0), up, fit,
                           np.array([p_xy[0], p_xy[1], height]), gap)
    if n is not None and not fit.ok:
        tilted = _tilted_candidate(W, z, n, a, b, gap, cfg)
        if tilted is not None and tilted.fit.ok:
            return tilted
    return candidate


def _robust_circle(q: np.ndarray, tolerance: float) -> tuple[np.ndarray, float] | None:
    """Least-squares (Kåsa) circle through 2D points, refitted twice without the points off it
    by more than `tolerance`·R (a handle, an inner wall): (centre, radius), or None."""
    keep = np.ones(len(q), bool)
    centre, radius = np.zeros(2), 0.0
    x, y = q[:, 0], q[:, 1]
    r2 = x * x + y * y
    for _ in range(3):
        n = int(keep.sum())
        if n < 5:
            return None
        xk, yk, rk = x[keep], y[keep], r2[keep]
        # Normal equations of [2x 2y 1]·(cx, cy, c) = x² + y².
        sx, sy = xk.sum(), yk.sum()
        M = np.array([[4 * (xk @ xk), 4 * (xk @ yk), 2 * sx],
                      [4 * (xk @ yk), 4 * (yk @ yk), 2 * sy],
                      [2 * sx, 2 * sy, n]])
        rhs = np.array([2 * (xk @ rk), 2 * (yk @ rk), rk.sum()])
        try:
            sol = np.linalg.solve(M, rhs)
        except np.linalg.LinAlgError:
            return None
        centre = sol[:2]
        radius = float(np.sqrt(max(sol[2] + centre @ centre, 0.0)))
        keep = np.abs(np.hypot(x - centre[0], y - centre[1]) - radius) <= tolerance * radius
    return (centre, radius) if radius > 0 else None


def _revolution_residual(p: np.ndarray, n: np.ndarray, c: _Candidate) -> float:
    """Median sine of the angle between each normal and the plane through the candidate's
    axis and its point: 0 on a surface of revolution about the axis (walls and end faces),
    whatever the points' spread along or around it."""
    m = np.cross(c.a, p - c.p_TA)
    norm = np.linalg.norm(m, axis=1)
    ok = norm > 1e-6
    return float(np.median(np.abs(np.einsum("ij,ij->i", n[ok], m[ok])) / norm[ok]))


def _normal_axis(n: np.ndarray, a0: np.ndarray) -> np.ndarray | None:
    """The axis of a surface of revolution from its normals: the side wall's normals are
    (nearly, for a taper) orthogonal to the axis, so the axis is the direction of least normal
    variance among the normals not along the current estimate (end faces are). Starts from a0;
    None when the result is not a lying axis (more than 45° from the table plane)."""
    a = a0 / np.linalg.norm(a0)
    for _ in range(3):
        side = np.abs(n @ a) < SIDE_WALL_COSINE
        if side.sum() < 10:
            return None
        _, vecs = np.linalg.eigh(n[side].T @ n[side])
        a = vecs[:, 0] * (1.0 if vecs[:, 0] @ a >= 0 else -1.0)
    return a if abs(a[2]) <= np.sqrt(0.5) else None


def _tilted_candidate(W: np.ndarray, z: np.ndarray, n: np.ndarray, a: np.ndarray,
                      b: np.ndarray, gap: float, cfg: CompletionConfig) -> _Candidate | None:
    """A lying round body whose axis may be tilted from the table (a mug resting on its rim and
    its handle): the axis direction from the normals (`_normal_axis`, starting along a), the
    axis point from a circle fitted to the points projected along it. None when the normals do
    not give a lying axis."""
    axis = _normal_axis(n, np.append(a, 0.0))
    if axis is None:
        return None
    p = np.column_stack([W, z])
    p0 = p.mean(axis=0)
    u = np.append(b, 0.0) - (np.append(b, 0.0) @ axis) * axis
    u = u / np.linalg.norm(u)
    v = np.cross(axis, u)
    d = p - p0
    circle = _robust_circle(np.column_stack([d @ u, d @ v]), 2 * cfg.circle_tolerance)
    if circle is None:
        return None
    s = d @ axis
    p_A = p0 + circle[0][0] * u + circle[0][1] * v + 0.5 * (s.min() + s.max()) * axis
    d = p - p_A
    fit = circle_test(np.column_stack([d @ u, d @ v]), cfg)
    return _Candidate(False, axis, u, v, fit, p_A, gap)


def _vertical_fit(W: np.ndarray, top: np.ndarray, c: np.ndarray, cfg: CompletionConfig
                  ) -> tuple[CircleFit, np.ndarray]:
    """Circle test of W about c, then refinements of c, each kept when it makes the test surer
    (higher confidence, then a rounder outline: a circle seen from off its centre has an
    outline that swings with the direction):

    - the top region's centroid without the handle points, once they are known (the paper's
      estimate, cleaned of a handle at rim height);
    - the centre of a least-squares (Kåsa) circle through the outline points on the circle: the
      top region of a bottle is its neck, whose visible side pulls the centroid towards the
      camera by a few millimetres, enough to make the body look lopsided; the top region of a
      tilted pan lying upside down is one side of its bottom.
    """
    def score(f: CircleFit) -> tuple[float, float]:
        return f.confidence, -f.spread

    fit = circle_test(W - c, cfg)
    keep = top & ~fit.handle
    if fit.handle.any() and keep.any():
        c1 = W[keep].mean(axis=0)
        fit1 = circle_test(W - c1, cfg)
        if score(fit1) >= score(fit):
            fit, c = fit1, c1
    for _ in range(3):
        if len(fit.rim) < 3:
            break
        rim = W[fit.rim] - c
        A = np.column_stack([2 * rim, np.ones(len(rim))])
        sol, *_ = np.linalg.lstsq(A, (rim ** 2).sum(axis=1), rcond=None)
        refit = circle_test(W - (c + sol[:2]), cfg)
        if score(refit) <= score(fit):
            break
        fit, c = refit, c + sol[:2]
    return fit, c
