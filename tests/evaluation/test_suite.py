"""Suite files: the shipped suites load with the sizes the paper's datasets ask for; bad files
fail with the file, the field and the allowed values."""

from pathlib import Path

import pytest

from tg_drake.errors import ScenarioError
from tg_drake.evaluation.suite import load_suite

SUITES = Path(__file__).resolve().parents[2] / "scenarios" / "suites"


def test_the_shipped_suites_stand_for_the_papers_datasets():
    suite, cases = load_suite(SUITES / "s_syn.yaml")
    assert suite.kind == "synthetic" and len(cases) >= 102
    assert len({c.target_placement.id for c in cases}) >= 41
    _, cases = load_suite(SUITES / "s_grasp.yaml")
    assert len(cases) >= 100
    assert {c.target_placement.containment for c in cases} == {"empty"}
    assert {c.target_placement.pose for c in cases} == {"upright", "sideways"}
    _, cases = load_suite(SUITES / "s_robot.yaml")
    assert sorted({len(c.objects) for c in cases}) == [2, 3, 4]
    suite, cases = load_suite(SUITES / "s_real.yaml")
    assert suite.settings == ["semi", "real", "noisy"]


def test_ground_truth_is_set_valued_with_its_reason():
    _, cases = load_suite(SUITES / "s_syn.yaml")
    by_key = {c.key: c for c in cases}
    cup = by_key["s_syn/cup_01_upright_full"].truth
    assert cup.tasks == ("pass", "pourOut", "p&pInUpright", "p&pOn")  # Table 3, a full dish
    assert cup.parts["p&pOn"] == ("middle", "top")  # Table 5: middle 0.6, top 0.4
    assert "Table 3" in cup.reason and "Table 5" in cup.reason
    pan = by_key["s_syn/pan_01_upsidedown_empty"].truth
    assert pan.parts["pass"] == ()  # no grasp of an upside-down pan
    # "full" only where the object holds water: no full hammer, no full glass lying down.
    assert "s_syn/hammer_01_sideways_full" not in by_key
    assert "s_syn/glass_01_sideways_full" not in by_key
    assert "s_syn/bottle_01_sideways_full" in by_key


def write(tmp_path, text, name="suite.yaml"):
    (tmp_path / "ground_truth.yaml").write_text((SUITES / "ground_truth.yaml").read_text())
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("text, message", [
    ("kind: synthetic\ndataset: syn\nground_truth: ground_truth.yaml\n"
     "generator: {objects: [mugg_01]}\n",
     r"field 'generator.objects': unknown object or category 'mugg_01'; allowed: all, pan"),
    ("kind: simulated\ndataset: syn\n", r"field 'kind': unknown suite kind 'simulated'; "
     r"allowed: synthetic, perceived, executed"),
    ("kind: synthetic\ndataset: sim\n", r"unknown dataset 'sim'; allowed: syn, real_semi"),
    ("kind: perceived\nsettings: [semi, exact]\n", r"unknown setting 'exact'; allowed: semi"),
    ("kind: executed\ndataset: grasp\nvariants: [pipeline, logic_only]\n",
     r"unknown variant 'logic_only'; allowed: pipeline, pipeline_uniform, local"),
    ("kind: synthetic\ndataset: syn\n", r"either a `generator` or `scenes`, not neither"),
    ("kind: synthetic\ndataset: syn\ngenerator: {objects: [cup]}\n",
     r"field 'ground_truth': a generated suite names its `ground_truth` tables file"),
    ("kind: synthetic\ndataset: syn\nground_truth: ground_truth.yaml\n"
     "generator: {poses: [lying]}\n", r"unknown pose 'lying'; allowed: upright"),
    ("kind: synthetic\ndataset: syn\nground_truth: ground_truth.yaml\ngenerator: {}\nbogus: 1\n",
     r"bogus"),
    ("kind: synthetic\ndataset: syn\nground_truth: missing.yaml\ngenerator: {}\n",
     r"missing.yaml: no such suite file"),
    ("kind: [synthetic\n", r"suite.yaml:2: not valid YAML: expected ',' or ']'"),
    ("kind: executed\ndataset: robot\nscenes:\n  - name: a\n    objects: [{id: cup_01}]\n"
     "    task: {task: pass, ground_truth: {tasks: [pass], parts: [rim], reason: x}}\n",
     r"field 'scenes\[0\].task.ground_truth.parts': unknown part 'rim'; allowed: top"),
    ("kind: executed\ndataset: robot\nscenes:\n  - name: a\n    objects: [{id: cup_01}]\n"
     "    task: {task: pass, ground_truth: {tasks: [pass], parts: [middle]}}\n",
     r"a scene's ground truth needs its `reason`"),
    ("kind: executed\ndataset: robot\nscenes:\n  - name: a\n    objects: [{id: cup_01}]\n"
     "    variations: [{shift: [0.5, 0.0]}]\n    task: {task: pass}\n",
     r"field 'scenes\[0\].variations\[0\] objects\[0\].xy': object at xy=\[0.5, 0.0\] is off"),
])
def test_bad_suite_files_name_the_file_field_and_allowed_values(tmp_path, text, message):
    path = write(tmp_path, text)
    with pytest.raises(ScenarioError, match=message) as info:
        load_suite(path)
    assert str(path.parent) in str(info.value)


def test_bad_ground_truth_tables_are_named(tmp_path):
    path = write(tmp_path, "kind: synthetic\ndataset: syn\nground_truth: gt.yaml\ngenerator: {}\n")
    text = (SUITES / "ground_truth.yaml").read_text()
    (tmp_path / "gt.yaml").write_text(text.replace("pourOut: {any: [middle]}",
                                                   "pourOut: {any: [spout]}", 1))
    with pytest.raises(ScenarioError, match=r"gt.yaml, field 'parts.table.dish.pourOut.any': "
                                            r"unknown part 'spout'"):
        load_suite(path)
    (tmp_path / "gt.yaml").write_text(text.replace("    cup: &dish_tasks", "    mug: &dish_tasks"))
    with pytest.raises(ScenarioError, match=r"unknown category 'mug'; allowed: pan, pot"):
        load_suite(path)


def test_the_sweep_draws_single_object_cases_with_the_categories_in_turn():
    from tg_drake.objects import get_object
    from tg_drake.types import CATEGORIES

    suite, cases = load_suite(SUITES / "sweep.yaml")
    assert suite.kind == "executed" and suite.dataset == "sweep" and len(cases) == 33
    assert [get_object(c.target_placement.id).category for c in cases] == \
        [CATEGORIES[i % len(CATEGORIES)] for i in range(33)]
    assert len({c.key for c in cases}) == 33 and all(len(c.objects) == 1 for c in cases)
    for c in cases:
        p = c.target_placement
        assert abs(p.xy[0]) <= 0.08 and abs(p.xy[1]) <= 0.12 and 0 <= p.yaw < 360
        assert c.task in c.truth.tasks and c.task in ("pass", "p&pOn", "p&pInUpright")
    assert len({c.target_placement.yaw for c in cases}) > 20  # turned, not all at one yaw
    assert load_suite(SUITES / "sweep.yaml")[1] == cases  # the suite's seed fixes the draw


@pytest.mark.parametrize("generator, message", [
    ("{sample: -1}", r"field 'generator.sample': sample is a number of cases"),
    ("{xy_spread: [0.1, 0.0]}", r"xy_spread and yaw_spread vary drawn cases only"),
])
def test_bad_sampling_settings_are_named(tmp_path, generator, message):
    path = write(tmp_path, f"kind: synthetic\ndataset: syn\nground_truth: ground_truth.yaml\n"
                           f"generator: {generator}\n")
    with pytest.raises(ScenarioError, match=message):
        load_suite(path)


def test_suites_may_name_objects_of_user_libraries(tmp_path):
    from library_helpers import copy_object

    from tg_drake.evaluation.jobs import run_case
    from tg_drake.objects import forget_registered

    copy_object("cup_01", "my_mug", tmp_path / "lib")
    try:
        path = write(tmp_path, "kind: synthetic\ndataset: syn\nground_truth: ground_truth.yaml\n"
                               "object_libraries: [lib]\ngenerator: {objects: [my_mug]}\n")
        suite, cases = load_suite(path)
        assert suite.object_libraries == [str((tmp_path / "lib").resolve())]
        assert {c.target_placement.id for c in cases} == {"my_mug"}
        assert cases[0].object_libraries == tuple(suite.object_libraries)
        assert cases[0].truth.category == "cup"
        forget_registered()  # as in a fresh worker: the case registers its libraries itself
        record = run_case(cases[0])
        assert record["object"] == "my_mug" and set(record["priors"]) == {"label_fractions",
                                                                           "manifolds"}
        path = write(tmp_path, "kind: executed\ndataset: robot\nobject_libraries: [lib]\n"
                               "scenes:\n  - name: a\n    objects: [{id: my_mug, resting: 1}]\n"
                               "    task: {task: pass, ground_truth: {tasks: [pass], "
                               "parts: [middle], reason: x}}\n", name="scenes.yaml")
        _, cases = load_suite(path)
        placement = cases[0].target_placement
        assert (placement.id, placement.pose, placement.resting) == ("my_mug", "sideways", 1)
        assert cases[0].truth.category == "cup"
    finally:
        forget_registered()


def test_a_user_object_without_a_category_needs_ground_truth(tmp_path):
    from library_helpers import copy_object

    from tg_drake.objects import forget_registered

    copy_object("cup_01", "thing", tmp_path / "lib", category=None)
    try:
        path = write(tmp_path, "kind: synthetic\ndataset: syn\nground_truth: ground_truth.yaml\n"
                               "object_libraries: [lib]\ngenerator: {objects: [thing]}\n")
        with pytest.raises(ScenarioError, match="thing has no category") as e:
            load_suite(path)
        assert e.value.field == "generator.objects"
        path = write(tmp_path, "kind: executed\ndataset: robot\nobject_libraries: [lib]\n"
                               "scenes:\n  - name: a\n    objects: [{id: thing}]\n"
                               "    task: {task: pass, ground_truth: {tasks: [pass], "
                               "parts: [middle], reason: x}}\n", name="scenes.yaml")
        with pytest.raises(ScenarioError, match="give the scene's task.ground_truth.category"):
            load_suite(path)
        _, cases = load_suite(write(tmp_path, path.read_text().replace(
            "reason: x", "category: cup, reason: x"), name="scenes2.yaml"))
        assert cases[0].truth.category == "cup"
    finally:
        forget_registered()
