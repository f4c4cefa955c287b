"""`tg-drake query`: the logic module from the command line."""

from __future__ import annotations

import io
import json
import sys

import pytest

from tg_drake.cli import main
from tg_drake.logic.theory import rules_dir

EXAMPLES = rules_dir() / "examples"


def test_query_prints_the_three_distributions_as_json(capsys):
    assert main(["query", str(EXAMPLES / "fig1_cup_pass.yaml"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert max(out["category"], key=out["category"].get) == "cup"
    assert out["task"] == {"pass": 1.0}
    assert max(out["part"], key=out["part"].get) == "middle"
    assert sum(out["part"].values()) == pytest.approx(1.0, abs=1e-9)  # float rounding.
    assert out["explanations"]["part"][0]["answer"] == "middle"
    assert out["theory"]["category"] == "specific"


def test_query_text_with_the_general_theory(capsys):
    assert main(["query", str(EXAMPLES / "hammer_pass_blocked.yaml"), "--theory", "general"]) == 0
    out = capsys.readouterr().out
    assert "theory: general" in out
    assert "1.000  handle" in out  # the usable area collides; the handle is left.


def test_query_uniform_drops_the_prior(capsys):
    assert main(["query", str(EXAMPLES / "fig1_cup.yaml"), "--json", "--uniform",
                 "--no-explain"]) == 0
    out = json.loads(capsys.readouterr().out)
    # Without the prior the cup/pan rule alone decides: 0.75 / 0.25 (the other categories are
    # ruled out by the handle), up to the uniform prior's own cup and pan mass.
    assert out["category"]["cup"] > out["category"]["pan"] > 0
    assert out["explanations"] == {}


def test_malformed_observations_file_is_a_clear_error(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("parts: {top: 1.0}\ntask: pour\n")
    assert main(["query", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.yaml" in err and "field 'task'" in err and "unknown task 'pour'" in err


def test_bench_figure_is_registered():
    import importlib

    from tg_drake.bench import FIGURES

    module, function = FIGURES["logic_scene_ms"].split(":")
    assert callable(getattr(importlib.import_module(module), function))



def test_a_reader_that_goes_away_stops_the_command_quietly(monkeypatch):
    # `tg-drake query … | head -1`: writing to the closed pipe raises BrokenPipeError.
    class ClosedPipe(io.StringIO):
        def write(self, text):
            raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(sys, "stdout", ClosedPipe())
    assert main(["query", str(EXAMPLES / "glass_seen_inside.yaml")]) == 141
