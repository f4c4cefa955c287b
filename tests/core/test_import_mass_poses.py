"""Import: mass properties (within 10 % of the library original at its density, open meshes,
density prior) and named stable resting poses (those of the library entry)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from tests.import_helpers import scan_like
from tg_drake.errors import ModelError
from tg_drake.importing import mesh as M
from tg_drake.importing.mass import density_prior, mass_properties
from tg_drake.importing.poses import named_poses, pose_name, stable_poses
from tg_drake.objects import get_object, load_library, mesh

SCAN_IDS = ("cup_01", "bowl_02", "bottle_01", "can_03", "pan_01", "hammer_01", "knife_02")


def _repaired(obj_id, holes=0):
    V, F = scan_like(obj_id, holes=holes)
    V_m, _ = M.to_metres_z_up(V, units="auto", up_axis="y")
    return M.repair(V_m, F)


def _mesh_density(obj_id):
    """The library object's mass over the volume its mesh encloses (its material pieces and
    cavities averaged in)."""
    V, F, _ = mesh(obj_id)
    return get_object(obj_id).mass / M.capped_moments(np.asarray(V), np.asarray(F))[0]


@pytest.mark.parametrize("obj_id", SCAN_IDS)
@pytest.mark.parametrize("holes", [0, 4])
def test_mass_within_ten_percent_of_the_library_original(obj_id, holes):
    o = get_object(obj_id)
    r = _repaired(obj_id, holes)
    mp = mass_properties(r.vertices, r.faces, watertight=r.watertight, category=o.category,
                         density=_mesh_density(obj_id))
    assert mp.mass == pytest.approx(o.mass, rel=0.10)
    assert mp.solid == ("closed mesh" if holes == 0 else "holes closed")
    if holes:
        assert any("holes closed" in w for w in mp.warnings)
    assert np.isfinite(mp.inertia).all() and np.all(np.linalg.eigvalsh(mp.inertia) > 0)


def test_mass_given_sets_the_density_and_keeps_the_shape():
    r = _repaired("cup_01")
    mp = mass_properties(r.vertices, r.faces, watertight=True, category="cup", mass=0.35)
    assert mp.mass == pytest.approx(0.35)
    assert mp.density == pytest.approx(0.35 / mp.volume)
    mp2 = mass_properties(r.vertices, r.faces, watertight=True, category="cup", mass=0.70)
    assert np.allclose(mp2.com, mp.com) and np.allclose(mp2.inertia, 2 * mp.inertia)


def test_density_prior_is_the_median_of_the_category():
    cups = [o.id for o in load_library().values() if o.category == "cup"]
    assert density_prior("cup") == pytest.approx(np.median([_mesh_density(i) for i in cups]))
    r = _repaired("cup_01")
    mp = mass_properties(r.vertices, r.faces, watertight=True, category="cup")
    assert "density prior" in mp.why and any("no mass or density" in w for w in mp.warnings)
    with pytest.raises(ModelError, match="unknown category 'mugg'"):
        density_prior("mugg")


def test_a_surface_bounding_no_solid_gets_its_hull_with_a_warning():
    # an open hemisphere wound inwards: its capped volume is negative, no solid
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.05)
    F = sphere.faces[sphere.triangles_center[:, 2] > 0.0][:, ::-1]
    mp = mass_properties(sphere.vertices, F, watertight=False, category=None, density=1000.0)
    hemisphere = 2 / 3 * np.pi * 0.05 ** 3
    assert mp.solid == "convex hull"
    assert mp.volume == pytest.approx(hemisphere, rel=0.05)  # 5 %: the icosphere's facets
    assert mp.mass == pytest.approx(1000.0 * mp.volume)
    assert any("convex hull" in w for w in mp.warnings)


def test_large_holes_are_capped_and_named_in_the_warning():
    # the same hemisphere wound outwards: its open face capped, a half ball
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.05)
    F = sphere.faces[sphere.triangles_center[:, 2] > 0.0]
    mp = mass_properties(sphere.vertices, F, watertight=False, category=None, density=1000.0)
    assert mp.solid == "holes closed"
    assert mp.volume == pytest.approx(2 / 3 * np.pi * 0.05 ** 3, rel=0.05)
    assert mp.com[2] == pytest.approx(3 / 8 * 0.05, rel=0.05)  # a half ball's centroid
    assert any("flat caps" in w for w in mp.warnings)


def test_mass_and_density_both_given_is_an_error():
    r = _repaired("cup_01")
    with pytest.raises(ModelError, match="both mass and density") as e:
        mass_properties(r.vertices, r.faces, watertight=True, category="cup", mass=1.0,
                        density=1000.0, file="mug.obj")
    assert e.value.file == "mug.obj"
    with pytest.raises(ModelError, match="allowed: a positive number"):
        mass_properties(r.vertices, r.faces, watertight=True, category="cup", mass=-1.0)


@pytest.mark.parametrize("obj_id", ["cup_02", "glass_01", "bowl_01", "pan_02", "bottle_03",
                                    "can_02", "pot_01", "hammer_02", "screwdriver_01",
                                    "cooking_tool_03"])
def test_named_resting_poses_are_those_of_the_library_entry(obj_id):
    o = get_object(obj_id)
    V, F, _ = (np.asarray(a) for a in mesh(o))
    poses = stable_poses(V, F, np.asarray(o.com), is_tool=o.is_tool)
    named = named_poses(poses)
    assert set(named) == set(o.poses)
    probs = [s.probability for s in poses]
    assert probs == sorted(probs, reverse=True) and sum(probs) <= 1.0 + 1e-9
    for name, r in named.items():
        lib = o.poses[name]
        # resting on z = 0: the lowest vertex on the table, the origin above T's origin
        V_T = V @ r.X_TO[:3, :3].T + r.X_TO[:3, 3]
        assert V_T[:, 2].min() == pytest.approx(0.0, abs=1e-6)
        assert r.xyz[:2] == (0.0, 0.0)
        # the same face down as the library's (the height of O's origin above the table)
        assert r.xyz[2] == pytest.approx(lib.xyz[2], abs=2e-3)  # 2 mm: a facet strip's tilt
        assert pose_name(r.X_TO[:3, 2], is_tool=o.is_tool) == name


def test_scan_like_import_rests_as_its_original():
    o = get_object("cup_01")
    r = _repaired("cup_01", holes=2)
    shift = -np.array([0.5 * (r.vertices[:, 0].min() + r.vertices[:, 0].max()),
                       0.5 * (r.vertices[:, 1].min() + r.vertices[:, 1].max()),
                       r.vertices[:, 2].min()])
    V = r.vertices + shift
    mp = mass_properties(V, r.faces, watertight=r.watertight, category="cup",
                         density=_mesh_density("cup_01"))
    assert set(named_poses(stable_poses(V, r.faces, mp.com, is_tool=False))) == set(o.poses)


def test_pose_names_by_where_z_points():
    assert pose_name(np.array([0, 0, 1.0]), is_tool=False) == "upright"
    assert pose_name(np.array([0, 0, -1.0]), is_tool=False) == "upsidedown"
    assert pose_name(np.array([1.0, 0, 0.1]), is_tool=False) == "sideways"
    assert pose_name(np.array([1.0, 0, 1.0]) / np.sqrt(2), is_tool=False) is None
    assert pose_name(np.array([0, 0, 1.0]), is_tool=True) == "sideways"  # a tool lying flat
    assert pose_name(np.array([0, 1.0, 0]), is_tool=True) is None  # on its edge
