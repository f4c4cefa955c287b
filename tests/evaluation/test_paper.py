"""The paper's figures live in one table (tg_drake.evaluation.paper), each once, and what prints
them beside ours reads them from there."""

import json
import re
from pathlib import Path

import pytest

from tg_drake.evaluation import paper, tables

ROOT = Path(__file__).resolve().parents[2]
RECORDS = [json.loads(line) for line in
           (Path(__file__).parent / "small_results.jsonl").read_text().splitlines()]


def test_each_figure_is_given_once_with_its_source():
    keys = [f.key for f in paper.FIGURES]
    assert len(keys) == len(set(keys))
    sources = [f.source for f in paper.FIGURES]
    assert len(sources) == len(set(sources))  # one cell of one table (or passage) each
    assert all(f.source.startswith(("Table tab:", "VI-", "V-D")) for f in paper.FIGURES)
    assert all(f.unit in ("%", "ms", "") for f in paper.FIGURES)
    assert all(0 <= f.value <= 100 for f in paper.FIGURES if f.unit == "%")
    # The nested view holds exactly the list.
    leaves = []

    def walk(node, key=()):
        for k, v in node.items():
            walk(v, (*key, k)) if isinstance(v, dict) else leaves.append(((*key, k), v))

    walk(paper.PAPER)
    assert sorted(leaves) == sorted((f.key, f.value) for f in paper.FIGURES)


def test_some_cells_against_the_papers_tables():
    assert paper.figure("category", "syn", "plm") == 93.14
    assert paper.figure("category", "real_semi", "plm") == 49.21
    assert paper.figure("task", "real_noisy", "plm_uniform") == 38.10
    assert paper.figure("pregrasp", "grasp", "pipeline") == 75.51
    assert paper.figure("pipeline_vs_local", "robot", "pipeline", "0.4") == 42.86
    assert paper.figure("grasp_and_place", "4", "reachable") == 16
    assert paper.figure("category", "grasp", "plm") is None  # "–" in the paper


def test_a_figure_given_twice_is_refused():
    with pytest.raises(ValueError, match="twice"):
        paper._nested([paper.FIGURES[0], paper.FIGURES[0]])


def test_tables_md_reads_the_papers_column_from_the_table(monkeypatch):
    t = tables.compute(RECORDS)
    assert t["paper"] is paper.PAPER
    monkeypatch.setitem(paper.PAPER["category"]["syn"], "manifolds", 12.34)
    monkeypatch.setitem(paper.PAPER["pipeline_vs_local"]["grasp"]["local"], "0.5", 56.78)
    md = tables.markdown(t, command="tg-drake eval small")
    assert "| S_SYN analogue | **9.09** (9.10) | **50.00** (63.40) | **100.00** (12.34) |" in md
    assert "| lt 0.5 | **50.00** (56.78) |" in md


def test_no_other_module_keeps_its_own_paper_figures():
    """The five dicts of paper figures went into one: no module but paper.py assigns a PAPER
    name, and the figures printed by the tools come from it."""
    offenders = []
    for path in [*(ROOT / "tg_drake").rglob("*.py"), *(ROOT / "tools").glob("*.py")]:
        if path.name == "paper.py":
            continue
        if re.search(r"^\s*PAPER\w*\s*[:=]", path.read_text(), flags=re.M):
            offenders.append(str(path.relative_to(ROOT)))
    assert offenders == []
