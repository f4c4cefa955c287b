"""`tg-drake eval` end to end on tiny suites: records stream to results.jsonl, a rerun skips them, a
sweep killed mid-way loses no finished result, a crashed case is a recorded failure, and the same
sweep runs on a local Ray instance."""

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tg_drake.cli import main

SUITES = Path(__file__).resolve().parents[2] / "scenarios" / "suites"
TINY = SUITES / "tiny.yaml"


def lines(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


def eval_(*args):
    return main(["eval", *map(str, args)])


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("tiny")
    assert eval_(TINY, "--out", out, "--workers", "0") == 0
    return out


def test_eval_writes_records_tables_and_plots_and_a_rerun_skips_them(tiny_run, capsys):
    records = lines(tiny_run / "results.jsonl")
    assert sorted(r["job"] for r in records) == [
        "tiny/cup_01_sideways_empty", "tiny/cup_01_upright_empty", "tiny/hammer_01_sideways_empty"]
    cup = next(r for r in records if r["job"] == "tiny/cup_01_upright_empty")
    assert cup["truth"]["tasks"] == ["pass", "p&pInUpright", "p&pOn"]
    assert abs(sum(cup["methods"]["plm"]["category"]) - 1.0) < 1e-5  # 6 digits kept per entry
    tables = json.loads((tiny_run / "tables.json").read_text())
    assert tables["category"]["syn"]["n"] == 3
    assert tables["task"]["syn"]["plm"]["E0"] == 100.0  # the sets of Table 3, perfect observations
    assert (tiny_run / "tables.md").read_text().startswith("# The paper's section VI tables")
    for png in ("accuracy.png", "task_ei.png", "pregrasp_ei.png"):
        assert (tiny_run / png).stat().st_size > 1000
    before = (tiny_run / "results.jsonl").read_text()
    capsys.readouterr()
    assert eval_(TINY, "--out", tiny_run, "--workers", "0") == 0
    assert "3 already done, 0 run now" in capsys.readouterr().err
    assert (tiny_run / "results.jsonl").read_text() == before


def test_a_crashed_case_is_a_failure_and_can_be_retried(tiny_run, tmp_path):
    good = {r["job"]: r for r in lines(tiny_run / "results.jsonl")}
    out = tmp_path / "results.jsonl"
    out.write_text(json.dumps(good["tiny/cup_01_upright_empty"]) + "\n"
                   + json.dumps({"job": "tiny/hammer_01_sideways_empty", "status": "error",
                                 "reason": "worker process died"}) + "\n")
    assert eval_(TINY, "--out", tmp_path, "--workers", "0") == 0
    tables = json.loads((tmp_path / "tables.json").read_text())
    assert tables["n_errors"] == 1 and tables["category"]["syn"]["n"] == 3
    # The hammer counts as wrong (tables round to 0.01 %).
    assert tables["category"]["syn"]["manifolds"] <= round(100 * 2 / 3, 2)
    assert eval_(TINY, "--out", tmp_path, "--workers", "0", "--retry-errors") == 0
    assert json.loads((tmp_path / "tables.json").read_text())["n_errors"] == 0


def test_a_sweep_killed_mid_way_loses_nothing_and_the_rerun_completes_it(tmp_path):
    suite = tmp_path / "perceived.yaml"
    suite.write_text(f"name: killed\nkind: perceived\nsettings: [semi, noisy]\n"
                     f"ground_truth: {SUITES / 'ground_truth.yaml'}\n"
                     "generator: {objects: [cup_01, hammer_01], poses: [upright, sideways], "
                     "yaws: [0, 90]}\n")
    out = tmp_path / "out"
    process = subprocess.Popen(
        [sys.executable, "-m", "tg_drake.cli", "eval", str(suite), "--out", str(out),
         "--workers", "1"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        start_new_session=True)
    results = out / "results.jsonl"
    try:
        deadline = time.monotonic() + 300
        while not (results.exists() and results.read_text().count("\n") >= 2):
            assert process.poll() is None, "the sweep ended before it could be killed"
            assert time.monotonic() < deadline, "no result within 5 minutes"
            time.sleep(0.05)
    finally:
        os.killpg(process.pid, signal.SIGKILL)  # the sweep and its worker, mid-way
        process.wait()
    finished = results.read_text().splitlines()
    done = {json.loads(line)["job"] for line in finished if line.endswith("}")}
    assert 1 <= len(done) < 6  # 6 cases: the cup upright and sideways, the hammer; 2 yaws
    assert eval_(suite, "--out", out, "--workers", "0") == 0
    after = results.read_text().splitlines()
    assert after[:len(finished) - 1] == finished[:-1]  # nothing finished was lost or rewritten
    records = [json.loads(line) for line in after if line.startswith("{") and line.endswith("}")]
    keys = [r["job"] for r in records]
    assert len(set(keys)) == 6 and len(keys) == 12  # every case, once, two settings each
    assert {r["dataset"] for r in records} == {"real_semi", "real_noisy"}


def test_the_same_sweep_runs_on_a_local_ray_instance(tiny_run, tmp_path):
    ray = pytest.importorskip("ray")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        assert eval_(TINY, "--out", tmp_path, "--executor", "ray", "--workers", "2") == 0
    finally:
        ray.shutdown()
    local = {r["job"]: r for r in lines(tiny_run / "results.jsonl")}
    remote = {r["job"]: r for r in lines(tmp_path / "results.jsonl")}
    assert remote.keys() == local.keys()
    assert all("methods" in r for r in remote.values()), [r.get("reason") for r in
                                                          remote.values()]
    for key, r in remote.items():  # the same answers: seeded per case, not per worker
        assert r["methods"] == local[key]["methods"] and r["priors"] == local[key]["priors"]


def test_another_theory_variant_runs_under_its_own_keys(tmp_path, capsys):
    assert eval_(TINY, "--out", tmp_path, "--workers", "0", "--theory", "learnt") == 2
    assert "field '--theory': unknown theory 'learnt'; allowed: specific, general" in \
        capsys.readouterr().err
    assert eval_(TINY, "--out", tmp_path, "--workers", "0", "--theory", "learned") == 0
    records = lines(tmp_path / "results.jsonl")
    assert {r["job"] for r in records} == {
        "tiny/cup_01_sideways_empty#learned", "tiny/cup_01_upright_empty#learned",
        "tiny/hammer_01_sideways_empty#learned"}
    assert {r["theory"] for r in records} == {"learned"}
    assert all("category" in r["methods"]["plm"] for r in records)


def test_a_malformed_results_file_or_path_is_a_clear_error(tmp_path, capsys):
    results = tmp_path / "results.jsonl"
    results.mkdir()
    assert eval_(TINY, "--out", tmp_path, "--workers", "0") == 2
    assert f"tg-drake eval: error: {results}: the results file is a folder" in \
        capsys.readouterr().err
    results.rmdir()
    results.write_text('{"job": "tiny/cup_01_upright_empty"}\n{"status": "ok"}\n')
    for extra in ([], ["--tables-only"]):
        assert eval_(TINY, "--out", tmp_path, "--workers", "0", *extra) == 2
        assert f"tg-drake eval: error: {results}:2: not a record of a sweep" in \
            capsys.readouterr().err
    results.write_bytes(b"\xff\xfe\n")
    assert eval_(TINY, "--out", tmp_path, "--tables-only") == 2
    assert f"{results}:1: not UTF-8 text" in capsys.readouterr().err


@pytest.mark.parametrize("options, message", [
    (["--workers", "-1"], "must be a number of processes ≥ 1, or 0 to run the jobs in this"),
    (["--executor", "ray", "--workers", "0"], "the number of jobs in flight, ≥ 1"),
    (["--executor", "ray", "--address", "head-node"], "malformed Ray address 'head-node'"),
    (["--executor", "ray", "--address", "127.0.0.1:{port}"],
     "no Ray cluster at --address 127.0.0.1:{port}: Connection refused"),
])
def test_bad_executor_options_are_refused_before_any_work(options, message, tmp_path, capsys,
                                                          monkeypatch):
    if "ray" in options:
        pytest.importorskip("ray")
    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    with socket.socket() as s:  # a port where nothing listens
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    options = [o.format(port=port) for o in options]
    assert eval_(TINY, "--out", tmp_path, *options) == 2
    assert message.format(port=port) in capsys.readouterr().err
    assert not (tmp_path / "results.jsonl").exists()


def test_the_bar_counts_an_executed_case_by_its_outcome_and_others_as_done():
    from tg_drake.evaluation.cli import outcome_label

    assert outcome_label([{"outcome": {"status": "placed", "reason": ""}}]) == "placed"
    assert outcome_label([{"outcome": {"status": "failed", "reason": "missed"}}]) == "failed"
    assert outcome_label([{"methods": {}}, {"methods": {}}]) == "done"  # perceived: 2 settings


def test_cases_selects_by_pattern_and_list_prints_the_keys_without_an_output_folder(capsys):
    assert eval_(SUITES / "s_grasp.yaml", "--cases", "s_grasp/pan_03_upright*", "--cases",
                 "s_grasp/knife_0?_sideways_empty_pass@pipeline", "--list") == 0
    keys = capsys.readouterr().out.split()
    assert sorted(keys) == sorted(
        [f"s_grasp/pan_03_upright_empty_{t}@pipeline" for t in ("pass", "p&pOn", "p&pInUpright")]
        + [k for k in keys if k.startswith("s_grasp/knife_")])
    assert any(k.startswith("s_grasp/knife_") for k in keys)
    assert eval_(SUITES / "s_grasp.yaml", "--cases", "no_such_case*", "--list") == 2
    err = capsys.readouterr().err
    assert "field '--cases': no case's key matches 'no_such_case*' (of 132 cases" in err
    assert eval_(SUITES / "s_grasp.yaml") == 2  # neither --out nor --list/--export
    assert "field '--out': the output folder is missing" in capsys.readouterr().err


def test_an_exported_case_is_the_scenario_the_sweep_runs(tmp_path, capsys):
    from pydrake.common.yaml import yaml_dump_typed

    from tg_drake.evaluation.jobs import scenario_of
    from tg_drake.evaluation.suite import load_suite
    from tg_drake.scenario import LocalOnly, load_scenario

    suite = SUITES / "s_grasp_baselines.yaml"
    key = "s_grasp_baselines/cup_01_upright_empty_pass@local"
    assert eval_(suite, "--cases", key, "--export", tmp_path) == 0
    files = list(tmp_path.iterdir())
    assert [f.name for f in files] == ["s_grasp_baselines_cup_01_upright_empty_pass_local.yaml"]
    assert f"tg-drake run {files[0]}" in files[0].read_text().splitlines()[1]
    loaded = load_scenario(files[0])
    assert isinstance(loaded.pipeline.scoring, LocalOnly)
    case = next(c for c in load_suite(suite)[1] if c.key == key)
    assert yaml_dump_typed(loaded) == yaml_dump_typed(scenario_of(case))
    # A selection without an executed case has no scenario to write.
    assert eval_(TINY, "--cases", "tiny/*", "--export", tmp_path / "none") == 2
    assert "only executed cases are scenarios" in capsys.readouterr().err
