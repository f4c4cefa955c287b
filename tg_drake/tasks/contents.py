"""The contents of containers as free spheres: where they start, and where they end up.

A core (NumPy, and Open3D for the wall the spheres touch; no Drake systems framework). The
station (tg_drake.station) builds the spheres from `ContentsConfig`/`DispenserConfig` and start
positions computed here; the task check counts them with `count_contents`.

"Inside a container" is decided from the container's own mesh in its frame O, not from a box: a
point is inside when it lies outside the container's solid and the mesh closes it in sideways and
below — rays from the point in every horizontal direction of O and along −z of O all hit the mesh
(`enclosed`). A sphere in an upright cup is inside; one in the crook of a handle, on the table
beside the cup, or above the rim is not (some horizontal ray escapes). The test works for any
closed (watertight) mesh, so an imported object with no library `dimensions` is handled the same
way; a mesh with no enclosed volume has no cavity and is refused.
"""

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np
import open3d as o3d

from tg_drake.errors import ScenarioError
from tg_drake.objects import mesh as object_mesh

CONTENTS_MODELS = ("mass", "spheres")

# Defaults chosen by measurement (tools/measure_contents.py: a full library cup standing in the
# station, robot idle, and turned upside down 0.25 m above the table by the tilt rig; CPU seconds
# per simulated second on a shared 2-core machine, the mass model 0.46). The cost grows about
# linearly with the number of spheres (10: 2.0, 20: 4.2, 36: 7.4 standing) and with the number of
# plant steps (20 spheres at 2.5 / 5 / 10 ms: 6.9 / 4.2 / 2.3), and barely with the modulus or the
# resolution hint; every setting kept every sphere in the standing cup and poured every one out of
# the turned cup (radius 6 mm: one of 20 bounced off the table). The scripted pour of
# tg_drake.simulation.pour (build included) costs, in CPU seconds, 2.6× the same run with the
# mass contents with 10 spheres at the 5 ms step, 5.5× with 20 (wall time on a heavily loaded
# machine: the bench's median of three 4.6× with 10, 9.5× with 20).
# The spheres touch a simplified copy of a container's mesh (`contents_wall`, below): the
# bench's pour_run_ratio 3.31 / 3.29 → 3.01 / 2.90 (two runs each, idle 2-core machine; the
# plain run 4.7 s, the pour 15.7 → 13.3 s); a 2 mm tolerance was no cheaper than 1 mm.
SPHERE_RADIUS = 0.008  # [m] measured: 14–36 lattice sites in the library's cups and glasses
# (10 mm: 4–18, too coarse a measure of a poured fraction)
MAX_SPHERES = 10  # [1] measured: a fill is at most this many spheres (the lowest sites first);
# the cost is proportional to it, and 10 still resolves a poured fraction to 0.1
SPHERE_MODULUS = 1e8  # [Pa] hydroelastic modulus, measured (1e6: a sphere sinks 3.5 mm of its
# 8 mm radius into the table; 1e7: dropped 15 cm from a dispenser into a bowl, one sank 5.7 mm
# into its 2.9 mm bottom — through it and into the table top; 1e8: 2.1 mm; the cost barely
# depends on it, above)
SPHERE_RESOLUTION = 0.016  # [m] hydroelastic mesh resolution hint (the coarsest sphere), measured
# (4 mm doubled the pour's cost)
SPHERE_DISSIPATION = 5.0  # [s/m] Hunt–Crossley dissipation (little bounce)
SPHERE_FRICTION = 0.3  # [1] static = dynamic Coulomb friction: a loose granular fill
DISPENSER_COUNT = MAX_SPHERES  # [1] spheres in a dispenser by default
DISPENSER_WIDTH = 0.045  # [m] inner side of the dispenser's square hopper by default
DISPENSER_WALL = 0.004  # [m] thickness of the hopper's walls and of its gate

# Sleep (tg_drake.simulation.sleep). Measured on a full library cup standing in the station,
# robot idle: its 10 spheres, dropped from their lattice sites, settle within 0.75 s (every
# sphere's speed bound under 7e-4 m/s, 3e-4 at 1 s, 4e-5 at 3 s: SAP's regularised friction lets
# resting contacts creep); a sphere rolling or sliding is far faster.
SLEEP_SPEED = 0.002  # [m/s] still: slower than this (centre's speed + spin × radius)
SLEEP_AFTER = 0.2  # [s] still this long (40 steps of 5 ms) before they sleep
SLEEP_PERIOD = 0.05  # [s] simulated time between checks (10 steps)
WAKE_MARGIN = 0.03  # [m] a body moving at up to 0.6 m/s crosses it between two checks
WAKE_SPEED = 0.01  # [m/s] measured: a full glass standing on the table, its spheres asleep,
# settles back on the compliant table top relieved of their weight (0.013 mm, its speed bound
# 2.6 mm/s: 0.5 mm/s and a slight turn times its 0.16 m reach): with SLEEP_SPEED as the
# threshold, sleep and wake alternated every 0.25 s
WAKE_SHIFT = 0.001  # [m] a near body (the container they lie in) moved this far wakes them;
# they then overlap its wall by at most that much

LATTICE_GAP = 0.05  # [1] lattice spacing = 2·radius·(1 + gap): spheres start apart
CLEARANCE = 1.1  # [1] a start site is at least this many radii from the container's mesh
ON_TABLE = 3.0  # [radii] a sphere's centre this near the table top lies on the table or on spheres
# lying on it (one resting in the groove between two stands 2.7 radii high)
_PAIRS = 400_000  # ray-triangle pairs per vectorised batch (memory: ~10 MB per array)
_HORIZONTAL = 12  # rays in O's xy plane for the enclosure test


def max_start_jitter(radius: float) -> float:
    """[m] the largest `start_jitter` for spheres of `radius` [m]: two neighbours on the lattice
    start 2·radius·LATTICE_GAP apart; each moved by at most this along every axis (√3 times it
    in all), they still do not touch."""
    return radius * LATTICE_GAP / 4.0


def jittered(p: np.ndarray, jitter: float, seed: int) -> np.ndarray:
    """Start positions (n, 3) [m], each moved by a uniform offset in [-jitter, jitter] along
    each axis, drawn with `seed` (jitter 0: unchanged)."""
    p = np.asarray(p, float)
    if jitter <= 0.0:
        return p
    return p + np.random.default_rng(seed).uniform(-jitter, jitter, size=p.shape)


@dataclass
class ContentsConfig:
    """Scenario.contents: how a "full" container's contents are simulated."""

    model: str = "mass"  # "mass": the water as a solid cylinder welded inside the container (its
    # mass and inertia only) | "spheres": free compliant-hydroelastic spheres of the water's mass
    radius: float = SPHERE_RADIUS  # [m] of each sphere
    count: int = 0  # [1] spheres per full container; 0: as many as fill the cavity on a lattice,
    # at most max_count (the lowest sites first)
    max_count: int = MAX_SPHERES  # [1] bound of a fill (count 0)
    modulus: float = SPHERE_MODULUS  # [Pa] hydroelastic modulus of a sphere
    resolution_hint: float = SPHERE_RESOLUTION  # [m] hydroelastic mesh resolution of a sphere
    dissipation: float = SPHERE_DISSIPATION  # [s/m] Hunt–Crossley dissipation
    friction: float = SPHERE_FRICTION  # [1] Coulomb friction (static = dynamic)
    mutual: bool = True  # the spheres touch each other (False: each touches only the rest of
    # the world, a cheaper fluid that keeps no volume)
    # Start jitter, to measure how much an outcome owes to the spheres' exact start (a pour is
    # chaotic: docs/design.md): each sphere's start moved by a uniform offset in
    # [-start_jitter, start_jitter] along each axis, drawn with `start_seed`; 0: on the lattice.
    start_jitter: float = 0.0  # [m], at most max_start_jitter(radius) (the spheres start apart)
    start_seed: int = 0
    # Resting spheres asleep (tg_drake.simulation.sleep): out of the physics while they and
    # everything near them lie still, until something near them moves.
    sleep: bool = True
    sleep_speed: float = SLEEP_SPEED  # [m/s] still: slower than this (centre + spin × radius)
    sleep_after: float = SLEEP_AFTER  # [s] still this long before they sleep
    sleep_period: float = SLEEP_PERIOD  # [s] simulated time between checks
    wake_margin: float = WAKE_MARGIN  # [m] a body this near a sphere is near them
    wake_speed: float = WAKE_SPEED  # [m/s] a near body faster than this wakes them
    wake_shift: float = WAKE_SHIFT  # [m] a near body moved this far wakes them

    def validate(self, where: str = "contents") -> None:
        if self.model not in CONTENTS_MODELS:
            raise ScenarioError(f"unknown contents model {self.model!r}; allowed: "
                                f"{', '.join(CONTENTS_MODELS)}", field=f"{where}.model")
        _check_count(self.count, f"{where}.count")
        _check_count(self.max_count, f"{where}.max_count", positive=True)
        for name, unit in (("radius", "m"), ("modulus", "Pa"), ("resolution_hint", "m")):
            _check_positive(getattr(self, name), f"{where}.{name}", unit)
        for name, unit in (("sleep_speed", "m/s"), ("sleep_after", "s"), ("sleep_period", "s"),
                           ("wake_margin", "m"), ("wake_speed", "m/s"), ("wake_shift", "m")):
            _check_positive(getattr(self, name), f"{where}.{name}", unit)
        for name, unit in (("dissipation", "s/m"), ("friction", "1")):
            _check_positive(getattr(self, name), f"{where}.{name}", unit, allow_zero=True)
        _check_positive(self.start_jitter, f"{where}.start_jitter", "m", allow_zero=True)
        if self.start_jitter > max_start_jitter(self.radius):
            raise ScenarioError(
                f"start_jitter {self.start_jitter} m would let spheres start overlapping; "
                f"allowed: 0 ≤ start_jitter ≤ {max_start_jitter(self.radius):.6g} m (radius × "
                f"LATTICE_GAP / 4)", field=f"{where}.start_jitter")
        if not isinstance(self.start_seed, int) or isinstance(self.start_seed, bool) \
                or self.start_seed < 0:
            raise ScenarioError(f"start_seed must be an integer ≥ 0, got {self.start_seed!r}",
                                field=f"{where}.start_seed")
        if self.radius > 0.05:
            raise ScenarioError(f"a sphere of radius {self.radius} m is no small contents; "
                                "allowed: 0 < radius ≤ 0.05 [m]", field=f"{where}.radius")


@dataclass
class DispenserConfig:
    """Scenario.dispenser (optional; pourIn): spheres held in a square hopper above `xy` on the
    table, its bottom `height` above the table top, released by a gate when the station input
    `dispenser.open` goes above 0.5."""

    xy: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.0])  # [m] the
    # hopper's centre in the table frame
    height: float = 0.3  # [m] of the hopper's bottom (the gate) above the table top
    count: int = 0  # [1] spheres; 0: DISPENSER_COUNT
    radius: float = 0.0  # [m] of each sphere; 0: contents.radius
    width: float = DISPENSER_WIDTH  # [m] inner side of the square hopper

    def sphere_radius(self, contents: ContentsConfig) -> float:
        return self.radius or contents.radius

    def sphere_count(self) -> int:
        return self.count or DISPENSER_COUNT

    def validate(self, table_size, contents: ContentsConfig, where: str = "dispenser") -> None:
        if len(self.xy) != 2 or not _finite(self.xy):
            raise ScenarioError(f"xy must be two finite numbers [m] (the hopper's centre in the "
                                f"table frame), got {self.xy}", field=f"{where}.xy")
        half = np.asarray(table_size, float) / 2
        if np.any(np.abs(self.xy) > half):
            raise ScenarioError(f"the dispenser at xy={list(self.xy)} is off the table "
                                f"(|x| ≤ {half[0]}, |y| ≤ {half[1]} in the table frame)",
                                field=f"{where}.xy")
        _check_positive(self.height, f"{where}.height", "m")
        _check_count(self.count, f"{where}.count")
        _check_positive(self.radius, f"{where}.radius", "m", allow_zero=True)
        if self.radius > 0.05:
            raise ScenarioError(f"a sphere of radius {self.radius} m is no small contents; "
                                "allowed: 0 (contents.radius) or ≤ 0.05 [m]",
                                field=f"{where}.radius")
        _check_positive(self.width, f"{where}.width", "m")
        radius = self.sphere_radius(contents)
        if self.width < 2 * CLEARANCE * radius:
            raise ScenarioError(f"a hopper of width {self.width} m holds no sphere of radius "
                                f"{radius} m; allowed: width ≥ {2 * CLEARANCE * radius:.3g} [m]",
                                field=f"{where}.width")


@dataclass(frozen=True)
class ContentsModel:
    """What the station built for one container (or the dispenser)."""

    name: str  # the container's instance name, or "dispenser"
    bodies: tuple[int, ...]  # indices of the spheres' bodies in the body_poses output
    radius: float  # [m]


def _finite(value) -> bool:
    try:
        return bool(np.all(np.isfinite(np.asarray(value, float))))
    except (TypeError, ValueError):
        return False


def _check_positive(value, field: str, unit: str, *, allow_zero: bool = False) -> None:
    if isinstance(value, bool) or not _finite(value) or not (
            value >= 0 if allow_zero else value > 0):
        raise ScenarioError(f"must be a finite number {'≥' if allow_zero else '>'} 0 [{unit}], "
                            f"got {value!r}", field=field)


def _check_count(value, field: str, *, positive: bool = False) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or value < (1 if positive else 0):
        raise ScenarioError(f"must be a whole number ≥ {1 if positive else 0}, got {value!r}",
                            field=field)


# ------------------------------------------------------------------------------------------------
# Ray casting on a triangle mesh (Möller–Trumbore), vectorised over points for one direction.


def _ray_hits(origins: np.ndarray, direction: np.ndarray, V: np.ndarray, F: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """(first hit distance (n,) [m], inf when none; number of hits (n,)) of rays from `origins`
    along the unit `direction` on the triangles F of V."""
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    e1, e2 = B - A, C - A
    p = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-15
    A, e1, e2, p, det = A[ok], e1[ok], e2[ok], p[ok], det[ok]
    inv = 1.0 / det
    first = np.full(len(origins), np.inf)
    hits = np.zeros(len(origins), int)
    if len(A) == 0:
        return first, hits
    chunk = max(1, _PAIRS // len(A))  # rays per batch, bounding the (rays × triangles) arrays
    for s in range(0, len(origins), chunk):
        T = origins[s:s + chunk, None, :] - A[None]
        u = np.einsum("nmk,mk->nm", T, p) * inv
        q = np.cross(T, e1[None])
        v = (q @ direction) * inv
        t = np.einsum("nmk,mk->nm", q, e2) * inv
        hit = (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-9)
        hits[s:s + chunk] = hit.sum(axis=1)
        first[s:s + chunk] = np.where(hit, t, np.inf).min(axis=1)
    return first, hits


def _horizontal_directions() -> np.ndarray:
    a = (np.arange(_HORIZONTAL) + 0.5) * 2 * np.pi / _HORIZONTAL  # off the mesh's seam planes
    return np.column_stack([np.cos(a), np.sin(a), np.zeros_like(a)])


# Along O's z, tilted by a few mrad so that a ray does not run through the mesh's seams (the
# generated meshes have vertices on the axis and on the xz and yz planes).
_UP = np.array([1.3e-3, 2.1e-3, 1.0]) / np.linalg.norm([1.3e-3, 2.1e-3, 1.0])
_DOWN = -_UP
_CUBE = np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)
                  if (i, j, k) != (0, 0, 0)], float)
_CUBE /= np.linalg.norm(_CUBE, axis=1, keepdims=True)


def _band(V: np.ndarray, F: np.ndarray, z_lo: float, z_hi: float) -> np.ndarray:
    """The triangles of F that reach into the slab z_lo ≤ z ≤ z_hi."""
    z = V[F][:, :, 2]
    return F[(z.max(axis=1) >= z_lo) & (z.min(axis=1) <= z_hi)]


def enclosed(p_O: np.ndarray, V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(n,) bool: each point of p_O (n, 3) [m, in the container's frame O] lies in the container's
    cavity — outside its solid (an even number of hits along +z) and closed in by its mesh (V, F)
    in every horizontal direction of O and below (along −z of O)."""
    p_O = np.atleast_2d(np.asarray(p_O, float))
    V = np.asarray(V, float)
    _, up_hits = _ray_hits(p_O, _UP, V, F)
    inside = up_hits % 2 == 0
    down, _ = _ray_hits(p_O, _DOWN, V, F)
    inside &= np.isfinite(down)
    for d in _horizontal_directions():
        if not inside.any():
            break
        idx = np.flatnonzero(inside)
        band = _band(V, F, p_O[idx, 2].min(), p_O[idx, 2].max())
        dist, _ = _ray_hits(p_O[idx], d, V, band)
        inside[idx[~np.isfinite(dist)]] = False
    return inside


def _clear(p_O: np.ndarray, V: np.ndarray, F: np.ndarray, distance: float) -> np.ndarray:
    """(n,) bool: no ray from the point in 26 directions (a cube's faces, edges and corners) hits
    the mesh within `distance` [m], nor is a mesh vertex that near."""
    band = _band(V, F, p_O[:, 2].min() - distance, p_O[:, 2].max() + distance)
    ok = np.ones(len(p_O), bool)
    if len(band) == 0:
        return ok
    for d in _CUBE:
        ok &= _ray_hits(p_O, d, V, band)[0] >= distance
    W = V[np.unique(band)]
    ok &= np.min(np.linalg.norm(p_O[:, None, :] - W[None], axis=2), axis=1) >= distance
    return ok


def _floor(V: np.ndarray, F: np.ndarray) -> float | None:
    """[m] z of the cavity's floor on O's axis: the second surface a ray up the axis from below
    meets (the first is the outside of the bottom); None when it meets fewer than two."""
    o = np.array([[0.0, 0.0, V[:, 2].min() - 0.01]])
    zs = []
    for _ in range(2):
        t, _ = _ray_hits(o, _UP, V, F)
        if not np.isfinite(t[0]):
            return None
        o = o + _UP * (t[0] + 1e-7)
        zs.append(float(o[0, 2]))
    return zs[1]


def _lattice(lo: np.ndarray, hi: np.ndarray, spacing: float) -> np.ndarray:
    """Points of a cubic lattice of `spacing` [m] within the box lo..hi, centred in x and y and
    starting at lo in z; ordered bottom layer first."""
    axes = []
    for k in range(3):
        n = max(int(math.floor((hi[k] - lo[k]) / spacing)) + 1, 0)
        start = 0.5 * (lo[k] + hi[k]) - 0.5 * (n - 1) * spacing if k < 2 else lo[k]
        axes.append(start + spacing * np.arange(n))
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    P = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    return P[np.lexsort((P[:, 1], P[:, 0], P[:, 2]))]


def cavity_sites(V: np.ndarray, F: np.ndarray, radius: float,
                 max_sites: int | None = None) -> np.ndarray:
    """(n, 3) [m, in O] sphere centres on a cubic lattice that fit in the container's cavity,
    layer by layer from its floor up (at most `max_sites`, the lowest first): each centre enclosed
    (`enclosed`), its top (centre + radius along z) enclosed too so that no sphere stands above
    the rim, and the sphere clear of the mesh by CLEARANCE radii."""
    V = np.asarray(V, float)
    F = np.asarray(F, np.int64)
    spacing = 2 * radius * (1 + LATTICE_GAP)
    lo, hi = V.min(axis=0) + radius, V.max(axis=0) - radius
    floor = _floor(V, F)
    z0 = lo[2] if floor is None else max(lo[2], floor + CLEARANCE * radius)
    # Centred on O's z axis (a container's symmetry axis), over the mesh's whole width.
    half = np.maximum(np.abs(lo[:2]), np.abs(hi[:2]))
    layer = _lattice(np.array([-half[0], -half[1], 0.0]), np.array([half[0], half[1], 0.0]),
                     spacing)
    sites = []
    z = z0
    while z <= hi[2] and (max_sites is None or len(sites) < max_sites):
        P = layer + [0.0, 0.0, z]
        P = P[enclosed(P, V, F)]
        if len(P):
            P = P[enclosed(P + [0.0, 0.0, radius], V, F)]
        if len(P):
            P = P[_clear(P, V, F, CLEARANCE * radius)]
        sites.extend(P)
        z += spacing
    sites = np.array(sites, float).reshape(-1, 3)
    return sites if max_sites is None else sites[:max_sites]


@functools.cache
def _cavity_sites_cached(key, radius: float, n: int, V_bytes: bytes, F_bytes: bytes, nv: int,
                         nf: int):
    V = np.frombuffer(V_bytes, float).reshape(nv, 3)
    F = np.frombuffer(F_bytes, np.int64).reshape(nf, 3)
    sites = cavity_sites(V, F, radius, n + 1)
    sites.setflags(write=False)
    return sites


def container_sites(obj_id: str, V: np.ndarray, F: np.ndarray, config: ContentsConfig,
                    *, field: str = "contents") -> np.ndarray:
    """(count, 3) [m, in O] start positions of a full container's spheres (cached per object and
    radius); ScenarioError naming the field when the cavity holds none or fewer than `count`."""
    V = np.ascontiguousarray(V, float)
    F = np.ascontiguousarray(F, np.int64)
    want = config.count or config.max_count
    sites = _cavity_sites_cached(obj_id, float(config.radius), want, V.tobytes(), F.tobytes(),
                                 len(V), len(F))
    if len(sites) == 0:
        raise ScenarioError(f"{obj_id}'s mesh encloses no open cavity that holds a sphere of "
                            f"radius {config.radius} m (a closed mesh is solid); use a smaller "
                            "radius, contents.model: mass, or containment: empty",
                            field=f"{field}.radius")
    n = config.count or min(len(sites), config.max_count)
    if n > len(sites):
        raise ScenarioError(f"{obj_id}'s cavity holds {len(sites)} spheres of radius "
                            f"{config.radius} m, fewer than {n}; allowed: 0 (fill) to "
                            f"{len(sites)}",
                            field=f"{field}.count")
    return np.array(sites[:n])


def hopper_sites(config: DispenserConfig, radius: float) -> np.ndarray:
    """(count, 3) [m] sphere centres in the dispenser's hopper frame H (origin at the centre of
    the gate's top, z up): a square lattice column within the hopper's inner `width`."""
    spacing = 2 * radius * (1 + LATTICE_GAP)
    half = 0.5 * config.width - radius * CLEARANCE
    if half < 0:
        raise ScenarioError(f"a hopper of width {config.width} m holds no sphere of radius "
                            f"{radius} m", field="dispenser.width")
    per_side = int(math.floor(2 * half / spacing)) + 1
    xs = (np.arange(per_side) - 0.5 * (per_side - 1)) * spacing
    layer = np.array([(x, y) for x in xs for y in xs])
    n = config.sphere_count()
    layers = -(-n // len(layer))
    z = radius * CLEARANCE + spacing * np.arange(layers)
    P = np.array([(x, y, zz) for zz in z for x, y in layer])
    return P[:n]


def hopper_height(config: DispenserConfig, radius: float) -> float:
    """[m] inner height of the hopper: its spheres' column and one diameter more."""
    top = hopper_sites(config, radius)[:, 2].max()
    return float(top + 3 * radius)


# ------------------------------------------------------------------------------------------------
# Where the spheres are.


def _translation(X) -> np.ndarray:
    if hasattr(X, "translation"):
        return np.asarray(X.translation(), float)
    return np.asarray(X, float)[:3, 3]


def _matrix(X) -> np.ndarray:
    if hasattr(X, "GetAsMatrix4"):
        return np.asarray(X.GetAsMatrix4(), float)
    return np.asarray(X, float)


def count_contents(model: ContentsModel, body_poses, *,
                   containers: dict[str, tuple[np.ndarray, object]],
                   table_z: float, mesh_of=object_mesh) -> dict[str, int]:
    """Where every sphere of `model` is: keys = each container's name (given as name → (X_WO 4×4
    or RigidTransform, LibraryObject)), "table", "floor", "elsewhere"; the counts sum to
    len(model.bodies).

    A sphere is in the first container whose cavity encloses its centre (`enclosed`, in that
    container's frame); else on the table when its centre is within ON_TABLE radii above the
    table top `table_z` [m, world z] (on it, or on spheres lying on it); on the floor when below
    the table top (it fell off); elsewhere otherwise (in the air, in the hopper, on the gripper,
    on another object). `mesh_of(obj)` gives (V, F, ...) of a container (tg_drake.objects.mesh
    by default)."""
    p_W = np.array([_translation(body_poses[int(b)]) for b in model.bodies]).reshape(-1, 3)
    counts = {name: 0 for name in containers}
    counts.update(table=0, floor=0, elsewhere=0)
    left = np.ones(len(p_W), bool)
    for name, (X_WO, obj) in containers.items():
        if not left.any():
            break
        X = _matrix(X_WO)
        p_O = (p_W[left] - X[:3, 3]) @ X[:3, :3]
        V, F = mesh_of(obj)[:2]
        inside = enclosed(p_O, np.asarray(V, float), np.asarray(F))
        idx = np.flatnonzero(left)[inside]
        counts[name] += len(idx)
        left[idx] = False
    z = p_W[left, 2]
    on_table = (z >= table_z) & (z <= table_z + ON_TABLE * model.radius)
    floor = z < table_z
    counts["table"] += int(on_table.sum())
    counts["floor"] += int(floor.sum())
    counts["elsewhere"] += int((~on_table & ~floor).sum())
    return counts


# The surface the spheres touch. A library container's collision mesh is its visual mesh (about
# 3,000 triangles for a cup); a compliant sphere's contact with it is clipped against every
# triangle under it, one contact point per piece, and the contact points are most of a pour's
# cost. The spheres touch a simplified copy of it instead, no farther than WALL_TOLERANCE from
# the original anywhere; the gripper, the table and everything else still touch the original.
WALL_TOLERANCE = 0.001  # [m] a sphere's radius / 8 at the default radius: well under a wall's
# 3–6 mm thickness, so no wall opens and no cavity shrinks by more than this


def _distance_to(V: np.ndarray, F: np.ndarray):
    """points (n, 3) → the largest of their distances [m] to the triangle mesh (V, F) (open3d's
    exact point-to-triangle distance); the mesh's scene is built once."""
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(V.astype(np.float32)), o3d.core.Tensor(F.astype(np.uint32)))
    return lambda P: float(scene.compute_distance(o3d.core.Tensor(P.astype(np.float32))).numpy()
                           .max())


def _samples(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """The points a mesh is compared by: its vertices and its triangles' centroids."""
    return np.vstack([V, V[F].mean(axis=1)])


@functools.lru_cache(maxsize=64)
def _wall_cached(V_bytes: bytes, F_bytes: bytes, tolerance: float):
    V = np.frombuffer(V_bytes, float).reshape(-1, 3)
    F = np.frombuffer(F_bytes, np.int64).reshape(-1, 3)
    source = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(V.copy()),
                                       o3d.utility.Vector3iVector(F.astype(np.int32)))
    to_original, original = _distance_to(V, F), _samples(V, F)
    best = (V, F)
    lo, hi = 4, len(F)  # the fewest triangles within the tolerance, by bisection
    while hi - lo > max(8, hi // 20):
        n = (lo + hi) // 2
        d = source.simplify_quadric_decimation(target_number_of_triangles=n)
        d.remove_degenerate_triangles()
        d.remove_unreferenced_vertices()
        Vd, Fd = np.asarray(d.vertices, float), np.asarray(d.triangles, np.int64)
        # Within the tolerance both ways (a symmetric distance over the samples).
        if (len(Fd) and to_original(_samples(Vd, Fd)) <= tolerance
                and _distance_to(Vd, Fd)(original) <= tolerance):
            best, hi = (Vd, Fd), n
        else:
            lo = n
    for a in best:
        a.setflags(write=False)
    return best


def contents_wall(V: np.ndarray, F: np.ndarray, tolerance: float = WALL_TOLERANCE
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The simplified surface of the mesh (V, F) that the spheres touch: quadric decimation to
    the fewest triangles whose surface stays within `tolerance` [m] of the original (both ways);
    the original when no fewer do. Cached per mesh."""
    V = np.ascontiguousarray(V, float)
    F = np.ascontiguousarray(F, np.int64)
    return _wall_cached(V.tobytes(), F.tobytes(), float(tolerance))
