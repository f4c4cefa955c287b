"""Scenario regression: the scenarios in scenarios/regression/ against their expected outcomes.

`scenarios/regression/expected.yaml` holds, per scenario, the category argmax, the set the best
task(s) must lie in, the part, the least accepted outcome and the tolerance for what may vary. Each
scenario runs once per session (end to end, about 10–25 s, shared with the other scenario tests);
each aspect is its own test, so a known failure of one aspect (`known_failure`, an expected
failure, strict) does not hide the others.
"""

from pathlib import Path

import pytest
import yaml

from tg_drake.systems.supervisor import FAILURE_REASONS, OUTCOME_STATUSES
from tg_drake.types import CATEGORIES, PART_LABELS, TASKS

FOLDER = Path(__file__).resolve().parents[2] / "scenarios" / "regression"
EXPECTED = yaml.safe_load((FOLDER / "expected.yaml").read_text())
ASPECTS = ("category", "tasks", "part", "outcome")
# Outcomes from worst to best: "at least lifted" accepts lifted and placed.
RANK = {status: i for i, status in enumerate(reversed(OUTCOME_STATUSES))}


def test_expectations_name_real_scenarios_and_values():
    """Every expectation names a scenario file and only allowed values (and every file has one)."""
    files = {p.stem for p in FOLDER.glob("*.yaml")} - {"expected"}
    assert set(EXPECTED) == files
    for name, e in EXPECTED.items():
        assert e["category"] in CATEGORIES, name
        assert e["tasks"] and set(e["tasks"]) <= set(TASKS), name
        assert e["part"] is None or e["part"] in PART_LABELS, name
        status, _, reason = str(e["outcome"]).partition(": ")
        assert status in OUTCOME_STATUSES, name
        assert (status == "failed") == bool(reason) and (not reason or reason in FAILURE_REASONS)
        assert e.get("tolerance"), f"{name}: write the tolerance down"
        assert set(e.get("known_failure") or {}) <= set(ASPECTS), name


def best(distribution: dict) -> set:
    top = max(distribution.values())
    return {k for k, v in distribution.items() if v >= top - 1e-9}


def check(name: str, aspect: str, r: dict) -> None:
    e = EXPECTED[name]
    if aspect == "category":
        winners = best(r["category"])
        assert winners == {e["category"]}, f"category argmax {winners} (ties fail)"
    elif aspect == "tasks":
        winners = best(r["task"])
        assert winners <= set(e["tasks"]), f"best tasks {winners} not within {e['tasks']}"
    elif aspect == "part":
        if e["part"] is None:
            assert "grasp" not in r, f"a grasp was executed: {r.get('grasp')}"
        else:
            assert best(r["part"]) == {e["part"]}, f"P(part | task) argmax {best(r['part'])}"
            assert r["grasp"]["part"] == e["part"], f"executed grasp on {r['grasp']['part']}"
    else:
        status, _, reason = str(e["outcome"]).partition(": ")
        o = r["outcome"]
        if status == "failed":
            assert (o["status"], o["reason"]) == ("failed", reason), o
        else:
            assert RANK[o["status"]] >= RANK[status], (
                f"outcome {o['status']} ({o['reason']}: {o['detail']}), expected at least {status}")


CASES = [pytest.param(name, aspect, id=f"{name}-{aspect}",
                      marks=([pytest.mark.xfail(reason=e["known_failure"][aspect], strict=True)]
                             if aspect in (e.get("known_failure") or {}) else []))
         for name, e in EXPECTED.items() for aspect in ASPECTS]


@pytest.mark.parametrize("name, aspect", CASES)
def test_regression(name, aspect, cached_run):
    check(name, aspect, cached_run(FOLDER / f"{name}.yaml"))
