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
