"""Scenario loading: Drake's typed YAML plus our validation, with errors that name the problem."""

import pytest

from tg_drake.errors import ScenarioError
from tg_drake.scenario import JointPdDriver, Scenario, WsgPdDriver, load_scenario, scenario_names


def write(tmp_path, text, name="s.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_missing_keys_keep_defaults(tmp_path):
    scenario = load_scenario(write(tmp_path, "random_seed: 3\n"))
    assert scenario.random_seed == 3
    assert scenario.plant_config.contact_model == "hydroelastic_with_fallback"
    assert scenario.plant_config.discrete_contact_approximation == "sap"
    assert isinstance(scenario.model_drivers["iiwa"], JointPdDriver)
    # The table is not a directive: the station builds it from table_size and X_WT.
    assert [d.add_model.name for d in scenario.directives if d.add_model] == ["iiwa", "wsg"]
    assert scenario.table_size == [0.8, 1.2]


def test_tagged_driver_union_is_chosen_in_yaml(tmp_path):
    scenario = load_scenario(write(tmp_path, """
model_drivers:
  iiwa: !JointPdDriver {kp: 3000}
  wsg: !WsgPdDriver {force_limit: 60}
"""))
    assert scenario.model_drivers["iiwa"].kp == 3000
    assert isinstance(scenario.model_drivers["wsg"], WsgPdDriver)
    assert scenario.model_drivers["wsg"].force_limit == 60


def test_named_entries_and_anchors(tmp_path):
    path = write(tmp_path, """
Base: &Base
  random_seed: 1
  task: {task: pass}
Variant:
  <<: *Base
  task: {task: pourOut}
""")
    assert scenario_names(path) == ["Base", "Variant"]
    assert load_scenario(path, scenario_name="Variant").task.task == "pourOut"
    assert load_scenario(path, scenario_name="Base").task.task == "pass"


def test_unknown_key_names_the_file_and_key(tmp_path):
    path = write(tmp_path, "random_sede: 3\n")
    with pytest.raises(ScenarioError, match=r"s\.yaml.*random_sede"):
        load_scenario(path)


def test_unknown_task_lists_the_allowed_tasks(tmp_path):
    path = write(tmp_path, "task: {task: juggle}\n")
    with pytest.raises(ScenarioError, match=r"field 'task\.task': unknown task 'juggle'; allowed: "
                                            r"pass, pourOut, pourIn"):
        load_scenario(path)


def test_unknown_driver_model(tmp_path):
    path = write(tmp_path, "model_drivers: {arm: !JointPdDriver {}}\n")
    with pytest.raises(ScenarioError, match="unknown model driver 'arm'; allowed: iiwa, wsg"):
        load_scenario(path)


def test_missing_file():
    with pytest.raises(ScenarioError, match="no_such.yaml: no such scenario file"):
        load_scenario("no_such.yaml")


def test_malformed_yaml(tmp_path):
    path = write(tmp_path, "task: [unclosed\n")
    with pytest.raises(ScenarioError, match=r"s\.yaml"):
        load_scenario(path)


def test_no_objects_target_is_an_error():
    with pytest.raises(ScenarioError, match="no objects"):
        Scenario().target_placement()


# ---- the pipeline block: typed stage configs, tagged alternatives ------------------------------

def _load(tmp_path, text, **kwargs):
    path = tmp_path / "s.yaml"
    path.write_text("objects:\n  - {id: cup_01}\n" + text)
    return load_scenario(path, **kwargs)


def test_pipeline_alternatives_are_tagged(tmp_path):
    from tg_drake.scenario import DepthPerception, DgiScorer, GroundTruthPerception, LocalOnly

    default = _load(tmp_path, "").pipeline
    assert isinstance(default.perception, DepthPerception)
    assert isinstance(default.scoring, DgiScorer) and default.selection == "pipeline"
    p = _load(tmp_path, "pipeline:\n  perception: !GroundTruthPerception {spacing: 0.005}\n"
              "  scoring: !LocalOnly {}\n").pipeline
    assert isinstance(p.perception, GroundTruthPerception) and p.perception.spacing == 0.005
    assert isinstance(p.scoring, LocalOnly) and p.selection == "local_only"
    assert p.prior_config().clouds == "ground_truth"  # follows the perception
    assert default.prior_config().clouds == "perceived"


def test_every_stage_config_is_settable_from_yaml(tmp_path):
    p = _load(tmp_path, """pipeline:
  perception: !DepthPerception
    camera: camera0
    config: {completion: {sigma: 0.8}, segmentation: {seed: 3}}
  prior: {n_neighbours: 5}
  logic: {category: general, grasp: general, use_prior: false, prior_floor: 0.1}
  feasibility: {max_torsion_lever: 0.1, min_pad_depth: 0.005}
  planner: {lift_height: 0.2, place_yaws: [0, 90], carry_limits: {velocity_scale: 0.3}}
""").pipeline
    assert p.perception.config.completion.sigma == 0.8
    assert p.perception.config.segmentation.seed == 3
    assert p.prior.n_neighbours == 5
    assert (p.logic.category, p.logic.grasp, p.logic.use_prior, p.logic.prior_floor) == (
        "general", "general", False, 0.1)
    assert (p.feasibility.max_torsion_lever, p.feasibility.min_pad_depth) == (0.1, 0.005)
    assert p.planner.lift_height == 0.2 and p.planner.place_yaws == [0, 90]
    assert p.planner.carry_limits.velocity_scale == 0.3
    assert p.planner.carry_limits.min_duration == 1.0  # the nested default is kept


def test_the_resolved_scenario_round_trips_through_yaml(tmp_path):
    from pydrake.common.yaml import yaml_dump_typed, yaml_load_typed

    from tg_drake.scenario import Scenario

    s = _load(tmp_path, "pipeline:\n  perception: !GroundTruthPerception {}\n"
              "  planner: {lift_height: 0.2}\n")
    again = yaml_load_typed(schema=Scenario, data=yaml_dump_typed(s))
    assert yaml_dump_typed(again) == yaml_dump_typed(s)
    assert again.pipeline.planner.lift_height == 0.2


def test_a_retired_model_file_in_the_directives_is_replaced(tmp_path, capsys):
    # A scenario written before the WSG became a URDF (an exported case, a result's `config`).
    from pydrake.common.yaml import yaml_dump_typed

    from tg_drake.scenario import RETIRED_MODEL_FILES

    old, new = next(iter(RETIRED_MODEL_FILES.items()))
    text = yaml_dump_typed(Scenario(objects=[])).replace(new, old)
    assert old in text
    path = tmp_path / "old.yaml"
    path.write_text(text)
    s = load_scenario(path)
    files = [d.add_model.file for d in s.directives if d.add_model]
    assert new in files and old not in files
    assert f"directives[2].add_model.file {old} is retired" in capsys.readouterr().err


@pytest.mark.parametrize("text, field, message", [
    ("pipeline:\n  perception: ground_truth\n", "pipeline.perception",
     "expected one of !DepthPerception {...} or !GroundTruthPerception {...}, got 'ground_truth'"),
    ("pipeline:\n  scoring: !Local {}\n", "pipeline.scoring",
     "unknown alternative !Local (did you mean !LocalOnly?); allowed: !DgiScorer, !LocalOnly"),
    ("pipeline:\n  planner: {lift_hieght: 0.2}\n", "pipeline.planner.lift_hieght",
     "unknown field 'lift_hieght' (did you mean 'lift_height'?); allowed: pregrasp_distance"),
    ("pipeline:\n  logic: {grasp: specfic}\n", "pipeline.logic.grasp",
     "unknown grasp model variant 'specfic'; allowed: specific, general, learned"),
    ("pipeline:\n  scoring: !OnePart {part: lid}\n", "pipeline.scoring.part",
     "unknown part 'lid'; allowed: top"),
    ("pipeline:\n  feasibility: {max_pad_cover: 1.5}\n", "pipeline.feasibility.max_pad_cover",
     "max_pad_cover must be in [0, 1], got 1.5"),
    ("pipeline:\n  category_theory: general\n", "pipeline.category_theory",
     "unknown field 'category_theory'; allowed: perception, prior, logic, scoring, feasibility"),
])
def test_pipeline_mistakes_name_the_field(tmp_path, text, field, message):
    with pytest.raises(ScenarioError) as e:
        _load(tmp_path, text)
    assert e.value.field == field
    assert message in str(e.value)
    assert "s.yaml" in str(e.value)


@pytest.mark.parametrize("entry, field, message", [
    ("{id: cup_01, yaww: 0}", "objects[0].yaww",
     "unknown field 'yaww' (did you mean 'yaw'?); allowed: id, name, pose, xy, yaw"),
    ("{id: cup_01, xy: 0.1}", "objects[0].xy", "expected a list, got 0.1"),
    ("{id: cup_01, yaw: ninety}", "objects[0].yaw", "expected a number, got 'ninety'"),
    ("[cup_01]", "objects[0]", "expected a mapping with keys among id, name"),
])
def test_object_mistakes_name_the_field(tmp_path, entry, field, message):
    path = tmp_path / "o.yaml"
    path.write_text(f"objects:\n  - {entry}\n")
    with pytest.raises(ScenarioError) as e:
        load_scenario(path)
    assert e.value.field == field
    assert message in str(e.value)


def test_a_missing_named_entry_lists_the_entries(tmp_path):
    path = tmp_path / "n.yaml"
    path.write_text("Mug: {objects: [{id: cup_01}]}\nCan: {objects: [{id: can_01}]}\n")
    with pytest.raises(ScenarioError, match="unknown scenario 'Mugg'; allowed: Mug, Can"):
        load_scenario(path, scenario_name="Mugg")


# ---- validation before anything is built -----------------------------------------------------

@pytest.mark.parametrize("text, field, message", [
    ("plant_config: {time_step: 0}\n", "plant_config.time_step", "> 0 [s], got 0"),
    ("plant_config: {time_step: .nan}\n", "plant_config.time_step", "got nan"),
    ("plant_config: {contact_model: hydro}\n", "plant_config.contact_model",
     "unknown contact model 'hydro'; allowed: point, hydroelastic"),
    ("plant_config: {discrete_contact_approximation: sapp}\n",
     "plant_config.discrete_contact_approximation", "allowed: tamsi, sap, similar, lagged"),
    ("model_drivers: {iiwa: !JointPdDriver {kp: -1}}\n", "model_drivers.iiwa.kp", "≥ 0"),
    ("model_drivers: {wsg: !WsgPdDriver {force_limit: 0}}\n", "model_drivers.wsg.force_limit",
     "> 0"),
    ("cameras: {camera0: {width: 0}}\n", "cameras.camera0.width", "> 0 [px], got 0"),
    ("cameras: {camera0: {focal: !FovDegrees {y: 190}}}\n", "cameras.camera0.focal.y",
     "(0, 180) [deg], got 190"),
    ("cameras: {camera0: {clipping_near: 2.0, clipping_far: 1.0}}\n",
     "cameras.camera0.clipping_near", "need 0 < clipping_near < clipping_far"),
    ("simulation_duration: .inf\n", "simulation_duration", "finite number > 0 [s], got inf"),
    ("simulator_config: {max_step_size: 0}\n", "simulator_config.max_step_size", "> 0 [s]"),
    ("task: {place_xy: [0.0, -0.9]}\n", "task.place_xy", "is off the table"),
    ("task: {place_xy: [.nan, 0]}\n", "task.place_xy", "two finite numbers"),
    ("table_size: [0.8, -1]\n", "table_size", "each side at least"),
    ("task: {ground_truth: {category: mugg}}\n", "task.ground_truth.category",
     "unknown category 'mugg'; allowed: pan, pot, cup"),
    ("task: {ground_truth: {parts: [lid]}}\n", "task.ground_truth.parts",
     "unknown part 'lid'; allowed: top"),
])
def test_simulation_settings_are_checked_before_building(tmp_path, text, field, message):
    with pytest.raises(ScenarioError) as e:
        _load(tmp_path, text)
    assert e.value.field == field
    assert message in str(e.value)


def test_interpenetrating_objects_are_refused(tmp_path):
    path = tmp_path / "i.yaml"
    path.write_text("objects:\n  - {id: cup_02, xy: [0.0, 0.0]}\n"
                    "  - {id: glass_01, xy: [0.0, 0.02]}\n")
    with pytest.raises(ScenarioError, match="cup_02 .objects.0.. and glass_01 .objects.1.. "
                       "interpenetrate by [0-9]+ mm"):
        load_scenario(path)
    path.write_text("objects:\n  - {id: cup_02, xy: [0.0, 0.0]}\n"
                    "  - {id: glass_01, xy: [0.0, 0.2]}\n")
    assert len(load_scenario(path).objects) == 2  # 20 cm apart


def test_input_size_limits(tmp_path):
    bomb = "a: &a [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
        for p, c in zip("abcdefgh", "bcdefghi", strict=True)) + "objects: *i\n"
    path = tmp_path / "bomb.yaml"
    path.write_text(bomb)  # 10⁹ values from 700 bytes
    with pytest.raises(ScenarioError, match="expands to more than"):
        load_scenario(path)
    big = tmp_path / "big.yaml"
    big.write_text("# " + "x" * 3_000_000 + "\n")
    with pytest.raises(ScenarioError, match="larger than"):
        load_scenario(big)
    binary = tmp_path / "bin.yaml"
    binary.write_bytes(b"\xff\xfe\x00objects: []")
    with pytest.raises(ScenarioError, match="not a UTF-8 text file"):
        load_scenario(binary)


def test_a_long_value_is_quoted_short(tmp_path):
    with pytest.raises(ScenarioError) as e:
        _load(tmp_path, "simulation_duration: [" + ", ".join(["1"] * 5000) + "]\n")
    assert len(str(e.value)) < 400


def test_random_seed_seeds_the_perception_stage(tmp_path):
    from pydrake.systems.framework import DiagramBuilder

    from tg_drake.diagram import add_pipeline

    scenario = _load(tmp_path, "random_seed: 7\npipeline:\n  perception: !DepthPerception\n"
                     "    config: {segmentation: {seed: 2}}\n")
    pipeline = add_pipeline(DiagramBuilder(), scenario=scenario)
    assert pipeline.perception.config.segmentation.seed == 9  # the config's seed + random_seed
