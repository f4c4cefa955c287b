"""Every scenario in scenarios/ ends the same through `tg-drake run` (`tg_drake.run.run_scenario`)
and through a diagram composed by hand with `add_pipeline`, simulated until the supervisor's
outcome is final (the README's "Composing your own diagram").

Both paths share the supervisor, so the logic's veto, the re-query policy and the execution
monitor are the same; only the driving loop differs (the hand loop uses a default `Simulator` and
steps of `STEP`). Each scenario runs once per path (the run_scenario result is shared with the
regression and pipeline tests).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from tg_drake.diagram import add_pipeline
from tg_drake.scenario import load_scenario, scenario_names

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
STEP = 0.25  # [s] simulated time between looks at the outcome in the hand-driven loop


# The cases run by default (one of each outcome path: placed, the logic's refusal, unreachable, a
# regression scenario whose run the regression tests share); every other scenario runs in
# `make test-slow` (the multi-object scenes take 30–70 s each through both paths).
DEFAULT_CASES = frozenset({"default.yaml", "pan_upside_down.yaml", "out_of_reach.yaml",
                           "regression/pan_upside_down.yaml",
                           "regression/can_sideways_place.yaml"})


def scenario_cases() -> list:
    """(file, entry) for every top-level and regression scenario file (each named entry of a
    multi-scenario file); suites are lists of cases, not scenarios. Cases outside DEFAULT_CASES
    are marked slow."""
    files = sorted(SCENARIOS.glob("*.yaml")) + sorted(
        p for p in (SCENARIOS / "regression").glob("*.yaml") if p.stem != "expected")
    cases = []
    for path in files:
        names = scenario_names(path)
        for name in names or [None]:
            label = str(path.relative_to(SCENARIOS)) + (f"#{name}" if name else "")
            marks = () if label in DEFAULT_CASES else (pytest.mark.slow,)
            cases.append(pytest.param(path, name, id=label, marks=marks))
    return cases


def outcome_by_hand(path: Path, name: str | None) -> tuple[str, str]:
    scenario = load_scenario(path, scenario_name=name)
    builder = DiagramBuilder()
    pipeline = add_pipeline(builder, scenario=scenario)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    supervisor_context = pipeline.supervisor.GetMyContextFromRoot(context)
    outcome_port = pipeline.ports["outcome"]
    simulator.Initialize()
    outcome = outcome_port.Eval(supervisor_context)
    while not outcome.final and context.get_time() < scenario.simulation_duration:
        simulator.AdvanceTo(min(context.get_time() + STEP, scenario.simulation_duration))
        outcome = outcome_port.Eval(supervisor_context)
    if not outcome.final:
        return "failed", "timeout"
    return outcome.status.value, outcome.reason.value


def test_every_scenario_file_is_a_case():
    ids = {c.id for c in scenario_cases()}
    assert "default.yaml" in ids and "regression/pan_upside_down.yaml" in ids
    assert not any("expected" in i for i in ids)
    assert DEFAULT_CASES <= ids  # a renamed scenario does not drop out of the default run


@pytest.mark.parametrize("path, name", scenario_cases())
def test_run_and_composed_diagram_agree(path, name, cached_run):
    result = cached_run(path, name)
    through_run = (result["outcome"]["status"], result["outcome"]["reason"])
    assert outcome_by_hand(path, name) == through_run, result["outcome"]


ENDS = re.compile(r"^# Ends: (placed|lifted|grasped|failed)(?: \((\w+)\))?(, task done)?$",
                  re.MULTILINE)


def expected_end(path: Path) -> tuple[str, str | None, bool]:
    """(status, reason or None, task done) from a scenario header's `# Ends:` line."""
    m = ENDS.search(path.read_text())
    assert m, f"{path.name}: its header has no '# Ends: <status> [(<reason>)][, task done]' line"
    return m.group(1), m.group(2), bool(m.group(3))


EXAMPLES = [c for c in scenario_cases() if "/" not in c.id and "#" not in c.id]


def test_every_example_says_how_it_ends():
    for case in EXAMPLES:
        expected_end(case.values[0])


@pytest.mark.parametrize("path, name", EXAMPLES)
def test_each_example_ends_as_its_header_says(path, name, cached_run):
    status, reason, task_done = expected_end(path)
    result = cached_run(path, name)
    outcome = result["outcome"]
    assert outcome["status"] == status, outcome
    if reason is not None:
        assert outcome["reason"] == reason, outcome
    if task_done:
        assert result["task_outcome"]["success"], result["task_outcome"]
