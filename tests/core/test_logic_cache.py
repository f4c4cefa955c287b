"""Compiled theories on disk (tg_drake.logic.cache): compiled once, loaded by the next process with
the same answers; another theory file's content, or a torn file, compiles again."""

import shutil

import pytest

from tg_drake.logic import engine
from tg_drake.logic.engine import CompiledTheory, LogicEngine
from tg_drake.logic.observations import Observations
from tg_drake.logic.theory import TheoryConfig, rules_dir

OBS = Observations(parts={"handle": 1.0, "middle": 1.0, "top": 1.0},
                   pose={"upright": 1.0}, containment={"empty": 1.0}, handles=1)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("TG_DRAKE_THEORY_CACHE", str(tmp_path / "theories"))
    engine._compiled.cache_clear()  # as in a new process
    yield tmp_path / "theories"
    engine._compiled.cache_clear()


def _no_compiling(monkeypatch):
    def refuse(self, *args, **kwargs):
        raise AssertionError("compiled again")
    monkeypatch.setattr(CompiledTheory, "__init__", refuse)


def test_a_compiled_theory_is_loaded_by_the_next_process_with_the_same_answers(cache,
                                                                            monkeypatch):
    first = LogicEngine(TheoryConfig()).query(OBS)
    assert len(list(cache.glob("*.pickle"))) == 1
    engine._compiled.cache_clear()
    with monkeypatch.context() as m:
        _no_compiling(m)
        again = LogicEngine(TheoryConfig()).query(OBS)
    assert again.category.tolist() == first.category.tolist()
    assert again.task.tolist() == first.task.tolist()


def test_another_theory_text_or_a_torn_file_compiles_again(cache, tmp_path, monkeypatch):
    rules = tmp_path / "rules"
    shutil.copytree(rules_dir(), rules)
    LogicEngine(TheoryConfig(), directory=rules).query(OBS)
    (path,) = cache.glob("*.pickle")
    path.write_bytes(path.read_bytes()[:100])  # torn: compiled again, replaced
    engine._compiled.cache_clear()
    assert LogicEngine(TheoryConfig(), directory=rules).query(OBS).evidence > 0
    assert path.stat().st_size > 1000
    with (rules / "queries.pl").open("a") as f:
        f.write("\n% an edit\n")
    engine._compiled.cache_clear()
    LogicEngine(TheoryConfig(), directory=rules).query(OBS)
    assert len(list(cache.glob("*.pickle"))) == 2  # the edited text has its own file


def test_the_cache_can_be_turned_off(cache, monkeypatch):
    monkeypatch.setenv("TG_DRAKE_THEORY_CACHE", "off")
    LogicEngine(TheoryConfig()).query(OBS)
    assert not cache.exists()
