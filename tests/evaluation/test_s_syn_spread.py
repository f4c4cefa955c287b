"""tools/s_syn_spread.py: S_SYN over several samplings of each object, measured as the tables do."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from tg_drake.errors import KernelError
from tg_drake.evaluation import jobs
from tg_drake.evaluation.suite import load_suite
from tg_drake.evaluation.tables import category

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def tool():
    spec = importlib.util.spec_from_file_location("s_syn_spread",
                                                  REPO / "tools" / "s_syn_spread.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def cases(tool):
    _, cases = load_suite(tool.SUITE)
    keep = {"glass_01", "cup_01", "knife_02"}  # a few objects keep the test fast
    return [c for c in cases if c.target_placement.id in keep]


def test_sampling_zero_is_the_suite_and_the_summary_is_over_the_samplings(tool, cases):
    result = tool.spread(cases, 2, progress=lambda line: None)
    as_run = category([jobs.run_synthetic(c) for c in cases])["syn"]
    for m in tool.METHODS:
        assert result["samplings"][0][m] == as_run[m]
        values = [r[m] for r in result["samplings"]]
        assert result["summary"][m]["mean"] == pytest.approx(np.mean(values), abs=0.01)
        assert result["summary"][m]["min"] == min(values)
        assert result["summary"][m]["max"] == max(values)
    assert result["n_objects"] == 3 and result["n_cases"] == len(cases)


def test_a_shifted_sampling_draws_new_clouds(tool, cases):
    first, second = (tool.sampling_records(cases, k) for k in (0, 1))
    assert any(a["priors"] != b["priors"] for a, b in zip(first, second, strict=True))


def test_a_missing_database_file_is_a_clear_error(tool, tmp_path, capsys):
    with pytest.raises(SystemExit):
        tool.main(["--database", str(tmp_path / "none.npz"), "--out", str(tmp_path / "x")])
    assert "none.npz: no such file" in capsys.readouterr().err


def test_another_database_file_is_used_and_a_missing_one_refused(tool, cases, tmp_path):
    shipped = REPO / "tg_drake" / "data" / "kernel_db.npz"
    default = tool.sampling_records(cases[:2], 0)
    try:
        jobs.use_database(shipped)  # the same file by its path: the same priors
        assert [r["priors"] for r in tool.sampling_records(cases[:2], 0)] == \
            [r["priors"] for r in default]
        with pytest.raises(KernelError, match="no such kernel database file"):
            jobs.use_database(tmp_path / "none.npz")
    finally:
        jobs.use_database(None)
