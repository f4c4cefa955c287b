"""User object libraries: loading, registering, id clashes, malformed library.yaml, the command."""

from __future__ import annotations

import json
from argparse import Namespace

import numpy as np
import pytest
import yaml
from library_helpers import copy_object

from tg_drake.errors import ModelError, ScenarioError
from tg_drake.objects import (
    add_library,
    forget_registered,
    get_object,
    load_library,
    main,
    mesh,
    register_object,
    shipped_root,
)


@pytest.fixture(autouse=True)
def _clean_registry():
    forget_registered()
    yield
    forget_registered()


def test_user_library_objects_live_in_their_folder(tmp_path):
    copy_object("cup_01", "my_mug", tmp_path)
    lib = load_library(tmp_path)
    obj = lib["my_mug"]
    assert obj.root == tmp_path.resolve()
    assert obj.directory == tmp_path.resolve() / "my_mug"
    assert obj.sdf_url == (tmp_path.resolve() / "my_mug" / "my_mug.sdf").as_uri()
    assert obj.sdf_url.startswith("file:///")
    assert obj.labels_source == "derived"
    assert [p.pose for p in obj.stable_poses] == list(obj.poses)
    assert obj.stable_poses[0].probability == 0.5
    np.testing.assert_allclose(obj.stable_poses[0].X_TO, obj.poses["upright"].X_TO)
    assert obj.source["units"] == "m"
    # the shipped library is unchanged: package:// URLs, generated labels, no stable poses
    cup = load_library()["cup_01"]
    assert cup.root == shipped_root() and cup.shipped
    assert cup.sdf_url == "package://tg_drake_models/objects/cup_01/cup_01.sdf"
    assert (cup.labels_source, cup.stable_poses, cup.source) == ("generated", (), None)
    assert not obj.shipped


def test_get_object_finds_a_library_only_once_it_is_added(tmp_path):
    copy_object("cup_01", "my_mug", tmp_path)
    with pytest.raises(ScenarioError, match="unknown object 'my_mug'.*cup_01"):
        get_object("my_mug")
    add_library(tmp_path)
    add_library(tmp_path)  # again: nothing happens
    assert get_object("my_mug").root == tmp_path.resolve()
    assert get_object("cup_01").shipped
    with pytest.raises(ScenarioError, match="unknown object 'nope'.*my_mug"):
        get_object("nope")


def test_mesh_cache_is_keyed_by_folder_not_id(tmp_path):
    # Two libraries hold an object "thing": one made from a cup, one from a knife.
    copy_object("cup_01", "thing", tmp_path / "a")
    copy_object("knife_01", "thing", tmp_path / "b")
    a, b = load_library(tmp_path / "a")["thing"], load_library(tmp_path / "b")["thing"]
    assert len(mesh(a)[0]) == len(mesh("cup_01")[0])
    assert len(mesh(b)[0]) == len(mesh("knife_01")[0]) != len(mesh(a)[0])


def test_an_id_in_two_libraries_names_both(tmp_path):
    copy_object("cup_01", "thing", tmp_path / "a")
    copy_object("knife_01", "thing", tmp_path / "b")
    add_library(tmp_path / "a")
    with pytest.raises(ModelError, match=r"'thing' is in both the library .*a and the library .*b"):
        add_library(tmp_path / "b")
    copy_object("cup_01", "cup_01", tmp_path / "c")
    with pytest.raises(ModelError, match="'cup_01' is in both the shipped library and"):
        add_library(tmp_path / "c")
    with pytest.raises(ModelError, match="'thing' is in both"):
        register_object(load_library(tmp_path / "b")["thing"])


def test_register_object_makes_one_object_known(tmp_path):
    copy_object("bowl_01", "scan_bowl", tmp_path)
    obj = load_library(tmp_path)["scan_bowl"]
    assert register_object(obj) is obj
    register_object(obj)  # again: nothing happens
    assert get_object("scan_bowl") is obj


@pytest.mark.parametrize("text, field", [
    ("objects: [a, b]\n", "objects"),
    ("hello\n", "objects"),
    ("objects:\n  x: 3\n", "objects.x"),
    ("objects:\n  x: {category: cup}\n", "objects.x.material"),
])
def test_malformed_library_yaml_names_file_and_field(tmp_path, text, field):
    (tmp_path / "library.yaml").write_text(text)
    with pytest.raises(ModelError) as e:
        load_library(tmp_path)
    assert e.value.file == str(tmp_path.resolve() / "library.yaml")
    assert e.value.field == field


def test_missing_library_and_bad_fields_are_named(tmp_path):
    with pytest.raises(ModelError, match="no library.yaml") as e:
        load_library(tmp_path)
    assert e.value.file.endswith("library.yaml")
    with pytest.raises(ModelError, match="no such object library folder"):
        load_library(tmp_path / "absent")
    copy_object("cup_01", "odd", tmp_path / "a", category="mug")
    with pytest.raises(ModelError, match="unknown category 'mug'") as e:
        load_library(tmp_path / "a")
    assert e.value.field == "objects.odd.category"
    copy_object("cup_01", "odd", tmp_path / "b", labels="guessed")
    with pytest.raises(ModelError, match="unknown label source 'guessed'"):
        load_library(tmp_path / "b")
    copy_object("cup_01", "odd", tmp_path / "c",
                stable_poses=[{"pose": "tilted", "probability": 1, "xyz": [0, 0, 0],
                               "rpy": [0, 0, 0], "support_margin": 0.01}])
    with pytest.raises(ModelError, match="tilted") as e:
        load_library(tmp_path / "c")
    assert e.value.field == "objects.odd"


def test_stable_pose_k_and_its_errors(tmp_path):
    copy_object("cup_01", "my_mug", tmp_path)
    obj = load_library(tmp_path)["my_mug"]
    assert obj.stable_pose(1).pose == list(obj.poses)[1]
    with pytest.raises(ScenarioError, match=r"no stable pose 7; allowed: 0 \(upright, p=0.50\)"):
        obj.stable_pose(7)
    with pytest.raises(ScenarioError, match="cup_01 lists no stable poses; give a `pose` among "
                                            "upright"):
        get_object("cup_01").stable_pose(0)


def test_objects_command_lists_a_user_library(tmp_path, capsys):
    copy_object("cup_01", "my_mug", tmp_path)
    copy_object("knife_01", "my_knife", tmp_path)
    assert main(Namespace(json=True, category=None, library=str(tmp_path))) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["id"] for r in rows] == ["my_mug", "my_knife"]
    assert rows[0]["labels"] == "derived" and rows[0]["sdf"].startswith("file:///")
    assert rows[0]["stable_poses"][0] == {"pose": "upright", "probability": 0.5}
    assert main(Namespace(json=False, category="knife", library=str(tmp_path))) == 0
    out = capsys.readouterr().out
    assert "my_knife" in out and "my_mug" not in out and "1 objects" in out
    yaml.safe_load((tmp_path / "library.yaml").read_text())  # still valid YAML


def test_a_library_written_again_is_read_again(tmp_path):
    copy_object("cup_01", "first", tmp_path)
    assert list(load_library(tmp_path)) == ["first"]
    assert load_library(tmp_path) is load_library(tmp_path / "library.yaml")  # cached
    copy_object("knife_01", "second", tmp_path)  # an import merged into the same folder
    assert list(load_library(tmp_path)) == ["first", "second"]


def test_registering_a_library_whose_object_has_no_files_names_the_sdf(tmp_path):
    copy_object("cup_01", "gone", tmp_path)
    (tmp_path / "gone" / "gone.sdf").unlink()
    assert "gone" in load_library(tmp_path)  # listed (tg-drake objects shows it)
    with pytest.raises(ModelError, match="gone's SDF is missing") as e:
        add_library(tmp_path)
    assert e.value.file.endswith("gone.sdf")


def test_an_object_imported_without_a_category_has_none(tmp_path, capsys):
    copy_object("bowl_01", "thing", tmp_path, category=None)
    obj = load_library(tmp_path)["thing"]
    assert obj.category is None and obj.is_container
    assert main(Namespace(json=False, category=None, library=str(tmp_path))) == 0
    assert "thing            -  " in capsys.readouterr().out
