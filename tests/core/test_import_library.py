"""Import, end to end: a scan-like cup → a library folder in the shipped format, re-readable;
the report and pictures; merging; the cache; the command."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
import trimesh
import yaml

from tests.import_helpers import read_obj, scan_like, write_obj
from tg_drake import cli
from tg_drake.errors import ModelError
from tg_drake.importing import ImportOptions, collision, import_cached, import_object, library
from tg_drake.importing import cli as import_cli
from tg_drake.importing import mesh as M
from tg_drake.objects import get_object, library_path, mesh

OPTIONAL_FIELDS = {"source", "labels", "stable_poses"}


def _mesh_density(obj_id):
    V, F, _ = mesh(obj_id)
    return get_object(obj_id).mass / M.capped_moments(np.asarray(V), np.asarray(F))[0]


@pytest.fixture(scope="module")
def scan_cup(tmp_path_factory):
    """The library's cup_01 as a scan-like OBJ (mm, y up, flipped and zero-area triangles, two
    holes) with the library's per-vertex labels, imported with the default backend."""
    d = tmp_path_factory.mktemp("scan")
    V, F = scan_like("cup_01", holes=2)
    write_obj(d / "Blue Mug.obj", V, F)
    labels = np.concatenate([mesh("cup_01")[2], [0]]).astype(np.uint8)  # + scan_like's extra
    np.save(d / "labels.npy", labels)
    options = ImportOptions(category="cup", up_axis="y", density=_mesh_density("cup_01"),
                            labels=d / "labels.npy")
    result = import_object(d / "Blue Mug.obj", options, d / "lib")
    return d, options, result


def test_library_folder_has_the_shipped_format(scan_cup):
    d, _, result = scan_cup
    lib = d / "lib"
    data = yaml.safe_load((lib / "library.yaml").read_text())
    entry = data["objects"]["blue_mug"]
    shipped = yaml.safe_load(library_path().read_text())["objects"]["cup_01"]
    assert list(entry)[:len(shipped)] == list(shipped)  # the shipped fields, in their order
    assert set(entry) - set(shipped) == OPTIONAL_FIELDS
    assert entry["labels"] == "given"
    assert entry["source"]["units"] == "mm" and entry["source"]["up_axis"] == "y"
    assert entry["source"]["sha256"] == library.resolve(d / "Blue Mug.obj").sha256()
    obj_dir = lib / "blue_mug"
    V, F = read_obj(obj_dir / "blue_mug.obj")
    parts = np.load(obj_dir / "blue_mug_parts.npy")
    assert parts.dtype == np.uint8 and len(parts) == len(V) == entry["n_vertices"]
    assert len(F) == entry["n_triangles"] and F.min() == 0 and F.max() == len(V) - 1
    assert np.ptp(V, axis=0) == pytest.approx(entry["extents"], abs=1e-4)
    # the given labels followed their vertices through the repair
    lib_V, _, lib_labels = mesh("cup_01")
    lo = np.asarray(lib_V).min(0)
    nearest = np.argmin(np.linalg.norm(
        (V - V.min(0) + lo)[:, None] - np.asarray(lib_V)[None], axis=2), axis=1)
    assert (parts == lib_labels[nearest]).mean() > 0.99
    assert result.object.n_vertices == len(V) and result.object.parts == ("top", "middle",
                                                                         "bottom", "handle")


def test_sdf_has_the_mass_and_convex_hydroelastic_pieces(scan_cup):
    d, _, result = scan_cup
    obj_dir = d / "lib" / "blue_mug"
    entry = yaml.safe_load((d / "lib" / "library.yaml").read_text())["objects"]["blue_mug"]
    root = ET.parse(obj_dir / "blue_mug.sdf").getroot()
    link = root.find("model/link")
    assert float(link.find("inertial/mass").text) == pytest.approx(entry["mass"], rel=1e-6)
    com = [float(x) for x in link.find("inertial/pose").text.split()[:3]]
    assert com == pytest.approx(entry["com"], abs=1e-6)
    assert link.find("visual/geometry/mesh/uri").text == "blue_mug.obj"
    cols = link.findall("collision")
    pieces = sorted(obj_dir.glob("blue_mug_collision_*.obj"))
    assert 1 < len(cols) == len(pieces) <= collision.BACKENDS["coacd"]["max_convex_hull"]
    ns = "{http://drake.mit.edu}"
    for c in cols:
        m = c.find("geometry/mesh")
        assert (obj_dir / m.find("uri").text).is_file()
        assert m.find(f"{ns}declare_convex") is not None
        props = c.find(f"{ns}proximity_properties")
        assert props.find(f"{ns}rigid_hydroelastic") is not None
        assert float(props.find(f"{ns}mu_static").text) == 1.0
    for p in pieces:  # convex: each piece is its own hull
        piece = trimesh.Trimesh(*read_obj(p))
        assert piece.is_watertight
        assert piece.volume == pytest.approx(piece.convex_hull.volume, rel=1e-6)
    # the pieces cover the object: each of its vertices lies within 5 mm of one (the
    # decomposition's concavity allowance, a fraction of the 15 cm box diagonal)
    V, _ = read_obj(obj_dir / "blue_mug.obj")
    outside = []  # per piece and vertex: the largest distance beyond one of its face planes
    for p in pieces:
        h = trimesh.Trimesh(*read_obj(p))
        outside.append(np.einsum("vfk,fk->vf", V[:, None] - h.triangles[None, :, 0],
                                 h.face_normals).max(axis=1))
    assert np.min(outside, axis=0).max() < 5e-3


def test_import_keeps_mass_and_poses_of_the_original(scan_cup):
    _, _, result = scan_cup
    o, lib = result.object, get_object("cup_01")
    assert o.mass == pytest.approx(lib.mass, rel=0.10)
    assert set(o.poses) == set(lib.poses)
    assert o.poses["upright"].rpy == pytest.approx((0.0, 0.0, 0.0), abs=1e-3)  # [rad] on its pieces
    # 10 %, and products of inertia within 1 % of the largest moment (the holes' asymmetry)
    assert np.diag(o.inertia) == pytest.approx(np.diag(lib.inertia), rel=0.10)
    assert np.abs(o.inertia - lib.inertia).max() < 0.01 * np.abs(lib.inertia).max() + \
        0.10 * np.abs(np.diag(lib.inertia)).max()


def test_report_says_what_was_decided(scan_cup):
    _, _, result = scan_cup
    text = result.report
    for words in ("mm (×0.001)", "y → z", "zero-area", "re-wound", "holes closed",
                  "upright", "sideways", "upsidedown", "convex pieces (coacd"):
        assert words in text, words
    assert len(text.splitlines()) <= 40  # one screen
    assert any("factor 0.001" in w for w in result.warnings)
    assert result.pictures and all(p.suffix == ".png" and p.stat().st_size > 1000
                                   for p in result.pictures)
    assert any(p.name.endswith("_upright.png") for p in result.pictures)


def test_a_second_object_is_merged_into_the_library(scan_cup, tmp_path):
    d, _, _ = scan_cup
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "library.yaml").write_text((d / "lib" / "library.yaml").read_text())
    can = trimesh.creation.cylinder(radius=3.3, height=12.0, sections=48)  # cm
    can.apply_translation([0, 0, 6.0])
    can.export(tmp_path / "tin.stl")
    r = import_object(tmp_path / "tin.stl", ImportOptions(category="can", obj_id="tin_can",
                                                          collision="vhacd"),
                      lib, pictures=False)
    data = yaml.safe_load((lib / "library.yaml").read_text())["objects"]
    assert list(data) == ["blue_mug", "tin_can"]
    assert r.object.extents == pytest.approx((0.066, 0.066, 0.12), abs=1e-3)
    assert set(r.object.poses) == {"upright", "sideways", "upsidedown"}
    assert r.pictures == ()


def test_import_cached_imports_once(tmp_path, monkeypatch):
    box = trimesh.creation.box([0.08, 0.05, 0.12])
    box.export(tmp_path / "carton.stl")
    options = ImportOptions(units="m", collision="vhacd")
    first = import_cached(tmp_path / "carton.stl", options, cache_root=tmp_path / "cache")
    assert first.mass > 0

    def no_import(*args, **kwargs):
        raise AssertionError("imported again")

    monkeypatch.setattr(library, "import_object", no_import)
    again = import_cached(tmp_path / "carton.stl", options, cache_root=tmp_path / "cache")
    assert again.mass == first.mass and again.id == first.id == "carton"
    assert len(list((tmp_path / "cache").iterdir())) == 1
    # another option or another content is another import
    with pytest.raises(AssertionError, match="imported again"):
        import_cached(tmp_path / "carton.stl", ImportOptions(units="m", collision="vhacd",
                                                             mass=1.0),
                      cache_root=tmp_path / "cache")


@pytest.mark.parametrize(("options", "match", "field"), [
    (ImportOptions(category="mugg"), "unknown category 'mugg'", "category"),
    (ImportOptions(units="feet"), "unknown units 'feet'", "units"),
    (ImportOptions(collision="bullet"), "unknown collision backend 'bullet'", "collision"),
    (ImportOptions(mass=1.0, density=1.0), "both mass and density", "mass"),
    (ImportOptions(obj_id="Blue Mug"), "allowed: lower-case letters", "id"),
])
def test_bad_options_name_the_field(tmp_path, options, match, field):
    with pytest.raises(ModelError, match=match) as e:
        import_object(tmp_path / "x.obj", options, tmp_path / "lib")
    assert e.value.field == field


def test_bad_labels_name_the_file(tmp_path):
    trimesh.creation.box([0.1] * 3).export(tmp_path / "box.stl")
    np.save(tmp_path / "short.npy", np.zeros(3, np.uint8))
    with pytest.raises(ModelError, match="for a mesh of") as e:
        import_object(tmp_path / "box.stl", ImportOptions(labels=tmp_path / "short.npy"),
                      tmp_path / "lib")
    assert e.value.file.endswith("short.npy") and e.value.field == "labels"


def test_command_imports_and_prints_the_report(tmp_path, capsys):
    can = trimesh.creation.cylinder(radius=0.03, height=0.1, sections=32)
    can.export(tmp_path / "tin.ply")
    rc = cli.main(["import-object", str(tmp_path / "tin.ply"), "--category", "can",
                   "--units", "m", "--mass", "0.2", "--collision", "vhacd", "--no-pictures",
                   "--out", str(tmp_path / "lib")])
    out = capsys.readouterr().out
    assert rc == 0
    assert "tin: can" in out and "0.2 kg (given" in out and "object_libraries" in out
    assert (tmp_path / "lib" / "tin" / "tin.sdf").is_file()
    rc = cli.main(["import-object", str(tmp_path / "missing.obj"), "--out",
                   str(tmp_path / "lib")])
    assert rc == 2 and "missing.obj: no such file" in capsys.readouterr().err


def test_command_choices_are_the_importers():
    assert import_cli.UNITS == ("auto", *M.UNITS)
    assert set(import_cli.UP_AXES) == set(M.UP_AXES)
    assert import_cli.BACKENDS == tuple(collision.BACKENDS)
