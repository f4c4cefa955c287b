"""`tg-drake eval --shard I/N` and `--tables-only`: deterministic slices of a sweep's cases, run
and resumed apart, merged into one set of tables with duplicates and missing cases reported."""

import json
import random
import shutil
from pathlib import Path

import pytest

from tg_drake.cli import main
from tg_drake.errors import ScenarioError
from tg_drake.evaluation.cli import load_cases
from tg_drake.evaluation.shards import object_set, parse_shard, shard

SUITES = Path(__file__).resolve().parents[2] / "scenarios" / "suites"
TINY = SUITES / "tiny.yaml"


def eval_(*args):
    return main(["eval", *map(str, args)])


@pytest.mark.parametrize("text, message", [
    ("0/3", "shards are numbered 1 to 3, got '0/3'"),
    ("4/3", "shards are numbered 1 to 3, got '4/3'"),
    ("1/0", "the number of shards N must be ≥ 1, got '1/0'"),
    ("-1/2", "shards are numbered 1 to 2"),
    ("2", "expected I/N, the I-th of N slices of the sweep (e.g. 1/4), got '2'"),
    ("a/b", "expected I/N"),
])
def test_a_bad_shard_is_a_clear_error_before_any_work(text, message, tmp_path, capsys):
    with pytest.raises(ScenarioError, match="field '--shard'"):
        parse_shard(text)
    assert eval_(TINY, "--out", tmp_path, "--workers", "0", f"--shard={text}") == 2
    assert f"tg-drake eval: error: field '--shard': {message}" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_shards_partition_the_cases_by_object_set_deterministically_and_evenly():
    cases = load_cases([SUITES / "s_grasp.yaml", SUITES / "s_real.yaml"])
    n = 3
    slices = [shard(cases, i, n) for i in range(1, n + 1)]
    keys = [[c.key for c in s] for s in slices]
    assert sorted(k for s in keys for k in s) == sorted(c.key for c in cases)  # all, once each
    shuffled = random.Random(0).sample(cases, len(cases))
    assert [sorted(c.key for c in shard(shuffled, i, n)) for i in range(1, n + 1)] == \
        [sorted(s) for s in keys]  # a function of the cases, not of their order
    for s in slices:  # a shard keeps its cases in the sweep's order
        assert [c.key for c in s] == [c.key for c in cases if c in s]
    owner = {}
    for i, s in enumerate(slices):
        for c in s:  # each object set (of a kind) in one shard: its workers stay warm
            assert owner.setdefault((c.kind, object_set(c)), i) == i
    groups = {}
    for c in cases:
        groups[(c.kind, object_set(c))] = groups.get((c.kind, object_set(c)), 0) + 1
    sizes = [len(s) for s in slices]
    assert max(sizes) - min(sizes) <= max(groups.values())
    assert parse_shard(" 2 / 3 ") == (2, 3) and [c.key for c in shard(cases, 1, 1)] == \
        [c.key for c in cases]


def test_shards_run_apart_resume_and_merge_into_one_set_of_tables(tmp_path, capsys):
    out = tmp_path / "out"
    for i in (1, 2):
        assert eval_(TINY, "--out", out, "--workers", "0", "--shard", f"{i}/2") == 0
    err = capsys.readouterr().err
    assert "shard 1/2: 2 cases: 0 already done, 2 run now" in err  # the cup's two poses
    assert "shard 2/2: 1 cases: 0 already done, 1 run now" in err  # the hammer
    assert sorted(p.name for p in out.iterdir()) == ["results-1-of-2.jsonl",
                                                     "results-2-of-2.jsonl"]  # no tables yet
    assert eval_(TINY, "--out", out, "--workers", "0", "--shard", "1/2") == 0
    assert "shard 1/2: 2 cases: 2 already done, 0 run now" in capsys.readouterr().err

    assert eval_(TINY, "--out", out, "--tables-only") == 0
    captured = capsys.readouterr()
    assert "merged 2 results file(s): results-1-of-2.jsonl, results-2-of-2.jsonl" in captured.err
    assert "3 of 3 cases have records" in captured.out
    tables = json.loads((out / "tables.json").read_text())
    assert tables["category"]["syn"]["n"] == 3 and tables["task"]["syn"]["plm"]["E0"] == 100.0
    assert "--tables-only" not in tables["command"]

    # A case in two files (a shard run twice under other names): reported, counted once.
    extra = tmp_path / "copied.jsonl"
    extra.write_text((out / "results-2-of-2.jsonl").read_text())
    assert eval_(TINY, "--out", out, "--tables-only", "--merge", extra) == 0
    err = capsys.readouterr().err
    assert ("1 case(s) recorded in more than one file, one file's records kept (e.g. "
            "tiny/hammer_01_sideways_empty in results-2-of-2.jsonl and copied.jsonl)") in err
    assert json.loads((out / "tables.json").read_text())["category"]["syn"]["n"] == 3

    # A shard not yet copied in: its cases are missing, and said to be.
    shutil.move(out / "results-2-of-2.jsonl", tmp_path / "later.jsonl")
    assert eval_(TINY, "--out", out, "--tables-only") == 0
    captured = capsys.readouterr()
    assert "1 case(s) with no record in any file: tiny/hammer_01_sideways_empty" in captured.err
    assert "2 of 3 cases have records" in captured.out
    assert eval_(TINY, "--out", out, "--tables-only", "--shard", "1/2") == 2
    assert "--tables-only merges every shard's results: leave --shard out" in \
        capsys.readouterr().err
    assert eval_(TINY, "--out", out, "--tables-only", "--merge", tmp_path / "nope.jsonl") == 2
    assert f"{tmp_path / 'nope.jsonl'}, field '--merge': no such results file or folder" in \
        capsys.readouterr().err
