"""The ProbLog theory: where its files are, which files make a variant, and how they load.

The theory lives in the repository's top-level ``rules/`` directory, one concern per file, each
opening with a ``%`` comment (rules/README.md). `rules_dir()` finds it at run time:

1. the directory named by the environment variable ``TG_DRAKE_RULES``, if set;
2. ``rules/`` next to the ``tg_drake`` package, i.e. the repository of an editable install or a
   source checkout;
3. ``tg_drake/rules/`` inside the package, where a packaged copy would go (pyproject ships
   ``tg_drake/rules/*``; the repository keeps the theory at the top, so a non-editable install
   needs a copy there or ``TG_DRAKE_RULES``).

A variant (`TheoryConfig`) picks the category model and the grasp model (paper IV-C: specific or
general) and whether outcomes are mutually exclusive.

`load_theory` parses the files with ProbLog's own parser and keeps where each clause came from.
`compile_clauses` rewrites them for the compiled path: every annotated disjunction (and every
probabilistic rule) becomes a chain of independent probabilistic facts, so that each variable of
the compiled circuit is an independent fact, and every rule of a reasoning file gets a switch fact
so that an explanation can take the rule out (tg_drake/logic/engine.py). `plain_clauses` gives
the theory unchanged, for the reference path.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from problog.errors import ProbLogError
from problog.logic import And, AnnotatedDisjunction, Clause, Constant, Not, Term, Var, list2term
from problog.program import PrologFile

from tg_drake.errors import RuleError, unknown_name
from tg_drake.logic.check import check_constants
from tg_drake.types import THEORY_VARIANTS as VARIANTS

# Files of every variant, in load order; {category} and {grasp} are the variant names.
THEORY_FILES: tuple[str, ...] = (
    "object_ontology.pl",
    "task_ontology.pl",
    "observations.pl",
    "affordances.pl",
    "category_spread.pl",
    "category_{category}.pl",
    "grasp_{grasp}.pl",
    "constraints.pl",
    "queries.pl",
)

# Files whose rules are reasons an explanation may name. Ontologies, the observation vocabulary
# and the query atoms are definitions: taking one out breaks every answer at once and says nothing.
EXPLAINING_FILES: frozenset[str] = frozenset({
    "affordances.pl", "category_spread.pl", "category_specific.pl", "category_general.pl",
    "grasp_specific.pl", "grasp_general.pl", "constraints.pl", "category_learned.pl",
    "grasp_learned.pl",
})

RULES_ENV = "TG_DRAKE_RULES"


@dataclass(frozen=True)
class TheoryConfig:
    """Which theory to query, and how to normalise (paper IV-C and VI)."""

    category: str = "specific"  # category model: "specific" or "general" (PLM vs PLM^general).
    grasp: str = "specific"  # task-dependent grasp model: "specific" or "general".
    exclusive: bool = True
    # True: an object has exactly one category and one part is grasped (the paper's mutual
    # exclusiveness); False: marginals normalised over the outcomes.

    def __post_init__(self):
        for name in ("category", "grasp"):
            if getattr(self, name) not in VARIANTS:
                raise unknown_name(f"{name} model variant", getattr(self, name), VARIANTS,
                                   error=RuleError, field=name)

    @classmethod
    def named(cls, theory: str, *, exclusive: bool = True) -> TheoryConfig:
        """Both models of one variant: "specific" or "general"."""
        if theory not in VARIANTS:
            raise unknown_name("theory", theory, VARIANTS, error=RuleError, field="theory")
        return cls(category=theory, grasp=theory, exclusive=exclusive)


def rules_dir() -> Path:
    """The directory holding the theory files (see the module docstring for the search order)."""
    searched = []
    env = os.environ.get(RULES_ENV)
    if env:
        path = Path(env)
        if (path / "queries.pl").is_file():
            return path
        raise RuleError(f"{RULES_ENV}={env} holds no theory (queries.pl missing)", file=env)
    package = Path(__file__).resolve().parent.parent
    for candidate in (package.parent / "rules", package / "rules"):
        searched.append(str(candidate))
        if (candidate / "queries.pl").is_file():
            return candidate
    raise RuleError("cannot find the ProbLog theory; searched " + ", ".join(searched)
                    + f"; set {RULES_ENV} to the rules/ directory")


@dataclass(frozen=True)
class SourceClause:
    """One clause of the theory and where it was written."""

    term: Term  # as parsed: a fact, a Clause, or an AnnotatedDisjunction.
    file: str  # file name inside rules/.
    line: int
    text: str  # the clause as written (whitespace collapsed).
    explains: bool  # whether an explanation may name it (EXPLAINING_FILES).

    @property
    def where(self) -> str:
        return f"{self.file}:{self.line}"


def theory_paths(config: TheoryConfig, directory: Path | None = None) -> list[Path]:
    directory = rules_dir() if directory is None else Path(directory)
    return [directory / name.format(category=config.category, grasp=config.grasp)
            for name in THEORY_FILES]


def load_theory(config: TheoryConfig, directory: Path | None = None) -> list[SourceClause]:
    """Parses the variant's files; a missing or malformed file, or a body literal with a
    constant nothing ever gives (a typo: tg_drake.logic.check), raises RuleError naming it."""
    clauses = []
    for path in theory_paths(config, directory):
        clauses.extend(_load_file(path))
    check_constants(clauses)
    return clauses


def _load_file(path: Path) -> list[SourceClause]:
    try:
        text = path.read_text()
    except OSError as e:
        raise RuleError(f"cannot read theory file: {e.strerror}", file=str(path)) from None
    first = next((line for line in text.splitlines() if line.strip()), "")
    if not first.startswith("%"):
        raise RuleError("a theory file opens with a % comment saying what it holds",
                        file=str(path), line=1)
    try:
        parsed = list(PrologFile(str(path)))
    except ProbLogError as e:
        location = getattr(e, "location", None)
        line = location[1] if isinstance(location, tuple) and len(location) == 3 else None
        raise RuleError(f"cannot parse: {getattr(e, 'base_message', e)}", file=str(path),
                        line=line) from None
    # Clause boundaries: a '.' followed by white space ends a clause ('0.25' does not).
    ends = [m.end() for m in re.finditer(r"\.(?=\s|$)", _blank_comments(text))]
    out = []
    for term in parsed:
        offset = term.location[1] if isinstance(term.location, tuple) else 0
        start = max((e for e in ends if e <= offset), default=0)
        end = min((e for e in ends if e > offset), default=len(text))
        written_start = start + len(text[start:end]) - len(text[start:end].lstrip())
        body = _blank_comments(text)[written_start:end]
        skip = len(body) - len(body.lstrip())
        line = text.count("\n", 0, written_start + skip) + 1
        written = " ".join(body.split())
        out.append(SourceClause(term, path.name, line, written, path.name in EXPLAINING_FILES))
    return out


def _blank_comments(text: str) -> str:
    """The text with every % comment replaced by spaces (offsets kept)."""
    return re.sub(r"%[^\n]*", lambda m: " " * len(m.group(0)), text)


def plain_clauses(clauses: list[SourceClause]) -> list[Term]:
    """The theory as written, for plain ProbLog."""
    return [c.term for c in clauses]


@dataclass(frozen=True)
class Choice:
    """A fact of a chain that encodes one annotated disjunction of the theory."""

    clause: int  # index of the clause in the loaded theory.
    head: int  # index of the head in the disjunction.
    weight: float  # its conditional weight q = p_i / (1 - p_1 - ... - p_{i-1}).


def compile_clauses(clauses: list[SourceClause]) -> tuple[list[Term], dict[tuple[int, int], Choice],
                                                          dict[int, int]]:
    """Rewrites the theory so that every probabilistic choice is an independent fact.

    Returns the clauses, the choice facts by (clause, head), and for each deterministic rule of
    a reasoning file (by clause index) its switch. A probabilistic head H_i of clause k with
    variables V becomes ``H_i :- Body, \\+ad_choice(k, 0, V), ..., ad_choice(k, i, V)`` with
    ``q_i::ad_choice(k, i, V)``: one independent choice per grounding of the clause, as in
    ProbLog's semantics of annotated disjunctions (setting a clause's choice weights to 0 takes
    it out). A deterministic rule of a reasoning file becomes ``H :- Body, rule_on(k)``, with
    the switch weighted 1 (0 takes it out). Facts stay as they are.
    """
    out: list[Term] = []
    choices: dict[tuple[int, int], Choice] = {}
    switches: dict[int, int] = {}
    for k, source in enumerate(clauses):
        term = source.term
        if isinstance(term, AnnotatedDisjunction):
            heads, body = list(term.heads), term.body
        elif isinstance(term, Clause) and term.head.probability is not None:
            heads, body = [term.head], term.body
        elif isinstance(term, Clause):
            heads, body = None, term.body
        elif term.probability is not None:  # a probabilistic fact: already independent.
            out.append(term)
            continue
        else:
            out.append(term)
            continue
        switch = []
        if source.explains and heads is None:
            switches[k] = k
            switch = [Term("rule_on", Constant(k))]
            out.append(Term("rule_on", Constant(k)).with_probability(Constant(0.5)))
        if heads is None:
            out.append(Clause(term.head, And.from_list(_literals(body) + switch)))
            continue
        names = sorted({str(v) for t in heads + ([body] if body is not None else [])
                        for v in t.variables()})
        variables = _list_term([_var(n) for n in names])
        p = [_probability(h, source) for h in heads]
        if sum(p) > 1.0 + 1e-9:
            raise RuleError(f"the probabilities of an annotated disjunction sum to {sum(p):.6g} "
                            "> 1", file=source.file, line=source.line)
        rest = 1.0
        previous: list[Term] = []
        for i, (head, pi) in enumerate(zip(heads, p, strict=False)):
            q = min(1.0, pi / rest) if rest > 1e-15 else 0.0
            fact = Term("ad_choice", Constant(k), Constant(i), variables)
            choices[(k, i)] = Choice(k, i, q)
            out.append(fact.with_probability(Constant(0.5)))
            out.append(Clause(head.with_probability(None),
                              And.from_list(_literals(body) + switch + previous + [fact])))
            previous = previous + [Not("\\+", fact)]
            rest -= pi
    return out, choices, switches


def _probability(head: Term, source: SourceClause) -> float:
    try:
        p = float(head.probability.compute_value())
    except Exception:  # noqa: BLE001 - any failure here is a malformed probability
        raise RuleError(f"probability of {head.with_probability(None)} is not a number",
                        file=source.file, line=source.line) from None
    if not 0.0 <= p <= 1.0:
        raise RuleError(f"probability {p} of {head.with_probability(None)} is outside [0, 1]",
                        file=source.file, line=source.line)
    return p


def _literals(body: Term) -> list[Term]:
    if body is None or body == Term("true"):
        return []
    if isinstance(body, And):
        return _literals(body.op1) + _literals(body.op2)
    return [body]


def _var(name: str):
    return Var(name)


def _list_term(items: list) -> Term:
    return list2term(items)
