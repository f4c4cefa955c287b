"""The contents core: a container's cavity from its mesh, start sites, counts, and bad input."""

import dataclasses

import numpy as np
import pytest

from tg_drake.errors import ScenarioError
from tg_drake.objects import get_object, mesh
from tg_drake.scenario import load_scenario
from tg_drake.tasks.contents import (
    CLEARANCE,
    LATTICE_GAP,
    WALL_TOLERANCE,
    ContentsConfig,
    ContentsModel,
    DispenserConfig,
    cavity_sites,
    container_sites,
    contents_wall,
    count_contents,
    enclosed,
    hopper_sites,
    jittered,
    max_start_jitter,
)

CUP = "cup_01"


def _cup():
    V, F = mesh(CUP)[:2]
    return get_object(CUP), np.asarray(V, float), np.asarray(F)


def test_the_cavity_is_the_inside_of_the_cup_not_its_box():
    obj, V, F = _cup()
    d = obj.dimensions
    inner = d["diameter"] / 2 - d["wall"]
    mid = d["height"] / 2
    points = np.array([
        [0.0, 0.0, mid],  # in the cavity
        [0.5 * inner, 0.0, mid],
        [0.0, 0.0, d["height"] + 0.01],  # above the rim
        [0.0, d["diameter"] / 2 + 0.01, mid],  # beside the cup, inside its bounding box? no: out
        [d["diameter"] / 2 + 0.5 * d["handle_reach"], 0.0, mid],  # in the handle's crook (box)
        [0.0, 0.0, 0.5 * d["base"]],  # inside the solid base
        [inner + 0.5 * d["wall"], 0.0, mid],  # inside the wall
    ])
    assert enclosed(points, V, F).tolist() == [True, True, False, False, False, False, False]


def test_start_sites_lie_in_the_cavity_clear_of_the_walls_and_apart():
    obj, V, F = _cup()
    r = 0.008
    sites = cavity_sites(V, F, r)
    assert len(sites) > 10
    assert enclosed(sites, V, F).all()
    d = obj.dimensions
    rho = np.hypot(sites[:, 0], sites[:, 1])
    assert np.all(rho + CLEARANCE * r <= d["diameter"] / 2 - d["wall"] + 1e-3)
    assert np.all(sites[:, 2] - r >= d["base"])
    assert np.all(sites[:, 2] + r <= d["height"])
    gaps = np.linalg.norm(sites[:, None] - sites[None], axis=2) + np.eye(len(sites))
    assert gaps.min() >= 2 * r
    # Bottom layer first; a bound takes the lowest sites.
    assert np.all(np.diff(sites[:, 2]) >= 0)
    assert np.array_equal(cavity_sites(V, F, r, 5), sites[:5])


def test_a_fill_is_bounded_by_max_count_and_count_is_exact():
    obj, V, F = _cup()
    assert len(container_sites(CUP, V, F, ContentsConfig(model="spheres", max_count=7))) == 7
    assert len(container_sites(CUP, V, F, ContentsConfig(model="spheres", count=3))) == 3
    with pytest.raises(ScenarioError) as e:
        container_sites(CUP, V, F, ContentsConfig(model="spheres", count=10_000))
    assert e.value.field == "contents.count"


def test_a_closed_container_mesh_has_no_cavity_for_spheres():
    # A can's or bottle's library mesh is its closed outer surface: a solid.
    V, F = mesh("can_01")[:2]
    assert len(cavity_sites(np.asarray(V, float), np.asarray(F), 0.008)) == 0
    with pytest.raises(ScenarioError, match="no open cavity"):
        container_sites("can_01", V, F, ContentsConfig(model="spheres"))


def _poses(points):
    out = []
    for p in points:
        X = np.eye(4)
        X[:3, 3] = p
        out.append(X)
    return out


def test_counts_follow_the_container_frame_and_sum_to_every_sphere():
    obj, V, F = _cup()
    r = 0.008
    sites = cavity_sites(V, F, r)[:4]
    # The cup upside down 0.2 m above the table at (0.7, 0.1): O's z points down.
    X_WO = np.eye(4)
    X_WO[:3, :3] = np.diag([1.0, -1.0, -1.0])
    X_WO[:3, 3] = [0.7, 0.1, 0.3]
    in_cup = sites @ X_WO[:3, :3].T + X_WO[:3, 3]
    table, floor, air = [0.1, 0.0, r], [0.0, 0.5, -0.3], [0.0, 0.0, 0.5]
    points = np.vstack([in_cup, [table, floor, air, [0.7, 0.1, 0.3 - 0.5]]])
    model = ContentsModel("cup", tuple(range(len(points))), r)
    counts = count_contents(model, _poses(points), containers={"cup": (X_WO, obj)}, table_z=0.0)
    assert counts == {"cup": 4, "table": 1, "floor": 2, "elsewhere": 1}
    assert sum(counts.values()) == len(points)


@pytest.mark.parametrize("text, field", [
    ("contents: {model: water}", "contents.model"),
    ("contents: {model: spheres, radius: -0.01}", "contents.radius"),
    ("contents: {model: spheres, radius: 0.2}", "contents.radius"),
    ("contents: {model: spheres, max_count: 0}", "contents.max_count"),
    ("contents: {model: spheres, count: 100000}\nobjects: [{id: cup_01, containment: full}]",
     "contents.count"),
    ("contents: {model: spheres}\nobjects: [{id: can_01, containment: full}]",
     "objects[0].containment"),
    ("dispenser: {xy: [2.0, 0.0]}", "dispenser.xy"),
    ("dispenser: {xy: [0.0, 0.0], height: -0.1}", "dispenser.height"),
    ("dispenser: {xy: [0.0, 0.0], count: -3}", "dispenser.count"),
    ("dispenser: {xy: [0.0, 0.0], width: 0.01}", "dispenser.width"),
    ("dispenser: {xy: [0.0, 0.0], height: 0.05}\nobjects: [{id: cup_01}]", "dispenser.height"),
])
def test_bad_contents_and_dispensers_name_their_field(text, field):
    with pytest.raises(ScenarioError) as e:
        load_scenario(scenario_text=text + "\ncameras: {}")
    assert e.value.field == field


def test_hopper_sites_stand_in_the_hopper_apart():
    config = DispenserConfig(xy=[0.0, 0.0], count=13)
    r = 0.008
    P = hopper_sites(config, r)
    assert len(P) == 13
    assert np.all(np.abs(P[:, :2]) + r <= config.width / 2)
    assert np.all(P[:, 2] >= r)
    gaps = np.linalg.norm(P[:, None] - P[None], axis=2) + np.eye(len(P))
    assert gaps.min() >= 2 * r


def _distances(P, V, F):
    """[m] each point's distance to the triangle mesh (V, F) (open3d's exact distance)."""
    import open3d as o3d
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(np.asarray(V, np.float32)),
                        o3d.core.Tensor(np.asarray(F, np.uint32)))
    return scene.compute_distance(o3d.core.Tensor(np.asarray(P, np.float32))).numpy()


def test_the_wall_the_spheres_touch_is_a_simpler_surface_within_its_tolerance():
    obj, V, F = _cup()
    Vw, Fw = contents_wall(V, F)
    assert len(Fw) < len(F) / 3  # the point of it: far fewer triangles to clip
    # Both ways within the tolerance (+ float32 round-off): every vertex and triangle centroid of
    # each surface near the other.
    tol = WALL_TOLERANCE + 1e-6
    assert _distances(np.vstack([V, V[F].mean(axis=1)]), Vw, Fw).max() <= tol
    assert _distances(np.vstack([Vw, Vw[Fw].mean(axis=1)]), V, F).max() <= tol
    # No sphere starts touching it: the start sites keep their clearance, less the tolerance.
    config = ContentsConfig(model="spheres")
    sites = container_sites(obj.id, V, F, config)
    assert _distances(sites, Vw, Fw).min() >= CLEARANCE * config.radius - tol


def test_a_wall_that_cannot_be_simplified_within_its_tolerance_is_the_original():
    _, V, F = _cup()
    Vw, Fw = contents_wall(V, F, tolerance=1e-7)
    assert np.array_equal(Vw, V) and np.array_equal(Fw, F)


def test_a_start_jitter_moves_each_sphere_within_its_bound_reproducibly_and_keeps_them_apart():
    p = np.array([[0.0, 0.0, 0.0], [0.0168, 0.0, 0.0], [0.0, 0.0168, 0.0]])  # the lattice (r 8 mm)
    j = max_start_jitter(0.008)
    assert j == pytest.approx(0.008 * LATTICE_GAP / 4)
    a, b = jittered(p, j, 3), jittered(p, j, 3)
    assert np.array_equal(a, b) and not np.array_equal(a, p)
    assert np.all(np.abs(a - p) <= j)
    assert not np.array_equal(a, jittered(p, j, 4))
    d = np.linalg.norm(a[:, None] - a[None], axis=2)[np.triu_indices(3, 1)]
    assert d.min() > 2 * 0.008
    assert np.array_equal(jittered(p, 0.0, 3), p)


@pytest.mark.parametrize("field, value", [("start_jitter", -1e-5), ("start_jitter", 1e-3),
                                          ("start_seed", -1), ("start_seed", 1.5)])
def test_a_start_jitter_out_of_bounds_is_refused_naming_the_field(field, value):
    with pytest.raises(ScenarioError) as e:
        dataclasses.replace(ContentsConfig(model="spheres"), **{field: value}).validate()
    assert e.value.field == f"contents.{field}"
