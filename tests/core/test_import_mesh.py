"""Import, first steps: what the user names → mesh file (source), loading, units, up axis,
repair."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from tests.import_helpers import scan_like, write_obj
from tg_drake.errors import ModelError
from tg_drake.importing import mesh as M
from tg_drake.importing.source import resolve
from tg_drake.objects import get_object, mesh


@pytest.mark.parametrize(("size_m", "units", "factor"), [
    (0.12, "m", 1.0), (0.12, "mm", 0.001), (0.35, "mm", 0.001), (0.12, "cm", 0.01),
    (0.19, "cm", 0.01),  # 19 units: in mm 1.9 cm, below a household object
])
def test_units_inferred_from_size_and_warned(size_m, units, factor):
    V = trimesh.creation.box([size_m, 0.5 * size_m, 0.3 * size_m]).vertices / factor
    V_m, pl = M.to_metres_z_up(V, units="auto", up_axis="z")
    assert pl.units == units and pl.factor == factor
    assert np.ptp(V_m, axis=0).max() == pytest.approx(size_m)
    if units == "m":
        assert pl.warnings == ()
    else:  # the warning states the factor
        assert len(pl.warnings) == 1 and f"factor {factor:g}" in pl.warnings[0]


@pytest.mark.parametrize(("across", "units"), [(1e5, "auto"), (1e-4, "auto"), (100.0, "m"),
                                               (0.1, "mm")])
def test_implausible_size_is_an_error_naming_the_units(across, units):
    V = trimesh.creation.box([across] * 3).vertices
    with pytest.raises(ModelError, match="table-top object") as e:
        M.to_metres_z_up(V, units=units, up_axis="z", file="big.obj")
    assert e.value.file == "big.obj" and e.value.field == "units"


def test_up_axis_turns_the_given_axis_to_z():
    V = np.array([[0.0, 0, 0], [0.01, 0.1, 0.02]])
    for axis, length in (("y", 0.1), ("x", 0.01), ("z", 0.02), ("-y", -0.1)):
        V_m, _ = M.to_metres_z_up(V, units="m", up_axis=axis)
        assert V_m[1, 2] == pytest.approx(length)
    for R in M.UP_AXES.values():  # proper rotations: a mesh is not mirrored
        assert np.linalg.det(R) == pytest.approx(1.0) and np.allclose(R @ R.T, np.eye(3))


def test_unknown_units_and_up_axis_list_the_allowed_ones():
    V = trimesh.creation.box([0.1] * 3).vertices
    with pytest.raises(ModelError, match="allowed: auto, m, cm, mm, inch"):
        M.to_metres_z_up(V, units="furlong", up_axis="z")
    with pytest.raises(ModelError, match="allowed: z, -z, y, -y, x, -x"):
        M.to_metres_z_up(V, units="m", up_axis="w")


def test_scan_like_mesh_is_repaired_without_nan_normals():
    o = get_object("cup_01")
    V, F = scan_like("cup_01")
    V_m, pl = M.to_metres_z_up(V, units="auto", up_axis="y")
    assert pl.units == "mm"
    r = M.repair(V_m, F)
    assert np.isfinite(r.vertex_normals).all()
    assert np.allclose(np.linalg.norm(r.vertex_normals, axis=1), 1.0)
    areas = 0.5 * np.linalg.norm(np.cross(r.vertices[r.faces[:, 1]] - r.vertices[r.faces[:, 0]],
                                          r.vertices[r.faces[:, 2]] - r.vertices[r.faces[:, 0]]),
                                 axis=1)
    assert areas.min() > M.MIN_AREA
    assert r.watertight and r.n_pieces == 1
    assert len(r.faces) == o.n_triangles  # the three zero-area triangles went
    assert any("zero-area" in s for s in r.repairs) and any("re-wound" in s for s in r.repairs)
    # outward: the enclosed volume is positive and the library's (object frame is a translation)
    vol = M.capped_moments(r.vertices, r.faces)[0]
    lib_V, lib_F, _ = (np.asarray(a) for a in mesh(o))
    assert vol == pytest.approx(M.capped_moments(lib_V, lib_F)[0], rel=1e-4)
    # the upright cup's height is along z again
    assert np.ptp(r.vertices[:, 2]) == pytest.approx(o.extents[2], abs=1e-4)


def test_open_mesh_is_reported_and_its_caps_close_it():
    V, F = scan_like("can_01", holes=3)
    V_m, _ = M.to_metres_z_up(V, units="mm", up_axis="y")
    r = M.repair(V_m, F)
    assert r.is_open and r.n_boundary_edges > 0
    caps = M.hole_caps(r.vertices, r.faces)
    assert len(caps) == r.n_boundary_edges
    closed = np.concatenate([r.vertices[r.faces], caps]).reshape(-1, 3)
    m = trimesh.Trimesh(closed, np.arange(len(closed)).reshape(-1, 3))
    m.merge_vertices()
    assert m.is_watertight  # every boundary edge met by a cap edge


def test_zero_area_triangles_alone_are_an_error():
    V = np.array([[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0], [0.05, 0, 0]], float)
    F = np.array([[0, 1, 2], [0, 3, 1], [1, 3, 2], [0, 0, 1], [2, 2, 2]])
    with pytest.raises(ModelError, match="usable triangles") as e:
        M.repair(V, F, file="flat.obj")
    assert e.value.file == "flat.obj"


def test_triangle_soup_is_an_error():
    rng = np.random.default_rng(0)
    V = rng.uniform(0, 0.1, (300, 3))
    F = np.arange(300).reshape(-1, 3)
    with pytest.raises(ModelError, match="soup") as e:
        M.repair(V, F, file="soup.obj")
    assert e.value.file == "soup.obj"


def test_load_concatenates_a_scene(tmp_path):
    scene = trimesh.Scene([trimesh.creation.box([0.1] * 3),
                           trimesh.creation.icosphere(radius=0.02).apply_translation([0.2, 0, 0])])
    scene.export(tmp_path / "two.glb")
    loaded = M.load(tmp_path / "two.glb")
    assert loaded.n_geometries == 2
    assert len(loaded.faces) == 12 + 1280  # a box and an icosphere of 3 subdivisions


@pytest.mark.parametrize("fmt", ["stl", "ply", "obj"])
def test_load_reads_the_formats(tmp_path, fmt):
    box = trimesh.creation.box([0.1, 0.2, 0.3])
    box.export(tmp_path / f"box.{fmt}")
    loaded = M.load(tmp_path / f"box.{fmt}")
    assert np.ptp(loaded.vertices, axis=0) == pytest.approx([0.1, 0.2, 0.3])


def test_bad_files_are_model_errors_naming_the_file(tmp_path):
    with pytest.raises(ModelError, match="no such file") as e:
        resolve(tmp_path / "missing.obj")
    assert e.value.file.endswith("missing.obj")
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(ModelError, match="unknown format '.txt'; allowed: a mesh file") as e:
        resolve(tmp_path / "notes.txt")
    assert e.value.file.endswith("notes.txt")
    (tmp_path / "empty.obj").write_text("# nothing\n")
    with pytest.raises(ModelError, match="no triangles") as e:
        M.load(tmp_path / "empty.obj")
    assert e.value.file.endswith("empty.obj")
    (tmp_path / "empty_dir").mkdir()
    with pytest.raises(ModelError, match="no mesh or model file") as e:
        resolve(tmp_path / "empty_dir")


def test_model_folders_and_files_resolve_to_their_mesh(tmp_path):
    V, F = scan_like("cup_01")
    # Google Scanned Objects: model.sdf naming meshes/model.obj
    gso = tmp_path / "Blue_Mug"
    (gso / "meshes").mkdir(parents=True)
    write_obj(gso / "meshes" / "model.obj", V, F)
    (gso / "model.sdf").write_text(
        "<sdf version='1.6'><model name='m'><link name='l'><visual name='v'><geometry><mesh>"
        "<uri>meshes/model.obj</uri><scale>0.5 0.5 0.5</scale></mesh></geometry></visual>"
        "</link></model></sdf>")
    s = resolve(gso)
    assert s.kind == "Google Scanned Objects" and s.mesh_file == gso / "meshes" / "model.obj"
    assert s.scale == (0.5, 0.5, 0.5) and s.name == "blue_mug"
    assert set(s.files) == {gso / "model.sdf", gso / "meshes" / "model.obj"}
    # YCB: google_16k preferred over tsdf
    ycb = tmp_path / "025_mug"
    for sub in ("tsdf", "google_16k"):
        (ycb / sub).mkdir(parents=True)
        write_obj(ycb / sub / "textured.obj", V, F)
    s = resolve(ycb)
    assert s.kind == "YCB" and s.mesh_file.parent.name == "google_16k"
    assert s.name == "obj_025_mug"
    # URDF with one link
    (tmp_path / "m.urdf").write_text(
        "<robot name='r'><link name='l'><collision><geometry><mesh filename='Blue_Mug/meshes/"
        "model.obj' scale='0.001 0.001 0.001'/></geometry></collision></link></robot>")
    s = resolve(tmp_path / "m.urdf")
    assert s.kind == "urdf" and s.scale == (0.001, 0.001, 0.001)
    # two bodies: an error naming the file
    (tmp_path / "two.sdf").write_text(
        "<sdf version='1.6'><model name='m'><link name='a'/><link name='b'/></model></sdf>")
    with pytest.raises(ModelError, match="2 bodies") as e:
        resolve(tmp_path / "two.sdf")
    assert e.value.file.endswith("two.sdf")


def test_package_uri_resolves_through_the_shipped_models(tmp_path):
    (tmp_path / "m.sdf").write_text(
        "<sdf version='1.9'><model name='m'><link name='l'><visual name='v'><geometry><mesh>"
        "<uri>package://tg_drake_models/objects/cup_01/cup_01.obj</uri></mesh></geometry>"
        "</visual></link></model></sdf>")
    s = resolve(tmp_path / "m.sdf")
    assert s.mesh_file == get_object("cup_01").mesh_path
    (tmp_path / "n.sdf").write_text((tmp_path / "m.sdf").read_text().replace(
        "tg_drake_models", "no_such_package"))
    with pytest.raises(ModelError, match="unknown package 'no_such_package'"):
        resolve(tmp_path / "n.sdf")
