"""Learning the theory's probabilities from executed grasps (issue 9; the paper's future work).

The hand-written causal probabilities of the grasp model (rules/grasp_*.pl) and of the category
model (rules/category_*.pl) are fitted to data with ProbLog's learning from interpretations
(`problog.learning.lfi`, EM), starting from the hand-written values. This module is the pure core:
records in, interpretations, fit, learned theory text out; no Drake.

**What is tunable.** Every clause of the model's file that carries a probability: in the grasp
model each ``P::grasp(X, T, Part) :- ...`` rule (one CP-event per super-category, task,
condition and part); in the category model each annotated disjunction from parts and pose to
categories. Deterministic rules (``cat(X, pot) :- tmb(X), two_handles(X).``, the
``incompatible/1`` signatures), the ontologies, affordances, the spread over sub-categories and
the constraints are definitions and stay fixed.

**Grasp interpretations.** An executed record is one grasp of a chosen part of an object whose
category, pose, containment and parts are known (ground-truth perception). For every task the
scene affords (`afforded_tasks`), the grasp served the task when the object was held through lift
and place AND the part is one the task allows (`allowed_parts`). Each grasp that served a task
becomes one interpretation: the scene's observations (``part/2``, ``pose/2``, ``empty/1`` or
``full/1``, ``cat/2`` of the true category, ``handle_pair/1``) and "the part grasped for the task
is this one and no other" (``grasp(o, T, Part)`` true, ``grasp(o, T, Other)`` false for every other
part). That is the event the theory's part query asks about (rules/queries.pl, exclusive mode), so
a learned probability is how often the part was among the ones that served the task where its
rule applies; parts that were tried and failed count against themselves through the other parts'
interpretations. A scene and task where no part served gives no interpretation.

**The parts a task allows** (`allowed_parts`) is our written-down knowledge of what each task
needs, not the theory's answer (which would make the learning circular):

- Rest: the part the object stands on when the task puts it down must stay free. The task's final
  pose is upright for p&pInUpright, upside down for p&pInUpsidedown, sideways for p&pInSideways and
  the current pose for p&pOn; upright rests on the bottom, upside down on the top (rim), sideways on
  its side (no part excluded).
- Shelf: p&pIn puts the object into a cupboard or box; a shelf or lid above leaves no room for
  fingers over the object, so the part that is then uppermost is not held (upright: top; upside
  down: bottom).
- Opening: a full open container (cup, glass, bowl, pan, pot) is never held at its top: fingers at
  the opening spill or dip into the contents.
- Pouring: pourOut and pourIn need the opening free (no top); pourOut turns the object about the
  grip, which a grip at the base cannot do with a full body above it (no bottom).
- Passing: the receiver takes what the robot leaves free; an object with exactly one handle (a
  cup, a pan, every tool) is handed over with the handle free, so the robot does not hold it (a
  pot has two handles: one each).

Only tasks the scene affords get interpretations: the non-zero entries of the affordance table
(rules/README.md, table 3), which the fit does not change.

**Category interpretations.** One per object and pose of the training objects: the labelled parts,
the pose, the handle count, and ``cat(o, C)`` true for the library category and false for every
other; no category prior (the kernel prior is a separate input), so the fit sees the category
model alone.

**Annotated disjunctions.** ProbLog 2.3's LFI divides the learned weights of an annotated
disjunction with a body by its number of heads (a two-head disjunction seen 5 times in 10 learns
0.25). We therefore fit a disjunction as the chain of independent choices it stands for (the same
encoding the compiled engine uses, tg_drake/logic/theory.py): head i holds when choice i does and
choices 1..i-1 do not, q_i = p_i / (1 - p_1 - ... - p_{i-1}); the learned q become p again.

**Bad input** raises `RuleError`: no interpretations, an evidence atom whose predicate the
theory does not define or whose constant it never names, an unknown category, pose, task or
part in a record, inconsistent evidence.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from problog import get_evaluatable
from problog.errors import InconsistentEvidenceError
from problog.learning.lfi import LFIProblem
from problog.logic import And, AnnotatedDisjunction, Clause, Constant, Not, Term, Var
from problog.program import SimpleProgram

from tg_drake.errors import RuleError, unknown_name
from tg_drake.logic.names import OBJECT, TASK_ATOMS
from tg_drake.logic.observations import observation_schema
from tg_drake.logic.theory import SourceClause, _load_file, rules_dir
from tg_drake.types import CATEGORIES, CONTAINMENTS, PART_LABELS, POSES, TASKS

MODELS: tuple[str, ...] = ("grasp", "category")

# Theory files each fit loads (the model's own file is added, {variant} its variant).
_BASE_FILES = {
    "grasp": ("object_ontology.pl", "task_ontology.pl", "observations.pl", "affordances.pl"),
    "category": ("object_ontology.pl", "observations.pl", "category_spread.pl"),
}

KIND = {"pan": "kitchen_container", "pot": "kitchen_container", "cup": "dish", "glass": "dish",
        "bowl": "dish", "bottle": "canister", "can": "canister", "hammer": "tool",
        "knife": "tool", "screwdriver": "tool", "cooking_tool": "tool"}
OPEN = frozenset({"pan", "pot", "cup", "glass", "bowl"})  # open on top: contents spill.
ONE_HANDLE = frozenset({"cup", "pan", "hammer", "knife", "screwdriver", "cooking_tool"})
_FINAL_POSE = {"p&pInUpright": "upright", "p&pInUpsidedown": "upsidedown",
               "p&pInSideways": "sideways"}


# ---- what the data say ---------------------------------------------------------------------------

def afforded_tasks(category: str, containment: str) -> tuple[str, ...]:
    """Tasks with a non-zero entry in the affordance table (rules/README.md, table 3)."""
    _check(category, CATEGORIES, "category")
    _check(containment, CONTAINMENTS, "containment")
    kind, full = KIND[category], containment == "full"
    out = ["pass"] if not (category == "pan" and full) else []
    if kind == "tool":
        return tuple(out + ["p&pInSideways", "p&pOn"])
    if full and kind != "kitchen_container":
        out.append("pourOut")
    if not full and kind != "canister":
        out.append("pourIn")
    out.append("p&pInUpright")
    if not full:
        out.append("p&pInUpsidedown")
    if kind == "canister":
        out.append("p&pInSideways")
    out.append("p&pOn")
    return tuple(t for t in TASKS if t in out)


def allowed_parts(category: str, pose: str, containment: str, task: str) -> frozenset[str]:
    """The parts whose grasp can serve `task` (module docstring: rest, shelf, opening, pouring,
    passing). Empty for a task the scene does not afford."""
    _check(pose, POSES, "pose")
    _check(task, TASKS, "task")
    if task not in afforded_tasks(category, containment):
        return frozenset()
    parts = {"handle", "usable_area"} if KIND[category] == "tool" else set(PART_LABELS) - {
        "usable_area"}
    final = _FINAL_POSE.get(task, pose if task == "p&pOn" else None)
    if final == "upright":  # rest
        parts.discard("bottom")
    elif final == "upsidedown":
        parts.discard("top")
    if task in ("p&pInUpright", "p&pInUpsidedown"):  # shelf
        parts.discard("top" if final == "upright" else "bottom")
    if category in OPEN and containment == "full":  # opening
        parts.discard("top")
    if task in ("pourOut", "pourIn"):  # pouring
        parts.discard("top")
        if task == "pourOut":
            parts.discard("bottom")
    if task == "pass" and category in ONE_HANDLE:  # passing
        parts.discard("handle")
    return frozenset(parts)


@dataclass(frozen=True)
class GraspRecord:
    """One executed grasp: the scene, the part grasped, and whether it was held through lift and
    place (the pipeline's outcome "placed")."""

    scene: str  # what groups the grasps of one object in one pose and containment.
    category: str
    pose: str
    containment: str
    parts: tuple[str, ...]  # the object's parts (observed with certainty).
    part: str  # the part grasped.
    held: bool  # held through lift and place.
    handles: int = 1  # 2 for a pair of opposite handles (a pot).

    def __post_init__(self):
        _check(self.category, CATEGORIES, "category")
        _check(self.pose, POSES, "pose")
        _check(self.containment, CONTAINMENTS, "containment")
        for p in (*self.parts, self.part):
            _check(p, PART_LABELS, "part")
        if self.part not in self.parts:
            raise RuleError(f"the grasped part {self.part!r} is not among the object's parts "
                            f"{list(self.parts)}", field=f"{self.scene}.part")

    def served(self, task: str) -> bool:
        return self.held and self.part in allowed_parts(self.category, self.pose,
                                                        self.containment, task)


Evidence = tuple[tuple[Term, bool], ...]


@dataclass(frozen=True)
class Interpretation:
    """A partial interpretation: atoms known true or false; `source` says where it came from."""

    evidence: Evidence
    source: str = ""


def scene_evidence(*, parts: Iterable[str], pose: str, containment: str | None,
                   category: str | None, handles: int = 1) -> list[tuple[Term, bool]]:
    """The observations of one object as evidence on the observation atoms of the schema."""
    o = Term(OBJECT)
    parts = set(parts)
    ev = [(Term("part", Term(p), o), p in parts) for p in PART_LABELS]
    ev += [(Term("pose", o, Term(p)), p == pose) for p in POSES]
    if containment is not None:
        ev += [(Term(c, o), c == containment) for c in CONTAINMENTS]
    if category is not None:
        ev += [(Term("cat", o, Term(c)), c == category) for c in CATEGORIES]
    ev.append((Term("handle_pair", o), handles == 2))
    ev += [(Term("collision", Term(p)), False) for p in PART_LABELS]
    ev += [(Term("no_hold", Term(p)), False) for p in PART_LABELS]
    return ev


def grasp_interpretations(records: Sequence[GraspRecord]) -> list[Interpretation]:
    """One interpretation per executed grasp and afforded task it served (module docstring)."""
    out = []
    o = Term(OBJECT)
    for r in records:
        base = scene_evidence(parts=r.parts, pose=r.pose, containment=r.containment,
                              category=r.category, handles=r.handles)
        for task in afforded_tasks(r.category, r.containment):
            if not r.served(task):
                continue
            t = Term(TASK_ATOMS[task])
            grasp = [(Term("grasp", o, t, Term(p)), p == r.part) for p in PART_LABELS]
            given = [(Term("task_given"), True)]  # the grasp served this task, named for it.
            out.append(Interpretation(tuple(base + given + grasp),
                                      f"{r.scene}:{r.part}:{task}"))
    return out


def category_interpretation(*, category: str, parts: Iterable[str], pose: str, handles: int = 1,
                            source: str = "") -> Interpretation:
    """A labelled object in a pose: its parts, pose and handles, and its category."""
    _check(category, CATEGORIES, "category")
    _check(pose, POSES, "pose")
    ev = scene_evidence(parts=parts, pose=pose, containment=None, category=category,
                        handles=handles)
    return Interpretation(tuple(ev), source or f"{category}:{pose}")


def success_table(records: Sequence[GraspRecord]) -> dict:
    """Counts for the data summary: per category, task and part, [served, tried]."""
    table: dict = {}
    for r in records:
        for task in afforded_tasks(r.category, r.containment):
            cell = table.setdefault(r.category, {}).setdefault(task, {}).setdefault(r.part, [0, 0])
            cell[0] += int(r.served(task))
            cell[1] += 1
    return table


# ---- the fit -------------------------------------------------------------------------------------

@dataclass
class LearnedClause:
    """A tunable clause: where it is written, its probabilities before and after the fit."""

    file: str
    line: int
    text: str
    before: list[float]
    after: list[float]
    n_evidence: int = 0  # interpretations in which its body held (0: kept as written).


@dataclass
class FitResult:
    model: str  # "grasp" or "category"
    variant: str  # the hand-written variant it started from ("specific" or "general")
    clauses: list[LearnedClause]
    log_likelihood: float
    iterations: int
    n_interpretations: int
    dropped: list[str] = field(default_factory=list)
    # interpretations left out: a served grasp the theory has no rule for (the structure, not
    # the probabilities, would have to change).

    @property
    def changed(self) -> list[LearnedClause]:
        return [c for c in self.clauses if c.n_evidence > 0]


def model_file(model: str, variant: str) -> str:
    if model not in MODELS:
        raise unknown_name("model", model, MODELS, error=RuleError, field="model")
    return f"{model}_{variant}.pl"


def tunable(clause: SourceClause) -> bool:
    term = clause.term
    return isinstance(term, AnnotatedDisjunction) or (
        isinstance(term, Clause) and term.head.probability is not None) or (
        not isinstance(term, Clause) and term.probability is not None)


def _heads(term: Term) -> list[Term]:
    if isinstance(term, AnnotatedDisjunction):
        return list(term.heads)
    if isinstance(term, Clause):
        return [term.head]
    return [term]


def _body(term: Term):
    return term.body if isinstance(term, AnnotatedDisjunction | Clause) else None


def _probabilities(clause: SourceClause) -> list[float]:
    return [float(h.probability.compute_value()) for h in _heads(clause.term)]


def _program(model: str, variant: str, directory: Path | None):
    """The LFI program: fixed files, the model's file with its tunable clauses as chains of
    ``t(q)`` choices, and the observation schema. Returns (clauses, tunable source clauses,
    the choice atoms' functors per tunable clause)."""
    directory = rules_dir() if directory is None else Path(directory)
    fixed: list[Term] = []
    for name in _BASE_FILES[model]:
        fixed += [c.term for c in _load(directory / name)]
    model_clauses = _load(directory / model_file(model, variant))
    program, tunables, functors = list(fixed), [], []
    for k, source in enumerate(model_clauses):
        if not tunable(source):
            program.append(source.term)
            continue
        heads, body = _heads(source.term), _body(source.term)
        names = sorted({str(v) for t in heads + ([body] if body is not None else [])
                        for v in t.variables()})
        variables = [Var(n) for n in names]
        p = _probabilities(source)
        q = _stick(p)
        chain, previous = [], []
        for i, (head, qi) in enumerate(zip(heads, q, strict=False)):
            choice = Term(f"lfi_{k}_{i}", *variables)
            chain.append(choice.functor)
            weight = Term("t", Constant(_inside(qi)))
            if body is None:
                program.append(choice.with_probability(weight))
            else:
                program.append(Clause(choice.with_probability(weight), body))
            literals = previous + [choice]
            program.append(Clause(head.with_probability(None), _and(literals)))
            previous = previous + [Not("\\+", choice)]
        tunables.append(source)
        functors.append(chain)
    schema, _ = observation_schema()
    if model == "category":  # no category prior: the category model alone.
        schema = [c for c in schema if _head_functor(c) not in ("cat", "obs_prior")]
    program += schema
    return program, tunables, functors


def _inside(q: float) -> float:
    """LFI keeps a weight of exactly 0 or 1 there (its expected counts are 0/0); start inside."""
    return min(max(q, 1e-3), 1.0 - 1e-3)


def _stick(p: list[float]) -> list[float]:
    out, rest = [], 1.0
    for pi in p:
        out.append(min(1.0, pi / rest) if rest > 1e-12 else 0.0)
        rest -= pi
    return out


def _unstick(q: list[float]) -> list[float]:
    out, rest = [], 1.0
    for qi in q:
        out.append(rest * qi)
        rest *= 1.0 - qi
    return out


def _and(literals: list[Term]) -> Term:
    return And.from_list(literals)


def _head_functor(clause: Term) -> str:
    head = _heads(clause)[0] if isinstance(clause, AnnotatedDisjunction | Clause) else clause
    return head.functor


def _load(path: Path) -> list[SourceClause]:
    return _load_file(path)


def _constants(terms: Iterable[Term]) -> set[str]:
    out: set[str] = set()
    stack = list(terms)
    while stack:
        t = stack.pop()
        if isinstance(t, Var) or t is None:
            continue
        if isinstance(t, AnnotatedDisjunction):
            stack += list(t.heads) + [t.body]
            continue
        if isinstance(t, Clause):
            stack += [t.head, t.body]
            continue
        if isinstance(t, Term):
            if not t.args:
                out.add(str(t.functor))
            stack += list(t.args)
    return out


def check_interpretations(interpretations: Sequence[Interpretation], program: list[Term]) -> None:
    """RuleError for no interpretations, or one naming a predicate or constant the theory lacks."""
    if not interpretations:
        raise RuleError("no interpretations to learn from: no executed grasp served a task "
                        "(or no records were given)")
    defined = set()
    for c in program:
        for h in _heads(c) if isinstance(c, AnnotatedDisjunction | Clause) else [c]:
            defined.add(h.signature)
    constants = _constants(program)
    for interp in interpretations:
        if not interp.evidence:
            raise RuleError("an interpretation holds no evidence", field=interp.source or None)
        for atom, value in interp.evidence:
            if not isinstance(atom, Term) or not isinstance(value, bool):
                raise RuleError(f"evidence is (atom, True|False), got ({atom!r}, {value!r})",
                                field=interp.source or None)
            if atom.signature not in defined:
                raise RuleError(f"the interpretation names {atom}, but the theory defines no "
                                f"predicate {atom.signature}", field=interp.source or None)
            unknown = _constants([atom]) - constants - {atom.functor}
            if unknown:
                raise RuleError(f"the interpretation names {atom}, but the theory never "
                                f"mentions {', '.join(sorted(unknown))}",
                                field=interp.source or None)


def fit(interpretations: Sequence[Interpretation], *, model: str = "grasp",
        variant: str = "specific", directory: Path | None = None, max_iter: int = 50,
        min_improvement: float = 1e-6, prior_strength: float = 0.0) -> FitResult:
    """Fits the tunable probabilities of `model` ("grasp" or "category") of the hand-written
    `variant` to the interpretations by ProbLog's LFI (EM), starting from the written values.

    EM is deterministic: the same interpretations in the same order give the same numbers.
    `prior_strength` m > 0 turns the estimate into a MAP one with a Beta (one head) or Dirichlet
    (an annotated disjunction) prior centred on the hand-written value p0 and worth m
    interpretations: p = (n·p_LFI + m·p0) / (n + m), n the interpretations in which the clause's
    body held. It keeps a probability of a clause with little data near its written value and
    away from exactly 0 or 1 (with the theory's independent grasp rules, two parts at 1 would
    make "exactly one part is grasped" impossible). 0 gives the plain maximum likelihood.
    Interpretations whose evidence the theory makes impossible (a served grasp it has no rule
    for in that scene) are dropped and listed (`FitResult.dropped`).
    """
    if prior_strength < 0:
        raise RuleError(f"prior_strength must be >= 0, got {prior_strength}",
                        field="prior_strength")
    if variant not in ("specific", "general"):
        raise unknown_name("variant", variant, ("specific", "general"), error=RuleError,
                           field="variant")
    model_file(model, variant)  # an unknown model is a RuleError.
    program, tunables, functors = _program(model, variant, directory)
    check_interpretations(interpretations, program)
    kept, dropped, counts = _analyse(interpretations, tunables, program)
    if not kept:
        raise RuleError("no interpretation is consistent with the theory's structure; "
                        f"dropped: {', '.join(dropped[:5])}")
    source = SimpleProgram()
    for clause in program:
        source.add_clause(clause)
    examples = [list(i.evidence) for i in kept]
    try:
        lfi = LFIProblem(source, examples, max_iter=max_iter, min_improv=min_improvement)
        log_likelihood = float(lfi.run())
    except InconsistentEvidenceError as e:
        raise RuleError(f"inconsistent evidence in the interpretations: {e}") from None
    learned = {str(name.functor): _weight(w)
               for name, w in zip(lfi.names, lfi._weights, strict=False)}
    clauses = []
    for source_clause, chain, n in zip(tunables, functors, counts, strict=False):
        before = _probabilities(source_clause)
        if n == 0:
            after = before
        else:
            mle = _unstick([learned.get(f, q) for f, q in zip(chain, _stick(before), strict=False)])
            after = [(n * a + prior_strength * b) / (n + prior_strength)
                     for a, b in zip(mle, before, strict=False)]
        clauses.append(LearnedClause(source_clause.file, source_clause.line, source_clause.text,
                                     before, _rounded(after), n))
    return FitResult(model, variant, clauses, log_likelihood, int(lfi.iteration), len(kept),
                     dropped)


def _rounded(p: list[float], digits: int = 4) -> list[float]:
    """Rounded for the file, the heads of a disjunction still summing to at most 1."""
    out = [round(x, digits) for x in p]
    excess = round(sum(out) - 1.0, digits)
    if excess > 0:
        i = max(range(len(out)), key=out.__getitem__)
        out[i] = round(out[i] - excess, digits)
    return out


def _weight(w) -> float:
    if isinstance(w, dict):  # {t(...): value} for non-ground tunable atoms: one shared value.
        values = list(w.values())
        return float(values[0]) if values else 0.0
    return float(w)


def _strip_tunable(clause: Term) -> Term:
    """The clause with a t(q) weight replaced by q (plain ProbLog cannot ground t/1)."""
    def fix(head: Term) -> Term:
        p = head.probability
        if isinstance(p, Term) and p.functor == "t":
            return head.with_probability(p.args[0])
        return head
    if isinstance(clause, Clause):
        return Clause(fix(clause.head), clause.body)
    return fix(clause)


def _analyse(interpretations, tunables, program) -> tuple[list, list[str], list[int]]:
    """Per distinct evidence, with plain ProbLog and the hand-written weights: whether the
    evidence is possible at all (else the interpretation is dropped: a served grasp the theory
    has no rule for in that scene), and for each tunable clause whether some grounding of its
    body holds for certain (then its probability is data-driven; the count is reported)."""
    counts = [0] * len(tunables)
    bodies = [_body(t.term) for t in tunables]
    groups: dict = {}
    for interp in interpretations:
        groups.setdefault(interp.evidence, []).append(interp)
    base = [_strip_tunable(c) for c in program]
    kept, dropped = [], []
    for evidence, members in groups.items():
        p = SimpleProgram()
        for clause in base:
            p.add_clause(clause)
        queries = []
        for k, body in enumerate(bodies):
            if body is not None:
                q = Term(f"lfi_body_{k}")
                p.add_clause(Clause(q, body))
                p.add_clause(Term("query", q))
                queries.append((k, q))
        for atom, value in evidence:
            p.add_clause(Term("evidence", atom, Term("true" if value else "false")))
        try:
            result = get_evaluatable("sdd").create_from(p).evaluate()
        except InconsistentEvidenceError:
            dropped += [m.source for m in members]
            continue
        kept += members
        for k, body in enumerate(bodies):
            if body is None:
                counts[k] += len(members)
        for k, q in queries:
            if result.get(q, 0.0) > 1.0 - 1e-9:
                counts[k] += len(members)
    return kept, dropped, counts


# ---- the learned theory file --------------------------------------------------------------------

_NUMBER = re.compile(r"(?<![\w.])(\d+(?:\.\d*)?|\.\d+)(?=\s*::)")


def learned_text(result: FitResult, *, header: Sequence[str], directory: Path | None = None
                 ) -> str:
    """The model's hand-written file with every fitted probability replaced, `header` lines as
    % comments on top (what data and which command made it)."""
    directory = rules_dir() if directory is None else Path(directory)
    path = directory / model_file(result.model, result.variant)
    lines = path.read_text().splitlines()
    for c in result.clauses:
        if c.n_evidence == 0:
            continue
        start = c.line - 1
        # The clause spans from its line to the line holding its closing '.'.
        end = start
        while end < len(lines) and not re.search(r"\.\s*(%.*)?$", lines[end]):
            end += 1
        values = iter(c.after)
        for j in range(start, min(end + 1, len(lines))):
            lines[j] = _NUMBER.sub(lambda m, values=values: _fmt(next(values, float(m.group(1)))),
                                  lines[j])
    head = [f"% {h}" if h else "%" for h in header]
    return "\n".join(head + ["%"] + lines) + "\n"


def _fmt(p: float) -> str:
    return f"{p:.4f}".rstrip("0").rstrip(".") if p not in (0.0, 1.0) else f"{p:.1f}"


def _check(name, allowed, kind):
    if name not in allowed:
        raise unknown_name(kind, name, allowed, error=RuleError, field=kind)


__all__ = ["GraspRecord", "Interpretation", "FitResult", "LearnedClause", "afforded_tasks",
           "allowed_parts", "grasp_interpretations", "category_interpretation", "fit",
           "learned_text", "success_table", "scene_evidence", "check_interpretations", "MODELS"]
