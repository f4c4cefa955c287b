"""Generates the object library in models/objects/ from parametric shape families.

    python tools/make_objects.py            # (re)write models/objects/ (set a, shipped)
    python tools/make_objects.py --check    # regenerate into a temp dir, compare bytes,
                                            # exit 1 on a difference
    python tools/make_objects.py --out DIR  # write elsewhere
    python tools/make_objects.py --set b    # set b: models/objects_b/ (with --check, --out)

Two object sets, one format. Set a is the shipped library (SEED, RANGES, VARIANTS). Set b (issue
20's held-out protocol, scenarios/suites/split.yaml) has another seed and wider shape families —
lidded pots, pots with two side handles, stemmed glasses, squat and tall cans, square and
shouldered bottles, mugs with varied handles, flat knives 2–5 mm thick, heavy hammers, ladles —
whose parameters are the one table FAMILIES_B; it is a user library (ids <category>_bNN, its
folder named in a scenario's `object_libraries:`), its library.yaml entries adding `family`.

Every object of the 11 categories is built from a few closed-surface primitives, with NumPy only
(scipy for convex hulls):

- a *loft*: rings of vertices (K, n, 3) joined by quads, closed by a fan to a pole at either end. A
  revolved profile (r, z) that starts and ends on the axis is a loft whose rings are circles (or
  superellipses); a container with a wall and a cavity is the profile bottom → outer wall → rim →
  inner wall → inner bottom, so the whole surface is one closed sheet;
- a *patch*: a rectangle of quads removed from a loft where a handle joins it;
- a *tube* swept along a planar Bézier curve, joined to a patch by a *band* (a strip of triangles
  zipped between the patch's boundary loop and the tube's first ring, by angle about the tube axis),
  and ending either in a second patch (a loop handle) or a rounded cap.

Each mesh is checked to be a closed, consistently oriented two-manifold with positive volume. Mass
properties are exact volume integrals of the closed mesh (signed tetrahedra), per material: a
sub-solid of another material (a wooden handle, an air-filled cavity) is integrated separately and
its share moved from the body's density to its own. The resting transforms come from the convex
hull:
for each pose, the object is put down on the hull face whose outward normal is closest to the pose's
"down" direction; from there it tips over any edge of its support polygon its centre of mass
projects beyond, and rolls over an edge it is within ROLL_MARGIN of when that lowers the centre of
mass (a mug on its side rolls until its handle touches, as it does in Drake).

Meshes are written with per-corner shading normals (Drake's renderer requires them; smooth across
edges under 40°, sharp at rims and bottoms) and 1 µm vertex resolution.

Object frame O: containers — origin at the centre of the bottom, z along the symmetry axis towards
the opening (or neck), handles towards +x. Tools — x along the long axis from the handle to the
usable area,
z the normal of the hull face the tool lies on (up), origin at the centre of the bottom face of the
axis-aligned bounding box, so the lying pose is the identity.

Shapes are drawn by Latin hypercube sampling within realistic ranges (fixed seed): each instance of
a
category falls in a different quarter of every range, so instances differ in size and proportions.
"""

from __future__ import annotations

import argparse
import filecmp
import math
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml
from scipy.spatial import ConvexHull

OUT = Path(__file__).resolve().parents[1] / "models" / "objects"
SEED = 20130706  # the library's one seed; every instance derives its own stream from it.
N_PER_CATEGORY = 4

# Kept identical to tg_drake.types (the tool runs without importing the package).
CATEGORIES = ("pan", "pot", "cup", "glass", "bowl", "bottle", "can",
              "hammer", "knife", "screwdriver", "cooking_tool")
PART_LABELS = ("top", "middle", "bottom", "handle", "usable_area")
TOP, MIDDLE, BOTTOM, HANDLE, USABLE = range(5)
TOOLS = ("hammer", "knife", "screwdriver", "cooking_tool")

# Density [kg/m³] and visual colour (RGB) of each material. Figures are handbook values for
# porcelain/stoneware, soda-lime glass, stainless steel, aluminium alloy, cast iron, beech, and
# moulded thermoplastics (PP/ABS/nylon ~1050–1150; PET 1380).
MATERIALS = {
    "ceramic": (2400.0, (0.93, 0.91, 0.86)),
    "glass": (2500.0, (0.70, 0.86, 0.90)),
    "steel": (7900.0, (0.62, 0.64, 0.67)),
    "aluminium": (2700.0, (0.80, 0.81, 0.83)),
    "cast_iron": (7200.0, (0.22, 0.22, 0.23)),
    "wood": (700.0, (0.62, 0.43, 0.24)),
    "plastic": (1100.0, (0.85, 0.20, 0.15)),
    "pet": (1380.0, (0.55, 0.80, 0.70)),
    "air": (0.0, (0.0, 0.0, 0.0)),
    # knife handles: scales around a full steel tang (about a quarter of the handle's volume)
    "wood_tang": (0.75 * 700.0 + 0.25 * 7900.0, (0.45, 0.30, 0.18)),
    "plastic_tang": (0.75 * 1100.0 + 0.25 * 7900.0, (0.12, 0.12, 0.12)),
}

# Suitable poses per category and the pose's "down" direction in the object frame. Bottles do not
# stand on their neck; pans and bowls do not roll on their rim; tools only lie flat ("sideways").
POSES_OF = {
    "pan": ("upright", "upsidedown"),
    "pot": ("upright", "sideways", "upsidedown"),
    "cup": ("upright", "sideways", "upsidedown"),
    "glass": ("upright", "sideways", "upsidedown"),
    "bowl": ("upright", "upsidedown"),
    "bottle": ("upright", "sideways"),
    "can": ("upright", "sideways", "upsidedown"),
    "hammer": ("sideways",), "knife": ("sideways",), "screwdriver": ("sideways",),
    "cooking_tool": ("sideways",),
}
DOWN = {"upright": (0.0, 0.0, -1.0), "upsidedown": (0.0, 0.0, 1.0), "sideways": (0.0, -1.0, 0.0)}
TOOL_DOWN = (0.0, 0.0, -1.0)
MAX_TILT = math.radians(35.0)  # a resting face further than this from "down" is another pose.
# An object whose COM projects less than this inside the face it stands on tips over the nearest
# edge. A facet strip of a tessellated round wall is 4–7 mm wide, and the compliant table lets the
# object rock over an edge: in simulation a mug on its side whose COM was 1.2 mm inside its strip
# rolled until its handle touched, as a real one does.
ROLL_MARGIN = 0.002
DECIMALS = 6  # vertex coordinates are written with 1 µm resolution.


# ------------------------------------------------------------------------------------------------
# Mesh assembly


class MeshBuilder:
    """Vertices with part labels and triangles, assembled piece by piece; faces can be removed."""

    def __init__(self):
        self._v: list[np.ndarray] = []
        self._l: list[np.ndarray] = []
        self._f: list[np.ndarray] = []
        self.nv = 0
        self.nf = 0
        self.dead: set[int] = set()

    def vertices(self, p, label) -> np.ndarray:
        p = np.asarray(p, float).reshape(-1, 3)
        idx = np.arange(self.nv, self.nv + len(p))
        self._v.append(p)
        self._l.append(np.broadcast_to(np.asarray(label, np.uint8), (len(p),)).copy())
        self.nv += len(p)
        return idx

    def faces(self, f) -> np.ndarray:
        f = np.asarray(f, np.int64).reshape(-1, 3)
        idx = np.arange(self.nf, self.nf + len(f))
        self._f.append(f)
        self.nf += len(f)
        return idx

    @property
    def V(self) -> np.ndarray:
        return np.concatenate(self._v)

    def face_array(self) -> np.ndarray:
        return np.concatenate(self._f)

    def result(self):
        F = self.face_array()
        keep = np.ones(len(F), bool)
        keep[list(self.dead)] = False
        F = F[keep]
        # vertices inside a removed patch are no longer used: drop them and renumber
        used = np.zeros(self.nv, bool)
        used[F.ravel()] = True
        new = np.cumsum(used) - 1
        return self.V[used], new[F], np.concatenate(self._l)[used]


def loft(mb: MeshBuilder, rings: np.ndarray, labels, start=None, end=None, start_label=0,
         end_label=0):
    """Joins rings (K, n, 3) by quads; optional poles close either end.

    Rings run anticlockwise about the direction of travel (ring k → k+1), so the surface faces
    outwards. Returns (ring vertex indices (K, n), quad face indices (K-1, n, 2)).
    """
    K, n = rings.shape[:2]
    labels = np.broadcast_to(np.asarray(labels, np.uint8), (K,))
    idx = mb.vertices(rings.reshape(-1, 3), np.repeat(labels, n)).reshape(K, n)
    j = np.arange(n)
    jn = (j + 1) % n
    if start is not None:
        s = mb.vertices(start, start_label)[0]
        mb.faces(np.stack([np.full(n, s), idx[0, jn], idx[0, j]], 1))
    a, b, c, d = idx[:-1, j], idx[:-1, jn], idx[1:, jn], idx[1:, j]
    quads = np.stack([np.stack([a, b, c], -1), np.stack([a, c, d], -1)], 2)  # (K-1, n, 2, 3)
    qf = mb.faces(quads.reshape(-1, 3)).reshape(K - 1, n, 2)
    if end is not None:
        e = mb.vertices(end, end_label)[0]
        mb.faces(np.stack([idx[-1, j], idx[-1, jn], np.full(n, e)], 1))
    return idx, qf


def remove_patch(mb: MeshBuilder, quad_faces: np.ndarray) -> np.ndarray:
    """Removes the given faces; returns their boundary loop in the removed faces' own direction
    (anticlockwise about the outward normal)."""
    fidx = quad_faces.reshape(-1)
    F = mb.face_array()[fidx]
    edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    inner = {(a, b) for a, b in edges.tolist()}
    nxt = {a: b for a, b in edges.tolist() if (b, a) not in inner}
    if len(nxt) != sum(1 for a, b in edges.tolist() if (b, a) not in inner):
        raise RuntimeError("patch boundary is not a simple loop")
    start = next(iter(nxt))
    loop = [start]
    while (v := nxt[loop[-1]]) != start:
        loop.append(v)
        if len(loop) > len(nxt):
            raise RuntimeError("patch boundary does not close")
    if len(loop) != len(nxt):
        raise RuntimeError("patch boundary has more than one loop")
    mb.dead.update(fidx.tolist())
    return np.array(loop)


def _angles(P, c, axis):
    u = np.cross(axis, [0.0, 0.0, 1.0])
    if np.linalg.norm(u) < 0.3:
        u = np.cross(axis, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(axis, u)
    d = P - c
    return np.mod(np.arctan2(d @ w, d @ u), 2 * np.pi)


def band(mb: MeshBuilder, A: np.ndarray, B: np.ndarray, axis: np.ndarray):
    """Triangles between loops A and B (both anticlockwise about `axis`, B further along it),
    zipped by angle about the axis. Uses A's edges forwards and B's backwards."""
    V = mb.V
    c = 0.5 * (V[A].mean(0) + V[B].mean(0))
    loops = []
    for L in (A, B):
        th = _angles(V[L], c, axis)
        k = int(np.argmin(th))
        L, th = np.roll(L, -k), np.roll(th, -k)
        if not np.all(np.diff(th) > 0):
            raise RuntimeError("band loop is not star-shaped about the tube axis")
        loops.append((L, np.append(th, th[0] + 2 * np.pi)))
    (A, ta), (B, tb) = loops
    m, n = len(A), len(B)
    i = j = 0
    tris = []
    while i < m or j < n:
        if j == n or (i < m and ta[i + 1] <= tb[j + 1]):
            tris.append((A[i % m], A[(i + 1) % m], B[j % n]))
            i += 1
        else:
            tris.append((A[i % m], B[(j + 1) % n], B[j % n]))
            j += 1
    mb.faces(tris)


# ------------------------------------------------------------------------------------------------
# Curves and sections


def superellipse(n: int, a, b, p=2.0, phase=0.0, flutes=0, flute_depth=0.0):
    """(n, 2) points of a superellipse |y/a|^p + |z/b|^p = 1, anticlockwise from +y."""
    th = phase + 2 * np.pi * np.arange(n) / n
    c, s = np.cos(th), np.sin(th)
    e = 2.0 / p
    r = 1.0 + flute_depth * np.cos(flutes * th) if flutes else 1.0
    return np.stack([a * np.sign(c) * np.abs(c) ** e * r, b * np.sign(s) * np.abs(s) ** e * r], 1)


def rounded_rect(n: int, a, b, rc):
    """(n, 2) points (n a multiple of 4) of a rectangle ±a × ±b with corners rounded to radius rc,
    anticlockwise from (a, 0), spaced evenly along the perimeter with a point on each end of every
    straight side (so a side is exactly flat, as wide as it really is)."""
    k = n // 4
    if 4 * k != n:
        raise ValueError("rounded_rect needs a multiple of 4 points")
    L1, L2 = b - rc, b - rc + np.pi * rc / 2  # quadrant path: side, arc, top side
    L = L2 + a - rc
    s = np.arange(k) * L / k
    for t in (L1, L2):  # snap the nearest free sample onto each tangent point
        free = np.arange(1, k)
        i = free[np.argmin(np.abs(s[free] - t))]
        s[i] = t
    s = np.sort(s)
    phi = np.clip((s - L1) / max(rc, 1e-12), 0, np.pi / 2)
    q = np.where((s <= L1)[:, None], np.stack([np.full(k, a), s], 1),
                 np.where((s <= L2)[:, None],
                          np.stack([a - rc + rc * np.cos(phi), b - rc + rc * np.sin(phi)], 1),
                          np.stack([a - rc - (s - L2), np.full(k, b)], 1)))
    q2 = np.concatenate([[[0.0, b]], q[:0:-1] * [-1, 1]])
    return np.concatenate([q, q2, -q, -q2])


def bezier(P0, P1, P2, P3, t):
    t = np.asarray(t)[:, None]
    return ((1 - t) ** 3 * P0 + 3 * (1 - t) ** 2 * t * P1 + 3 * (1 - t) * t ** 2 * P2
            + t ** 3 * P3)


def arclength_samples(curve, n_dense=2000):
    """Returns (s_total, f) where f(s) gives points and unit tangents at arc lengths s."""
    t = np.linspace(0.0, 1.0, n_dense)
    P = curve(t)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])

    def f(sv):
        tv = np.interp(sv, s, t)
        h = 1e-5
        p = curve(tv)
        d = curve(np.clip(tv + h, 0, 1)) - curve(np.clip(tv - h, 0, 1))
        return p, d / np.linalg.norm(d, axis=1, keepdims=True)
    return s[-1], f


def resample(poly: np.ndarray, key: np.ndarray, h: float, h_from=None) -> np.ndarray:
    """Resamples a dense 2-D polyline with at most `h` between points, keeping every key point.
    h_from[i] (if finite) overrides h for the piece that starts at key point i."""
    ks = np.flatnonzero(key)
    out = []
    for k0, k1 in zip(ks[:-1], ks[1:], strict=False):
        sub = poly[k0:k1 + 1]
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(sub, axis=0), axis=1))])
        hk = h if h_from is None or not np.isfinite(h_from[k0]) else h_from[k0]
        m = max(1, math.ceil(s[-1] / hk - 1e-9))
        sv = np.linspace(0.0, s[-1], m + 1)[:-1]
        out.append(np.stack([np.interp(sv, s, sub[:, 0]), np.interp(sv, s, sub[:, 1])], 1))
    out.append(poly[-1:])
    return np.concatenate(out)


class Profile:
    """A dense (r, z) polyline with key points (corners, part boundaries, patch edges)."""

    def __init__(self):
        self.pts: list[np.ndarray] = []
        self.key: list[np.ndarray] = []
        self.h: list[np.ndarray] = []

    def add(self, pts, keys=None, h=np.inf):
        pts = np.asarray(pts, float).reshape(-1, 2)
        k = np.zeros(len(pts), bool)
        k[[0, -1]] = True
        if keys is not None:
            k |= keys
        hh = np.full(len(pts), float(h))
        if self.pts and np.allclose(self.pts[-1][-1], pts[0]):
            self.key[-1][-1] = True
            self.h[-1][-1] = hh[0]
            pts, k, hh = pts[1:], k[1:], hh[1:]
        self.pts.append(pts)
        self.key.append(k)
        self.h.append(hh)

    def line(self, p0, p1, h=np.inf):
        """A straight piece; h: its own maximum point spacing (default: the profile's)."""
        self.add(np.array([p0, p1], float), h=h)

    def curve(self, f, u0, u1, z_keys=(), n=600):
        """Adds f(u) for u in [u0, u1]; points with z in z_keys (found on the dense curve) are
        keys."""
        u = np.linspace(u0, u1, n)
        P = f(u)
        extra = []
        for zk in z_keys:
            dz = P[:, 1] - zk
            cross = np.flatnonzero(np.sign(dz[:-1]) * np.sign(dz[1:]) < 0)
            for i in cross:
                lo, hi = u[i], u[i + 1]
                for _ in range(60):  # bisection to 1e-18 of the parameter interval
                    mid = 0.5 * (lo + hi)
                    if np.sign(f(np.array([mid]))[0, 1] - zk) == np.sign(P[i, 1] - zk):
                        lo = mid
                    else:
                        hi = mid
                extra.append(0.5 * (lo + hi))
        uu = np.concatenate([u, extra])
        order = np.argsort(uu) if u1 > u0 else np.argsort(-uu)
        uu = uu[order]
        keys = np.zeros(len(uu), bool)
        keys[np.isin(uu, extra)] = True
        self.add(f(uu), keys)

    def arc(self, p0, p1, bulge_dir, n=24):
        """Half circle from p0 to p1 bulging towards bulge_dir."""
        p0, p1 = np.asarray(p0), np.asarray(p1)
        c = 0.5 * (p0 + p1)
        r = 0.5 * np.linalg.norm(p1 - p0)
        a0 = math.atan2(*(p0 - c)[::-1])
        a1 = math.atan2(*(p1 - c)[::-1])
        mid = math.atan2(bulge_dir[1], bulge_dir[0])
        # go from a0 to a1 through `mid`
        span = (a1 - a0) % (2 * np.pi)
        if not ((mid - a0) % (2 * np.pi) < span):
            span -= 2 * np.pi
        t = a0 + span * np.linspace(0, 1, n)
        pts = c + r * np.stack([np.cos(t), np.sin(t)], 1)
        pts[0], pts[-1] = p0, p1
        self.add(pts)

    def resampled(self, h: float) -> np.ndarray:
        return resample(np.concatenate(self.pts), np.concatenate(self.key), h,
                        np.concatenate(self.h))


def revolve(profile: np.ndarray, n: int, *, p=2.0, R=None, origin=None, p_of_z=None):
    """Rings of a profile (r, z) from the axis to the axis, revolved about local z.

    Ring vertices sit at angles (j + ½)·2π/n, so faces are centred on multiples of 2π/n (a face
    points exactly along ±x and ±y when n is a multiple of 4). Returns (rings, start pole, end pole)
    in the frame (R, origin), by default the identity. p_of_z(z) (optional) gives each ring's
    section exponent from its height (a square body under a round neck).
    """
    R = np.eye(3) if R is None else R
    origin = np.zeros(3) if origin is None else origin
    inner = profile[1:-1]
    if p_of_z is None:
        sec = superellipse(n, 1.0, 1.0, p, phase=np.pi / n)[None, :, :]
    else:
        sec = np.stack([superellipse(n, 1.0, 1.0, float(pz), phase=np.pi / n)
                        for pz in p_of_z(inner[:, 1])])
    loc = np.concatenate([inner[:, :1, None] * sec,
                          np.broadcast_to(inner[:, None, 1:], (len(inner), n, 1))], 2)
    to_world = lambda q: q @ R.T + origin  # noqa: E731
    return (to_world(loc), to_world(np.array([0.0, 0.0, profile[0, 1]])),
            to_world(np.array([0.0, 0.0, profile[-1, 1]])))


# ------------------------------------------------------------------------------------------------
# Handles: tubes along planar curves, joined to patches


def select_quads(mb, qf, V, predicate):
    """Quads of a loft (by face-pair indices qf (K-1, n, 2)) whose centroid satisfies predicate."""
    F = mb.face_array()
    cen = V[F[qf[..., 0]]].mean(axis=2) * 0.5 + V[F[qf[..., 1]]].mean(axis=2) * 0.5
    nrm = np.cross(V[F[qf[..., 0], 1]] - V[F[qf[..., 0], 0]],
                   V[F[qf[..., 0], 2]] - V[F[qf[..., 0], 0]])
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True) + 1e-30
    mask = predicate(cen, nrm)
    if not mask.any():
        raise RuntimeError("empty patch")
    return qf[mask]


def tube(mb, curve, e_a, half_a, half_b, label, *, n_sec=16, h=0.008, p=2.0, start_loop=None,
         end_loop=None, cap=False, gap=0.002, taper=None):
    """Sweeps a (super)elliptical section along `curve` (t ∈ [0, 1] → points).

    e_a is the normal of the curve's plane: the section's `half_a` axis; the other axis is T × e_a.
    The tube starts `gap` after the curve's start (joined to start_loop by a band) and ends `gap`
    before its end (joined to end_loop) or in a rounded cap. taper(s_frac) scales the section.
    Returns (ring vertex indices, rings, cap pole or None).
    """
    e_a = np.asarray(e_a, float)
    L, f = arclength_samples(curve)
    s_end = L - (gap if end_loop is not None else 0.0)
    m = max(2, math.ceil((s_end - gap) / h) + 1)
    s = np.linspace(gap, s_end, m)
    C, T = f(s)
    sec = superellipse(n_sec, 1.0, 1.0, p)
    scale = np.ones(m) if taper is None else taper(s / L)
    rings = [C[i] + scale[i] * (half_a * sec[:, :1] * e_a
                                + half_b * sec[:, 1:] * np.cross(T[i], e_a))
             for i in range(m)]
    if cap:
        r_cap = min(half_a, half_b) * scale[-1]
        psi = np.linspace(0, np.pi / 2, 5)[1:-1]
        for ps in psi:
            c = C[-1] + T[-1] * r_cap * np.sin(ps)
            k = math.cos(ps) * scale[-1]
            rings.append(c + k * (half_a * sec[:, :1] * e_a
                                  + half_b * sec[:, 1:] * np.cross(T[-1], e_a)))
    rings = np.array(rings)
    end = C[-1] + T[-1] * min(half_a, half_b) * scale[-1] if cap else None
    idx, _ = loft(mb, rings, label, end=end, end_label=label)
    if start_loop is not None:
        band(mb, start_loop, idx[0], T[0])
    if end_loop is not None:
        band(mb, idx[-1], end_loop[::-1], T[-1])
    return idx, rings, end


def closed_tube_solid(rings, end_pole=None):
    """A closed mesh (V, F) of tube rings capped by planar fans (for a handle's own mass)."""
    mb = MeshBuilder()
    s = rings[0].mean(0)
    e = rings[-1].mean(0) if end_pole is None else end_pole
    loft(mb, rings, 0, start=s, end=e)
    V, F, _ = mb.result()
    return V, F


# ------------------------------------------------------------------------------------------------
# Mesh checks and mass properties


def check_closed(V, F, name):
    """Raises unless (V, F) is a closed, consistently oriented two-manifold with outward faces."""
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    if (e[:, 0] == e[:, 1]).any():
        raise RuntimeError(f"{name}: degenerate triangle")
    key = e[:, 0] * len(V) + e[:, 1]
    rev = e[:, 1] * len(V) + e[:, 0]
    if len(np.unique(key)) != len(key):
        raise RuntimeError(f"{name}: a directed edge is used twice (inconsistent orientation)")
    if not np.isin(rev, key).all():
        raise RuntimeError(f"{name}: open boundary edge")
    used = np.zeros(len(V), bool)
    used[F.ravel()] = True
    if not used.all():
        raise RuntimeError(f"{name}: unused vertices")
    if volume_integrals(V, F)[0] <= 0:
        raise RuntimeError(f"{name}: faces point inwards")


def volume_integrals(V, F):
    """(volume, first moment (3,), second moment ∫x xᵀ dV (3, 3)) of a closed mesh, unit density."""
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    v = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    s = a + b + c
    first = (v[:, None] * s).sum(0) / 4.0
    outer = (np.einsum("ni,nj->nij", a, a) + np.einsum("ni,nj->nij", b, b)
             + np.einsum("ni,nj->nij", c, c) + np.einsum("ni,nj->nij", s, s))
    second = (v[:, None, None] * outer).sum(0) / 20.0
    return v.sum(), first, second


@dataclass
class MassProperties:
    mass: float
    volume: float  # material volume [m³]
    com: np.ndarray
    inertia: np.ndarray  # about the COM, object-frame axes [kg·m²]


def mass_properties(V, F, density, pieces=()) -> MassProperties:
    """Mass properties of the solid bounded by (V, F) of `density`, where each sub-solid
    (Vp, Fp, density_p) of `pieces` has its own density (0 for a cavity)."""
    vol, m1, m2 = volume_integrals(V, F)
    mass, first, second, matvol = density * vol, density * m1, density * m2, vol
    for Vp, Fp, rho in pieces:
        pv, p1, p2 = volume_integrals(Vp, Fp)
        mass += (rho - density) * pv
        first += (rho - density) * p1
        second += (rho - density) * p2
        if rho == 0.0:
            matvol -= pv
    com = first / mass
    J = second - mass * np.outer(com, com)  # ∫ (x-c)(x-c)ᵀ dm
    inertia = np.trace(J) * np.eye(3) - J
    # Entries below the sums' rounding (double precision over ~10⁴ faces: 1e-12 of the trace) are
    # zero: a symmetric solid's products of inertia, which otherwise come out as ±1e-20 noise that
    # differs with the NumPy/BLAS build and keeps the files from being reproduced bit for bit.
    inertia[np.abs(inertia) < INERTIA_ROUNDING * np.trace(inertia)] = 0.0
    return MassProperties(mass, matvol, com, inertia)


INERTIA_ROUNDING = 1e-12  # relative to the trace of the inertia


# ------------------------------------------------------------------------------------------------
# Resting poses


def rot_to(n, target):
    """The smallest rotation taking unit vector n to target (a half turn about x or y if
    opposite)."""
    n, target = np.asarray(n, float), np.asarray(target, float)
    axis = np.cross(n, target)
    s, c = np.linalg.norm(axis), float(n @ target)
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        perp = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
        perp -= n * (perp @ n)
        perp /= np.linalg.norm(perp)
        return 2 * np.outer(perp, perp) - np.eye(3)
    k = axis / s
    Kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    ang = math.atan2(s, c)
    return np.eye(3) + math.sin(ang) * Kx + (1 - math.cos(ang)) * Kx @ Kx


PLANE_TOL = 2e-6  # [m] a hull vertex this close to a face's plane rests on the table with it
# (vertices are rounded to 1 µm).


def _support(hull, f, com):
    """The support polygon when the object stands on hull facet f: every hull vertex on f's plane.

    Returns (vertex ids on the plane, outward normal, the plane's 2-D basis (u, w), the polygon's
    edge lines in that basis (E, 3), the hull-vertex ids on each edge, the distance of the COM's
    projection inside each edge [m] (negative: outside))."""
    n, off = hull.equations[f, :3], hull.equations[f, 3]
    hv = hull.vertices
    verts = hv[np.abs(hull.points[hv] @ n + off) < PLANE_TOL]
    u = np.cross(n, [0, 0, 1.0]) if abs(n[2]) < 0.9 else np.cross(n, [1.0, 0, 0])
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    q = hull.points[verts] @ np.stack([u, w], 1)
    h2 = ConvexHull(q)
    inside = -(h2.equations[:, :2] @ np.array([com @ u, com @ w]) + h2.equations[:, 2])
    edges = []
    for k, line in enumerate(h2.equations):
        on = np.abs(q @ line[:2] + line[2]) < PLANE_TOL
        on[h2.simplices[k]] = True
        edges.append(verts[on])
    return verts, n, (u, w), h2.equations, edges, inside


def _across(hull, f, basis, line, edge):
    """The face the object lands on when it tips over an edge of its support polygon on facet f.

    Rotating about the edge line, a hull vertex at height h above the table and d beyond the edge
    touches down after atan2(h, d): the first to touch fixes the new plane, whose outward normal is
    n0·cos θ + t·sin θ (t: the edge's outward direction in the old plane). Returns (the hull facet
    in that plane, its normal, its offset)."""
    n0, off0 = hull.equations[f, :3], hull.equations[f, 3]
    t = line[0] * basis[0] + line[1] * basis[1]
    P = hull.points[hull.vertices]
    a = hull.points[edge[0]]
    d = (P - a) @ t
    h = -(P @ n0 + off0)
    beyond = d > PLANE_TOL
    if not beyond.any():
        return None
    theta = np.arctan2(h[beyond], d[beyond]).min()
    n1 = math.cos(theta) * n0 + math.sin(theta) * t
    face = int(np.argmax(hull.equations[:, :3] @ n1))
    return face, n1, -float(n1 @ a)


def resting_face(V, com, down, max_tilt=MAX_TILT):
    """The convex-hull face the object comes to rest on when put down with `down` (object frame)
    towards the table.

    Starts on the hull face closest to `down` and tips over edges of its support polygon: over the
    edge the COM projects beyond, if any; else over an edge the COM projects less than
    ROLL_MARGIN inside of, when the face beyond lowers the COM (a mug on its side rolls until its
    handle touches; a barrel-shaped wall made of narrow facet strips stays on the strip under its
    COM, the lowest). The COM's height drops at every roll, so the walk ends. Returns (outward
    unit normal, margin [m] of the COM inside the final support polygon); raises if that face is
    more than `max_tilt` from `down` (the pose does not suit the object).
    """
    hull = ConvexHull(V)
    down = np.asarray(down, float)
    f = int(np.argmax(hull.equations[:, :3] @ down))

    def height(n, off):  # of the COM above a plane (scipy: n·x + off <= 0 inside)
        return -(n @ com + off)

    for _ in range(len(hull.simplices)):
        verts, n, basis, lines, edges, inside = _support(hull, f, com)
        if inside.min() < 0:  # the COM is outside: it tips over that edge
            k = int(np.argmin(inside))
            nxt = _across(hull, f, basis, lines[k], edges[k])
            if nxt is None:
                raise RuntimeError("hull walk found no face across the tipping edge")
            f = nxt[0]
            continue
        options = []
        h0 = height(hull.equations[f, :3], hull.equations[f, 3])
        for k in np.flatnonzero(inside < ROLL_MARGIN):
            nxt = _across(hull, f, basis, lines[k], edges[k])
            if nxt is not None and height(nxt[1], nxt[2]) < h0 - 1e-9:
                options.append((height(nxt[1], nxt[2]), nxt[0]))
        if not options:
            break
        f = min(options)[1]
    else:
        raise RuntimeError("hull walk did not settle")
    margin = float(inside.min())
    if n @ down < math.cos(max_tilt):
        raise RuntimeError(f"put down towards {down.tolist()}, the object rolls to a face "
                           f"{math.degrees(math.acos(np.clip(n @ down, -1, 1))):.0f}° away")
    return n, margin


def rpy_of(R):
    """Drake's RollPitchYaw (R = Rz(y)·Ry(p)·Rx(r)) of a rotation matrix."""
    pitch = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    if abs(math.cos(pitch)) < 1e-9:
        return (math.atan2(-R[1, 2], R[1, 1]), pitch, 0.0)
    return (math.atan2(R[2, 1], R[2, 2]), pitch, math.atan2(R[1, 0], R[0, 0]))


# ------------------------------------------------------------------------------------------------
# Shape families


@dataclass
class Model:
    category: str
    V: np.ndarray
    F: np.ndarray
    labels: np.ndarray
    material: str  # main material (the body; for tools, the usable area's)
    part_materials: dict  # part name → material, where it differs from `material`
    pieces: list  # (V, F, material) sub-solids with their own material (cavities: "air")
    cavity: tuple | None  # containers: (volume [m³], height of its centroid [m]) filled to the rim
    dimensions: dict
    rim: dict = field(default_factory=dict)
    closed_top: bool = False  # an open-container category closed by a lid (no rim to pinch)
    poses: tuple | None = None  # the poses that suit it, when not its category's (POSES_OF)


def lhs(rng, n, ranges: dict) -> list[dict]:
    """Latin hypercube: n parameter sets, each range split in n strata, one sample per stratum."""
    out = [dict() for _ in range(n)]
    for name, (lo, hi) in ranges.items():
        strata = rng.permutation(n)
        u = (strata + rng.random(n)) / n
        for i in range(n):
            out[i][name] = lo + (hi - lo) * u[i]
    return out


def thirds_labels(z, H):
    """Part label of body vertices by height: bottom, middle, top thirds (1 µm tolerance so a ring
    placed on a boundary belongs to the part above it)."""
    return np.where(z >= 2 * H / 3 - 1e-6, TOP, np.where(z >= H / 3 - 1e-6, MIDDLE, BOTTOM))


def open_profile(H, r_bot, r_top, wall, base, beta, chamfer, h, z_keys=()):
    """(r, z) profile of an open container: bottom, outer wall, rounded rim, inner wall, inner
    bottom. Wall shape r(u) = r_bot + (r_top − r_bot)·((1−β)u + β√(1−(1−u)²)), z = uH; the inner
    wall is the outer wall offset by `wall` along its normal; the rim is rounded, its crest is the
    top of the body. Returns (profile, cavity volume, outer-wall radius function, body height);
    the profile has points at the thirds of the body height. The cavity is (volume, height of its
    centroid)."""
    def g(u):
        return (1 - beta) * u + beta * np.sqrt(np.clip(1 - (1 - u) ** 2, 0, None))

    def dg(u):
        return (1 - beta) + beta * (1 - u) / np.sqrt(np.clip(1 - (1 - u) ** 2, 1e-12, None))

    def outer(u):
        return np.stack([r_bot + (r_top - r_bot) * g(u), u * H], 1)

    def normal(u):
        d = np.stack([(r_top - r_bot) * dg(u), np.full_like(u, H)], 1)
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        return np.stack([d[:, 1], -d[:, 0]], 1)

    def inner(u):
        return outer(u) - wall * normal(u)

    u_c = chamfer / H
    uu = np.linspace(u_c, 1.0, 4000)
    zi = inner(uu)[:, 1]
    u_b = float(np.interp(base, zi, uu))  # inner wall meets the inner bottom at z = base
    o1, i1 = outer(np.array([1.0]))[0], inner(np.array([1.0]))[0]
    top = 0.5 * (o1[1] + i1[1]) + 0.5 * np.linalg.norm(o1 - i1)  # the rounded rim's crest
    keys = sorted(set([top / 3, 2 * top / 3, *z_keys]))
    pr = Profile()
    p_c = outer(np.array([u_c]))[0]
    # Flat bottoms are single fans: no rings needed for the shape, and every triangle on the table
    # is a polygon of the hydroelastic contact surface (fewer: faster contact).
    pr.line((0.0, 0.0), (p_c[0] - chamfer, 0.0), h=1.0)
    pr.line((p_c[0] - chamfer, 0.0), p_c)
    pr.curve(outer, u_c, 1.0, z_keys=[z for z in keys if chamfer < z < H])
    pr.arc(o1, i1, (0.0, 1.0), n=5)
    pr.curve(inner, 1.0, u_b, z_keys=[z for z in keys if base < z < i1[1]])
    ib = inner(np.array([u_b]))[0]
    pr.line(ib, (0.0, ib[1]), h=1.0)
    prof = pr.resampled(h)
    # Cavity (filled to the inner rim): volume of revolution π ∮ r² dz of the inner region.
    cav = np.concatenate([inner(np.linspace(u_b, 1.0, 4000)), [[0.0, i1[1]]], [[0.0, ib[1]]]])
    r0, z0 = cav[:, 0], cav[:, 1]
    r1, z1 = np.roll(r0, -1), np.roll(z0, -1)
    vol = np.pi * np.sum((z1 - z0) * (r0 ** 2 + r0 * r1 + r1 ** 2) / 3.0)
    mz = np.pi * np.sum((z1 - z0) * ((r0 + r1) / 2) ** 2 * (z0 + z1) / 2)  # midpoint rule, 4000 pts
    cavity = (abs(vol), mz / vol)
    return prof, cavity, (lambda z: r_bot + (r_top - r_bot) * g(np.asarray(z) / H)), top


def offset_closed_profile(prof, t):
    """The profile (axis to axis) offset inwards by t (a cavity wall), poles kept on the axis."""
    d = np.diff(prof, axis=0)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    nseg = np.stack([d[:, 1], -d[:, 0]], 1)  # outward normal of each segment
    nv = np.zeros_like(prof)
    nv[:-1] += nseg
    nv[1:] += nseg
    nv /= np.linalg.norm(nv, axis=1, keepdims=True)
    cos_half = np.ones(len(prof))
    cos_half[1:-1] = np.clip(np.einsum("ij,ij->i", nv[1:-1], nseg[1:]), 0.3, 1.0)
    q = prof - t * nv / cos_half[:, None]
    q[0] = (0.0, prof[0, 1] + t)
    q[-1] = (0.0, prof[-1, 1] - t)
    return q


def body_of_revolution(mb, prof, n, *, label_fn, R=None, origin=None, p=2.0, p_of_z=None):
    rings, s, e = revolve(prof, n, p=p, R=R, origin=origin, p_of_z=p_of_z)
    labels = label_fn(prof)
    idx, qf = loft(mb, rings, labels[1:-1], start=s, end=e, start_label=labels[0],
                   end_label=labels[-1])
    return idx, qf


def patch_on_wall(mb, qf, phi_c, half_width, z_lo, z_hi, outward=True):
    """The quads of a revolved wall centred at angle phi_c within ±half_width (arc length at the
    wall) between heights z_lo and z_hi, on the outside of the wall."""
    V = mb.V

    def pred(c, nrm):
        phi = np.arctan2(c[..., 1], c[..., 0])
        dphi = np.angle(np.exp(1j * (phi - phi_c)))
        rad = np.hypot(c[..., 0], c[..., 1])
        radial = nrm[..., 0] * np.cos(phi) + nrm[..., 1] * np.sin(phi)
        return ((np.abs(dphi) * rad <= half_width) & (c[..., 2] > z_lo) & (c[..., 2] < z_hi)
                & ((radial > 0.5) if outward else (radial < -0.5)))
    return remove_patch(mb, select_quads(mb, qf, V, pred))


def wall_point(r_of_z, phi, z, dz=1e-4):
    """A point on a revolved wall, with the wall's outward normal."""
    r = float(r_of_z(z))
    drdz = (float(r_of_z(z + dz)) - float(r_of_z(z - dz))) / (2 * dz)
    c, s = math.cos(phi), math.sin(phi)
    n = np.array([c, s, -drdz])
    return np.array([r * c, r * s, z]), n / np.linalg.norm(n)


def side_handles(mb, qf, r_of_z, r_top, zh, hp, P):
    """Two loop handles at ±x on a revolved wall (a pot's), centred at height zh, each spanning
    P["span"] along the wall, of round section radius P["hr"], reaching P["reach"] out. Returns
    their closed solids (for a handle of its own material)."""
    e_z = np.array([0.0, 0.0, 1.0])
    half_span = P["span"] / 2
    pieces = []
    for phi0 in (0.0, np.pi):
        ends = []
        for sgn in (-1, 1):
            phi = phi0 + sgn * half_span / r_top
            ends.append((phi, *wall_point(r_of_z, phi, zh)))
        loops = [patch_on_wall(mb, qf, phi, P["hr"] + 0.004, zh - hp, zh + hp)
                 for phi, _, _ in ends]
        (_, p1, n1), (_, p2, n2) = ends
        k = P["reach"] * 1.3
        curve = lambda t, p1=p1, n1=n1, p2=p2, n2=n2, k=k: bezier(  # noqa: E731
            p1, p1 + k * n1, p2 + k * n2, p2, t)
        tidx, rings, _ = tube(mb, curve, e_z, P["hr"], P["hr"], HANDLE,
                              start_loop=loops[0], end_loop=loops[1], h=0.008, n_sec=12)
        pieces.append(closed_tube_solid(rings))
    return pieces


def make_open_container(category, P, variant):
    """pan, pot, cup, glass, bowl: a revolved profile with a cavity, plus handles."""
    H, r_top, wall, base = P["H"], P["r_top"], P["wall"], P["base"]
    r_bot = P["r_bot"]
    n = {"pan": 48, "pot": 48, "cup": 40, "glass": 40, "bowl": 48}[category]
    h = {"pan": 0.016, "pot": 0.015, "cup": 0.009, "glass": 0.011, "bowl": 0.011}[category]
    mb = MeshBuilder()
    z_keys = []
    if category == "cup":
        z1, z2 = P["z1"] * H, P["z2"] * H
        hp = P["hb"] + 0.0035  # patch half height: handle half thickness + a flange
        z_keys += [z1 - hp, z1 + hp, z2 - hp, z2 + hp]
    elif category == "pan":
        zh = H - P["hb"] - 0.008
        hp = P["hb"] + 0.002
        z_keys += [zh - hp, zh + hp]
    elif category == "pot":
        zh = H - P["hr"] - 0.012
        hp = P["hr"] + 0.003
        z_keys += [zh - hp, zh + hp]
    prof, cavity, r_of_z, top = open_profile(H, r_bot, r_top, wall, base, P["beta"],
                                             P["chamfer"], h, z_keys)
    lab = lambda pr: thirds_labels(pr[:, 1], top)  # noqa: E731
    idx, qf = body_of_revolution(mb, prof, n, label_fn=lab)
    e_y = np.array([0.0, 1.0, 0.0])
    pieces = []
    dims = {"height": top, "diameter": 2 * r_top, "bottom_diameter": 2 * r_bot, "wall": wall,
            "base": base}
    if category == "cup":
        reach = P["reach"]
        A = patch_on_wall(mb, qf, 0.0, P["ha"] + 0.004, z1 - hp, z1 + hp)
        B = patch_on_wall(mb, qf, 0.0, P["ha"] + 0.004, z2 - hp, z2 + hp)
        p1, n1 = wall_point(r_of_z, 0.0, z1)
        p2, n2 = wall_point(r_of_z, 0.0, z2)
        k = reach * 1.2
        curve = lambda t: bezier(p1, p1 + k * n1, p2 + k * n2, p2, t)  # noqa: E731
        tidx, rings, _ = tube(mb, curve, e_y, P["ha"], P["hb"], HANDLE, start_loop=A,
                              end_loop=B, h=0.007, p=P.get("handle_p", 2.0))
        pieces.append(closed_tube_solid(rings))
        dims["handle_reach"] = float(mb.V[tidx][:, 0].max() - r_of_z(z1))
    elif category == "pan":
        p1, n1 = wall_point(r_of_z, 0.0, zh)
        A = patch_on_wall(mb, qf, 0.0, P["ha"] + 0.002, zh - hp, zh + hp)
        d = np.array([math.cos(P["angle"]), 0.0, math.sin(P["angle"])])
        p3 = p1 + P["L"] * d
        curve = lambda t: bezier(p1, p1 + 0.03 * n1, p3 - 0.05 * d, p3, t)  # noqa: E731
        taper = lambda s: 0.8 + 0.2 * np.clip(s * 3, 0, 1)  # noqa: E731  # narrower at the root
        tidx, rings, pole = tube(mb, curve, e_y, P["ha"], P["hb"], HANDLE, start_loop=A,
                                 cap=True, h=0.02, n_sec=16, taper=taper)
        pieces.append(closed_tube_solid(rings, end_pole=pole))
        dims["handle_length"] = P["L"]
    elif category == "pot":
        pieces += side_handles(mb, qf, r_of_z, r_top, zh, hp, P)
        dims["handle_reach"] = P["reach"]
    V, F, L = mb.result()
    mats = variant["materials"]
    handle_mat = mats.get("handle", variant["material"])
    solids = ([(Vp, Fp, handle_mat) for Vp, Fp in pieces]
              if handle_mat != variant["material"] else [])
    return Model(category, V, F, L, variant["material"],
                 {"handle": handle_mat} if solids else {}, solids, cavity, dims,
                 rim={"wall": wall, "opening_radius": r_top - wall})


def make_closed_container(category, P, variant):
    """bottle, can: a closed revolved shell; the cavity is a sub-solid of air."""
    n, h = 40, (0.012 if category == "bottle" else 0.010)
    pr = Profile()
    R, H = P["R"], P["H"]
    if category == "bottle":
        rn, hn, hs = P["rn"], P["neck"], P["shoulder"]
        h_body = H - hn - hs
        punt = P["punt"]
        pr.line((0.0, punt), (0.72 * R, 0.0))
        pr.line((0.72 * R, 0.0), (R - 0.004, 0.0))
        pr.line((R - 0.004, 0.0), (R, 0.004))
        pr.curve(lambda u: np.stack([np.full_like(u, R), 0.004 + u * (h_body - 0.004)], 1), 0, 1,
                 z_keys=[H / 3, 2 * H / 3])

        def shoulder(u):  # a smooth (cosine) blend from the body radius to the neck radius
            return np.stack([rn + (R - rn) * 0.5 * (1 + np.cos(np.pi * u)), h_body + u * hs], 1)
        pr.curve(shoulder, 0, 1, z_keys=[H / 3, 2 * H / 3])
        lip = 0.012
        pr.curve(lambda u: np.stack([np.full_like(u, rn), h_body + hs + u * (hn - lip)], 1), 0, 1,
                 z_keys=[2 * H / 3])
        rl = rn + P["lip"]
        pr.line((rn, H - lip), (rl, H - lip + 0.002))
        pr.line((rl, H - lip + 0.002), (rl, H - 0.001))
        pr.line((rl, H - 0.001), (rl - 0.001, H))
        pr.line((rl - 0.001, H), (0.0, H))
        dims = {"height": H, "diameter": 2 * R, "neck_diameter": 2 * rn, "wall": P["wall"]}
    else:  # can: stands on a ring, rolled bead at the top, recessed lid
        dome, bead = 0.008, 0.0025
        pr.line((0.0, dome), (R - 0.010, 0.0015))
        pr.line((R - 0.010, 0.0015), (R - 0.007, 0.0))
        pr.line((R - 0.007, 0.0), (R - 0.003, 0.0))
        pr.line((R - 0.003, 0.0), (R, 0.010))
        pr.curve(lambda u: np.stack([np.full_like(u, R), 0.010 + u * (H - 0.022)], 1), 0, 1,
                 z_keys=[H / 3, 2 * H / 3])
        pr.line((R, H - 0.012), (R - 0.005, H - bead))
        pr.line((R - 0.005, H - bead), (R - 0.0045, H))
        pr.line((R - 0.0045, H), (R - 0.0065, H))
        pr.line((R - 0.0065, H), (R - 0.0075, H - 0.004))
        pr.line((R - 0.0075, H - 0.004), (0.0, H - 0.004))
        dims = {"height": H, "diameter": 2 * R, "wall": P["wall"]}
    prof = pr.resampled(h)
    p_of_z = None
    if "p_body" in P:  # a square body (superellipse sections) blending into a round neck
        z0, z1 = H - P["neck"] - P["shoulder"], H - P["neck"]
        w = lambda z: 0.5 * (1 + np.cos(np.pi * np.clip((z - z0) / (z1 - z0), 0, 1)))  # noqa: E731
        p_of_z = lambda z: 2.0 + (P["p_body"] - 2.0) * w(np.asarray(z))  # noqa: E731
        dims["section_exponent"] = P["p_body"]
    mb = MeshBuilder()
    body_of_revolution(mb, prof, n, label_fn=lambda q: thirds_labels(q[:, 1], H), p_of_z=p_of_z)
    V, F, L = mb.result()
    cav = offset_closed_profile(prof, P["wall"])
    cmb = MeshBuilder()
    rings, s, e = revolve(cav, n, p_of_z=p_of_z)
    loft(cmb, rings, 0, start=s, end=e)
    Vc, Fc, _ = cmb.result()
    vol, first, _ = volume_integrals(Vc, Fc)
    cavity = (vol, first[2] / vol)
    return Model(category, V, F, L, variant["material"], {}, [(Vc, Fc, "air")], cavity, dims)


def make_lidded_pot(P, variant):
    """A pot closed by a domed lid with a knob, resting on its rim, and two side handles: one
    closed surface (the lid's overhang and the wall's top are one solid); the cavity under the
    lid is a sub-solid of air, and the cavity of a 'full' pot (as a closed bottle's or can's)."""
    H, r_top, wall, base = P["H"], P["r_top"], P["wall"], P["base"]
    r_bot = r_top - P["taper"]
    n, h, c = 48, 0.015, 0.003  # sections, profile spacing [m], bottom chamfer [m]
    ov, e, t = P["overhang"], P["lid_edge"], P["lid_t"]  # lid overhang, edge height, sheet [m]
    R_l, rk, hk = r_top + ov, P["knob_r"], P["knob_h"]
    zh, hp = H - P["hr"] - 0.012, P["hr"] + 0.003  # handle height and patch half height [m]

    def r_of_z(z):
        return r_bot + (r_top - r_bot) * np.asarray(z) / H

    def dome(r):  # the lid's top surface [m]: a paraboloid from its edge to the knob
        return H + e + P["dome"] * (1 - (np.asarray(r) / R_l) ** 2)

    z_knob = float(dome(0.6 * rk))
    T = z_knob + hk  # the top of the knob: the object's height
    keys = [T / 3, 2 * T / 3]
    pr = Profile()
    pr.line((0.0, 0.0), (r_bot - c, 0.0), h=1.0)
    pr.line((r_bot - c, 0.0), (float(r_of_z(c)), c))
    pr.curve(lambda u: np.stack([r_of_z(c + u * (H - c)), c + u * (H - c)], 1), 0, 1,
             z_keys=[zh - hp, zh + hp, *keys])
    pr.line((r_top, H), (R_l, H))
    pr.line((R_l, H), (R_l, H + e))
    pr.curve(lambda u: np.stack([R_l + (0.6 * rk - R_l) * u, dome(R_l + (0.6 * rk - R_l) * u)],
                                1), 0, 1, z_keys=keys)
    pr.line((0.6 * rk, z_knob), (0.6 * rk, z_knob + 0.4 * hk))
    pr.line((0.6 * rk, z_knob + 0.4 * hk), (rk, z_knob + 0.55 * hk))
    pr.line((rk, z_knob + 0.55 * hk), (rk, T - 0.002))  # the knob's top edge: a 2 mm chamfer
    pr.line((rk, T - 0.002), (rk - 0.002, T))
    pr.line((rk - 0.002, T), (0.0, T), h=1.0)
    prof = pr.resampled(h)
    mb = MeshBuilder()
    idx, qf = body_of_revolution(mb, prof, n, label_fn=lambda q: thirds_labels(q[:, 1], T))
    pieces = side_handles(mb, qf, r_of_z, r_top, zh, hp, P)
    V, F, L = mb.result()

    # the air under the lid: the inner wall (the outer one less `wall`) from the inner bottom up
    # to the lid, whose underside is its top surface less the sheet `t`
    r_c = r_top - wall
    q = Profile()
    q.line((0.0, base), (float(r_of_z(base)) - wall, base), h=1.0)
    q.line((float(r_of_z(base)) - wall, base), (r_c, H), h=1.0)
    q.line((r_c, H), (r_c, float(dome(r_c)) - t), h=1.0)
    q.curve(lambda u: np.stack([r_c * (1 - u), dome(r_c * (1 - u)) - t], 1), 0, 1, n=40)
    cmb = MeshBuilder()
    rings, s_, e_ = revolve(q.resampled(h), n)
    loft(cmb, rings, 0, start=s_, end=e_)
    Vc, Fc, _ = cmb.result()
    vol, first, _ = volume_integrals(Vc, Fc)
    hm = variant["materials"].get("handle", variant["material"])
    solids = [(Vc, Fc, "air")] + ([(Vp, Fp, hm) for Vp, Fp in pieces]
                                  if hm != variant["material"] else [])
    dims = {"height": T, "diameter": 2 * r_top, "bottom_diameter": 2 * r_bot, "wall": wall,
            "base": base, "lid_diameter": 2 * R_l, "lid_height": T - H,
            "handle_reach": P["reach"]}
    return Model("pot", V, F, L, variant["material"],
                 {"handle": hm} if hm != variant["material"] else {}, solids,
                 (vol, first[2] / vol), dims, rim={"wall": wall, "opening_radius": r_c},
                 closed_top=True, poses=("upright", "sideways"))


def make_stemmed_glass(P, variant):
    """A stemmed (wine) glass: a foot, a stem and an open bowl, one revolved profile."""
    r_top, wall, Hb = P["r_top"], P["wall"], P["H_bowl"]
    R_f, t_f, r_s, z_s = P["r_foot"], P["foot_t"], P["r_stem"], P["H_stem"]
    n, h = 40, 0.011
    bowl, cavity, _, top_b = open_profile(Hb, P["r_bot"], r_top, wall, P["base"], P["beta"],
                                          0.002, h)
    if not (bowl[0, 1] == 0.0 and bowl[1, 1] == 0.0 and bowl[2, 1] > 0.0):
        raise RuntimeError("the bowl profile does not start with its flat bottom")
    r1 = float(bowl[1, 0])  # where the stem meets the bowl
    # [m] the foot's edge: a 1.5 mm chamfer; it rises 8 mm to the stem, which flares over its
    # last 8 mm into the bowl
    pr = Profile()
    pr.line((0.0, 0.0), (R_f - 0.0015, 0.0), h=1.0)
    pr.line((R_f - 0.0015, 0.0), (R_f, 0.0015))
    pr.line((R_f, 0.0015), (R_f - 0.0015, t_f))
    # the foot rises to the stem: flat near its edge, steep at the stem
    pr.curve(lambda u: np.stack([R_f - 0.0015 + (r_s - R_f + 0.0015) * u, t_f + 0.008 * u ** 4],
                                1), 0, 1)
    pr.line((r_s, t_f + 0.008), (r_s, z_s - 0.008))
    pr.curve(lambda u: np.stack([r_s + (r1 - r_s) * u ** 2, z_s - 0.008 + 0.008 * u], 1), 0, 1)
    foot = pr.resampled(h)
    prof = np.concatenate([foot, bowl[2:] + [0.0, z_s]])
    T = z_s + top_b
    mb = MeshBuilder()
    body_of_revolution(mb, prof, n, label_fn=lambda q: thirds_labels(q[:, 1], T))
    V, F, L = mb.result()
    dims = {"height": T, "diameter": 2 * r_top, "foot_diameter": 2 * R_f,
            "stem_diameter": 2 * r_s, "stem_height": z_s, "wall": wall, "base": z_s + P["base"]}
    return Model("glass", V, F, L, variant["material"], {}, [], (cavity[0], cavity[1] + z_s),
                 dims, rim={"wall": wall, "opening_radius": r_top - wall})


def loft_tool(stations, n_sec, labels):
    """A tool lofted along +x: stations (x, y_c, z_c, a, b, p, flutes, depth[, rc]) → closed mesh.
    Sections are superellipses (half axes a along y, b along z, exponent p, optional flutes), or
    rounded rectangles when a corner radius rc > 0 is given. The first and last stations are the
    poles."""
    mb = MeshBuilder()
    st = np.array([tuple(s_) + (0.0,) * (9 - len(s_)) for s_ in stations], float)
    rings = []
    for x, yc, zc, a, b, p, fl, dep, rc in st[1:-1]:
        if rc > 0:
            sec = rounded_rect(n_sec, a, b, min(rc, 0.999 * min(a, b)))
        else:
            sec = superellipse(n_sec, a, b, p, flutes=int(fl), flute_depth=dep)
        rings.append(np.column_stack([np.full(n_sec, x), yc + sec[:, 0], zc + sec[:, 1]]))
    rings = np.array(rings)
    idx, _ = loft(mb, rings, labels[1:-1], start=st[0, :3], end=st[-1, :3],
                  start_label=labels[0], end_label=labels[-1])
    return mb, rings


def rounded_end(x0, x1, n):
    """Stations x and section scale for a rounded (elliptic) end from x0 (full) to x1 (point)."""
    t = np.linspace(0, 1, n + 1)[1:-1]
    return x0 + (x1 - x0) * np.sin(t * np.pi / 2), np.cos(t * np.pi / 2)


def make_knife(P, variant):
    Lh, Lb = P["Lh"], P["Lb"]
    ha, hb = P["ha"], P["hb"]
    hblade, tb = P["blade_h"], P["blade_t"]
    spine = ha - 0.002
    st, lab = [], []
    # butt: rounded end of the handle, pole at x = 0
    xs, k = rounded_end(0.012, 0.0, 4)
    st.append((0.0, 0, 0, 0, 0, 2, 0, 0))
    lab.append(HANDLE)
    for x, kk in zip(xs[::-1], k[::-1], strict=False):
        st.append((x, 0, 0, ha * kk, hb * kk, 2.0, 0, 0, 0.4 * hb * kk))
        lab.append(HANDLE)
    for x in np.linspace(0.012, Lh, 6):  # flat-sided scales (a rounded-rectangle section)
        st.append((x, 0, 0, ha, hb, 2.0, 0, 0, 0.4 * hb))
        lab.append(HANDLE)
    # bolster: the handle section narrows to the blade's root
    st.append((Lh + 0.006, spine - hblade / 2, 0, hblade / 2, 0.6 * hb, 2.2, 0, 0))
    lab.append(USABLE)
    x_straight = Lh + 0.006 + 0.55 * Lb
    for x in np.linspace(Lh + 0.012, x_straight, 5):
        st.append((x, spine - hblade / 2, 0, hblade / 2, tb / 2, 2.0, 0, 0))
        lab.append(USABLE)
    x_tip = Lh + 0.006 + Lb
    for t in np.linspace(0, 1, 8)[1:-1]:
        x = x_straight + t * (x_tip - x_straight)
        hh = hblade * math.sqrt(1 - t ** 2)  # the edge curves up to the spine
        st.append((x, spine - hh / 2, 0, hh / 2, tb / 2 * (1 - 0.7 * t), 2.0, 0, 0))
        lab.append(USABLE)
    st.append((x_tip, spine - 0.0005, 0, 0, 0, 2, 0, 0))
    lab.append(USABLE)
    mb, rings = loft_tool(st, 20, np.array(lab, np.uint8))
    V, F, L = mb.result()
    handle = _split_solid(rings, st, lab.index(USABLE) - 2)
    dims = {"length": x_tip, "handle_length": Lh, "blade_length": Lb, "blade_height": hblade,
            "blade_thickness": tb}
    hm = variant["materials"]["handle"]
    one_piece = hm == variant["material"]  # a flat knife cut from one sheet
    return Model("knife", V, F, L, variant["material"], {} if one_piece else {"handle": hm},
                 [] if one_piece else [(*handle, hm)], None, dims)


def _split_solid(rings, st, k_split):
    """The closed sub-solid from the start pole to ring k_split (ring index, inclusive)."""
    mb = MeshBuilder()
    loft(mb, rings[:k_split + 1], 0, start=np.asarray(st[0][:3], float),
         end=rings[k_split].mean(0))
    V, F, _ = mb.result()
    return V, F


def make_screwdriver(P, variant):
    Lh, Ls, rh, rs = P["Lh"], P["Ls"], P["rh"], P["rs"]
    st, lab = [(0.0, 0, 0, 0, 0, 2, 0, 0)], [HANDLE]
    xs, k = rounded_end(0.010, 0.0, 4)
    for x, kk in zip(xs[::-1], k[::-1], strict=False):
        st.append((x, 0, 0, 0.92 * rh * kk, 0.92 * rh * kk, 2, 6, 0.06))
        lab.append(HANDLE)
    prof = lambda t: rh * (0.92 + 0.08 * np.sin(np.pi * np.clip(t, 0, 1)) ** 0.5)  # noqa: E731
    for x in np.linspace(0.010, Lh - 0.012, 7):
        r = prof((x - 0.01) / (Lh - 0.022))
        st.append((x, 0, 0, r, r, 2, 6, 0.06))
        lab.append(HANDLE)
    # nose of the handle and a ferrule down to the shaft
    st.append((Lh, 0, 0, 0.55 * rh, 0.55 * rh, 2, 6, 0.03))
    lab.append(HANDLE)
    st.append((Lh + 0.004, 0, 0, 1.6 * rs, 1.6 * rs, 2, 0, 0))
    lab.append(USABLE)
    x_tip = Lh + Ls
    for x in np.linspace(Lh + 0.012, x_tip - 0.010, 4):
        st.append((x, 0, 0, rs, rs, 2, 0, 0))
        lab.append(USABLE)
    if variant["tip"] == "flat":
        for t in (0.4, 0.8):
            st.append((x_tip - 0.010 * (1 - t), 0, 0, rs * (1 + 0.15 * t), rs * (1 - 0.8 * t),
                       2.5, 0, 0))
            lab.append(USABLE)
        st.append((x_tip, 0, 0, rs * 1.15, rs * 0.2, 4, 0, 0))
        lab.append(USABLE)
        st.append((x_tip + 0.0003, 0, 0, 0, 0, 2, 0, 0))
    else:  # cross-head: a cone to a point
        for t in (0.35, 0.7):
            st.append((x_tip - 0.010 * (1 - t), 0, 0, rs * (1 - 0.8 * t), rs * (1 - 0.8 * t),
                       2, 0, 0))
            lab.append(USABLE)
        st.append((x_tip, 0, 0, 0, 0, 2, 0, 0))
    lab.append(USABLE)
    mb, rings = loft_tool(st, 24, np.array(lab, np.uint8))
    V, F, L = mb.result()
    handle = _split_solid(rings, st, lab.index(USABLE) - 2)
    dims = {"length": float(st[-1][0]), "handle_length": Lh, "handle_diameter": 2 * rh,
            "shaft_diameter": 2 * rs, "shaft_length": Ls}
    return Model("screwdriver", V, F, L, variant["material"],
                 {"handle": variant["materials"]["handle"]},
                 [(*handle, variant["materials"]["handle"])], None, dims)


def make_spatula(P, variant):
    Lh, Ln, Lhd, W, t = P["Lh"], P["Ln"], P["Lhead"], P["W"], P["t"]
    ha, hb = P["ha"], P["hb"]
    st, lab = [(0.0, 0, 0, 0, 0, 2, 0, 0)], [HANDLE]
    xs, k = rounded_end(0.008, 0.0, 4)
    for x, kk in zip(xs[::-1], k[::-1], strict=False):
        st.append((x, 0, 0, ha * kk, hb * kk, 2.0, 0, 0, 0.7 * hb * kk))
        lab.append(HANDLE)
    for x in np.linspace(0.008, Lh, 5):  # a flat handle, as moulded or riveted ones are
        st.append((x, 0, 0, ha, hb, 2.0, 0, 0, 0.7 * hb))
        lab.append(HANDLE)
    for x, a, b in zip(np.linspace(Lh, Lh + Ln, 4)[1:], (0.8 * ha, 0.55 * ha, 0.45 * ha),
                       (0.7 * hb, 0.5 * hb, 0.4 * hb), strict=False):
        st.append((x, 0, 0, a, max(b, t / 2), 2.0, 0, 0, 0.7 * max(b, t / 2)))
        lab.append(HANDLE)
    x0 = Lh + Ln
    for s_, w in zip((0.01, 0.02, 0.03), (0.5, 0.8, 1.0), strict=False):  # the head widens
        st.append((x0 + s_, 0, 0, max(w * W / 2, 0.45 * ha), t / 2, 6, 0, 0))
        lab.append(USABLE)
    for x in np.linspace(x0 + 0.03, x0 + Lhd - 0.008, 4)[1:]:
        st.append((x, 0, 0, W / 2, t / 2, 6, 0, 0))
        lab.append(USABLE)
    xe, ke = rounded_end(x0 + Lhd - 0.008, x0 + Lhd, 3)
    for x, kk in zip(xe, ke, strict=False):  # rounded corners at the working edge
        st.append((x, 0, 0, W / 2 * (0.6 + 0.4 * kk), t / 2 * (0.5 + 0.5 * kk), 6, 0, 0))
        lab.append(USABLE)
    st.append((x0 + Lhd, 0, 0, 0, 0, 2, 0, 0))
    lab.append(USABLE)
    mb, rings = loft_tool(st, 24, np.array(lab, np.uint8))
    V, F, L = mb.result()
    handle = _split_solid(rings, st, lab.index(USABLE) - 2)
    dims = {"length": x0 + Lhd, "handle_length": Lh + Ln, "head_length": Lhd, "head_width": W,
            "head_thickness": t}
    hm = variant["materials"]["handle"]
    return Model("cooking_tool", V, F, L, variant["material"],
                 {"handle": hm} if hm != variant["material"] else {},
                 [(*handle, hm)] if hm != variant["material"] else [], None, dims)


def make_ladle(P, variant):
    """A revolved bowl (usable area) with a long curved flat handle towards −x."""
    R, D, wall = P["R"], P["D"], P["wall"]
    mb = MeshBuilder()
    zh = D - 0.006
    hp = P["lhb"] + 0.002
    prof, _, r_of_z, _ = open_profile(D, 0.45 * R, R, wall, wall, 0.95, 0.002, 0.008,
                                   (zh - hp, zh + hp))
    idx, qf = body_of_revolution(mb, prof, 40, label_fn=lambda q: np.full(len(q), USABLE))
    A = patch_on_wall(mb, qf, np.pi, P["lha"] + 0.002, zh - hp, zh + hp)
    p1, n1 = wall_point(r_of_z, np.pi, zh)
    ang = P["angle"]
    d = np.array([-math.cos(ang), 0.0, math.sin(ang)])
    p3 = p1 + 0.03 * n1 + np.array([0, 0, 0.04]) + P["L"] * d
    curve = lambda t: bezier(p1, p1 + 0.035 * n1, p1 + 0.02 * n1 + np.array([0, 0, 0.05]), p3, t)  # noqa: E731
    tidx, rings, _ = tube(mb, curve, np.array([0.0, -1.0, 0.0]), P["lha"], P["lhb"], HANDLE,
                          start_loop=A, cap=True, h=0.015, n_sec=12, p=3.0)
    V, F, L = mb.result()
    dims = {"bowl_diameter": 2 * R, "bowl_depth": D, "handle_length": P["L"]}
    m = Model("cooking_tool", V, F, L, variant["material"], {}, [], None, dims)
    return m


def make_hammer(P, variant):
    """A steel head (a revolved rounded-square body along y) with a handle along −x."""
    Lh, Lhead, rh = P["Lh"], P["Lhead"], P["rhead"]
    ha, hb = P["ha"], P["hb"]
    mb = MeshBuilder()
    # head in local coordinates: axis z_l = world y, x_l = world z, y_l = world x
    Rw = np.array([[0, 1, 0], [0, 0, 1], [1, 0, 0]], float)  # columns: local axes in world
    centre = np.array([Lh, 0.0, 0.0])
    origin = centre - Lhead / 2 * np.array([0, 1.0, 0])
    pw = ha + 0.003  # patch half width along the head axis
    pr = Profile()
    c = 0.003
    rp = P["peen"] * rh
    pr.line((0.0, 0.0), (rh - c, 0.0))
    pr.line((rh - c, 0.0), (rh, c))
    mid = Lhead / 2
    pr.curve(lambda u: np.stack([np.full_like(u, rh), c + u * (Lhead * 0.75 - c)], 1), 0, 1,
             z_keys=[mid - pw, mid + pw])
    pr.line((rh, Lhead * 0.75), (rp, Lhead - c))
    pr.line((rp, Lhead - c), (rp - c, Lhead))
    pr.line((rp - c, Lhead), (0.0, Lhead))
    prof = pr.resampled(0.006)
    idx, qf = body_of_revolution(mb, prof, 40, label_fn=lambda q: np.full(len(q), USABLE),
                                 R=Rw, origin=origin, p=P["p"])
    V = mb.V

    def pred(cn, nrm):
        return ((nrm[..., 0] < -0.5) & (np.abs(cn[..., 2]) < hb + 0.004)
                & (np.abs(cn[..., 1]) < pw) & (cn[..., 0] < Lh))
    A = remove_patch(mb, select_quads(mb, qf, V, pred))
    p1 = np.array([Lh - rh, 0.0, 0.0])
    p3 = np.array([0.0, 0.0, 0.0]) + np.array([hb, 0, 0])
    curve = lambda t: p1 + (p3 - p1) * np.asarray(t)[:, None]  # noqa: E731
    taper = lambda s: 0.85 + 0.15 * np.clip(s * 1.5, 0, 1)  # noqa: E731  # thinner at the head
    tidx, rings, pole = tube(mb, curve, np.array([0.0, 1.0, 0.0]), ha, hb, HANDLE,
                             start_loop=A, cap=True, h=0.025, n_sec=20, p=2.4, taper=taper)
    V, F, L = mb.result()
    handle = closed_tube_solid(rings, end_pole=pole)
    hm = variant["materials"]["handle"]
    dims = {"length": Lh + rh, "handle_length": Lh - rh, "head_length": Lhead,
            "head_width": 2 * rh}
    return Model("hammer", V, F, L, variant["material"], {"handle": hm}, [(*handle, hm)], None,
                 dims)


# ------------------------------------------------------------------------------------------------
# The catalogue: parameter ranges [m, rad] and per-instance variants (material, style)

RANGES = {
    "pan": dict(r_top=(0.10, 0.14), H=(0.040, 0.060), flare=(0.3, 0.7), wall=(0.003, 0.0045),
                base=(0.004, 0.006), beta=(0.3, 0.6), L=(0.15, 0.20), angle=(0.14, 0.24),
                ha=(0.010, 0.013), hb=(0.006, 0.008)),
    "pot": dict(r_top=(0.08, 0.12), H=(0.10, 0.16), taper=(0.0, 0.008), wall=(0.0010, 0.0016),
                base=(0.003, 0.005), reach=(0.022, 0.032), span=(0.05, 0.07), hr=(0.004, 0.006)),
    "cup": dict(r_top=(0.035, 0.045), H=(0.08, 0.11), taper=(0.0, 0.010), wall=(0.004, 0.0055),
                base=(0.006, 0.008), beta=(0.0, 0.25), reach=(0.025, 0.033), z1=(0.72, 0.80),
                z2=(0.25, 0.35), ha=(0.006, 0.0075), hb=(0.0035, 0.0045)),
    "glass": dict(r_top=(0.030, 0.0425), H=(0.09, 0.15), taper=(0.0, 0.012), wall=(0.002, 0.003),
                  base=(0.006, 0.012)),
    "bowl": dict(r_top=(0.060, 0.080), H=(0.050, 0.075), r_bot=(0.030, 0.040),
                 wall=(0.004, 0.0055), base=(0.005, 0.007), beta=(0.4, 0.9)),
    "bottle": dict(R=(0.030, 0.042), H=(0.20, 0.30), rn=(0.0125, 0.016), neck=(0.05, 0.08),
                   shoulder=(0.03, 0.06), punt=(0.002, 0.012), lip=(0.0015, 0.003)),
    "can": dict(R=(0.0265, 0.037), H=(0.10, 0.135)),
    "hammer": dict(Lh=(0.24, 0.32), Lhead=(0.09, 0.12), rhead=(0.012, 0.016), ha=(0.013, 0.016),
                   hb=(0.009, 0.011), p=(3.0, 4.0), peen=(0.6, 0.85)),
    "knife": dict(Lh=(0.09, 0.12), Lb=(0.08, 0.20), ha=(0.010, 0.012), hb=(0.0065, 0.008),
                  blade_h=(0.018, 0.045), blade_t=(0.0015, 0.0022)),
    "screwdriver": dict(Lh=(0.08, 0.11), Ls=(0.07, 0.15), rh=(0.012, 0.017), rs=(0.0025, 0.004)),
    "cooking_tool": dict(Lh=(0.12, 0.16), Ln=(0.04, 0.06), Lhead=(0.08, 0.10), W=(0.06, 0.08),
                         t=(0.002, 0.003), ha=(0.010, 0.012), hb=(0.005, 0.007), R=(0.035, 0.05),
                         D=(0.035, 0.045), wall=(0.0010, 0.0016), L=(0.20, 0.26),
                         angle=(0.45, 0.65), lha=(0.007, 0.009), lhb=(0.002, 0.0028)),
}

VARIANTS = {
    "pan": [dict(material="aluminium", materials={"handle": "plastic"}),
            dict(material="steel", materials={}),
            dict(material="aluminium", materials={"handle": "wood"}),
            dict(material="cast_iron", materials={})],
    "pot": [dict(material="steel", materials={}), dict(material="aluminium", materials={}),
            dict(material="steel", materials={}), dict(material="steel", materials={})],
    "cup": [dict(material="ceramic", materials={})] * 3 + [dict(material="plastic", materials={})],
    "glass": [dict(material="glass", materials={})] * 3 + [dict(material="plastic", materials={})],
    "bowl": [dict(material="ceramic", materials={}), dict(material="ceramic", materials={}),
             dict(material="plastic", materials={}), dict(material="glass", materials={})],
    "bottle": [dict(material="glass", materials={}, wall=0.003),
               dict(material="pet", materials={}, wall=0.0004),
               dict(material="glass", materials={}, wall=0.0025),
               dict(material="pet", materials={}, wall=0.0005)],
    "can": [dict(material="aluminium", materials={}, wall=0.00015),
            dict(material="steel", materials={}, wall=0.00022),
            dict(material="aluminium", materials={}, wall=0.00015),
            dict(material="steel", materials={}, wall=0.00025)],
    "hammer": [dict(material="steel", materials={"handle": "wood"}),
               dict(material="steel", materials={"handle": "plastic"}),
               dict(material="steel", materials={"handle": "wood"}),
               dict(material="steel", materials={"handle": "wood"})],
    "knife": [dict(material="steel", materials={"handle": "wood_tang"}),
              dict(material="steel", materials={"handle": "plastic_tang"}),
              dict(material="steel", materials={"handle": "plastic_tang"}),
              dict(material="steel", materials={"handle": "wood_tang"})],
    "screwdriver": [dict(material="steel", materials={"handle": "plastic"}, tip="flat"),
                    dict(material="steel", materials={"handle": "plastic"}, tip="cross"),
                    dict(material="steel", materials={"handle": "plastic"}, tip="flat"),
                    dict(material="steel", materials={"handle": "wood"}, tip="cross")],
    "cooking_tool": [dict(material="plastic", materials={"handle": "plastic"}, kind="spatula"),
                     dict(material="steel", materials={}, kind="ladle"),
                     dict(material="steel", materials={"handle": "wood"}, kind="spatula"),
                     dict(material="plastic", materials={}, kind="ladle")],
}


# ------------------------------------------------------------------------------------------------
# Set b (issue 20): another seed and wider shape families, a user library in models/objects_b/
# (ids <category>_b01 ...). Per category, its families in turn — instance b01 is of the first
# family, b02 of the second, b03 of the first again, ... — each family's instances drawn by Latin
# hypercube within its own ranges [m, rad, or the section exponent], its variants (material,
# style) taken in turn. `shape` picks a builder of its own (else the category's, as in set a);
# parameters a builder needs that the family does not vary are fixed in `fixed`.

SEED_B = 20260420
N_PER_CATEGORY_B = 4
FAMILIES_B = {
    "pan": [dict(family="frying pan, wider", ranges=dict(
        r_top=(0.09, 0.14), H=(0.035, 0.070), flare=(0.2, 0.8), wall=(0.0025, 0.0045),
        base=(0.004, 0.007), beta=(0.2, 0.7), L=(0.13, 0.22), angle=(0.10, 0.30),
        ha=(0.009, 0.012), hb=(0.006, 0.009)),
        variants=[dict(material="aluminium", materials={"handle": "plastic"}),
                  dict(material="steel", materials={}),
                  dict(material="aluminium", materials={"handle": "wood"}),
                  dict(material="cast_iron", materials={})])],
    "pot": [dict(family="lidded pot with two side handles", shape="lidded_pot", ranges=dict(
        r_top=(0.075, 0.115), H=(0.08, 0.15), taper=(0.0, 0.008), wall=(0.0010, 0.0016),
        base=(0.003, 0.005), reach=(0.020, 0.030), span=(0.045, 0.065), hr=(0.004, 0.006),
        overhang=(0.002, 0.004), lid_edge=(0.003, 0.005), lid_t=(0.0010, 0.0015),
        dome=(0.008, 0.020), knob_r=(0.010, 0.016), knob_h=(0.012, 0.020)),
        variants=[dict(material="steel", materials={}),
                  dict(material="aluminium", materials={})]),
            dict(family="pot with two side handles, squat to tall", ranges=dict(
                r_top=(0.07, 0.13), H=(0.07, 0.19), taper=(0.0, 0.010),
                wall=(0.0010, 0.0018), base=(0.003, 0.005), reach=(0.018, 0.035),
                span=(0.04, 0.08), hr=(0.004, 0.0065)),
        variants=[dict(material="aluminium", materials={}),
                  dict(material="steel", materials={})])],
    "cup": [dict(family="mug, tall D handle of flattened section", ranges=dict(
        r_top=(0.033, 0.048), H=(0.075, 0.12), taper=(-0.006, 0.012), wall=(0.0035, 0.006),
        base=(0.006, 0.009), beta=(0.0, 0.35), reach=(0.028, 0.040), z1=(0.80, 0.86),
        z2=(0.14, 0.22), ha=(0.0065, 0.009), hb=(0.0030, 0.0040), handle_p=(3.0, 4.0)),
        variants=[dict(material="ceramic", materials={}),
                  dict(material="plastic", materials={})]),
            dict(family="mug, small ring handle near the rim", ranges=dict(
                r_top=(0.035, 0.046), H=(0.07, 0.10), taper=(0.0, 0.008),
                wall=(0.004, 0.0055), base=(0.006, 0.008), beta=(0.0, 0.25),
                reach=(0.026, 0.032), z1=(0.78, 0.84), z2=(0.46, 0.54), ha=(0.005, 0.0065),
                hb=(0.0035, 0.0045), handle_p=(2.0, 2.0)),
        variants=[dict(material="ceramic", materials={})] * 2)],
    "glass": [dict(family="stemmed glass", shape="stemmed_glass", ranges=dict(
        r_top=(0.030, 0.045), H_bowl=(0.07, 0.11), r_bot=(0.010, 0.016), wall=(0.0015, 0.0025),
        base=(0.004, 0.008), beta=(0.5, 0.9), r_foot=(0.030, 0.040), foot_t=(0.003, 0.005),
        r_stem=(0.0035, 0.005), H_stem=(0.05, 0.09)),
        variants=[dict(material="glass", materials={})] * 2),
              dict(family="tumbler, squat to tall", ranges=dict(
                  r_top=(0.028, 0.046), H=(0.07, 0.16), taper=(0.0, 0.015),
                  wall=(0.002, 0.0035), base=(0.006, 0.014)),
        variants=[dict(material="glass", materials={}), dict(material="plastic", materials={})])],
    "bowl": [dict(family="bowl, wider", ranges=dict(
        r_top=(0.055, 0.090), H=(0.040, 0.085), r_bot=(0.025, 0.045), wall=(0.0035, 0.006),
        base=(0.005, 0.008), beta=(0.3, 0.95)),
        variants=[dict(material="ceramic", materials={}), dict(material="glass", materials={}),
                  dict(material="plastic", materials={}),
                  dict(material="ceramic", materials={})])],
    "bottle": [dict(family="square bottle", ranges=dict(
        R=(0.028, 0.040), H=(0.18, 0.28), rn=(0.0125, 0.016), neck=(0.04, 0.07),
        shoulder=(0.03, 0.05), punt=(0.002, 0.006), lip=(0.0015, 0.003), p_body=(4.0, 6.0)),
        variants=[dict(material="glass", materials={}, wall=0.003),
                  dict(material="pet", materials={}, wall=0.0005)]),
               dict(family="shouldered bottle", ranges=dict(
                   R=(0.032, 0.042), H=(0.24, 0.32), rn=(0.0125, 0.015), neck=(0.07, 0.10),
                   shoulder=(0.010, 0.018), punt=(0.004, 0.014), lip=(0.0015, 0.003)),
        variants=[dict(material="glass", materials={}, wall=0.0035),
                  dict(material="glass", materials={}, wall=0.003)])],
    "can": [dict(family="squat can", ranges=dict(R=(0.040, 0.050), H=(0.030, 0.045)),
                 variants=[dict(material="steel", materials={}, wall=0.00022),
                           dict(material="aluminium", materials={}, wall=0.0002)]),
            dict(family="tall can", ranges=dict(R=(0.026, 0.033), H=(0.15, 0.19)),
                 variants=[dict(material="aluminium", materials={}, wall=0.00015),
                           dict(material="steel", materials={}, wall=0.00022)])],
    "hammer": [dict(family="heavy hammer", ranges=dict(
        Lh=(0.22, 0.30), Lhead=(0.11, 0.15), rhead=(0.019, 0.024), ha=(0.015, 0.018),
        hb=(0.010, 0.012), p=(2.5, 4.0), peen=(0.8, 0.95)),
        variants=[dict(material="steel", materials={"handle": "wood"}),
                  dict(material="steel", materials={"handle": "plastic"})]),
               dict(family="hammer, wider", ranges=dict(
                   Lh=(0.20, 0.34), Lhead=(0.08, 0.13), rhead=(0.011, 0.017),
                   ha=(0.012, 0.017), hb=(0.008, 0.011), p=(3.0, 4.5), peen=(0.55, 0.85)),
        variants=[dict(material="steel", materials={"handle": "wood"}),
                  dict(material="steel", materials={"handle": "plastic"})])],
    "knife": [dict(family="flat knife, 2-5 mm thick", ranges=dict(
        Lh=(0.08, 0.12), Lb=(0.08, 0.18), ha=(0.008, 0.011), hb=(0.0010, 0.0025),
        blade_h=(0.016, 0.035), blade_t=(0.0012, 0.0018)),
        variants=[dict(material="steel", materials={"handle": "steel"}),
                  dict(material="steel", materials={"handle": "plastic_tang"})]),
              dict(family="knife, wider", ranges=dict(
                  Lh=(0.08, 0.13), Lb=(0.07, 0.22), ha=(0.009, 0.013), hb=(0.006, 0.009),
                  blade_h=(0.016, 0.050), blade_t=(0.0015, 0.0025)),
        variants=[dict(material="steel", materials={"handle": "wood_tang"}),
                  dict(material="steel", materials={"handle": "plastic_tang"})])],
    "screwdriver": [dict(family="screwdriver, wider", ranges=dict(
        Lh=(0.07, 0.12), Ls=(0.05, 0.17), rh=(0.011, 0.018), rs=(0.0025, 0.0045)),
        variants=[dict(material="steel", materials={"handle": "plastic"}, tip="cross"),
                  dict(material="steel", materials={"handle": "wood"}, tip="flat"),
                  dict(material="steel", materials={"handle": "plastic"}, tip="flat"),
                  dict(material="steel", materials={"handle": "plastic"}, tip="cross")])],
    "cooking_tool": [dict(family="ladle, wider", ranges=dict(
        R=(0.035, 0.060), D=(0.035, 0.060), wall=(0.0010, 0.0015), L=(0.20, 0.30),
        angle=(0.40, 0.70), lha=(0.007, 0.010), lhb=(0.002, 0.003)),
        variants=[dict(material="steel", materials={}, kind="ladle"),
                  dict(material="plastic", materials={}, kind="ladle")]),
                     dict(family="spatula, wider", ranges=dict(
                         Lh=(0.11, 0.17), Ln=(0.03, 0.07), Lhead=(0.07, 0.11),
                         W=(0.055, 0.085), t=(0.002, 0.0035), ha=(0.009, 0.013),
                         hb=(0.005, 0.008)),
        variants=[dict(material="steel", materials={"handle": "wood"}, kind="spatula"),
                  dict(material="plastic", materials={"handle": "plastic"}, kind="spatula")])],
}


def build(category: str, P: dict, variant: dict) -> Model:
    shape = variant.get("shape")
    if shape == "lidded_pot":
        return make_lidded_pot(P, variant)
    if shape == "stemmed_glass":
        return make_stemmed_glass(P, variant)
    if category in ("pan", "pot", "cup", "glass", "bowl"):
        P = dict(P)
        if category == "pan":
            P["r_bot"] = P["r_top"] - P["flare"] * P["H"]
            P["chamfer"] = 0.003
        elif category == "bowl":
            P["chamfer"] = 0.003
        else:
            P["r_bot"] = P["r_top"] - P["taper"]
            P["beta"] = P.get("beta", 0.0)
            P["chamfer"] = 0.002 if category != "pot" else 0.003
        return make_open_container(category, P, variant)
    if category in ("bottle", "can"):
        return make_closed_container(category, dict(P, wall=variant["wall"]), variant)
    if category == "hammer":
        return make_hammer(P, variant)
    if category == "knife":
        return make_knife(P, variant)
    if category == "screwdriver":
        return make_screwdriver(P, variant)
    if variant["kind"] == "ladle":
        return make_ladle(P, variant)
    return make_spatula(P, variant)


# ------------------------------------------------------------------------------------------------
# Finishing: frames, checks, mass, poses, files


def grasp_widths(V, labels, is_open_container, rim):
    """Per part: the smallest width across the part over closing directions in the object's xy
    plane (fingers closing across it); an open container's top is also pinched across its rim."""
    th = np.linspace(0, np.pi, 180, endpoint=False)
    D = np.stack([np.cos(th), np.sin(th)], 1)
    out = {}
    for k, name in enumerate(PART_LABELS):
        pts = V[labels == k]
        if len(pts) == 0:
            continue
        proj = pts[:, :2] @ D.T
        w = float((proj.max(0) - proj.min(0)).min())
        if is_open_container and name == "top":
            w = min(w, float(rim["wall"]))
        out[name] = w
    return out


def rnd(x, digits: int) -> float:
    """A plain float rounded to `digits` decimals (no -0.0), for stable YAML text."""
    return round(float(x), digits) + 0.0


def sig(x, digits: int = 7) -> float:
    """A plain float rounded to `digits` significant digits, for stable YAML text."""
    return float(f"{float(x):.{digits}g}") + 0.0


def finish(obj_id: str, m: Model) -> dict:
    """Frames the tool meshes, checks the mesh, computes mass and resting poses; returns the
    library entry and the arrays to write."""
    V, F = m.V, m.F
    is_tool = m.category in TOOLS
    if is_tool:
        # z: normal of the face the tool lies on; origin at the bottom centre of the bounding box.
        mp = mass_properties(V, F, MATERIALS[m.material][0],
                             [(Vp, Fp, MATERIALS[mat][0]) for Vp, Fp, mat in m.pieces])
        # (a ladle lies tilted on its bowl and handle end: search well past MAX_TILT here)
        n, tool_margin = resting_face(V, mp.com, TOOL_DOWN, max_tilt=math.radians(80))
        R = rot_to(n, TOOL_DOWN)
        V = V @ R.T
        lo, hi = V.min(0), V.max(0)
        shift = -np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
        V = V + shift
        m.pieces = [(Vp @ R.T + shift, Fp, mat) for Vp, Fp, mat in m.pieces]
    V = np.round(V, DECIMALS) + 0.0
    check_closed(V, F, obj_id)
    for i, (Vp, Fp, _) in enumerate(m.pieces):
        check_closed(Vp, Fp, f"{obj_id} piece {i}")
    rho = MATERIALS[m.material][0]
    mp = mass_properties(V, F, rho, [(Vp, Fp, MATERIALS[mat][0]) for Vp, Fp, mat in m.pieces])
    poses = {}
    for pose in m.poses or POSES_OF[m.category]:
        if is_tool:  # lying flat on the face that defined the frame: X_TO is the identity
            n, margin = np.array(TOOL_DOWN), tool_margin
        else:
            n, margin = resting_face(V, mp.com, DOWN[pose])
        R = rot_to(n, (0.0, 0.0, -1.0))
        if pose == "upsidedown" and abs(n[2] - 1) < 1e-9:
            R = np.diag([1.0, -1.0, -1.0])  # half turn about x
        z = -float((V @ R.T)[:, 2].min())
        rpy = rpy_of(R)
        poses[pose] = {"xyz": [0.0, 0.0, rnd(z, 6)], "rpy": [rnd(a, 6) for a in rpy],
                       "support_margin": rnd(margin, 4)}
    labels = m.labels.astype(np.uint8)
    parts = [p for k, p in enumerate(PART_LABELS) if (labels == k).any()]
    lo, hi = V.min(0), V.max(0)
    open_c = m.category in ("pan", "pot", "cup", "glass", "bowl") and not m.closed_top
    widths = grasp_widths(V, labels, open_c, m.rim)
    entry = {
        "category": m.category,
        "material": m.material,
        "density": rnd(mp.mass / mp.volume, 2),
        "part_materials": dict(sorted(m.part_materials.items())),
        "mass": sig(mp.mass),
        "volume": sig(mp.volume),
        "cavity_volume": None if m.cavity is None else sig(m.cavity[0]),
        "cavity_centroid": None if m.cavity is None else [0.0, 0.0, rnd(m.cavity[1], 6)],
        "com": [rnd(c, 6) for c in mp.com],
        "inertia": [sig(x) for x in mp.inertia[np.triu_indices(3)]],
        "extents": [rnd(float(x), 4) for x in hi - lo],
        "dimensions": {k: rnd(v, 6) for k, v in m.dimensions.items()},
        "parts": parts,
        "grasp_widths": {k: rnd(v, 4) for k, v in widths.items()},
        "poses": poses,
        "n_vertices": int(len(V)),
        "n_triangles": int(len(F)),
        "color": list(MATERIALS[m.material][1]),
    }
    return entry, V, F, labels, mp


def sdf_text(obj_id, entry, mp) -> str:
    inertia = mp.inertia
    r, g, b = entry["color"]
    return f"""<?xml version="1.0"?>
<!-- Generated by tools/make_objects.py: do not edit. {entry['category']}, {entry['material']},
     mass {entry['mass']:.4f} kg from the closed mesh's volume and the materials' densities. -->
<sdf version="1.9" xmlns:drake="http://drake.mit.edu">
  <model name="{obj_id}">
    <link name="{obj_id}">
      <inertial>
        <pose>{mp.com[0]:.6f} {mp.com[1]:.6f} {mp.com[2]:.6f} 0 0 0</pose>
        <mass>{mp.mass:.9g}</mass>
        <inertia>
          <ixx>{inertia[0, 0]:.9e}</ixx>
          <ixy>{inertia[0, 1]:.9e}</ixy>
          <ixz>{inertia[0, 2]:.9e}</ixz>
          <iyy>{inertia[1, 1]:.9e}</iyy>
          <iyz>{inertia[1, 2]:.9e}</iyz>
          <izz>{inertia[2, 2]:.9e}</izz>
        </inertia>
      </inertial>
      <visual name="visual">
        <geometry>
          <mesh><uri>{obj_id}.obj</uri></mesh>
        </geometry>
        <material>
          <diffuse>{r:.3f} {g:.3f} {b:.3f} 1</diffuse>
        </material>
      </visual>
      <collision name="collision">
        <geometry>
          <mesh><uri>{obj_id}.obj</uri></mesh>
        </geometry>
        <drake:proximity_properties>
          <drake:rigid_hydroelastic/>
          <drake:mu_dynamic>1.0</drake:mu_dynamic>
          <drake:mu_static>1.0</drake:mu_static>
        </drake:proximity_properties>
      </collision>
    </link>
  </model>
</sdf>
"""


CREASE = math.radians(40.0)  # faces meeting at a sharper angle than this shade as separate faces


def corner_normals(V, F):
    """Shading normals per triangle corner: the area-weighted mean of the normals of the faces
    around the corner's vertex within CREASE of this face (smooth walls, sharp rims and bottom
    edges). Returns (unique normals (N, 3) rounded to 1e-4, index per corner (F, 3))."""
    fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])  # length = 2 × area
    un = fn / np.linalg.norm(fn, axis=1, keepdims=True)
    corners_v = F.ravel()
    corners_f = np.repeat(np.arange(len(F)), 3)
    order = np.argsort(corners_v, kind="stable")
    start = np.searchsorted(corners_v[order], np.arange(len(V) + 1))
    deg = np.diff(start)
    # pairs (corner c, face g incident to c's vertex)
    n_pairs = deg[corners_v]
    c_idx = np.repeat(np.arange(len(corners_v)), n_pairs)
    offs = np.arange(len(c_idx)) - np.repeat(np.cumsum(n_pairs) - n_pairs, n_pairs)
    g = corners_f[order][start[corners_v][c_idx] + offs]
    keep = np.einsum("ij,ij->i", un[corners_f[c_idx]], un[g]) > math.cos(CREASE)
    acc = np.zeros((len(corners_v), 3))
    np.add.at(acc, c_idx[keep], fn[g[keep]])
    acc /= np.linalg.norm(acc, axis=1, keepdims=True)
    acc = np.round(acc, 4) + 0.0
    normals, idx = np.unique(acc, axis=0, return_inverse=True)
    return normals, idx.reshape(F.shape)


def obj_text(obj_id, V, F) -> str:
    """Wavefront OBJ: vertices, shading normals (Drake's renderer needs them), triangles."""
    N, NI = corner_normals(V, F)
    head = f"# {obj_id}: generated by tools/make_objects.py (metres, object frame O)\n"
    v = "\n".join(f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in V.tolist())
    vn = "\n".join(f"vn {x:.4f} {y:.4f} {z:.4f}" for x, y, z in N.tolist())
    f = "\n".join(f"f {a}//{na} {b}//{nb} {c}//{nc}" for (a, b, c), (na, nb, nc)
                   in zip((F + 1).tolist(), (NI + 1).tolist(), strict=False))
    return head + f"o {obj_id}\n" + v + "\n" + vn + "\n" + f + "\n"


def instances_a():
    """(id, category, parameters, variant) of every object of set a, the shipped library."""
    for ci, cat in enumerate(CATEGORIES):
        rng = np.random.default_rng([SEED, ci])
        params = lhs(rng, N_PER_CATEGORY, RANGES[cat])
        for i in range(N_PER_CATEGORY):
            yield f"{cat}_{i + 1:02d}", cat, params[i], VARIANTS[cat][i]


def instances_b():
    """(id, category, parameters, variant) of every object of set b (FAMILIES_B)."""
    for ci, cat in enumerate(CATEGORIES):
        fams = FAMILIES_B[cat]
        counts = [len(range(fi, N_PER_CATEGORY_B, len(fams))) for fi in range(len(fams))]
        drawn = [lhs(np.random.default_rng([SEED_B, ci, fi]), k, fam["ranges"])
                 for fi, (fam, k) in enumerate(zip(fams, counts, strict=True))]
        for i in range(N_PER_CATEGORY_B):
            fi, j = i % len(fams), i // len(fams)
            fam = fams[fi]
            variant = dict(fam["variants"][j % len(fam["variants"])], family=fam["family"])
            if "shape" in fam:
                variant["shape"] = fam["shape"]
            yield f"{cat}_b{i + 1:02d}", cat, drawn[fi][j], variant


SETS = {"a": dict(out=OUT, instances=instances_a, title="The object library"),
        "b": dict(out=OUT.parent / "objects_b", instances=instances_b,
                  title="Object set b (issue 20: another seed, wider shape families; "
                        "a user library)")}


def generate(out: Path, verbose=False, object_set: str = "a") -> dict:
    out.mkdir(parents=True, exist_ok=True)
    library = {}
    spec = SETS[object_set]
    for obj_id, cat, params, variant in spec["instances"]():
        m = build(cat, params, variant)
        entry, V, F, labels, mp = finish(obj_id, m)
        if "family" in variant:
            entry["family"] = variant["family"]
        d = out / obj_id
        d.mkdir(exist_ok=True)
        (d / f"{obj_id}.obj").write_text(obj_text(obj_id, V, F))
        (d / f"{obj_id}.sdf").write_text(sdf_text(obj_id, entry, mp))
        with open(d / f"{obj_id}_parts.npy", "wb") as fh:
            np.save(fh, labels)
        entry.pop("color")
        library[obj_id] = entry
        if verbose:
            print(f"{obj_id:16s} {entry['mass']:7.3f} kg  {len(F):5d} triangles  "
                  f"poses {', '.join(entry['poses'])}")
    header = (f"# {spec['title']}, generated by tools/make_objects.py: do not edit.\n"
              "# Units: metres, kilograms, kg/m³, kg·m². Object "
              "frame O: containers — origin at the\n"
              "# bottom centre, z along the symmetry axis towards "
              "the opening, handles towards +x;\n"
              "# tools — x along the long axis towards the usable "
              "area, z up when lying flat, origin at\n"
              "# the bottom centre of the bounding box. "
              "cavity_volume, cavity_centroid: the water of a\n"
              "# 'full' container (filled to the rim, upright). poses: "
              "X_TO (table-top frame T → object frame\n"
              "# O) as xyz + rpy (Drake's RollPitchYaw) resting on z "
              "= 0; support_margin: how far the\n"
              "# centre of mass projects inside the support polygon. "
              "inertia: ixx ixy ixz iyy iyz izz\n"
              "# about the centre of mass. grasp_widths: smallest width of each part across the\n"
              "# object's xy plane (an open container's top: its rim wall).\n")
    text = header + yaml.safe_dump({"objects": library}, sort_keys=False,
                                   default_flow_style=None, width=100, allow_unicode=True)
    (out / "library.yaml").write_text(text)
    return library


def compare_trees(a: Path, b: Path) -> list[str]:
    """Relative paths that differ between two directory trees (missing, extra or changed bytes)."""
    fa = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
    fb = {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
    diff = sorted(str(p) for p in fa ^ fb)
    diff += sorted(str(p) for p in fa & fb if not filecmp.cmp(a / p, b / p, shallow=False))
    return diff


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", dest="object_set", choices=tuple(SETS), default="a",
                    help="the object set: a, the shipped library (models/objects/); b, the second "
                         "set with wider shape families (models/objects_b/)")
    ap.add_argument("--out", type=Path, help="output directory (default: the set's folder)")
    ap.add_argument("--check", action="store_true",
                    help="regenerate into a temporary directory and compare bytes with --out")
    ap.add_argument("-v", "--verbose", action="store_true")
    args = ap.parse_args(argv)
    if args.out is None:
        args.out = SETS[args.object_set]["out"]
    if args.check:
        with tempfile.TemporaryDirectory() as tmp:
            generate(Path(tmp), args.verbose, args.object_set)
            diff = compare_trees(Path(tmp), args.out)
        if diff:
            print(f"{len(diff)} file(s) differ from {args.out}:", *diff[:20], sep="\n  ")
            return 1
        print(f"{args.out}: every file matches the generator")
        return 0
    lib = generate(args.out, args.verbose, args.object_set)
    print(f"wrote {len(lib)} objects to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
