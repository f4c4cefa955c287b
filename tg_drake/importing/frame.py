"""The object frame O of an imported mesh, its part labels, dimensions, grasp widths and cavity.

Input: a repaired mesh in metres, z up, upright as modelled (containers stand on their bottom;
tools may be modelled lying or standing, in any orientation), anywhere and at any yaw. Output: an
`ObjectFrame` whose X_OM maps the input's coordinates into the frame O of tg_drake/objects.py.

Containers (pan, pot, cup, glass, bowl, bottle, can):

- the axis is vertical, through the point the surface normals' horizontal lines meet (a body of
  revolution's normals all cross its axis; a handle's do not): an iteratively reweighted
  least-squares intersection of those lines, with Tukey weights;
- the mesh is cut by horizontal planes; in each cut and each angular sector the largest radius is
  the body's there, and their median over the sectors is the body's radius at that height, so a
  handle (a few sectors) does not move it. A vertex lying more than HANDLE_CLEARANCE outside that
  radius profile, or above the body's top, is the handle;
- O: origin at the bottom centre, z up the axis, x towards the handle (the largest handle when
  there are two); without a handle the input's x direction is kept;
- parts: bottom, middle, top thirds of the body's height (a vertex within CUT_TOLERANCE below a
  cut belongs to the part above, as in tools/make_objects.py), plus the handle;
- an inner surface (faces turned towards the axis, not downwards, at least INNER_SHARE of a cut)
  over at least OPEN_DEPTH of the height makes an open vessel (radii are per-sector medians):
  wall = outer − inner radius across the wall, base = height of the inner bottom, cavity = the
  water filling the inner surface up to the rim's lowest point. A closed body (a bottle or can
  scanned from outside) has no inner surface: the wall is a prior (WALL_PRIOR) and the cavity the
  enclosed volume less a shell of that thickness (first order: section area less perimeter ×
  wall).

Tools (hammer, knife, screwdriver, cooking_tool):

- x along the long axis: the first principal axis of the surface (area-uniform samples);
- z: the outward normal, reversed, of the convex hull's facet the tool rests on, found among the
  facets its centre of mass (uniform density) projects into, facing within 60° of the surface's
  thinnest principal axis: the one holding the centre of mass lowest. x is the long axis made
  perpendicular to z and turned (within MAX_X_TURN) to the narrowest bounding box; y = z × x;
  origin at the bottom centre of the bounding box in O;
- handle versus usable area: the section width (along y) and thickness (along z) profiles along x
  are fitted, as logarithms, by two constant segments; the split is where one profile, next to the
  best step, has gone a fraction of the way from the handle's level to the usable area's. Which
  segment is the usable area, and where it begins, is a rule per category (TOOL_RULES):

  - hammer: the head — the wider segment, from a quarter of the way up the width's step;
  - knife: the blade — the thinner segment, from where the handle has thinned a tenth of the way
    (the bolster is the blade's);
  - screwdriver: the shaft and tip — the narrower segment, from halfway down the width's step (the
    handle's tapered nose is handle);
  - cooking_tool: the spatula head or the ladle bowl — the wider segment, from a quarter of the
    way up the width's step, or from the narrowest section of a neck before it (a handle
    narrowing by NECK_NARROWING or more): the neck is handle;
  - unknown category: the segment less like a hand grip (section further from GRIP_SECTION in
    log width + log thickness), from halfway along the larger step; said in the notes.

  x points from the handle to the usable area.

Category None: a container when the surface is a body of revolution about a vertical axis
(REVOLUTION_MIN of the area with horizontal normals, averaged over NORMAL_RADIUS, has normals
pointing at one axis within REVOLUTION_ANGLE), not
slender (height at most MAX_CONTAINER_ASPECT body diameters) and not dwarfed by a handle (at most
MAX_CONTAINER_REACH body diameters across) whose body spans at least MIN_BODY_SHARE of its
height; otherwise a tool. Said in the notes.

Dimensions [m] — containers: height (body, handle excluded), diameter (the body's largest), wall,
base, handle_length (how far the handle reaches out from the wall); tools: length, width,
thickness (bounding box in O), handle_length (along x). Grasp widths as library.yaml defines
them: per part, the smallest width of its vertices over closing directions in O's xy plane, an
open container's top pinched across its rim wall.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import trimesh
from scipy.ndimage import maximum_filter1d
from scipy.sparse import coo_matrix
from scipy.spatial import cKDTree

from tg_drake.errors import ModelError, unknown_name
from tg_drake.types import CATEGORIES, PART_LABELS

TOOL_CATEGORIES = ("hammer", "knife", "screwdriver", "cooking_tool")
TOP, MIDDLE, BOTTOM, HANDLE, USABLE = (PART_LABELS.index(p) for p in
                                       ("top", "middle", "bottom", "handle", "usable_area"))

N_SAMPLES = 20000  # surface samples (area-uniform) for the fits; a fixed seed keeps them repeatable
SAMPLE_SEED = 0
N_SCORE = 8000  # of them for the body-of-revolution test (container or tool)
SECTORS = 36  # angular sectors of a cut (10° each: a handle spans only a few)
N_CUTS = 240  # horizontal cuts over a container's height ...
MIN_CUT_SPACING = 0.0002  # [m] ... at most one per 0.2 mm
# [m] a vertex this far outside the body's radius profile is handle: above faceting (a 40-gon's
# edge midpoints lie 0.3 % inside its corners) and scan noise, below any handle's thickness.
HANDLE_CLEARANCE = 0.002
CUT_TOLERANCE = 5e-4  # [m] a vertex this close below a third's cut belongs to the part above
# a cut holds the body (or an inner surface) when it has points in this share of its sectors
COVERAGE = 0.5
INNER_SHARE = 0.2  # ... and this share of the cut's points face the axis (half do in a vessel)
OPEN_DEPTH = 0.3  # an inner surface over this share of the height makes an open vessel
# [m] wall of a closed container seen from outside only: bottles are glass (2.5–3 mm) or PET
# (0.4–0.5 mm), cans aluminium or tinplate (0.15–0.25 mm); other categories: a ceramic-like 3 mm.
WALL_PRIOR = {"bottle": 0.0015, "can": 0.0002}
WALL_PRIOR_DEFAULT = 0.003
REVOLUTION_MIN = 0.5
# [°] a normal pointing this close at the axis belongs to a body of revolution (a 24-gon's facets
# are 7.5° off at their edges)
REVOLUTION_ANGLE = 10.0
# [m] normals are averaged over this radius (or 2.5 sample spacings) for that test: a scan's
# noise (0.3 mm on 3 mm triangles) tilts single triangles by 10° and more; a 30 mm radius wall
# turns 8° over it
NORMAL_RADIUS = 0.004
MAX_CONTAINER_ASPECT = 6.0  # height / diameter: bottles reach about 4.5, a standing screwdriver 7
# longest horizontal extent / body diameter: a long-handled saucepan reaches about 2.3, a ladle 4
MAX_CONTAINER_REACH = 3.0
# body height / overall height: a pan's handle rises above its rim (body 0.67 of it); a ladle
# standing on its bowl is mostly handle (about 0.1)
MIN_BODY_SHARE = 0.5
MAX_X_TURN = 15.0  # [°] search for the narrowest box about the principal axis
TOOL_BINS = 200  # stations of the section profile along a tool's length
# Per tool category: which of the two segments is the usable area ("wider" or "narrower" in the
# profile `channel`: 0 width, 1 thickness), and where the handle ends: where that profile has gone
# `fraction` of the way (in logarithms) from the handle's level towards the usable area's.
TOOL_RULES = {
    # the head: wider; it begins where the section has widened a quarter of the way
    "hammer": ("wider", 0, 0.25, "the head is the wider segment"),
    # the blade: thinner; it begins where the handle starts thinning (the bolster is the blade's)
    "knife": ("narrower", 1, 0.1, "the blade is the thinner segment, from where the handle thins"),
    # the shaft and tip: narrower; the handle's tapered nose is still handle
    "screwdriver": ("narrower", 0, 0.5, "the shaft and tip are the narrower segment"),
    # the spatula head or ladle bowl: wider, from where the section has widened a quarter of the
    # way (a narrowing neck is handle)
    "cooking_tool": ("wider", 0, 0.25, "the head or bowl is the wider segment"),
}
# a cooking tool's neck: a section this much narrower than the handle's median, within this share
# of the length before the head
NECK_NARROWING = 0.8
NECK_SEARCH = 0.15
GRIP_SECTION = (0.025, 0.02)  # [m] width, thickness of a typical hand grip (unknown category)
TUKEY_C = 4.685  # Tukey biweight constant (95 % efficiency under Gaussian noise)


@dataclass(frozen=True)
class ObjectFrame:
    X_OM: np.ndarray  # (4,4) maps the input mesh's coordinates (metres, z up) to O
    kind: str  # "container" | "tool"
    labels: np.ndarray  # (V,) uint8 index into PART_LABELS, per vertex of the input mesh
    parts: tuple[str, ...]  # in PART_LABELS order
    dimensions: dict  # [m] containers: height, diameter, wall, base (+ handle_length);
    #                   tools: length, width, thickness, handle_length
    grasp_widths: dict  # part → [m], as library.yaml defines it
    cavity_volume: float | None  # [m³] containers (water when full), None for tools
    cavity_centroid: tuple | None  # [m] in O
    notes: tuple[str, ...]  # what was decided and why (goes into the import report)


# ------------------------------------------------------------------------------------------------
# Input checks


def _check(vertices, faces, category, labels):
    V = np.asarray(vertices, dtype=float)
    if V.ndim != 2 or V.shape[1] != 3 or len(V) == 0:
        raise ModelError(f"mesh vertices must be a non-empty (V, 3) array, got shape {V.shape}",
                         field="vertices")
    if not np.isfinite(V).all():
        raise ModelError("mesh vertices hold NaN or infinite coordinates", field="vertices")
    F = np.asarray(faces)
    if F.ndim != 2 or F.shape[1] != 3 or len(F) == 0:
        raise ModelError(f"mesh faces must be a non-empty (F, 3) array, got shape {F.shape}",
                         field="faces")
    if not np.issubdtype(F.dtype, np.integer):
        raise ModelError(f"mesh faces must be integer vertex indices, got {F.dtype}",
                         field="faces")
    if F.min() < 0 or F.max() >= len(V):
        raise ModelError(f"face indices {F.min()}..{F.max()} outside the {len(V)} vertices",
                         field="faces")
    F = F.astype(np.int64)
    if category is not None and category not in CATEGORIES:
        raise unknown_name("category", category, CATEGORIES, error=ModelError, field="category")
    L = None
    if labels is not None:
        L = np.asarray(labels)
        if L.ndim != 1 or len(L) != len(V):
            raise ModelError(f"part labels: {L.shape[0] if L.ndim else 0} values for {len(V)} "
                             f"vertices (one per vertex, in vertex order)", field="labels")
        if not (np.issubdtype(L.dtype, np.integer) or
                (np.issubdtype(L.dtype, np.floating) and np.all(L == np.round(L)))):
            raise ModelError(f"part labels must be integers, got {L.dtype}", field="labels")
        bad = (L < 0) | (L >= len(PART_LABELS))
        if bad.any():
            raise ModelError(f"part labels {sorted(set(L[bad].tolist()))[:5]} out of range; "
                             f"allowed: 0..{len(PART_LABELS) - 1} "
                             f"({', '.join(PART_LABELS)})", field="labels")
        L = L.astype(np.uint8)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    if not (np.linalg.norm(np.cross(b - a, c - a), axis=1) > 0).any():
        raise ModelError("mesh has no triangle of positive area", field="faces")
    if not (np.ptp(V, axis=0) > 0).sum() == 3:
        raise ModelError(f"mesh is flat (extents {np.ptp(V, axis=0)} m)", field="vertices")
    return V, F, L


# ------------------------------------------------------------------------------------------------
# Geometry helpers


def _face_geometry(V, F):
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    cross = np.cross(b - a, c - a)
    area2 = np.linalg.norm(cross, axis=1)
    N = np.zeros_like(cross)
    ok = area2 > 0
    N[ok] = cross[ok] / area2[ok, None]
    return N, 0.5 * area2


def _samples(V, F, N, area, n=N_SAMPLES):
    """Area-uniform surface points with their face normals."""
    rng = np.random.default_rng(SAMPLE_SEED)
    tri = rng.choice(len(F), size=n, p=area / area.sum())
    r1, r2 = rng.random(n), rng.random(n)
    s = np.sqrt(r1)
    w = np.stack([1 - s, s * (1 - r2), s * r2], 1)
    P = np.einsum("nk,nkj->nj", w, V[F[tri]])
    return P, N[tri]


def _centre_of_mass(V, F, area):
    """Uniform-density centre of mass of a closed mesh (signed tetrahedra); the surface's centroid
    when the mesh encloses no volume."""
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    o = V.mean(0)
    vol6 = np.einsum("ij,ij->i", a - o, np.cross(b - o, c - o))
    if vol6.sum() > 1e-12:
        return o + ((a + b + c - 3 * o) * vol6[:, None]).sum(0) / (4 * vol6.sum()), vol6.sum() / 6
    return ((a + b + c) / 3 * area[:, None]).sum(0) / area.sum(), 0.0


def _vertex_area(V, F, area):
    w = np.zeros(len(V))
    np.add.at(w, F.ravel(), np.repeat(area / 3, 3))
    return w


def _axis_centre(P, N):
    """(x, y) where the horizontal normal lines of the surface meet, and the residual distances of
    every line (NaN for samples with a steep normal). IRLS with Tukey weights."""
    nh = N[:, :2]
    ln = np.linalg.norm(nh, axis=1)
    use = ln > 0.5
    dist = np.full(len(P), np.nan)
    if use.sum() < 10:
        return None, dist
    u = nh[use] / ln[use, None]
    p = P[use, :2]
    M = np.eye(2)[None] - u[:, :, None] * u[:, None, :]  # projectors across each line
    Mp = np.einsum("nij,nj->ni", M, p)
    w = np.ones(len(u))
    c = np.zeros(2)
    for it in range(15):
        A = np.einsum("n,nij->ij", w, M)
        if np.linalg.cond(A) > 1e8:
            break
        c = np.linalg.solve(A, (w[:, None] * Mp).sum(0))
        d = np.abs((c[0] - p[:, 0]) * u[:, 1] - (c[1] - p[:, 1]) * u[:, 0])
        s = 1.4826 * np.median(d) + 1e-5  # [m] robust scale, 10 µm floor
        k = (1.0 if it < 3 else TUKEY_C) * s * (3.0 if it < 3 else 1.0)
        t = d / k
        w = np.where(t < 1, (1 - t ** 2) ** 2, 0.0)
        if w.sum() < 3:
            break
    d = np.abs((c[0] - p[:, 0]) * u[:, 1] - (c[1] - p[:, 1]) * u[:, 0])
    dist[use] = d
    return c, dist


def _cuts(V, F, N, levels, c):
    """Horizontal cuts of the mesh at `levels`: for every cut, points along each face's segment
    (denser the further round the axis (x, y) = `c` it reaches) with their face normals, the cut
    index of each point, and per cut the enclosed material area and the cut's length (Green's
    theorem on the oriented segments)."""
    Fz = V[F][:, :, 2]
    fzmin, fzmax = Fz.min(1), Fz.max(1)
    pts, nrm, cut = [], [], []
    area = np.zeros(len(levels))
    length = np.zeros(len(levels))
    order = np.argsort(fzmin)
    zs = fzmin[order]
    for k, z in enumerate(levels):
        cand = order[: np.searchsorted(zs, z, side="right")]
        cand = cand[fzmax[cand] >= z]
        if len(cand) == 0:
            continue
        above = Fz[cand] >= z
        na = above.sum(1)
        m = (na == 1) | (na == 2)
        idx = cand[m]
        if len(idx) == 0:
            continue
        A = above[m]
        lone = np.where(na[m] == 1, np.argmax(A, 1), np.argmin(A, 1))
        tri = V[F[idx]]
        r = np.arange(len(idx))
        p0, p1, p2 = tri[r, lone], tri[r, (lone + 1) % 3], tri[r, (lone + 2) % 3]
        a = p0 + ((z - p0[:, 2]) / (p1[:, 2] - p0[:, 2]))[:, None] * (p1 - p0)
        b = p0 + ((z - p0[:, 2]) / (p2[:, 2] - p0[:, 2]))[:, None] * (p2 - p0)
        n = N[idx]
        d = np.stack([-n[:, 1], n[:, 0]], 1)  # material on the left of the oriented segment
        flip = ((b - a)[:, :2] * d).sum(1) < 0
        a2 = np.where(flip[:, None], b, a)
        b2 = np.where(flip[:, None], a, b)
        # about the axis: a hole's open ends then cost only the sliver between them and it
        a2, b2 = a2[:, :2] - c, b2[:, :2] - c
        area[k] = 0.5 * np.sum(a2[:, 0] * b2[:, 1] - a2[:, 1] * b2[:, 0])
        length[k] = np.linalg.norm((b - a)[:, :2], axis=1).sum()
        # points along each segment, at least two per angular sector it spans about the axis
        # (a coarse CAD mesh's long triangles cut into few, long segments)
        seg = np.linalg.norm((b - a)[:, :2], axis=1)
        r_mid = np.linalg.norm(0.5 * (a + b)[:, :2] - c, axis=1)
        h = np.maximum(0.25 * (r_mid + seg) * 2 * np.pi / SECTORS, 1e-4)
        n_pts = np.clip(np.ceil(seg / h).astype(int), 2, 64) + 1
        rep = np.repeat(np.arange(len(idx)), n_pts)
        t = (np.arange(len(rep)) - np.repeat(np.cumsum(n_pts) - n_pts, n_pts)) / (
            np.repeat(n_pts, n_pts) - 1)
        pts.append(a[rep] + t[:, None] * (b - a)[rep])
        nrm.append(n[rep])
        cut.append(np.full(len(rep), k))
    if not pts:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, int), area, length
    return np.concatenate(pts), np.concatenate(nrm), np.concatenate(cut), area, length


def _row_median(A, mask):
    """Median of each row of A over its masked entries (NaN where a row has none)."""
    X = np.where(mask, A, np.nan)
    out = np.full(len(A), np.nan)
    ok = mask.any(1)
    out[ok] = np.nanmedian(X[ok], axis=1)
    return out


def _group_median(key, values, n_keys):
    """Median of `values` per integer key in 0..n_keys−1 (NaN for keys without values)."""
    out = np.full(n_keys, np.nan)
    if len(key) == 0:
        return out
    order = np.lexsort((values, key))
    k, v = key[order], values[order]
    counts = np.bincount(k, minlength=n_keys)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    has = counts > 0
    lo = start[has] + (counts[has] - 1) // 2
    hi = start[has] + counts[has] // 2
    out[has] = 0.5 * (v[lo] + v[hi])
    return out


def _sector_reduce(key, values, n_keys, fn, fill):
    out = np.full(n_keys, fill, float)
    fn.at(out, key, values)
    return out


def _grasp_widths(p_O, labels, open_top_wall):
    th = np.linspace(0, np.pi, 180, endpoint=False)
    D = np.stack([np.cos(th), np.sin(th)], 1)
    out = {}
    for k, name in enumerate(PART_LABELS):
        pts = p_O[labels == k]
        if len(pts) == 0:
            continue
        proj = pts[:, :2] @ D.T
        w = float((proj.max(0) - proj.min(0)).min())
        if open_top_wall is not None and name == "top":
            w = min(w, float(open_top_wall))
        out[name] = w
    return out


def _transform(R, p):
    """X with X·[v; 1] = R·(v − p)."""
    X = np.eye(4)
    X[:3, :3] = R
    X[:3, 3] = -R @ p
    return X


def _apply(X, V):
    return V @ X[:3, :3].T + X[:3, 3]


# ------------------------------------------------------------------------------------------------
# Container or tool from the shape


def _smoothed_normals(P, N, radius):
    """Sample normals averaged over the samples within `radius` that face the same side (a
    scan's noise tilts each triangle's normal by ten degrees and more; the two sides of a thin
    wall must not cancel)."""
    pairs = cKDTree(P).query_pairs(radius, output_type="ndarray")
    pairs = pairs[np.einsum("ij,ij->i", N[pairs[:, 0]], N[pairs[:, 1]]) > 0]
    i, j = np.concatenate([pairs[:, 0], pairs[:, 1]]), np.concatenate([pairs[:, 1], pairs[:, 0]])
    S = N + coo_matrix((np.ones(len(i)), (i, j)), shape=(len(P), len(P))).tocsr() @ N
    return S / np.linalg.norm(S, axis=1, keepdims=True)


def _revolution_score(P, N, area_total):
    """(share of the horizontal-normal surface whose normals point at one vertical axis, within
    REVOLUTION_ANGLE; the axis (x, y); the median radius of those samples [m])."""
    P, N = P[:N_SCORE], N[:N_SCORE]  # (the samples are in random order)
    N = _smoothed_normals(P, N, max(NORMAL_RADIUS, 2.5 * math.sqrt(area_total / len(P))))
    c, dist = _axis_centre(P, N)
    use = np.isfinite(dist)
    if c is None or use.sum() < 10:
        return 0.0, c, 0.0
    r = np.linalg.norm(P[use, :2] - c, axis=1)
    hit = dist[use] < math.sin(math.radians(REVOLUTION_ANGLE)) * r
    return float(np.mean(hit)), c, float(np.median(r[hit])) if hit.any() else 0.0


# ------------------------------------------------------------------------------------------------
# Containers


def _container(V, F, N, area, P, Ns, category, notes):
    c, _ = _axis_centre(P, Ns)
    if c is None:
        c = 0.5 * (V[:, :2].min(0) + V[:, :2].max(0))
        notes.append("axis: too few wall faces for a fit; the bounding box's centre")
    z0, z1 = float(V[:, 2].min()), float(V[:, 2].max())
    n_cuts = int(min(N_CUTS, max(8, math.ceil((z1 - z0) / MIN_CUT_SPACING))))
    dz = (z1 - z0) / n_cuts
    levels = z0 + (np.arange(n_cuts) + 0.5) * dz
    Pc, Nc, kc, sec_area, sec_len = _cuts(V, F, N, levels, c)
    rel = Pc[:, :2] - c
    r = np.linalg.norm(rel, axis=1)
    th = np.arctan2(rel[:, 1], rel[:, 0])
    s = np.minimum(((th + np.pi) / (2 * np.pi) * SECTORS).astype(int), SECTORS - 1)
    key = kc * SECTORS + s
    radial = np.where(r > 0, (Nc[:, 0] * rel[:, 0] + Nc[:, 1] * rel[:, 1]) / np.maximum(r, 1e-12),
                      0.0)
    rmax = _sector_reduce(key, r, n_cuts * SECTORS, np.maximum, -np.inf).reshape(n_cuts, SECTORS)
    occupied = np.isfinite(rmax)
    coverage = occupied.mean(1)
    body_cut = coverage >= COVERAGE
    if not body_cut.any():
        raise ModelError("no horizontal cut of the mesh goes round a body: is it upright with z "
                         "up?", field="vertices")
    R_body = np.where(body_cut, _row_median(rmax, occupied), np.nan)
    # per-cut spread of the sector maxima (scan noise), robust
    dev = np.abs(rmax - R_body[:, None])
    sel = occupied & body_cut[:, None]
    spread = float(np.median(dev[sel])) if sel.any() else 0.0
    noise = 3 * 1.4826 * (0.0 if not np.isfinite(spread) else float(spread))  # [m] 3σ
    tol = HANDLE_CLEARANCE + noise

    # vertices: handle = outside the body's radius profile (neighbouring cuts too) or above it
    rv = np.linalg.norm(V[:, :2] - c, axis=1)
    kv = np.clip(((V[:, 2] - z0) / dz).astype(int), 0, n_cuts - 1)
    Rb = np.where(body_cut, R_body, -np.inf)
    # the largest body radius within the noise (and a cut) above or below the vertex: a noisy
    # flat bottom's cuts catch only patches of it
    half = 1 + int(math.ceil(noise / dz))
    Rlim = maximum_filter1d(Rb, size=2 * half + 1, mode="nearest")[kv]
    first_cut, top_cut = (int(i) for i in np.nonzero(body_cut)[0][[0, -1]])
    # above or below the body (by more than the noise: a pan's handle rises just above its rim)
    outside = ((V[:, 2] > levels[top_cut] + dz + noise)
               | (V[:, 2] < levels[first_cut] - dz - noise))
    # (a gap in the profile between body cuts is not handle)
    handle_v = outside | (np.isfinite(Rlim) & (rv > Rlim + tol))
    body_v = ~handle_v
    if not body_v.any() or np.ptp(V[body_v, 2]) <= 0:
        raise ModelError("the mesh has no body of revolution about a vertical axis (everything "
                         "lies outside its radius profile): is it upright with z up?",
                         field="vertices")
    bottom = float(V[body_v, 2].min())
    top = float(V[body_v, 2].max())
    H = top - bottom

    # yaw: the handle (its largest cluster by angle) towards +x
    va = _vertex_area(V, F, area)
    yaw = 0.0
    has_handle = handle_v.any() and va[handle_v].sum() > 0
    if has_handle:
        hv = V[handle_v, :2] - c
        ang = np.arctan2(hv[:, 1], hv[:, 0])
        wts = va[handle_v]
        hist = np.bincount(np.minimum(((ang + np.pi) / (2 * np.pi) * SECTORS).astype(int),
                                      SECTORS - 1), weights=wts, minlength=SECTORS)
        smooth = hist + np.roll(hist, 1) + np.roll(hist, -1)
        peak = -np.pi + (np.argmax(smooth) + 0.5) * 2 * np.pi / SECTORS
        near = np.abs(np.angle(np.exp(1j * (ang - peak)))) < math.radians(60)
        yaw = float(np.angle(np.sum(wts[near] * np.exp(1j * ang[near]))))
        n_clusters = int((smooth > 0.25 * smooth.max()).sum() > 0) + int(
            hist[np.abs(np.angle(np.exp(1j * (-np.pi + (np.arange(SECTORS) + 0.5) * 2 * np.pi
                                               / SECTORS - peak)))) > math.radians(90)].sum()
            > 0.25 * hist.sum())
        notes.append(f"handle: {handle_v.sum()} vertices more than {1000 * tol:.1f} mm outside the "
                     f"body's radius profile or above its top; O's x points at "
                     f"{'the larger of two handles' if n_clusters > 1 else 'it'} "
                     f"(yaw {math.degrees(yaw):.1f}° in the input)")
    else:
        notes.append("no handle (nothing outside the body of revolution): O's x keeps the "
                     "input's x direction")
    cy, sy = math.cos(yaw), math.sin(yaw)
    R = np.array([[cy, sy, 0.0], [-sy, cy, 0.0], [0.0, 0.0, 1.0]])
    X_OM = _transform(R, np.array([c[0], c[1], bottom]))
    p_O = _apply(X_OM, V)

    # labels: thirds of the body's height, plus the handle
    zO = p_O[:, 2]
    labels = np.where(zO >= 2 * H / 3 - CUT_TOLERANCE, TOP,
                      np.where(zO >= H / 3 - CUT_TOLERANCE, MIDDLE, BOTTOM)).astype(np.uint8)
    labels[handle_v] = HANDLE

    # inner surface: faces turned to the axis and not downwards, inside the body's radius
    inward = (radial < 0) & (Nc[:, 2] > -0.2)
    rin = _group_median(key[inward], r[inward], n_cuts * SECTORS).reshape(n_cuts, SECTORS)
    in_occ = np.isfinite(rin)
    # an inner surface holds a fair share of the cut (not a few stray faces turned inwards)
    share = np.bincount(kc[inward], minlength=n_cuts) / np.maximum(
        np.bincount(kc, minlength=n_cuts), 1)
    cav_cut = (in_occ.mean(1) >= COVERAGE) & body_cut & (share >= INNER_SHARE)
    cav_idx = np.nonzero(cav_cut)[0]
    depth = (cav_idx.max() - cav_idx.min() + 1) * dz if len(cav_idx) else 0.0
    is_open = len(cav_idx) > 0 and depth >= OPEN_DEPTH * H
    Rmax = float(np.nanmax(R_body))
    dims = {"height": H, "diameter": 2 * Rmax}
    if is_open:
        R_in = _row_median(rin, in_occ)
        # a sector far off its cut's median (a handle's inner side) takes the median
        far = np.abs(rin - R_in[:, None]) > np.maximum(0.1 * R_in[:, None], 0.002)
        rin = np.where(in_occ & far, R_in[:, None], rin)
        outward = radial > 0.3
        rout = _group_median(key[outward], r[outward], n_cuts * SECTORS).reshape(n_cuts, SECTORS)
        R_out = _row_median(rout, np.isfinite(rout))
        lo, hi = levels[cav_idx.min()], levels[cav_idx.max()]
        mid = cav_cut & (levels > lo + 0.3 * (hi - lo)) & (levels < lo + 0.7 * (hi - lo))
        if not mid.any():
            mid = cav_cut
        # across the wall: the radial gap times the cosine of the wall's tilt from vertical
        tilt_cos = float(np.median(-radial[inward & mid[kc]]))
        wall = float(np.nanmedian((R_out - R_in)[mid])) * tilt_cos
        # base: the inner bottom — upward faces near the axis, else the lowest cut with a cavity
        up = (Ns[:, 2] > 0.9) & (np.linalg.norm(P[:, :2] - c, axis=1) < 0.5 * R_in[cav_idx[0]]) \
            & (P[:, 2] < lo + 0.25 * (hi - lo))
        base = float(np.median(P[up, 2]) - bottom) if up.sum() >= 5 else float(lo - dz / 2 - bottom)
        # brim-full: water stands up to the rim's lowest point (the lowest sector's crest)
        bv = p_O[body_v]
        sec_v = np.minimum(((np.arctan2(bv[:, 1], bv[:, 0]) + np.pi) / (2 * np.pi) * SECTORS)
                           .astype(int), SECTORS - 1)
        crest = _sector_reduce(sec_v, bv[:, 2], SECTORS, np.maximum, -np.inf)
        fill = bottom + float(crest[np.isfinite(crest)].min())
        full = cav_cut & (levels <= fill) & (levels >= bottom + base)
        n_in = in_occ.sum(1)
        # polar area over the sectors
        a_cut = np.pi * np.where(in_occ, rin, 0.0) ** 2 @ np.ones(SECTORS) / np.maximum(n_in, 1)
        a_cut = np.where(full, np.nan_to_num(a_cut), 0.0)
        vol = float(a_cut.sum() * dz)
        cz = float((a_cut * (levels - bottom)).sum() * dz / vol) if vol > 0 else 0.0
        dims.update(wall=wall, base=base)
        notes.append(f"open vessel: an inner surface over {100 * depth / H:.0f} % of the height; "
                     f"wall {1000 * wall:.1f} mm (outer − inner radius across the wall), base "
                     f"{1000 * base:.1f} mm; cavity filled to the rim's lowest point, "
                     f"{1000 * (fill - bottom):.1f} mm up")
        open_wall = wall
    else:
        wall = WALL_PRIOR.get(category, WALL_PRIOR_DEFAULT)
        keep = body_cut & (levels >= bottom + wall) & (levels <= top - wall)
        a_cut = np.where(keep, np.clip(sec_area - sec_len * wall, 0, None), 0.0)
        vol = float(a_cut.sum() * dz)
        cz = float((a_cut * (levels - bottom)).sum() * dz / vol) if vol > 0 else 0.0
        dims.update(wall=wall, base=wall)
        notes.append(f"closed container (no inner surface over {100 * OPEN_DEPTH:.0f} % of the "
                     f"height): wall {1000 * wall:.2f} mm is a prior for "
                     f"{category or 'an unknown category'}; cavity = enclosed volume less a shell "
                     f"of that wall")
        open_wall = None
    if has_handle:
        hp = p_O[handle_v]
        rh = np.linalg.norm(hp[:, :2], axis=1)
        kh = np.clip(((hp[:, 2]) / dz).astype(int), 0, n_cuts - 1)
        # reach beyond the wall, from the handle's vertex nearest the body
        gap = rh - np.where(np.isfinite(Rb[kh]), Rb[kh], np.inf)
        root = int(np.argmin(np.where(np.isfinite(gap), gap, np.inf)))
        R_root = Rb[kh[root]] if np.isfinite(Rb[kh[root]]) else Rmax
        dims["handle_length"] = float(rh.max() - R_root)
    parts = tuple(p for k, p in enumerate(PART_LABELS) if (labels == k).any())
    widths = _grasp_widths(p_O, labels, open_wall)
    return X_OM, labels, parts, dims, widths, vol, (0.0, 0.0, cz), open_wall


# ------------------------------------------------------------------------------------------------
# Tools


def _resting_normal(V, F, area, e3):
    """Outward normal of the hull facet the tool rests on (see the module docstring)."""
    com, _ = _centre_of_mass(V, F, area)
    hull = trimesh.convex.convex_hull(V)
    hf = hull.faces
    hv = hull.vertices
    groups = [np.asarray(g) for g in hull.facets]
    in_facet = np.zeros(len(hf), bool)
    for g in groups:
        in_facet[g] = True
    groups += [np.array([i]) for i in np.nonzero(~in_facet)[0]]
    best, best_h = None, np.inf
    fn = hull.face_normals
    for g in groups:
        n = fn[g].mean(0)
        n /= np.linalg.norm(n)
        if abs(n @ e3) < 0.5:
            continue
        d = float(n @ hv[hf[g[0], 0]])
        h = d - float(n @ com)
        if h >= best_h:
            continue
        q = com + h * n  # projection onto the facet's plane
        a, b, cc = hv[hf[g, 0]], hv[hf[g, 1]], hv[hf[g, 2]]
        # inside one of its triangles (barycentric, 1e-9 slack)
        v0, v1, v2 = b - a, cc - a, q - a
        d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
        d20, d21 = (v2 * v0).sum(1), (v2 * v1).sum(1)
        den = d00 * d11 - d01 ** 2
        ok = den > 0
        vv = np.where(ok, (d11 * d20 - d01 * d21) / np.where(ok, den, 1), -1)
        ww = np.where(ok, (d00 * d21 - d01 * d20) / np.where(ok, den, 1), -1)
        if np.any((vv >= -1e-9) & (ww >= -1e-9) & (vv + ww <= 1 + 1e-9)):
            best, best_h = n, h
    return best


def _two_segments(S):
    """Best split k (1..B−1) of the rows of S (B, C) into two constant segments (least squares)."""
    B = len(S)
    c1 = np.cumsum(S, 0)
    c2 = np.cumsum(S ** 2, 0)
    k = np.arange(1, B)
    nl, nr = k, B - k
    sl, sl2 = c1[k - 1], c2[k - 1]
    sr, sr2 = c1[-1] - sl, c2[-1] - sl2
    sse = (sl2 - sl ** 2 / nl[:, None] + sr2 - sr ** 2 / nr[:, None]).sum(1)
    return int(k[np.argmin(sse)])


def _tool(V, F, N, area, P, Ns, category, notes):
    mu = P.mean(0)
    _, _, Wt = np.linalg.svd(P - mu, full_matrices=False)
    e1, e3 = Wt[0], Wt[2]
    n = _resting_normal(V, F, area, e3)
    if n is None:
        # the side away from the centre of mass... both are alike: take −e3's
        n = -e3
        notes.append("tool: no hull facet near the thinnest axis holds the centre of mass; z is "
                     "the thinnest principal axis of the surface")
    else:
        notes.append("tool: z is the normal of the hull facet it rests on (the lowest centre of "
                     "mass among those facing within 60° of its thinnest axis)")
    z = -n
    x = e1 - (e1 @ z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    # x turned in the resting plane, within ±MAX_X_TURN of the principal axis, to the narrowest
    # bounding box (a knife's offset blade tilts the principal axis off its spine)
    uv = V @ np.stack([x, y]).T
    phi = np.radians(np.arange(-MAX_X_TURN, MAX_X_TURN + 1e-9, 0.25))
    wy = -np.sin(phi)[:, None] * uv[:, 0] + np.cos(phi)[:, None] * uv[:, 1]  # y after turning
    turn = phi[int(np.argmin(np.ptp(wy, axis=1) + 1e-9 * np.abs(phi)))]
    x, y = math.cos(turn) * x + math.sin(turn) * y, -math.sin(turn) * x + math.cos(turn) * y
    R = np.stack([x, y, z])
    q = P @ R.T
    qv = V @ R.T
    x0, x1 = float(qv[:, 0].min()), float(qv[:, 0].max())
    edges = np.linspace(x0, x1, TOOL_BINS + 1)
    b = np.clip(np.searchsorted(edges, q[:, 0], side="right") - 1, 0, TOOL_BINS - 1)
    ymax = _sector_reduce(b, q[:, 1], TOOL_BINS, np.maximum, -np.inf)
    ymin = _sector_reduce(b, q[:, 1], TOOL_BINS, np.minimum, np.inf)
    zmax = _sector_reduce(b, q[:, 2], TOOL_BINS, np.maximum, -np.inf)
    zmin = _sector_reduce(b, q[:, 2], TOOL_BINS, np.minimum, np.inf)
    width, thick = ymax - ymin, zmax - zmin
    good = np.isfinite(width)
    xc = 0.5 * (edges[:-1] + edges[1:])
    width = np.interp(xc, xc[good], width[good])
    thick = np.interp(xc, xc[good], thick[good])
    S = np.log(np.stack([np.maximum(width, 0.1 * width.max()),
                         np.maximum(thick, 0.1 * thick.max())], 1))
    k = _two_segments(S)
    lvl_a, lvl_b = S[:k].mean(0), S[k:].mean(0)
    wa, wb = np.exp(lvl_a), np.exp(lvl_b)  # (width, thickness) of either segment
    if category in TOOL_RULES:
        usable, ch, frac, rule = TOOL_RULES[category]
        sign = 1 if usable == "wider" else -1
        usable_high = sign * (lvl_b[ch] - lvl_a[ch]) > 0
    else:
        ch, frac = int(np.argmax(np.abs(lvl_b - lvl_a))), 0.5
        g = np.log(np.array(GRIP_SECTION))
        da, db = np.abs(np.log(wa) - g).sum(), np.abs(np.log(wb) - g).sum()
        usable_high = db > da
        rule = ("category unknown: the handle is the segment whose section is nearer a hand "
                "grip's (a guess)")
    # the segments' typical sections (medians: rounded ends and tapering tips do not count)
    med_a, med_b = np.median(S[:k, ch]), np.median(S[k:, ch])
    h_lvl, u_lvl = (med_a, med_b) if usable_high else (med_b, med_a)
    sig = S[:, ch] - (h_lvl + frac * (u_lvl - h_lvl))
    # the crossing of that level nearest the step
    cross = np.nonzero(np.sign(sig[:-1]) != np.sign(sig[1:]))[0]
    if len(cross):
        j = int(cross[np.argmin(np.abs(cross + 0.5 - k))])
        t = sig[j] / (sig[j] - sig[j + 1])
        split = float(xc[j] + t * (xc[j + 1] - xc[j]))
    else:
        split = float(edges[k])
    if category == "cooking_tool":
        # a neck (the handle narrowing before the head) is handle up to its narrowest section
        side = (xc < split) if usable_high else (xc > split)
        near = side & (np.abs(xc - split) < NECK_SEARCH * (x1 - x0))
        if near.any():
            j = int(np.flatnonzero(near)[np.argmin(S[near, ch])])
            if S[j, ch] < h_lvl + math.log(NECK_NARROWING):
                # a bin reports its widest section: the narrowest lies up to a bin further on
                step = edges[1] - edges[0]
                split = float(edges[j + 1] + step if usable_high else edges[j] - step)
                rule += "; the neck is handle up to its narrowest section"
    if not usable_high:
        R = np.stack([-x, -y, z])
        qv = V @ R.T
        split = -split
    handle = qv[:, 0] < split
    lo, hi = qv.min(0), qv.max(0)
    origin_q = np.array([0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]])
    X_OM = np.eye(4)
    X_OM[:3, :3] = R
    X_OM[:3, 3] = -origin_q
    p_O = _apply(X_OM, V)
    labels = np.where(handle, HANDLE, USABLE).astype(np.uint8)
    split_O = split - origin_q[0]
    ext = hi - lo
    dims = {"length": float(ext[0]), "width": float(ext[1]), "thickness": float(ext[2]),
            "handle_length": float(split_O - p_O[:, 0].min())}
    notes.append(f"tool: handle | usable area split {1000 * dims['handle_length']:.1f} mm from "
                 f"the handle's end (two-segment fit of the section's "
                 f"{('width', 'thickness')[ch]} along the long axis); {rule}")
    parts = tuple(p for k_, p in enumerate(PART_LABELS) if (labels == k_).any())
    return X_OM, labels, parts, dims, _grasp_widths(p_O, labels, None)


# ------------------------------------------------------------------------------------------------


def derive_frame(vertices: np.ndarray, faces: np.ndarray, category: str | None, *,
                 labels: np.ndarray | None = None) -> ObjectFrame:
    """The object frame, part labels, dimensions, grasp widths and cavity of a mesh (see the
    module docstring). `labels` (one per vertex, PART_LABELS indices) replace the derived ones.
    ModelError naming what is wrong for an empty or malformed mesh, labels of the wrong length or
    out of range, or an unknown category."""
    V, F, L = _check(vertices, faces, category, labels)
    N, area = _face_geometry(V, F)
    notes: list[str] = []
    P, Ns = _samples(V, F, N, area)
    if category is None:
        score, c, Rm = _revolution_score(P, Ns, float(area.sum()))
        aspect = float(np.ptp(V[:, 2]) / (2 * Rm)) if Rm > 0 else np.inf
        th = np.linspace(0, np.pi, 90, endpoint=False)
        proj = V[:, :2] @ np.stack([np.cos(th), np.sin(th)])
        reach = float((proj.max(0) - proj.min(0)).max() / (2 * Rm)) if Rm > 0 else np.inf
        is_container = (score >= REVOLUTION_MIN and aspect <= MAX_CONTAINER_ASPECT
                        and reach <= MAX_CONTAINER_REACH)
        notes.append(f"category not given: {'a container' if is_container else 'a tool'} from the "
                     f"shape ({100 * score:.0f} % of the side surface faces one vertical axis, "
                     f"needed {100 * REVOLUTION_MIN:.0f} %; height {aspect:.1f} diameters, at "
                     f"most {MAX_CONTAINER_ASPECT:g}; {reach:.1f} diameters across, at most "
                     f"{MAX_CONTAINER_REACH:g})")
    else:
        is_container = category not in TOOL_CATEGORIES
    container = None
    if is_container:
        try:
            container = _container(V, F, N, area, P, Ns, category, notes)
        except ModelError:
            if category is not None:
                raise
        if category is None:
            share = 0.0 if container is None else container[3]["height"] / float(np.ptp(V[:, 2]))
            if share < MIN_BODY_SHARE:
                notes.clear()
                notes.append(f"category not given: a tool from the shape (its body of revolution "
                             f"spans {100 * share:.0f} % of its height, less than "
                             f"{100 * MIN_BODY_SHARE:.0f} %: a bowl on a handle)")
                container = None
    if container is not None:
        X_OM, lab, parts, dims, widths, vol, cen, open_wall = container
        kind, cavity_volume, cavity_centroid = "container", vol, cen
    else:
        X_OM, lab, parts, dims, widths = _tool(V, F, N, area, P, Ns, category, notes)
        kind, cavity_volume, cavity_centroid, open_wall = "tool", None, None, None
    if L is not None:
        lab = L
        parts = tuple(p for k, p in enumerate(PART_LABELS) if (lab == k).any())
        widths = _grasp_widths(_apply(X_OM, V), lab, open_wall)
        notes.append("part labels: given by the user (derived ones discarded)")
    return ObjectFrame(X_OM=X_OM, kind=kind, labels=lab, parts=parts,
                       dimensions={k: float(v) for k, v in dims.items()},
                       grasp_widths={k: float(v) for k, v in widths.items()},
                       cavity_volume=cavity_volume, cavity_centroid=cavity_centroid,
                       notes=tuple(notes))
