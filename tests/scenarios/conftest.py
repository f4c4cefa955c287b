"""One end-to-end run per scenario file (and named entry) for the whole test session: the
regression, pipeline and outcome-path tests read the same `tg_drake.run.run_scenario` result."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tg_drake.run import run_scenario
from tg_drake.scenario import load_scenario

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
_RESULTS: dict = {}


def scenario_result(path: Path, name: str | None = None) -> dict:
    """`run_scenario` on the file `path` (entry `name`), run once per session; the result
    serialises to JSON (result.json)."""
    key = (str(Path(path).resolve()), name)
    if key not in _RESULTS:
        scenario = load_scenario(path, scenario_name=name)
        label = str(Path(path).resolve().relative_to(SCENARIOS.parent))
        result = run_scenario(scenario, scenario_path=label + (f"#{name}" if name else ""))
        json.dumps(result)
        _RESULTS[key] = result
    return _RESULTS[key]


@pytest.fixture(scope="session")
def cached_run():
    return scenario_result
