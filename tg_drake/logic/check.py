"""A static check of the theory: body literals that can never hold.

ProbLog accepts `isa_task(T, passs)` or `part(hnadle, X)` and the rule never fires: a typo in a
constant reads as a rule that does not apply. `check_constants` finds, for every argument
position of every predicate, the constants it can take — from the clause heads (a constant, or a
variable bound by the body's literals), and for the observations that enter from Python
(tg_drake/logic/observations.py) from the shared vocabulary — by a fixpoint over the program, and
raises RuleError at the first body literal with a constant that nothing ever gives (file, line,
the literal, the constants allowed there and the closest). A position that a head leaves open
(a variable the body does not bind, a number, a compound term) takes anything: not checked.
"""

from __future__ import annotations

import difflib

from problog.logic import AnnotatedDisjunction, Clause, Constant, Not, Term, Var

from tg_drake.errors import RuleError
from tg_drake.logic.names import (
    CATEGORY_ATOMS,
    OBJECT,
    PART_ATOMS,
    POSE_ATOMS,
    TASK_ATOMS,
)

ANY = None  # a position that takes any constant

# The observation predicates (entered from Python as data) and the constants of each argument
# (ANY: the object); their own clauses in the theory, if any, add to these.
OBSERVED: dict[tuple[str, int], tuple] = {
    ("part", 2): (frozenset(PART_ATOMS), ANY),
    ("pose", 2): (ANY, frozenset(POSE_ATOMS)),
    ("cat", 2): (ANY, frozenset(CATEGORY_ATOMS)),
    ("task", 1): (frozenset(TASK_ATOMS.values()),),
    ("collision", 1): (frozenset(PART_ATOMS),),
    ("no_hold", 1): (frozenset(PART_ATOMS),),
    ("empty", 1): (ANY,),
    ("full", 1): (ANY,),
    ("handle_pair", 1): (ANY,),
    ("interior_seen", 1): (ANY,),
    ("interior_hidden", 1): (ANY,),
    ("task_given", 0): (),
}
# Literals that are ProbLog's or Prolog's own, not the theory's predicates.
BUILTINS = frozenset({"=", "\\=", "==", "\\==", "<", ">", "=<", ">=", "is", "=:=", "=\\=",
                      "true", "fail", "false", "call", "query", "evidence", "member", "findall",
                      "between", "length", "append", ","})


def _rules(clauses) -> list[tuple[Term, list[Term], list[Term], object]]:
    """(head, body literals, the positive ones, source) for every head of every clause."""
    out = []
    for source in clauses:
        term = source.term
        if isinstance(term, AnnotatedDisjunction):
            heads, body = list(term.heads), term.body
        elif isinstance(term, Clause):
            heads, body = [term.head], term.body
        else:
            heads, body = [term], None
        literals, binding = _literals(body), _literals(body, negated=False)
        out.extend((head, literals, binding, source) for head in heads)
    return out


def _literals(body, *, negated: bool = True) -> list[Term]:
    """The body's literals, conjunctions and disjunctions flattened; a negation as its atom (it
    must be able to hold for its negation to mean anything), or left out (`negated=False`: the
    literals that bind variables)."""
    if body is None:
        return []
    if isinstance(body, Not):
        return _literals(body.args[0]) if negated else []
    if isinstance(body, Term) and body.functor in (",", ";") and body.arity == 2:
        return (_literals(body.args[0], negated=negated)
                + _literals(body.args[1], negated=negated))
    return [body]


def _is_constant(t) -> bool:
    return isinstance(t, Term) and not isinstance(t, Var | Constant) and t.arity == 0


def _key(t: Term) -> tuple[str, int]:
    return (t.functor, t.arity)


def _positive(literals) -> list[Term]:
    return [t for t in literals if isinstance(t, Term) and _key(t)[0] not in BUILTINS]


def domains(clauses) -> dict[tuple[str, int], list]:
    """(predicate, arity) → per argument the set of constants it can take, or ANY."""
    rules = _rules(clauses)
    dom: dict[tuple[str, int], list] = {k: list(v) for k, v in OBSERVED.items()}
    for head, _, _, _ in rules:
        dom.setdefault(_key(head), [frozenset()] * head.arity)
    changed = True
    while changed:
        changed = False
        for head, _, binding, _ in rules:
            positive = _positive(binding)
            for i, arg in enumerate(head.args):
                value = _value(arg, positive, dom)
                old = dom[_key(head)][i]
                new = ANY if (old is ANY or value is ANY) else old | value
                if new != old:
                    dom[_key(head)][i] = new
                    changed = True
    return dom


def _value(arg, positive: list[Term], dom) -> frozenset | None:
    """The constants a head argument can take given the body's literals."""
    if _is_constant(arg):
        return frozenset({arg.functor})
    if not isinstance(arg, Var):
        return ANY  # a number or a compound term: not tracked
    bound = None  # the intersection of the positions the variable takes in the body
    for lit in positive:
        for j, a in enumerate(lit.args):
            if isinstance(a, Var) and a.name == arg.name:
                d = dom.get(_key(lit), [ANY] * lit.arity)[j]
                if d is ANY:
                    continue
                bound = d if bound is None else bound & d
    return ANY if bound is None else bound


def known_constants(clauses) -> frozenset[str]:
    """Every constant some clause head or observation can give a predicate: the theory's words."""
    words = set()
    for positions in domains(clauses).values():
        for d in positions:
            if d is not ANY:
                words |= d
    return frozenset(words)


def check_constants(clauses) -> None:
    """RuleError for the first body literal with a constant that no head or observation ever
    gives (a typo: the literal can never hold). A known word at a position it cannot take (a
    rule that does not fire for a reason the theory states) is left alone."""
    dom = domains(clauses)
    words = known_constants(clauses)
    for _, literals, _, source in _rules(clauses):
        for lit in literals:
            if not isinstance(lit, Term) or _key(lit)[0] in BUILTINS or _key(lit) not in dom:
                continue
            for j, a in enumerate(lit.args):
                allowed = dom[_key(lit)][j]
                if allowed is ANY or not _is_constant(a) or a.functor == OBJECT:
                    continue
                if a.functor not in allowed and a.functor not in words:
                    close = difflib.get_close_matches(a.functor, sorted(allowed), n=1)
                    hint = f"; did you mean {close[0]!r}?" if close else ""
                    raise RuleError(
                        f"{lit} can never hold: argument {j + 1} of {lit.functor}/{lit.arity} "
                        f"is one of {', '.join(sorted(allowed)) or 'nothing'}{hint}",
                        file=source.file, line=source.line)
