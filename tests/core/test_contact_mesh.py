"""The collision mesh of a generated object: fewer triangles, the same surface within tolerance."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from tg_drake.contact_mesh import CONTACT_TOLERANCE, contact_mesh, surface_distance
from tg_drake.objects import get_object, load_library, mesh


def _obj_mesh(path):
    m = trimesh.load(path, process=False, force="mesh")
    return np.asarray(m.vertices), np.asarray(m.faces)


def test_surface_distance_of_a_shifted_copy_is_the_shift():
    box = trimesh.creation.box((0.1, 0.1, 0.1))
    V = np.asarray(box.vertices)
    assert surface_distance(V, box.faces, V, box.faces) == pytest.approx(0.0, abs=1e-7)
    assert surface_distance(V, box.faces, V + [0.0, 0.0, 0.002], box.faces) == \
        pytest.approx(0.002, abs=1e-5)


def test_a_sphere_keeps_its_shape_with_far_fewer_triangles():
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=0.04)  # 5120 triangles
    V, F = contact_mesh(sphere.vertices, sphere.faces)
    assert len(F) < len(sphere.faces) / 4
    assert surface_distance(sphere.vertices, sphere.faces, V, F) <= CONTACT_TOLERANCE
    # A looser tolerance keeps fewer; the result repeats.
    V2, F2 = contact_mesh(sphere.vertices, sphere.faces, tolerance=4 * CONTACT_TOLERANCE)
    assert len(F2) < len(F)
    V3, F3 = contact_mesh(sphere.vertices, sphere.faces)
    assert np.array_equal(V, V3) and np.array_equal(F, F3)


def test_a_mesh_no_decimation_keeps_is_returned_as_it_is():
    box = trimesh.creation.box((0.05, 0.05, 0.05))  # 12 triangles: nothing to drop
    V, F = contact_mesh(box.vertices, box.faces, tolerance=1e-9)
    assert np.array_equal(F, box.faces)


@pytest.mark.parametrize("obj_id", ["can_02", "cup_01", "knife_01"])
def test_the_library_collides_with_its_decimated_mesh(obj_id):
    obj = get_object(obj_id)
    sdf = obj.sdf_path.read_text()
    collision = sdf[sdf.index("<collision"):]
    assert f"<uri>{obj_id}_collision.obj</uri>" in collision
    assert f"<uri>{obj_id}.obj</uri>" in sdf[:sdf.index("<collision")]  # the visual: the mesh
    V, F, _ = mesh(obj)
    V_c, F_c = _obj_mesh(obj.directory / f"{obj_id}_collision.obj")
    assert len(F_c) < len(F)
    # Written at 1 µm resolution: within the tolerance and that rounding.
    assert surface_distance(V, F, V_c, F_c) <= CONTACT_TOLERANCE + 2e-6


def test_every_library_object_has_its_collision_mesh():
    for obj in load_library().values():
        assert (obj.directory / f"{obj.id}_collision.obj").is_file(), obj.id
