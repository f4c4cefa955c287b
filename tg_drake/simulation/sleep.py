"""Resting contents asleep: spheres that lie still, with nothing moving near them, leave the
physics until something near them moves again.

A container's spheres cost most while they lie still: in the container before it is grasped, in
the target bowl after a pour, on the table after a spill (`tg_drake.tasks.contents`: each resting
sphere is a contact surface clipped against its container's mesh at every step). Physics engines
let such bodies sleep; Drake does not, so the simulation loop does it between steps
(`advance`):

- **Asleep**: every sphere has been still (`ContentsConfig.sleep_speed` [m/s]: its centre's
  speed plus its spin times its radius) for `sleep_after` [s], and so has every other body near
  them (a body is near when its bounding sphere, from its collision geometries, comes within
  `wake_margin` [m] of a sphere). Then every sphere's joint is locked (SAP drops its degrees of
  freedom) and its contacts are filtered (a transient collision filter in the scene graph's
  context: no contact surface is computed for it). They stay exactly where they lay.
- **Awake** again, at the first check after: a body near them moves faster than `wake_speed`
  [m/s], or a body that was near when they fell asleep (the container they lie in, the bowl) has
  moved or turned by `wake_shift` [m] at its bounding sphere. The filter is removed and the
  joints unlocked; they go on from rest where they lay. (`wake_speed` is above `sleep_speed`: a
  light container relieved of its contents' weight settles back on its compliant support by a
  fraction of a millimetre, slowly, and that alone should not wake them.)
- **Strays** (whether or not sleep is on): a sphere out of the workspace (`workspace`: over
  the floor the station lays for the contents, up to 2 m above the table) at a full check is
  locked and filtered for good where it is, and counted there (the floor or elsewhere).

All spheres sleep and wake together: one sphere resting on another never loses its support.
The full check runs every `sleep_period` [s] of simulated time; while they sleep, the bodies
that were near them are watched after every plant step, so a support that starts to move (a
dispenser's gate sliding open, a container taken by the hand) wakes them one step later. Checks
run at fixed simulated times: a run is deterministic. While asleep the spheres' weight does not
press on what they lie in; nothing near them moves then, so nothing can tell. `contents:
{sleep: false}` turns it off.

    sleeper = ContentsSleep.for_station(station, scenario.contents)  # None: no spheres
    advance(simulator, t_end, sleeper)   # simulator.AdvanceTo with the checks in between
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet, Role
from pydrake.multibody.tree import BodyIndex
from pydrake.systems.analysis import SimulatorStatus

from tg_drake.table import FLOOR_MARGIN, TABLE_HEIGHT

# ---------------------------------------------------------------------------------------------
# The core: decisions on arrays.


def speeds(v_W: np.ndarray, w_W: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """[m/s] a bound on how fast any point of each body moves: its reference point's speed
    |v_W| (n, 3) plus its spin |w_W| (n, 3) [rad/s] times `reach` (n,) [m], the farthest its
    geometry lies from that point."""
    return (np.linalg.norm(np.asarray(v_W, float), axis=1)
            + np.linalg.norm(np.asarray(w_W, float), axis=1) * np.asarray(reach, float))


def near_spheres(p_spheres: np.ndarray, radius: float, centres: np.ndarray, radii: np.ndarray,
                 margin: float) -> np.ndarray:
    """Which bodies (bounding spheres `centres` (m, 3), `radii` (m,) [m]) come within `margin`
    [m] of some sphere of `radius` [m] centred at `p_spheres` (n, 3): a bool (m,) array."""
    p = np.asarray(p_spheres, float).reshape(-1, 3)
    c = np.asarray(centres, float).reshape(-1, 3)
    if len(p) == 0 or len(c) == 0:
        return np.zeros(len(c), bool)
    d = np.linalg.norm(c[:, None, :] - p[None, :, :], axis=2).min(axis=1)
    return d < np.asarray(radii, float) + radius + margin


def shifted(X_then: np.ndarray, X_now: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """[m] how far each body's geometry moved between two poses (k, 4, 4) at most: its reference
    point's displacement plus the turn's angle times `reach` (k,) [m]."""
    X0, X1 = np.asarray(X_then, float), np.asarray(X_now, float)
    move = np.linalg.norm(X1[:, :3, 3] - X0[:, :3, 3], axis=1)
    R = np.einsum("kji,kjl->kil", X0[:, :3, :3], X1[:, :3, :3])  # R0ᵀ R1
    cos = np.clip((np.trace(R, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    return move + np.arccos(cos) * np.asarray(reach, float)


def inside(p: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Which points (n, 3) lie in the box [lo, hi] (world, m): a bool (n,) array."""
    p = np.asarray(p, float).reshape(-1, 3)
    return np.all((p >= lo) & (p <= hi), axis=1)


def workspace(X_WT: np.ndarray, table_size) -> tuple[np.ndarray, np.ndarray]:
    """The box [lo, hi] (world, m) the contents may be in: over the floor (the table's footprint
    widened by FLOOR_MARGIN on every side, TABLE_HEIGHT below the top:
    `station.add_contents_floor`), from just under the floor's top to STRAY_HEIGHT above the
    table top. A sphere outside it has strayed: shot out of a pinch between two rigid walls (now
    and then in a pour, at 20–30 m/s), it would fly or fall without end until the simulation
    stopped on a non-finite pose."""
    X_WT = np.asarray(X_WT, float)
    half = 0.5 * np.asarray(table_size, float) + FLOOR_MARGIN
    corners = np.array([[sx * half[0], sy * half[1], 0.0] for sx in (-1, 1) for sy in (-1, 1)])
    xy = (corners @ X_WT[:3, :3].T + X_WT[:3, 3])[:, :2]
    z = X_WT[2, 3]
    lo = np.array([*xy.min(axis=0), z - TABLE_HEIGHT - STRAY_MARGIN_BELOW])
    hi = np.array([*xy.max(axis=0), z + STRAY_HEIGHT])
    return lo, hi


STRAY_MARGIN_BELOW = 0.05  # [m] under the floor's top
STRAY_HEIGHT = 2.0  # [m] above the table top


# ---------------------------------------------------------------------------------------------
# The station's bodies and the loop.


@dataclass
class _Bounds:
    """A body's bounding sphere: centre in the body frame, radius [m]."""

    body: object
    p_BC: np.ndarray
    radius: float


def bounding_sphere(plant, inspector, body) -> _Bounds | None:
    """The sphere about the body's collision geometries' oriented boxes (None: no collision
    geometry, or none with a box — it touches nothing the spheres do)."""
    corners = []
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    for g in plant.GetCollisionGeometriesForBody(body):
        obb = inspector.GetObbInGeometryFrame(g)
        if obb is None:
            continue
        X_BO = inspector.GetPoseInFrame(g).GetAsMatrix4() @ obb.pose().GetAsMatrix4()
        corners.append((X_BO @ np.c_[signs * obb.half_width(), np.ones(8)].T).T[:, :3])
    if not corners:
        return None
    pts = np.vstack(corners)
    centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    return _Bounds(body, centre, float(np.linalg.norm(pts - centre, axis=1).max()))


@dataclass
class ContentsSleep:
    """The spheres' sleep and wake (module doc) for one simulator's plant; `update` at each
    check, `watch` after each step while they sleep. `events` lists (simulated time [s],
    "sleep" | "wake" | "froze N strayed") for the record."""

    plant: object
    scene_graph: object
    spheres: list  # the spheres' bodies
    sphere_geometries: list  # each sphere's proximity geometry ids
    radius: float  # [m] the largest sphere's
    others: list  # every other body that can move and touch
    p_BC: np.ndarray  # (m, 3) [m] the centres of their bounding spheres, in their frames
    radii: np.ndarray  # (m,) [m] the radii of their bounding spheres
    config: object  # ContentsConfig (its sleep_* and wake_* fields)
    lo: np.ndarray = field(default_factory=lambda: np.full(3, -np.inf))  # the workspace [m]
    hi: np.ndarray = field(default_factory=lambda: np.full(3, np.inf))
    frozen: set = field(default_factory=set)  # indices of the spheres frozen as strays
    still_since: float | None = None
    asleep: bool = False
    filter_id: object = None
    near_then: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))  # when they slept
    X_then: np.ndarray = field(default_factory=lambda: np.zeros((0, 4, 4)))  # the others then
    events: list = field(default_factory=list)

    @classmethod
    def for_station(cls, station, config) -> ContentsSleep | None:
        """None when the station has no spheres. With `config.sleep` off they never sleep, but
        strays are still frozen (`workspace`)."""
        spheres = [station.plant.get_body(BodyIndex(b)) for m in station.contents
                   for b in m.bodies]
        if not spheres:
            return None
        plant = station.plant
        inspector = station.scene_graph.model_inspector()
        ids = {int(b.index()) for b in spheres}
        static = {int(b.index()) for b in plant.GetBodiesWeldedTo(plant.world_body())}
        bounds = [bounding_sphere(plant, inspector, plant.get_body(BodyIndex(i)))
                  for i in range(plant.num_bodies()) if i not in ids and i not in static]
        bounds = [b for b in bounds if b is not None]
        scenario = station.scenario
        lo, hi = workspace(scenario.X_WT.GetDeterministicValue().GetAsMatrix4(),
                           scenario.table_size)
        return cls(plant, station.scene_graph, spheres,
                   [list(plant.GetCollisionGeometriesForBody(b)) for b in spheres],
                   max(m.radius for m in station.contents), [b.body for b in bounds],
                   np.array([b.p_BC for b in bounds]).reshape(-1, 3),
                   np.array([b.radius for b in bounds]), config, lo, hi)

    @property
    def reach(self) -> np.ndarray:
        """[m] the farthest each other body's geometry lies from its origin."""
        return np.linalg.norm(self.p_BC, axis=1) + self.radii

    def _state(self, plant_context):
        poses = self.plant.get_body_poses_output_port().Eval(plant_context)
        vels = self.plant.get_body_spatial_velocities_output_port().Eval(plant_context)

        def arrays(bodies, reach):
            X = np.array([poses[b.index()].GetAsMatrix4() for b in bodies]).reshape(-1, 4, 4)
            V = [vels[b.index()] for b in bodies]
            v = np.array([s.translational() for s in V]).reshape(-1, 3)
            w = np.array([s.rotational() for s in V]).reshape(-1, 3)
            return X, speeds(v, w, reach)

        X_s, v_s = arrays(self.spheres, np.full(len(self.spheres), self.radius))
        X_o, v_o = arrays(self.others, self.reach)
        centres = np.einsum("kij,kj->ki", X_o[:, :3, :3], self.p_BC) + X_o[:, :3, 3]
        return X_s[:, :3, 3], v_s, X_o, v_o, centres

    def asleep_time(self, t_end: float) -> float:
        """[s] of simulated time the spheres slept up to `t_end`."""
        total, since = 0.0, None
        for t, event in self.events:
            if event == "sleep":
                since = t
            elif event == "wake" and since is not None:
                total, since = total + t - since, None
        return total + (t_end - since if since is not None else 0.0)

    def update(self, root_context) -> None:
        """One check at the context's time (module doc)."""
        c = self.config
        t = root_context.get_time()
        p_s, v_s, X_o, v_o, centres = self._state(
            self.plant.GetMyContextFromRoot(root_context))
        strays = [int(i) for i in np.flatnonzero(~inside(p_s, self.lo, self.hi))
                  if int(i) not in self.frozen]
        if strays:
            self._freeze(root_context, t, strays)
        if not c.sleep:
            return
        if self.frozen:  # (strays take no part in sleep and wake)
            keep = np.array([i not in self.frozen for i in range(len(p_s))])
            p_s, v_s = p_s[keep], v_s[keep]
        near = near_spheres(p_s, self.radius, centres, self.radii, c.wake_margin)
        if self.asleep:
            if np.any(v_o[near] > c.wake_speed) or self._moved(X_o[self.near_then]):
                self._wake(root_context, t)
            return
        if np.all(v_s < c.sleep_speed) and np.all(v_o[near] < c.sleep_speed):
            if self.still_since is None:
                self.still_since = t
            elif t - self.still_since >= c.sleep_after - 1e-9:
                self._sleep(root_context, t, near, X_o)
        else:
            self.still_since = None

    def _moved(self, X_near: np.ndarray) -> bool:
        """Has a body that was near them when they fell asleep (poses X_near, in the order of
        `near_then`) moved or turned by `wake_shift`?"""
        i = np.flatnonzero(self.near_then)
        return bool(np.any(shifted(self.X_then[i], X_near, self.reach[i])
                           > self.config.wake_shift))

    def watch(self, root_context) -> None:
        """The check after every step while they sleep: a body that was near them when they
        fell asleep moves faster than `wake_speed` or has moved by `wake_shift` — wake."""
        plant_context = self.plant.GetMyContextFromRoot(root_context)
        i = np.flatnonzero(self.near_then)
        bodies = [self.others[k] for k in i]
        V = [self.plant.EvalBodySpatialVelocityInWorld(plant_context, b) for b in bodies]
        v = np.array([s.translational() for s in V]).reshape(-1, 3)
        w = np.array([s.rotational() for s in V]).reshape(-1, 3)
        X = np.array([self.plant.EvalBodyPoseInWorld(plant_context, b).GetAsMatrix4()
                      for b in bodies]).reshape(-1, 4, 4)
        if np.any(speeds(v, w, self.reach[i]) > self.config.wake_speed) or self._moved(X):
            self._wake(root_context, root_context.get_time())

    def _filter(self, root_context, geometries):
        """A transient filter in the scene graph's context: `geometries` touch nothing."""
        sg_context = self.scene_graph.GetMyMutableContextFromRoot(root_context)
        everything = self.scene_graph.model_inspector().GetAllGeometryIds(Role.kProximity)
        return self.scene_graph.collision_filter_manager(sg_context).ApplyTransient(
            CollisionFilterDeclaration().ExcludeBetween(GeometrySet(geometries),
                                                        GeometrySet(list(everything))))

    def _freeze(self, root_context, t, strays) -> None:
        """Strays (spheres out of the workspace) locked and their contacts filtered, for good:
        they are counted where they are (`count_contents`: the floor or elsewhere)."""
        plant_context = self.plant.GetMyMutableContextFromRoot(root_context)
        for i in strays:
            self.spheres[i].Lock(plant_context)
            self.frozen.add(i)
        self._filter(root_context, [g for i in strays for g in self.sphere_geometries[i]])
        self.events.append((round(float(t), 6), f"froze {len(strays)} strayed"))

    def _sleep(self, root_context, t, near, X_o) -> None:
        plant_context = self.plant.GetMyMutableContextFromRoot(root_context)
        for b in self.spheres:
            b.Lock(plant_context)
        self.filter_id = self._filter(root_context,
                                      [g for gs in self.sphere_geometries for g in gs])
        self.asleep, self.near_then, self.X_then = True, near.copy(), X_o.copy()
        self.events.append((round(float(t), 6), "sleep"))

    def _wake(self, root_context, t) -> None:
        sg_context = self.scene_graph.GetMyMutableContextFromRoot(root_context)
        self.scene_graph.collision_filter_manager(sg_context).RemoveDeclaration(self.filter_id)
        plant_context = self.plant.GetMyMutableContextFromRoot(root_context)
        for i, b in enumerate(self.spheres):
            if i not in self.frozen:
                b.Unlock(plant_context)
        self.asleep, self.filter_id, self.still_since = False, None, None
        self.events.append((round(float(t), 6), "wake"))


def advance(simulator, t_end: float, sleeper: ContentsSleep | None) -> None:
    """`simulator.AdvanceTo(t_end)`; with a `sleeper`, one plant step at a time: every
    `sleep_period` a full check (`ContentsSleep.update`), and while the spheres sleep, after
    every step a watch on the bodies that were near them (`ContentsSleep.watch`: a support that
    starts to move wakes them one step later). Stops early, as AdvanceTo does, when the
    simulator's monitor says so."""
    if sleeper is None:
        simulator.AdvanceTo(t_end)
        return
    context = simulator.get_context()
    h = sleeper.plant.time_step()
    every = max(1, int(round(sleeper.config.sleep_period / h)))
    if not sleeper.config.sleep:  # only the strays' check, every sleep_period
        h, every = h * every, 1
    k = int(np.floor(context.get_time() / h + 1e-6))
    while context.get_time() < t_end - 1e-12:
        k += 1
        status = simulator.AdvanceTo(min(t_end, k * h))
        if status.reason() == SimulatorStatus.ReturnReason.kReachedTerminationCondition:
            return
        if k % every == 0:
            sleeper.update(simulator.get_mutable_context())
        elif sleeper.asleep:
            sleeper.watch(simulator.get_mutable_context())
