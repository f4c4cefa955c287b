"""Golden cases: each tests/core/logic_cases/NAME.yaml (an observations file, the format of
`tg-drake query`) with NAME.expected.yaml next to it — the theory variant and either the expected
distributions (every outcome not listed is 0) with a tolerance, or the error it must raise.

The expected numbers come from plain ProbLog (`reference_query`: the scene as a program, ground
per query), so a case checks the compiled path against ProbLog's own semantics, and catches any
change of the theory's answers. After a deliberate change of the theory, regenerate with

    .venv/bin/python tests/core/test_logic_golden.py --write

and review the diff of the .expected.yaml files.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
import yaml

import tg_drake.errors
from tg_drake.logic.engine import QUERIES, LogicEngine, reference_query
from tg_drake.logic.observations import Observations
from tg_drake.logic.theory import TheoryConfig

CASES = Path(__file__).parent / "logic_cases"
# Plain ProbLog and the compiled circuit differ by float rounding only (~1e-15); 1e-9 is the
# agreement the compiled path promises.
TOLERANCE = 1e-9


def _cases():
    return sorted(p for p in CASES.glob("*.yaml") if not p.name.endswith(".expected.yaml"))


def _expected_path(case: Path) -> Path:
    return case.with_name(case.stem + ".expected.yaml")


@pytest.mark.parametrize("case", _cases(), ids=lambda p: p.stem)
def test_golden_case(case):
    spec = yaml.safe_load(_expected_path(case).read_text())
    config = TheoryConfig(**spec["theory"])
    if "error" in spec:
        error = getattr(tg_drake.errors, spec["error"])
        with pytest.raises(error, match=spec["match"]):
            LogicEngine(config).query(Observations.from_file(case))
        return
    answer = LogicEngine(config).query(Observations.from_file(case))
    tolerance = float(spec.get("tolerance", TOLERANCE))
    for q in QUERIES:
        got = answer.distribution(q)
        want = spec["expected"][q]
        assert set(want) <= set(got), f"{q}: unexpected outcomes {set(want) - set(got)}"
        for name, p in got.items():
            assert p == pytest.approx(want.get(name, 0.0), abs=tolerance), f"{q}: {name}"


def test_every_case_has_its_expectation():
    cases = _cases()
    assert len(cases) >= 10
    for case in cases:
        assert _expected_path(case).is_file(), case.name
        assert case.read_text().startswith("#"), f"{case.name}: say what the case is"


# Variants of the cases first written (regeneration keeps what the .expected file says).
_INITIAL = {"fig1_cup_general": TheoryConfig.named("general"),
            "fig1_cup_non_exclusive": TheoryConfig(exclusive=False)}


def _write():
    for case in _cases():
        path = _expected_path(case)
        old = yaml.safe_load(path.read_text()) if path.is_file() else {}
        if "error" in old:
            continue
        config = TheoryConfig(**old["theory"]) if "theory" in old else _INITIAL.get(
            case.stem, TheoryConfig())
        answer = reference_query(Observations.from_file(case), config)
        header = case.read_text().splitlines()[0]
        body = {"theory": {"category": config.category, "grasp": config.grasp,
                           "exclusive": config.exclusive},
                "tolerance": TOLERANCE,
                "expected": {q: {k: float(v) for k, v in answer.distribution(q).items() if v > 0}
                             for q in QUERIES}}
        path.write_text(f"{header}\n# Expected: plain ProbLog (reference_query); regenerate with "
                        f"tests/core/test_logic_golden.py --write.\n"
                        + yaml.safe_dump(body, sort_keys=False, width=100))
        print("wrote", path.name)


if __name__ == "__main__" and "--write" in sys.argv:
    _write()
