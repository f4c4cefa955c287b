"""Observations about one object, as data for the theory (paper IV-A).

`Observations` holds what perception, the kernel prior, the user and the planner say about the
object under query: probabilistic parts, the pose likelihood, containment, the category prior (an
annotated disjunction, or uniform), the given task or a task prior, collision(Part) evidence
(unreachable parts), no_hold(Part) evidence (parts on which no grasp would hold), the handle
count, and whether the object's inside was seen through a wide opening (`interior_seen`,
ours: the paper's parts cannot tell a glass from a can of the same shape; an open top can).
Whether the task was given enters as the fact `task_given` (the affordances' probabilities are
those of task prediction: rules/affordances.pl).
It is validated on construction; bad input raises `RuleError` naming the field and the allowed
values.

The observations enter the theory in two ways, and both are built here from ProbLog terms, never
from strings:

- `observation_schema()`: the *structure*, every perception-driven atom declared as a
  probabilistic fact (annotated disjunctions broken into chains of independent facts), with
  `parameters(obs)` giving their weights for one scene. The compiled theory is ground once on the
  schema and only re-weighted per scene (tg_drake/logic/engine.py).
- `observation_clauses(obs)`: the scene as a plain ProbLog program (facts and annotated
  disjunctions with the scene's probabilities) for the reference path that re-grounds per query.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml
from problog.logic import And, AnnotatedDisjunction, Clause, Constant, Not, Term

from tg_drake.errors import RuleError, unknown_name
from tg_drake.logic.names import OBJECT, TASK_ATOMS
from tg_drake.types import (
    CATEGORIES,
    CONTAINMENTS,
    PART_LABELS,
    POSES,
    TASKS,
    CategoryDistribution,
    ObjectDescription,
    part_index,
)

# A sum of probabilities may exceed 1 by this much and still be a distribution: float rounding of
# numbers that were normalised elsewhere (e.g. the kernel prior) is ~1e-15; a user's file written
# with two decimals is exact. Above it, the input is not a distribution.
SUM_TOLERANCE = 1e-6


@dataclass
class Observations:
    """What is known about the object under query (the constant ``o`` in the theory)."""

    parts: dict[str, float]  # PART_LABELS entry → probability the part is there (missing: 0).
    pose: dict[str, float] = field(default_factory=dict)
    # POSES entry → likelihood; sums to at most 1, the rest is "pose unknown".
    containment: dict[str, float] | None = None
    # CONTAINMENTS entry → probability (sums to at most 1); None: unknown, i.e. 0.5 each.
    category_prior: dict[str, float] | None = None
    # CATEGORIES entry → probability (an annotated disjunction, sum ≤ 1); None: uniform 1/11.
    task: str | None = None  # the given TASKS entry, or None to infer the task.
    task_prior: dict[str, float] | None = None
    # TASKS entry → probability when the task is inferred (sum ≤ 1, > 0); None: uniform 1/7.
    collisions: tuple[str, ...] = ()  # parts the gripper cannot reach: collision(Part) evidence.
    no_hold: tuple[str, ...] = ()  # parts on which no grasp would hold (the feasibility stage):
    # no_hold(Part) evidence (ours, beyond the paper).
    handles: int = 1  # handles seen when the handle part is there: 1, or 2 (a pot's pair).
    handle_pair: float | None = None  # P(the handle part is a pair, as a pot's) given the view
    # (`handle_pair_probability`); None: 1 with two handles seen, else 0.
    interior_seen: float = 0.0  # probability that the object's inside was seen through a wide
    # opening (0: not seen, or it could not be: upside down, facing away). Beyond the paper.
    interior_hidden: float = 0.0  # probability that perception looked for the inside and did
    # not see it (1 − interior_seen for a perceived object; 0: not looked for). Beyond the paper.
    source: str | None = None  # the file these came from, for error messages.

    def __post_init__(self):
        self.parts = _distribution(self.parts, PART_LABELS, "parts", "part", self.source,
                                   exclusive=False)
        self.pose = _distribution(self.pose or {}, POSES, "pose", "pose", self.source)
        if self.containment is not None:
            self.containment = _distribution(self.containment, CONTAINMENTS, "containment",
                                             "containment", self.source)
        if self.category_prior is not None:
            self.category_prior = _distribution(self.category_prior, CATEGORIES,
                                                "category_prior", "category", self.source)
            if sum(self.category_prior.values()) <= 0.0:
                raise RuleError("the category prior is all zero (evidence of probability 0); "
                                "give a distribution or leave it out for a uniform prior",
                                file=self.source, field="category_prior")
        if self.task is not None:
            if self.task not in TASKS:
                raise unknown_name("task", self.task, TASKS, error=RuleError, file=self.source,
                                   field="task")
            if self.task_prior is not None:
                raise RuleError("give either a task or a task prior, not both",
                                file=self.source, field="task_prior")
        if self.task_prior is not None:
            self.task_prior = _distribution(self.task_prior, TASKS, "task_prior", "task",
                                            self.source)
            if sum(self.task_prior.values()) <= 0.0:
                raise RuleError("the task prior is all zero (evidence of probability 0)",
                                file=self.source, field="task_prior")
        collisions = (self.collisions,) if isinstance(self.collisions, str) else self.collisions
        for name in collisions:
            if name not in PART_LABELS:
                raise unknown_name("part", name, PART_LABELS, error=RuleError, file=self.source,
                                   field="collisions")
        self.collisions = tuple(dict.fromkeys(collisions))
        no_hold = (self.no_hold,) if isinstance(self.no_hold, str) else self.no_hold
        for name in no_hold:
            if name not in PART_LABELS:
                raise unknown_name("part", name, PART_LABELS, error=RuleError, file=self.source,
                                   field="no_hold")
        self.no_hold = tuple(dict.fromkeys(no_hold))
        if self.handles not in (1, 2):
            raise RuleError(f"handles must be 1 or 2, got {self.handles!r}", file=self.source,
                            field="handles")
        for name in ("handle_pair", "interior_seen", "interior_hidden"):
            p = getattr(self, name)
            if p is None and name == "handle_pair":
                continue
            if isinstance(p, bool) or not isinstance(p, int | float) or not math.isfinite(p) \
                    or not 0.0 <= p <= 1.0:
                raise RuleError(f"{name} must be a probability in [0, 1], got {p!r}",
                                file=self.source, field=name)
            setattr(self, name, float(p))

    # ---- as weights of the compiled schema -------------------------------------------------

    def parameters(self) -> np.ndarray:
        """The weights of the schema's probabilistic facts for this scene, in SCHEMA_PARAMETERS
        order (annotated disjunctions as the conditional weights of their fact chains)."""
        return np.concatenate([
            _vector(self.parts, PART_LABELS),
            stick_breaking(_vector(self.pose, POSES)),
            stick_breaking(self.containment_vector()),
            stick_breaking(self.category_vector()),
            stick_breaking(self.task_vector()),
            np.array([float(p in self.collisions) for p in PART_LABELS]),
            np.array([float(p in self.no_hold) for p in PART_LABELS]),
            np.array([self.pair_probability]),
            np.array([self.interior_seen]),
            np.array([self.interior_hidden]),
            np.array([float(self.task is not None)]),
        ])

    @property
    def pair_probability(self) -> float:
        """P(handle_pair(o)): `handle_pair` when given, else 1 with two handles seen, 0 with one."""
        if self.handle_pair is not None:
            return self.handle_pair
        return float(self.handles == 2)

    def containment_vector(self) -> np.ndarray:
        if self.containment is None:  # unknown: either is as likely.
            return np.full(len(CONTAINMENTS), 1.0 / len(CONTAINMENTS))
        return _vector(self.containment, CONTAINMENTS)

    def category_vector(self) -> np.ndarray:
        if self.category_prior is None:
            return np.full(len(CATEGORIES), 1.0 / len(CATEGORIES))
        return _vector(self.category_prior, CATEGORIES)

    def task_vector(self) -> np.ndarray:
        if self.task is not None:
            return np.array([float(t == self.task) for t in TASKS])
        if self.task_prior is None:
            return np.full(len(TASKS), 1.0 / len(TASKS))
        return _vector(self.task_prior, TASKS)

    # ---- constructors ----------------------------------------------------------------------

    @classmethod
    def from_dict(cls, data: dict, *, source: str | None = None) -> Observations:
        """From a parsed observations file (see rules/examples/fig1_cup.yaml)."""
        if not isinstance(data, dict):
            raise RuleError("an observations file holds a mapping of fields", file=source)
        allowed = ("parts", "pose", "containment", "category_prior", "task", "task_prior",
                   "collisions", "no_hold", "handles", "handle_pair", "interior_seen",
                   "interior_hidden")
        for key in data:
            if key not in allowed:
                raise unknown_name("field", key, allowed, error=RuleError, file=source,
                                   field=str(key))
        if "parts" not in data:
            raise RuleError("missing field; it maps part names to probabilities",
                            file=source, field="parts")
        for key in ("parts", "pose", "category_prior", "task_prior"):
            if data.get(key) is not None and not isinstance(data[key], dict):
                raise RuleError("expected a mapping of names to probabilities", file=source,
                                field=key)
        containment = data.get("containment")
        if isinstance(containment, str):
            if containment not in CONTAINMENTS:
                raise unknown_name("containment", containment, CONTAINMENTS, error=RuleError,
                                   file=source, field="containment")
            containment = {containment: 1.0}
        elif containment is not None and not isinstance(containment, dict):
            raise RuleError("expected empty, full, or a mapping of them to probabilities",
                            file=source, field="containment")
        collisions = data.get("collisions") or ()
        if not isinstance(collisions, list | tuple | str):
            raise RuleError("expected a list of part names", file=source, field="collisions")
        no_hold = data.get("no_hold") or ()
        if not isinstance(no_hold, list | tuple | str):
            raise RuleError("expected a list of part names", file=source, field="no_hold")
        handles = data.get("handles", 1)
        if isinstance(handles, bool) or not isinstance(handles, int):
            raise RuleError(f"handles must be 1 or 2, got {handles!r}", file=source,
                            field="handles")
        task = data.get("task")
        if task is not None and not isinstance(task, str):
            raise RuleError(f"expected a task name, got {task!r}", file=source, field="task")
        return cls(parts=data["parts"], pose=data.get("pose") or {}, containment=containment,
                   category_prior=data.get("category_prior"), task=task,
                   task_prior=data.get("task_prior"),
                   collisions=tuple(collisions) if not isinstance(collisions, str)
                   else (collisions,),
                   no_hold=tuple(no_hold) if not isinstance(no_hold, str) else (no_hold,),
                   handles=handles, handle_pair=data.get("handle_pair"),
                   interior_seen=data.get("interior_seen", 0.0),
                   interior_hidden=data.get("interior_hidden", 0.0), source=source)

    @classmethod
    def from_file(cls, path: str | Path) -> Observations:
        """From a YAML observations file; a malformed file raises RuleError naming it."""
        path = Path(path)
        try:
            data = yaml.safe_load(path.read_text())
        except OSError as e:
            raise RuleError(f"cannot read observations: {e.strerror}", file=str(path)) from None
        except yaml.YAMLError as e:
            mark = getattr(e, "problem_mark", None)
            raise RuleError(f"not valid YAML: {getattr(e, 'problem', e)}", file=str(path),
                            line=mark.line + 1 if mark is not None else None) from None
        return cls.from_dict(data, source=str(path))

    @classmethod
    def from_object(cls, obj: ObjectDescription, *,
                    prior: CategoryDistribution | None = None, task: str | None = None,
                    collisions: tuple[str, ...] = (), prior_floor: float | None = 0.0,
                    no_hold: tuple[str, ...] = ()) -> Observations:
        """From perception's description of one object, the kernel prior (None: uniform), the
        task ("" or None: infer it), the parts the planner could not reach and those on which
        no grasp would hold (`no_hold`). `prior_floor`
        mixes the prior with the uniform one: (1 − floor)·p + floor/11 (None: the prior's own
        fitted floor, `CategoryDistribution.floor`)."""
        category_prior = None
        if prior is not None:
            p = np.asarray(prior.probabilities, dtype=float)
            if p.shape != (len(CATEGORIES),):
                raise RuleError(f"a category prior has {len(CATEGORIES)} entries, one per "
                                f"category ({', '.join(CATEGORIES)}); got shape {p.shape}",
                                field="category_prior")
            if prior_floor is None:  # the database's fitted floor for this kind of query
                prior_floor = float(prior.floor)
            if not 0.0 <= prior_floor <= 1.0:
                raise RuleError(f"prior_floor must lie in [0, 1], got {prior_floor}",
                                field="prior_floor")
            p = (1.0 - prior_floor) * p + prior_floor / len(CATEGORIES)
            category_prior = dict(zip(CATEGORIES, p.tolist(), strict=True))
        return cls(parts=dict(obj.part_probabilities), pose=dict(obj.pose_likelihood),
                   containment=None if obj.containment is None else {obj.containment: 1.0},
                   category_prior=category_prior, task=task or None,
                   collisions=tuple(collisions), no_hold=tuple(no_hold),
                   handles=(n := count_handles(obj)), handle_pair=pair_probability_of(obj, n),
                   interior_seen=float(obj.interior_seen),
                   interior_hidden=float(obj.interior_hidden))


def _points_O(obj: ObjectDescription) -> np.ndarray:
    """(N, 3) a perceived object's cloud in its own frame (z the symmetry axis) [m]."""
    X_WO = np.asarray(obj.X_WO, dtype=float)
    return (np.asarray(obj.p_W, dtype=float) - X_WO[:3, 3]) @ X_WO[:3, :3]


def count_handles(obj: ObjectDescription) -> int:
    """1 or 2 handles on a perceived object (`handle_count` on its cloud in its own frame)."""
    return handle_count(_points_O(obj), np.asarray(obj.labels))


def handle_count(p_O: np.ndarray, labels: np.ndarray) -> int:
    """1 or 2: whether the handle points sit on one side of the object's z (symmetry) axis or
    on two opposite sides (a pot's pair of handles). p_O: (N, 3) points in the object frame.

    The directions from the z axis to the handle points, in the xy plane, are averaged as unit
    vectors: one handle gives a mean resultant length near 1, two opposite handles near 0. The
    split at 0.5 is where a second, equal cluster at more than 120° from the first would pull the
    mean below it.
    """
    handle = np.asarray(labels) == part_index("handle")
    d = np.asarray(p_O, dtype=float)[handle][:, :2]
    norm = np.linalg.norm(d, axis=1)
    d = d[norm > 0] / norm[norm > 0, None]
    if len(d) == 0:
        return 1
    return 2 if np.linalg.norm(d.mean(axis=0)) < 0.5 else 1


# P(pair) of a container whose handle part is there, before the view is weighed: the share of
# pots (two side handles) among the training containers with a handle part of the object-wise
# split (scenarios/suites/split.yaml, sets a and b: 5 pots, 5 pans and 5 cups).
HANDLE_PAIR_PRIOR = 5 / 15
OPPOSITE_HALF_ANGLE = np.pi / 4  # [rad] the body's side opposite the handle: within ±45° of the
# direction away from it, about the symmetry axis.


def opposite_unseen(p_O: np.ndarray, labels: np.ndarray, visible: np.ndarray) -> float:
    """The share [0, 1] of the body's points opposite the handle, at the handle's height, that
    completion added rather than the camera saw: how far the view could have missed a second
    handle there. p_O: (N, 3) points in the object frame (z the symmetry axis); 1 when no body
    point lies there (nothing seen of that side); 0 without handle points."""
    p_O = np.asarray(p_O, dtype=float)
    handle = np.asarray(labels) == part_index("handle")
    d = p_O[handle, :2]
    norm = np.linalg.norm(d, axis=1)
    if not np.any(norm > 0):
        return 0.0
    u = (d[norm > 0] / norm[norm > 0, None]).mean(axis=0)
    if np.linalg.norm(u) == 0:
        return 0.0
    away = -u / np.linalg.norm(u)
    z = p_O[handle, 2]
    body = ~handle & (p_O[:, 2] >= z.min()) & (p_O[:, 2] <= z.max())
    r = np.linalg.norm(p_O[:, :2], axis=1)
    cos = np.divide(p_O[:, :2] @ away, r, out=np.zeros(len(p_O)), where=r > 0)
    opposite = body & (cos >= np.cos(OPPOSITE_HALF_ANGLE))
    if not np.any(opposite):
        return 1.0
    return float(1.0 - np.mean(np.asarray(visible, dtype=bool)[opposite]))


def handle_pair_probability(handles: int, unseen: float,
                            prior: float = HANDLE_PAIR_PRIOR) -> float:
    """P(the handle part is a pair | the view): 1 when two handles are seen; with one seen, Bayes
    on "a pair's second handle lies where the view did not look" (probability `unseen`) against
    "a single handle is always the only one seen": prior·unseen / (prior·unseen + 1 − prior)."""
    if handles == 2:
        return 1.0
    num = prior * float(unseen)
    return num / (num + 1.0 - prior) if num > 0 else 0.0


def pair_probability_of(obj: ObjectDescription, handles: int | None = None) -> float:
    """`handle_pair_probability` of a perceived object, from its cloud in its own frame
    (`handles`: its `count_handles`, when already counted)."""
    if not obj.part_probabilities.get("handle", 0.0) > 0:
        return 0.0
    p_O = _points_O(obj)
    if handles is None:
        handles = handle_count(p_O, np.asarray(obj.labels))
    return handle_pair_probability(handles, opposite_unseen(p_O, obj.labels, obj.visible))


def _distribution(values, names, field_name, kind, source, *, exclusive=True) -> dict[str, float]:
    if not isinstance(values, dict):
        raise RuleError("expected a mapping of names to probabilities", file=source,
                        field=field_name)
    out = {}
    for name, p in values.items():
        if name not in names:
            raise unknown_name(kind, name, names, error=RuleError, file=source,
                               field=f"{field_name}.{name}")
        if isinstance(p, bool) or not isinstance(p, int | float) or not math.isfinite(p) \
                or not 0.0 <= p <= 1.0:
            raise RuleError(f"probability of {name!r} must be a number in [0, 1], got {p!r}",
                            file=source, field=f"{field_name}.{name}")
        out[name] = float(p)
    total = sum(out.values())
    if exclusive and total > 1.0 + SUM_TOLERANCE:
        raise RuleError(f"the outcomes are mutually exclusive, so their probabilities sum to at "
                        f"most 1; got {total:.6g}", file=source, field=field_name)
    return out


def _vector(values: dict[str, float], names) -> np.ndarray:
    return np.array([values.get(n, 0.0) for n in names])


def stick_breaking(p: np.ndarray) -> np.ndarray:
    """The weights q of a chain of independent facts c_1..c_n that encodes an annotated
    disjunction with probabilities p: outcome i is (not c_1, ..., not c_{i-1}, c_i), so
    q_i = p_i / (1 - p_1 - ... - p_{i-1}). A remainder of 0 makes the later weights 0."""
    p = np.asarray(p, dtype=float)
    rest = 1.0 - np.concatenate([[0.0], np.cumsum(p)[:-1]])
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.where(rest > 1e-15, p / np.where(rest > 1e-15, rest, 1.0), 0.0)
    return np.clip(q, 0.0, 1.0)


# ---- the schema: every perception-driven atom as a probabilistic fact --------------------------

def _o() -> Term:
    return Term(OBJECT)


def _ad_groups():
    """(parameter group, head atoms, body) for each annotated disjunction of the observations."""
    o = _o()
    return [
        ("pose", [Term("pose", o, Term(p)) for p in POSES], None),
        ("containment", [Term(c, o) for c in CONTAINMENTS], None),
        ("prior", [Term("cat", o, Term(c)) for c in CATEGORIES], Term("object", o)),
        ("task", [Term("task", Term(TASK_ATOMS[t])) for t in TASKS], None),
    ]


# Parameter rows of the schema, in the order of Observations.parameters().
SCHEMA_PARAMETERS: tuple[tuple[str, str], ...] = (
    tuple(("part", p) for p in PART_LABELS)
    + tuple(("pose", p) for p in POSES)
    + tuple(("containment", c) for c in CONTAINMENTS)
    + tuple(("prior", c) for c in CATEGORIES)
    + tuple(("task", t) for t in TASKS)
    + tuple(("collision", p) for p in PART_LABELS)
    + tuple(("no_hold", p) for p in PART_LABELS)
    + (("handles", "pair"),)
    + (("interior", "seen"),)
    + (("interior", "hidden"),)
    + (("task_given", "given"),)
)

# The placeholder weight of schema facts while grounding: anything strictly inside (0, 1) keeps a
# fact a variable (ProbLog folds 0 and 1 into constants).
PLACEHOLDER = 0.5


def observation_schema() -> tuple[list[Term], dict[Term, int]]:
    """The observation structure as ProbLog clauses, and for each schema fact the row of
    `Observations.parameters()` that weighs it."""
    o = _o()
    clauses: list[Term] = [Term("object", o)]
    rows: dict[Term, int] = {}
    index = {key: i for i, key in enumerate(SCHEMA_PARAMETERS)}
    for part in PART_LABELS:
        fact = Term("part", Term(part), o)
        clauses.append(fact.with_probability(Constant(PLACEHOLDER)))
        rows[fact] = index[("part", part)]
    for group, heads, body in _ad_groups():
        names = [key[1] for key in SCHEMA_PARAMETERS if key[0] == group]
        for i, head in enumerate(heads):
            choice = Term(f"obs_{group}", Constant(i))
            clauses.append(choice.with_probability(Constant(PLACEHOLDER)))
            rows[choice] = index[(group, names[i])]
            literals = ([body] if body is not None else []) + [
                Not("\\+", Term(f"obs_{group}", Constant(j))) for j in range(i)] + [choice]
            clauses.append(Clause(head, _conjunction(literals)))
    for part in PART_LABELS:
        fact = Term("collision", Term(part))
        clauses.append(fact.with_probability(Constant(PLACEHOLDER)))
        rows[fact] = index[("collision", part)]
    for part in PART_LABELS:
        fact = Term("no_hold", Term(part))
        clauses.append(fact.with_probability(Constant(PLACEHOLDER)))
        rows[fact] = index[("no_hold", part)]
    fact = Term("handle_pair", o)
    clauses.append(fact.with_probability(Constant(PLACEHOLDER)))
    rows[fact] = index[("handles", "pair")]
    fact = Term("interior_seen", o)
    clauses.append(fact.with_probability(Constant(PLACEHOLDER)))
    rows[fact] = index[("interior", "seen")]
    fact = Term("interior_hidden", o)
    clauses.append(fact.with_probability(Constant(PLACEHOLDER)))
    rows[fact] = index[("interior", "hidden")]
    fact = Term("task_given")
    clauses.append(fact.with_probability(Constant(PLACEHOLDER)))
    rows[fact] = index[("task_given", "given")]
    return clauses, rows


def observation_clauses(obs: Observations) -> list[Term]:
    """The scene as a plain ProbLog program: facts with their probabilities and the annotated
    disjunctions themselves (the paper's form: 0.56::cup(o); 0.36::can(o); ... <- object(o))."""
    o = _o()
    clauses: list[Term] = [Term("object", o)]

    def fact(term: Term, p: float):
        if p >= 1.0:
            clauses.append(term)
        elif p > 0.0:
            clauses.append(term.with_probability(Constant(p)))

    for part in PART_LABELS:
        fact(Term("part", Term(part), o), obs.parts.get(part, 0.0))
    vectors = {"pose": _vector(obs.pose, POSES), "containment": obs.containment_vector(),
               "prior": obs.category_vector(), "task": obs.task_vector()}
    for group, heads, body in _ad_groups():
        p = vectors[group]
        kept = [h.with_probability(Constant(float(pi)))
                for h, pi in zip(heads, p, strict=False) if pi > 0]
        if kept:
            clauses.append(AnnotatedDisjunction(kept, body if body is not None else Term("true")))
    for part in obs.collisions:
        clauses.append(Term("collision", Term(part)))
    for part in obs.no_hold:
        clauses.append(Term("no_hold", Term(part)))
    fact(Term("handle_pair", o), obs.pair_probability)
    fact(Term("interior_seen", o), obs.interior_seen)
    fact(Term("interior_hidden", o), obs.interior_hidden)
    fact(Term("task_given"), float(obs.task is not None))
    # An observation predicate with no clause in this scene (no collision, no pose, ...) is
    # defined as failing, so that ProbLog does not reject the theory's calls to it.
    defined = {_head(c).signature for c in clauses}
    for head in _schema_heads():
        if head.signature not in defined:
            clauses.append(Clause(head, Term("fail")))
            defined.add(head.signature)
    return clauses


def _head(clause: Term) -> Term:
    if isinstance(clause, AnnotatedDisjunction):
        return clause.heads[0]
    if isinstance(clause, Clause):
        return clause.head
    return clause


def _schema_heads() -> list[Term]:
    o = _o()
    heads = [Term("part", Term(PART_LABELS[0]), o), Term("collision", Term(PART_LABELS[0])),
             Term("no_hold", Term(PART_LABELS[0])), Term("handle_pair", o),
             Term("interior_seen", o), Term("interior_hidden", o), Term("task_given")]
    for _, group_heads, _ in _ad_groups():
        heads.extend(group_heads)
    return heads


def _conjunction(literals: list[Term]) -> Term:
    return And.from_list(literals)
