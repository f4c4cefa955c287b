"""Scenario surfaces (p&pOn) and the task fields: validation names the field."""

import pytest

from tg_drake.errors import ScenarioError
from tg_drake.scenario import load_scenario, place_surface

CAN = "objects: [{id: can_01, pose: upright, xy: [0.0, 0.0]}]\n"


def load(text):
    return load_scenario(scenario_text=CAN + text)


def test_a_shelf_is_the_place_surface_of_p_and_p_on():
    s = load("surfaces: [{name: shelf, xy: [0.0, -0.3], size: [0.2, 0.2, 0.08]},"
             " {name: board, xy: [0.2, 0.3], size: [0.1, 0.1, 0.02]}]\n"
             "task: {task: p&pOn, place_on: board}\n")
    assert place_surface(s).name == "board"
    s.task.place_on = ""
    assert place_surface(s).name == "shelf"  # the first by default
    s.task.task = "pass"
    assert place_surface(s) is None


def test_p_and_p_on_without_surfaces_places_on_the_table():
    assert place_surface(load("task: {task: p&pOn}\n")) is None


@pytest.mark.parametrize("text, match", [
    ("surfaces: [{name: shelf, xy: [0.35, 0.0], size: [0.2, 0.2, 0.08]}]\n",
     r"surfaces\[0\]\.xy.*reaches off the table"),
    ("surfaces: [{name: shelf, xy: [0.05, 0.0], size: [0.2, 0.2, 0.08]}]\n",
     r"surfaces\[0\]\.xy.*stands under can_01"),
    ("surfaces: [{name: a, xy: [0.0, -0.3], size: [0.1, 0.1, 0.05]},"
     " {name: a, xy: [0.0, 0.3], size: [0.1, 0.1, 0.05]}]\n", r"surfaces\[1\]\.name.*two surfaces"),
    ("surfaces: [{name: shelf, xy: [0.0, -0.3], size: [0.2, 0.0, 0.08]}]\n",
     r"surfaces\[0\]\.size"),
    ("surfaces: [{xy: [0.0, -0.3], size: [0.2, 0.2, 0.08]}]\n", r"surfaces\[0\]\.name"),
    ("surfaces: [{name: shelf, xy: [0.0, -0.3], size: [0.2, 0.2, 0.08]}]\n"
     "task: {task: p&pOn, place_on: table}\n", r"task\.place_on.*unknown surface 'table'"),
    ("task: {task: pourOut, pour_into: bowl_01}\n",
     r"task\.pour_into.*unknown object to pour into 'bowl_01'"),
])
def test_bad_surfaces_and_task_fields_name_the_field(text, match):
    with pytest.raises(ScenarioError, match=match):
        load(text)


@pytest.mark.parametrize("entry", [
    "{id: hammer_01, pose: sideways, xy: [0.0, 0.0], containment: full}",
    "{id: knife_01, pose: sideways, xy: [0.0, 0.0], containment: full}",
])
def test_a_full_object_without_a_cavity_is_refused_naming_the_field(entry):
    # Issue 21's bad input: a full container of an object with no cavity (a tool).
    with pytest.raises(ScenarioError, match="has no cavity to fill; allowed: empty") as e:
        load_scenario(scenario_text=f"objects: [{entry}]\ntask: {{task: pourOut}}\n")
    assert e.value.field == "objects[0].containment"
    # The same object empty loads.
    load_scenario(scenario_text=f"objects: [{entry.replace('full', 'empty')}]\n")
