"""The object-wise split (scenarios/suites/split.yaml, tg_drake.evaluation.split)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tg_drake.errors import ScenarioError
from tg_drake.evaluation.split import SPLIT_PATH, load_split
from tg_drake.objects import forget_registered, get_object, load_library


def test_the_shipped_set_holds_out_the_fourth_instance_of_every_category():
    s = load_split("a")
    assert s.held_out == tuple(f"{o.category}_04" for o in load_library().values()
                               if o.id.endswith("_04"))
    assert len(s.train) == 33 and len(s.held_out) == 11
    assert set(s.train) | set(s.held_out) == set(load_library())
    assert s.sets["a"].shipped


def test_every_set_is_split_object_wise_per_category():
    split = load_split()
    assert not set(split.train) & set(split.held_out)
    for s in split.sets.values():
        lib = load_library(s.library)
        assert set(s.ids) == set(lib)
        for cat in {o.category for o in lib.values()}:
            n_train = sum(lib[i].category == cat for i in s.train)
            n_held = sum(lib[i].category == cat for i in s.held_out)
            assert n_train >= 1 and n_held >= 1, (s.name, cat)


def test_role_of_an_object_and_of_its_scan_like_version():
    s = load_split("a")
    assert s.role("cup_01") == "train" and s.role("cup_04") == "held_out"
    assert s.role("cup_04_scan") == "held_out"
    assert s.set_of("knife_02_scan").name == "a"
    with pytest.raises(ScenarioError, match="'mug_07' is in no object set"):
        s.role("mug_07")


def test_register_libraries_makes_every_id_known():
    split = load_split()
    forget_registered()
    try:
        split.register_libraries()
        for obj_id in split.train + split.held_out:
            assert get_object(obj_id).id == obj_id
    finally:
        forget_registered()


def _write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "split.yaml"
    p.write_text(text)
    return p


A_TRAIN = [i for i in load_library() if not i.endswith("_04")]
A_HELD = [i for i in load_library() if i.endswith("_04")]


@pytest.mark.parametrize("text,match", [
    ("nothing: 1\n", "field 'sets'"),
    ("sets: {a: {library: objects, train: [cup_01]}}\n", "sets.a.held_out.*missing held_out"),
    (f"sets: {{a: {{library: objects, train: {A_TRAIN}, held_out: {A_HELD[:-1]}}}}}\n",
     "cooking_tool_04 are on neither side"),
    (f"sets: {{a: {{library: objects, train: {A_TRAIN + ['cup_04']}, held_out: {A_HELD}}}}}\n",
     "on both sides: cup_04"),
    (f"sets: {{a: {{library: objects, train: {A_TRAIN + ['mug_9']}, held_out: {A_HELD}}}}}\n",
     "unknown object 'mug_9'"),
    (f"sets: {{a: {{library: objects, train: {A_TRAIN + A_HELD[:1]}, "
     f"held_out: {A_HELD[1:]}}}}}\n", "category pan has no held_out object"),
    ("sets: {a: {library: no_such_folder, train: [], held_out: []}}\n",
     "sets.a.library.*no such object library folder"),
    ("sets: {a: {library: objects, train: [], held_out: [], seed: 3}}\n", "unknown key 'seed'"),
])
def test_a_malformed_split_names_file_and_field(tmp_path, text, match):
    with pytest.raises(ScenarioError, match=match):
        load_split(path=_write(tmp_path, text))


def test_an_unknown_set_and_an_id_in_two_sets_are_named(tmp_path):
    with pytest.raises(ScenarioError, match="unknown object set 'z'; allowed: a"):
        load_split("z")
    entry = f"{{library: objects, train: {A_TRAIN}, held_out: {A_HELD}}}"
    p = _write(tmp_path, f"sets: {{a: {entry}, a2: {entry}}}\n")
    with pytest.raises(ScenarioError, match="'pan_01' is in sets a and a2"):
        load_split(path=p)


def test_the_split_file_is_the_one_in_the_suites_folder():
    assert SPLIT_PATH.is_file() and SPLIT_PATH.parent.name == "suites"
