"""The theory's static check: a constant nothing ever gives (a typo) is an error naming the file,
the line and the closest word; the shipped variants pass it."""

from __future__ import annotations

import shutil

import pytest
from problog.program import PrologString

from tg_drake.errors import RuleError
from tg_drake.logic.check import check_constants, domains
from tg_drake.logic.theory import VARIANTS, TheoryConfig, load_theory, rules_dir


@pytest.mark.parametrize("variant", VARIANTS)
def test_the_shipped_theory_passes(variant):
    load_theory(TheoryConfig.named(variant))  # raises on a finding


class _Source:
    def __init__(self, term, line):
        self.term, self.file, self.line = term, "t.pl", line


def _clauses(text):
    return [_Source(t, k + 1) for k, t in enumerate(PrologString(text))]


def test_domains_follow_heads_and_the_variables_bodies_bind():
    d = domains(_clauses("leaf(a). leaf(b). up(a, top). isa(T, T) :- leaf(T). isa(a, c).\n"
                         "free(X, Y) :- leaf(X)."))
    assert d[("isa", 2)] == [frozenset("ab"), frozenset("abc")]
    assert d[("free", 2)] == [frozenset("ab"), None]  # Y is not bound: anything
    assert d[("part", 2)][0] >= {"handle", "usable_area"}  # an observation: the parts


@pytest.mark.parametrize("body, message", [
    ("isa(T, bb)", r"isa\(T,bb\) can never hold: argument 2 of isa/2 is one of a, b, c; did "
                   r"you mean 'b'\?"),
    ("part(hnadle, X)", r"argument 1 of part/2 is one of bottom, handle, .*did you mean "
                        r"'handle'\?"),
    ("\\+ pose(X, upsdiedown)", r"pose\(X,upsdiedown\) can never hold.*'upsidedown'"),
])
def test_a_typo_in_a_body_constant_is_named_with_its_line(body, message):
    text = f"leaf(a). leaf(b). isa(T, T) :- leaf(T). isa(a, c).\nr(X) :- leaf(X), {body}."
    with pytest.raises(RuleError, match=message) as e:
        check_constants(_clauses(text))
    assert e.value.line == 5  # the fifth clause


def test_a_known_word_where_it_cannot_hold_is_not_an_error():
    # c is a word of the theory (a head gives it to isa/2); a rule that asks leaf(c) just does
    # not fire, for reasons the theory states: not a typo.
    check_constants(_clauses("leaf(a). isa(a, c). r(X) :- leaf(c)."))


def test_a_typo_in_the_rules_folder_stops_the_load(tmp_path):
    rules = tmp_path / "rules"
    shutil.copytree(rules_dir(), rules)
    path = rules / "grasp_specific.pl"
    text = path.read_text()
    assert "isa_task(T, pass)" in text
    path.write_text(text.replace("isa_task(T, pass)", "isa_task(T, passs)", 1))
    line = text[:text.index("isa_task(T, pass)")].count("\n") + 1
    with pytest.raises(RuleError, match=r"did you mean 'pass'\?") as e:
        load_theory(TheoryConfig.named("specific"), rules)
    assert e.value.file.endswith("grasp_specific.pl") and e.value.line == line
