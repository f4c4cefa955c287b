"""Scenario objects beyond the shipped library: object_libraries, mesh entries, resting."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from library_helpers import copy_object
from pydrake.math import RigidTransform, RollPitchYaw

from tg_drake.errors import ModelError, ScenarioError
from tg_drake.objects import forget_registered, get_object, load_library
from tg_drake.scenario import load_scenario, nearest_pose_label
from tg_drake.station import placement_pose


@pytest.fixture(autouse=True)
def _clean_registry():
    forget_registered()
    yield
    forget_registered()


def _write(folder: Path, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "s.yaml"
    path.write_text(text)
    return path


def test_object_libraries_resolve_against_the_scenario_folder(tmp_path, monkeypatch):
    copy_object("cup_01", "my_mug", tmp_path / "scenes" / "lib")
    path = _write(tmp_path / "scenes", "object_libraries: [lib]\n"
                                       "objects: [{id: my_mug, xy: [0, 0.05], yaw: 30}]\n")
    monkeypatch.chdir(tmp_path)  # not the scenario's folder
    scenario = load_scenario(path)
    assert scenario.object_libraries == [str((tmp_path / "scenes" / "lib").resolve())]
    assert get_object("my_mug").root == (tmp_path / "scenes" / "lib").resolve()
    assert scenario.target_placement().id == "my_mug"


def test_object_libraries_errors_name_the_entry(tmp_path):
    path = _write(tmp_path, "object_libraries: [nowhere]\nobjects: [{id: cup_01}]\n")
    with pytest.raises(ScenarioError, match="no such object library folder") as e:
        load_scenario(path)
    assert e.value.field == "object_libraries[0]"
    copy_object("cup_01", "cup_01", tmp_path / "lib")
    path = _write(tmp_path, "object_libraries: [lib]\nobjects: [{id: cup_01}]\n")
    with pytest.raises(ScenarioError, match="'cup_01' is in both the shipped library and") as e:
        load_scenario(path)
    assert e.value.field == "object_libraries[0]"
    path = _write(tmp_path, "object_libraries: [package://elsewhere/lib]\n"
                            "objects: [{id: cup_01}]\n")
    with pytest.raises(ScenarioError, match="unknown package 'elsewhere'.*allowed: "
                                            "tg_drake_models"):
        load_scenario(path)


def test_the_shipped_library_through_package_url(tmp_path):
    # Registering the shipped folder as a user library is an id clash with itself only if the
    # folders differ: they do not, so it is accepted and changes nothing.
    path = _write(tmp_path, "object_libraries: [package://tg_drake_models/objects]\n"
                            "objects: [{id: cup_01}]\n")
    assert load_scenario(path).target_placement().id == "cup_01"


@pytest.mark.parametrize("entry, field, message", [
    ("{id: cup_01, mesh: m.obj}", "objects[0]", "both `id` and `mesh` are given; an object is "
                                                "either `{id: ID, ...}`"),
    ("{name: x}", "objects[0]", "neither `id` nor `mesh` is given"),
    ("{id: cup_01, pose: upright, resting: auto}", "objects[0].resting",
     "give either `pose` (upright, sideways, upsidedown) or `resting`"),
    ("{id: cup_01, category: cup}", "objects[0].category", "apply to `mesh` entries only"),
    ("{mesh: m.obj, units: furlong}", "objects[0].units",
     "unknown units 'furlong'; allowed: auto, m, cm, mm, inch"),
    ("{mesh: m.obj, up_axis: w}", "objects[0].up_axis", "unknown up axis 'w'; allowed: z, y, x"),
    ("{mesh: m.obj, category: mug}", "objects[0].category", "unknown category 'mug'; allowed: pan"),
    ("{mesh: m.obj, collision: hull}", "objects[0].collision",
     "unknown collision backend 'hull'; allowed: coacd, vhacd"),
    ("{mesh: m.obj, mass: 0.3, density: 900}", "objects[0].density", "give `mass` or `density`"),
    ("{mesh: m.obj, mass: -0.3}", "objects[0].mass", "must be a finite number > 0 [kg]"),
    ("{mesh: m.obj, mass: heavy}", "objects[0].mass", "expected a number, got 'heavy'"),
    ("{mesh: absent.obj}", "objects[0].mesh", "no such mesh file or model folder"),
    ("{mesh: m.obj, labels: absent.npy}", "objects[0].labels", "no such part label file"),
    ("{id: cup_01, resting: auto}", "objects[0].resting",
     "cup_01 lists no stable poses; give a `pose` among upright, sideways, upsidedown"),
    ("{id: cup_01, resting: [1]}", "objects[0].resting", "expected a single value (int or str)"),
    ("{id: cup_01, resting: two}", "objects[0].resting", "resting must be auto or a whole number"),
])
def test_mesh_and_resting_mistakes_name_the_field(tmp_path, entry, field, message):
    (tmp_path / "m.obj").write_text("v 0 0 0\n")  # never imported: the checks come first
    path = _write(tmp_path, f"objects:\n  - {entry}\n")
    with pytest.raises(ScenarioError) as e:
        load_scenario(path)
    assert e.value.field == field
    assert message in str(e.value)
    assert str(path) in str(e.value)


def test_resting_k_picks_the_kth_most_probable_stable_pose(tmp_path):
    copy_object("cup_01", "my_mug", tmp_path / "lib")
    names = list(load_library(tmp_path / "lib")["my_mug"].poses)
    for resting, pose in (("auto", names[0]), ("0", names[0]), ("1", names[1])):
        path = _write(tmp_path, f"object_libraries: [lib]\n"
                                f"objects: [{{id: my_mug, resting: {resting}}}]\n")
        placement = load_scenario(path).objects[0]
        assert placement.pose == pose
    # A tilted stable pose (no name) first: auto takes the most probable named one; K = 0 rests
    # as found, labelled with the nearest of its poses (28.6° from upright).
    stable = [dict(pose=None, probability=0.6, xyz=[0, 0, 0.03], rpy=[0.5, 0, 0],
                   support_margin=0.001)] + [
        dict(pose=p, probability=0.1, support_margin=0.01, **{k: list(v) for k, v in (
            ("xyz", r.xyz), ("rpy", r.rpy))}) for p, r in get_object_poses(tmp_path)]
    copy_object("cup_01", "tilted_mug", tmp_path / "lib", stable_poses=stable)
    path = _write(tmp_path, "object_libraries: [lib]\nobjects: [{id: tilted_mug, resting: auto}]\n")
    assert load_scenario(path).objects[0].pose == names[0]
    path = _write(tmp_path, "object_libraries: [lib]\nobjects: [{id: tilted_mug, resting: 0}]\n")
    scenario = load_scenario(path)
    placement = scenario.objects[0]
    assert (placement.pose, placement.resting) == ("upright", 0)
    X_WO = placement_pose(scenario, placement)
    assert X_WO.rotation().ToRollPitchYaw().roll_angle() == pytest.approx(0.5, abs=1e-9)
    assert X_WO.translation()[2] - scenario.X_WT.GetDeterministicValue().translation()[2] \
        == pytest.approx(0.03)
    # The label is the nearest pose the object has: tilted 80°, a cup is sideways.
    obj = load_library(tmp_path / "lib")["tilted_mug"]
    tilted = RigidTransform(RollPitchYaw(np.deg2rad(80), 0, 0), [0, 0, 0]).GetAsMatrix4()
    assert nearest_pose_label(tilted, obj) == "sideways"
    assert nearest_pose_label(np.diag([1.0, -1, -1, 1]), obj) == "upsidedown"
    path = _write(tmp_path, "object_libraries: [lib]\nobjects: [{id: my_mug, resting: 9}]\n")
    with pytest.raises(ScenarioError, match=r"my_mug has no stable pose 9; allowed: 0 \(upright, "
                                            r"p=0.50\), 1 \(") as e:
        load_scenario(path)
    assert e.value.field == "objects[0].resting"


def get_object_poses(tmp_path):
    return list(load_library(tmp_path / "lib")["my_mug"].poses.items())


@pytest.fixture
def fake_importer(tmp_path, monkeypatch):
    """tg_drake.importing's import_cached stood in for by one that 'imports' a shipped cup into a
    library (the real import of a mesh entry: tests/scenarios/test_scan_cup_run.py); the options
    are the real ImportOptions."""
    calls = []

    def import_cached(source, options, *, cache_root=None):
        calls.append((Path(source), options))
        if options.units == "inch":
            raise ModelError("the mesh is 30 m across", file=str(source), field="units")
        lib = tmp_path / "cache"
        if not (lib / "blue_mug").is_dir():
            copy_object("cup_01", "blue_mug", lib, category=options.category or "cup")
        return load_library(lib)["blue_mug"]

    import tg_drake.importing.library as library
    monkeypatch.setattr(library, "import_cached", import_cached)
    return calls


def test_a_mesh_entry_becomes_a_registered_object(tmp_path, fake_importer):
    (tmp_path / "scenes" / "mugs").mkdir(parents=True)
    (tmp_path / "scenes" / "mugs" / "blue_mug.obj").write_text("v 0 0 0\n")
    path = _write(tmp_path / "scenes",
                  "objects:\n  - {mesh: mugs/blue_mug.obj, category: cup, units: mm, up_axis: y,"
                  " mass: 0.35, collision: vhacd, xy: [0, 0.05], yaw: 30, name: mine,"
                  " resting: 1}\n  - {id: can_02, xy: [0.2, -0.2]}\n")
    scenario = load_scenario(path)
    placement = scenario.objects[0]
    assert placement.id == "blue_mug" and placement.instance_name == "mine"
    assert placement.mesh == str((tmp_path / "scenes" / "mugs" / "blue_mug.obj").resolve())
    assert placement.pose == list(get_object("blue_mug").poses)[1]
    source, options = fake_importer[0]
    assert source == Path(placement.mesh)
    assert (options.category, options.units, options.up_axis, options.mass, options.density,
            options.collision) == ("cup", "mm", "y", 0.35, None, "vhacd")
    # the resolved scenario validates again (the station resolves it again) to the same object
    from tg_drake.scenario import validate
    validate(scenario)
    assert scenario.objects[0].id == "blue_mug" and len(fake_importer) == 2


def test_import_errors_name_the_entry_and_field(tmp_path, fake_importer):
    (tmp_path / "m.obj").write_text("v 0 0 0\n")
    path = _write(tmp_path, "objects: [{mesh: m.obj, units: inch}]\n")
    with pytest.raises(ScenarioError, match="30 m across") as e:
        load_scenario(path)
    assert e.value.field == "objects[0].units"


def test_a_dumped_scenario_loads_again(tmp_path):
    from pydrake.common.yaml import yaml_dump_typed

    from tg_drake.scenario import Scenario
    copy_object("cup_01", "my_mug", tmp_path / "lib")
    path = _write(tmp_path, "object_libraries: [lib]\nobjects: [{id: my_mug, xy: [0, 0.1]}]\n")
    text = yaml_dump_typed(load_scenario(path), schema=Scenario)
    again = _write(tmp_path / "again", text)
    scenario = load_scenario(again)  # every default written out: pose with resting null, ...
    assert scenario.objects[0].id == "my_mug" and scenario.objects[0].xy == [0, 0.1]


def test_one_mesh_imported_with_other_options_and_a_library_name_get_their_own_ids(
        tmp_path, monkeypatch):
    import trimesh
    monkeypatch.setenv("TG_DRAKE_CACHE", str(tmp_path / "cache"))
    trimesh.creation.box([0.08, 0.05, 0.12]).export(tmp_path / "carton.stl")
    trimesh.creation.box([0.06, 0.06, 0.10]).export(tmp_path / "cup_01.stl")
    path = _write(tmp_path, "objects:\n"
                            "  - {mesh: carton.stl, units: m, mass: 0.2, collision: vhacd,"
                            " resting: auto}\n"
                            "  - {mesh: carton.stl, units: m, mass: 0.5, collision: vhacd,"
                            " name: heavy, xy: [0.2, 0], resting: auto}\n"
                            "  - {mesh: cup_01.stl, units: m, collision: vhacd, xy: [-0.2, 0],"
                            " resting: auto}\n")
    scenario = load_scenario(path)
    light, heavy, named = scenario.objects
    assert light.id == "carton"
    assert heavy.id.startswith("carton_") and len(heavy.id) == len("carton_") + 6
    assert named.id.startswith("cup_01_")
    assert get_object(light.id).mass == pytest.approx(0.2)
    assert get_object(heavy.id).mass == pytest.approx(0.5)
    assert get_object("cup_01").category == "cup"  # the shipped cup is untouched
    from tg_drake.scenario import validate
    validate(scenario)  # the station resolves the objects again: the same ids
    assert [p.id for p in scenario.objects] == [light.id, heavy.id, named.id]
