"""The logic module's core: three queries on one object's observations (paper IV).

Queries, each a distribution over mutually exclusive outcomes:

- category: P(cat(o, C) | obs, M) over the 11 CATEGORIES;
- task (when not given): P(affords(o, T) | obs, M) over the 7 TASKS, with T drawn from the task
  prior (uniform unless given);
- pre-grasp part: P(grasp(o, T, Pt) | obs, M) for the given task (or marginalised over the task
  prior when the task is inferred), over the parts.

Normalisation (the paper's mutual-exclusiveness assumption) is explicit: for every outcome q of a
query the theory gives the joint probability P(q, e) with the evidence e (queries.pl), and the
answer is P(q, e) / sum_q' P(q', e). In exclusive mode the outcomes are "exactly this one" (an
object has exactly one category, the gripper takes exactly one part) and e includes "exactly one
category, compatible with the parts", so the normalisation is conditioning on exclusiveness. In
non-exclusive mode the outcomes are the marginals and e is "compatible with the parts".

Two paths give the same numbers (tests check 1e-9):

- `LogicEngine.query`: the theory and the observation *structure* are ground and compiled to an
  SDD once per `TheoryConfig` (ProbLog grounding, an SDD built with PySDD), then turned into a
  NumPy circuit (tg_drake/logic/circuit.py); a scene only re-weights the observation facts and
  evaluates every outcome in one pass.
- `reference_query`: plain ProbLog, the scene written as a program (facts and annotated
  disjunctions) and ground, compiled and evaluated once per query.

Explanations: for the leading answers of each query, the rules and observations that carry most
of its probability. A reason's share is 1 - p_without / p, with p the answer's normalised
probability and p_without the same with the rule taken out (its switch or choice facts weighted
0) or the observation dropped; all reasons are one batched pass of the circuit.
"""


import functools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from problog import get_evaluatable
from problog.errors import InconsistentEvidenceError
from problog.formula import LogicDAG, LogicFormula
from problog.logic import Term
from problog.program import SimpleProgram
from pysdd.sdd import SddManager, Vtree

from tg_drake.errors import RuleError
from tg_drake.logic.cache import cached
from tg_drake.logic.circuit import Circuit
from tg_drake.logic.names import TASK_ATOMS
from tg_drake.logic.observations import (
    PLACEHOLDER,
    SCHEMA_PARAMETERS,
    Observations,
    observation_clauses,
    observation_schema,
)
from tg_drake.logic.theory import (
    TheoryConfig,
    compile_clauses,
    load_theory,
    plain_clauses,
    rules_dir,
    theory_paths,
)
from tg_drake.types import CATEGORIES, PART_LABELS, POSES, TASKS, Explanation, GraspSemantics

QUERIES: tuple[str, ...] = ("category", "task", "part")

# Outcome atoms of each query and the evidence atom, per mode (rules/queries.pl).
_ATOMS = {
    True: {"category": "only_category", "task": "task_is", "part": "only_part_is",
           "evidence": "consistent_single"},
    False: {"category": "category_is", "task": "task_is", "part": "part_is",
            "evidence": "consistent"},
}
_OUTCOMES = {
    "category": [Term(c) for c in CATEGORIES],
    "task": [Term(TASK_ATOMS[t]) for t in TASKS],
    "part": [Term(p) for p in PART_LABELS],
}
NAMES = {"category": CATEGORIES, "task": TASKS, "part": PART_LABELS}

# The evidence is taken to be impossible below this probability. Joint probabilities here are
# sums of a few thousand products of weights in [0, 1]; float rounding puts noise near 1e-16
# around a true 0, and observations as unlikely as 1e-12 are inconsistent for any practical use.
EVIDENCE_FLOOR = 1e-12
# A reason is reported when it carries at least this share of an answer's probability.
MIN_SHARE = 0.01
MAX_REASONS = 6  # reasons listed per answer.
MAX_ANSWERS = 3  # answers explained per query (those with probability > 0).
DEFAULT_THEORY = TheoryConfig()  # the default variant (frozen: one shared default is safe)


@dataclass
class LogicAnswer:
    """The three answers for one object, as vectors in CATEGORIES / TASKS / PART_LABELS order."""

    category: np.ndarray  # (11,) sums to 1.
    task: np.ndarray  # (7,) sums to 1 (one-hot for a given task), or all 0 if none is afforded.
    part: np.ndarray  # (5,) sums to 1, or all 0 when every grasp is ruled out.
    given_task: str | None
    evidence: float  # P(e): probability of the observations' consistency evidence.
    observed_parts: tuple[str, ...]  # parts with probability > 0.
    collisions: tuple[str, ...] = ()
    explanations: dict[str, list[Explanation]] = field(default_factory=dict)
    grasp_probability: float = 1.0  # P(exactly one part grasped | e), before normalising `part`.

    def distribution(self, query: str) -> dict[str, float]:
        values = getattr(self, query)
        names = NAMES[query]
        if query == "part":
            return {p: float(values[i]) for i, p in enumerate(names) if p in self.observed_parts}
        if query == "task" and self.given_task is not None:
            return {self.given_task: 1.0}
        return {n: float(v) for n, v in zip(names, values, strict=True)}

    def to_semantics(self, target: int = 0) -> GraspSemantics:
        return GraspSemantics(
            category=self.distribution("category"), task=self.distribution("task"),
            part=self.distribution("part"), given_task=self.given_task,
            explanations=dict(self.explanations), collisions=tuple(self.collisions),
            target=target, grasp_probability=float(self.grasp_probability))


def _normalise(conditional: np.ndarray) -> np.ndarray:
    """P(q | e) over the outcomes, divided by their sum; all zeros when no outcome is possible
    (every grasp ruled out): a sum below EVIDENCE_FLOOR is float noise around 0."""
    total = conditional.sum()
    return conditional / total if total > EVIDENCE_FLOOR else np.zeros_like(conditional)


def _answer(obs: Observations, joints: dict[str, np.ndarray], evidence: float,
            config: TheoryConfig) -> LogicAnswer:
    if evidence <= EVIDENCE_FLOOR:
        raise _inconsistent(obs, config)
    task = (np.array([float(t == obs.task) for t in TASKS]) if obs.task is not None
            else _normalise(joints["task"]))
    return LogicAnswer(
        category=_normalise(joints["category"]), task=task, part=_normalise(joints["part"]),
        given_task=obs.task, evidence=float(evidence),
        observed_parts=tuple(p for p in PART_LABELS if obs.parts.get(p, 0.0) > 0.0),
        collisions=tuple(obs.collisions), grasp_probability=float(joints["part"].sum()))


def _inconsistent(obs: Observations, config: TheoryConfig) -> RuleError:
    prior = ("uniform" if obs.category_prior is None else
             ", ".join(f"{c} {p:g}" for c, p in obs.category_prior.items() if p > 0))
    parts = ", ".join(f"{p} {v:g}" for p, v in obs.parts.items() if v > 0) or "none"
    return RuleError(
        "the observations have probability 0 under the theory "
        f"({config.category} category model): no category of the prior ({prior}) is "
        f"compatible with the observed parts ({parts}, handles {obs.handles}, "
        f"P(pair) {obs.pair_probability:.2g}"
        + (f", inside seen {obs.interior_seen:g}" if obs.interior_seen > 0 else "") + ")",
        file=obs.source, field="category_prior")


def compile_sdd(dag: LogicDAG, root_keys: list, evidence_key) -> tuple[Circuit, list[Term], int]:
    """Compiles root ∧ evidence for every root, and the evidence, into one SDD (PySDD).

    Variables are the DAG's atoms in the order a depth-first walk from the evidence and then the
    roots first meets them, on a right-linear vtree: facts that decide many answers (category,
    pose, parts) come first, as in a good OBDD order. On this theory that compiles in about a
    second where the default balanced vtree over ProbLog's atom order took 15-20 s.
    Returns the circuit, the atom name of each variable (1-based order), and the SDD size.
    """
    order: list[int] = []
    seen: set[int] = set()
    stack = [abs(k) for k in reversed([evidence_key, *root_keys]) if k]
    while stack:  # iterative depth-first walk, children in order.
        key = stack.pop()
        if key in seen:
            continue
        seen.add(key)
        node = dag.get_node(key)
        if type(node).__name__ == "atom":
            order.append(key)
        else:
            stack.extend(abs(c) for c in reversed(node.children) if c and abs(c) not in seen)
    var_of = {key: i + 1 for i, key in enumerate(order)}
    n = max(len(order), 1)
    manager = SddManager.from_vtree(Vtree(var_count=n, var_order=list(range(1, n + 1)),
                                          vtree_type="right"))
    cache: dict[int, object] = {}

    def inode(key):
        if key == 0:
            return manager.true()
        if key is None:
            return manager.false()
        node_key = abs(key)
        if node_key not in cache:
            node = dag.get_node(node_key)
            kind = type(node).__name__
            if kind == "atom":
                result = manager.literal(var_of[node_key])
            elif kind == "conj":
                result = manager.true()
                for child in node.children:
                    result = result & inode(child)
            else:
                result = manager.false()
                for child in node.children:
                    result = result | inode(child)
            cache[node_key] = result
        result = cache[node_key]
        return ~result if key < 0 else result

    evidence = inode(evidence_key)
    roots = [inode(k) & evidence for k in root_keys] + [evidence]
    circuit = Circuit.from_sdd(roots)
    names = []
    for key in order:
        name = dag.get_node(key).name
        if name.functor == "choice":  # ProbLog's name for an instance of a non-ground fact.
            name = name.args[2]
        names.append(name)
    return circuit, names, int(sum(r.size() for r in roots))



class CompiledTheory:
    """One theory variant, ground and compiled once for the observation structure."""

    def __init__(self, config: TheoryConfig, directory: Path | None = None):
        self.config = config
        self.clauses = load_theory(config, directory)
        compiled, choices, switches = compile_clauses(self.clauses)
        schema, schema_rows = observation_schema()

        # Parameter vector: [choice weights | rule switches | observation parameters].
        choice_keys = sorted(choices)
        choice_row = {key: i for i, key in enumerate(choice_keys)}
        switch_keys = sorted(switches)
        switch_row = {k: len(choice_keys) + i for i, k in enumerate(switch_keys)}
        self.obs_offset = len(choice_keys) + len(switch_keys)
        self.base = np.concatenate([
            [choices[key].weight for key in choice_keys],
            np.ones(len(switch_keys)),
            np.full(len(SCHEMA_PARAMETERS), PLACEHOLDER),
        ])

        atoms = _ATOMS[config.exclusive]
        program = SimpleProgram()
        for clause in compiled + schema:
            program.add_clause(clause)
        roots: list[Term] = [Term(atoms[q], o) for q in QUERIES for o in _OUTCOMES[q]]
        evidence_atom = Term(atoms["evidence"])
        for atom in roots + [evidence_atom]:
            program.add_clause(Term("query", atom))

        dag = LogicDAG.create_from(LogicFormula.create_from(program))
        keys = dict(dag.queries())
        circuit, var_atoms, self.sdd_size = compile_sdd(
            dag, [keys[a] for a in roots], keys[evidence_atom])
        self.circuit = circuit
        self.n_roots = len(roots)

        # Which parameter row weighs each SDD variable.
        self.var_row = np.zeros(len(var_atoms) + 1, dtype=np.int64)  # row 0: unused.
        for var, name in enumerate(var_atoms, start=1):
            if name.functor == "ad_choice":
                row = choice_row[(int(name.args[0]), int(name.args[1]))]
            elif name.functor == "rule_on":
                row = switch_row[int(name.args[0])]
            else:
                row = self.obs_offset + schema_rows[name.with_probability(None)]
            self.var_row[var] = row
        # A probabilistic rule is taken out by zeroing its choice weights.
        rule_rows: dict[int, list[int]] = {k: [row] for k, row in switch_row.items()}
        for (k, _), row in choice_row.items():
            if self.clauses[k].explains:
                rule_rows.setdefault(k, []).append(row)

        # Static reasons: every rule of a reasoning file (its switch or choice rows).
        # Observation reasons are built per scene (their text carries the scene's values).
        self.rule_reasons = [(f"{self.clauses[k].text}  [{self.clauses[k].where}]", rows,
                              self.clauses[k].file) for k, rows in sorted(rule_rows.items())]
        self.n_params = len(self.base)

    def parameters(self, obs: Observations) -> np.ndarray:
        params = self.base.copy()
        params[self.obs_offset:] = obs.parameters()
        return params

    def evaluate(self, params: np.ndarray) -> np.ndarray:
        """Joint probabilities of all roots (outcomes ∧ evidence, then the evidence) for a
        parameter vector (n_params,) or a batch (n_params, B)."""
        return self.circuit.evaluate(params[self.var_row])

    def split(self, values: np.ndarray) -> tuple[dict[str, np.ndarray], np.ndarray]:
        out, start = {}, 0
        for q in QUERIES:
            n = len(_OUTCOMES[q])
            out[q] = values[start:start + n]
            start += n
        return out, values[self.n_roots]

    # ---- explanations --------------------------------------------------------------------

    def observation_reasons(self, obs: Observations) -> list[tuple[str, list[int]]]:
        rows = {key: self.obs_offset + i for i, key in enumerate(SCHEMA_PARAMETERS)}
        reasons = []
        for part in PART_LABELS:
            p = obs.parts.get(part, 0.0)
            if p > 0:
                reasons.append((f"observed part({part}, o) with P={p:g}", [rows[("part", part)]]))
        if any(v > 0 for v in obs.pose.values()):
            text = ", ".join(f"{k} {v:g}" for k, v in obs.pose.items() if v > 0)
            reasons.append((f"observed pose: {text}", [rows[("pose", p)] for p in POSES]))
        containment = ("unknown (empty 0.5, full 0.5)" if obs.containment is None else
                       ", ".join(f"{k} {v:g}" for k, v in obs.containment.items() if v > 0))
        reasons.append((f"observed containment: {containment}",
                        [rows[("containment", c)] for c in ("empty", "full")]))
        prior = ("uniform" if obs.category_prior is None else
                 ", ".join(f"{c} {p:g}" for c, p in sorted(obs.category_prior.items(),
                                                          key=lambda kv: -kv[1]) if p > 0))
        reasons.append((f"category prior: {prior}", [rows[("prior", c)] for c in CATEGORIES]))
        if obs.pair_probability > 0 and obs.parts.get("handle", 0.0) > 0:
            reasons.append(("observed two handles" if obs.pair_probability >= 1 else
                            f"a second handle unseen, P(pair)={obs.pair_probability:.2g}",
                            [rows[("handles", "pair")]]))
        if obs.interior_seen > 0:
            reasons.append((f"saw the inside through an open top with P={obs.interior_seen:g}",
                            [rows[("interior", "seen")]]))
        if obs.interior_hidden > 0:
            reasons.append((f"looked for the inside and did not see it, P={obs.interior_hidden:g}",
                            [rows[("interior", "hidden")]]))
        return reasons

    def explain(self, obs: Observations, params: np.ndarray,
                answer: LogicAnswer) -> dict[str, list[Explanation]]:
        """Reasons for the leading answers of each query, with their shares (module docstring).

        A reason's share of an answer is (p - p_without) / p, with p the answer's normalised
        probability and p_without the same with the rule taken out or the observation dropped:
        the part of the answer's probability that depends on that reason. It credits a rule that
        rules a competitor out (e.g. "a canister has no handle" for a cup) as much as one that
        makes the answer. Reasons that would raise the answer are not listed. Ties are broken in
        favour of the query's own model, then observations.
        """
        reasons = [(text, rows, file) for text, rows, file in self.rule_reasons]
        reasons += [(text, rows, None) for text, rows in self.observation_reasons(obs)]
        batch = np.repeat(params[:, None], len(reasons) + 1, axis=1)
        for j, (_, rows, _) in enumerate(reasons):
            batch[rows, j + 1] = 0.0
        joints, evidence = self.split(self.evaluate(batch))
        # Without a reason the evidence may become impossible: that column then answers 0.
        scale = np.where(evidence > EVIDENCE_FLOOR, 1.0 / np.maximum(evidence, EVIDENCE_FLOOR),
                         0.0)
        out = {}
        for q in QUERIES:
            if q == "task" and obs.task is not None:
                continue
            conditional = joints[q] * scale
            totals = conditional.sum(axis=0)
            with np.errstate(divide="ignore", invalid="ignore"):
                normalised = np.where(totals > EVIDENCE_FLOOR, conditional / totals, 0.0)
            probabilities = getattr(answer, q)
            order = [i for i in np.argsort(-probabilities, kind="stable")[:MAX_ANSWERS]
                     if probabilities[i] > 0]
            own = _OWN_FILES[q]
            priority = np.array([0 if file is not None and file.startswith(own) else
                                 1 if file is None else 2 for _, _, file in reasons])
            explanations = []
            for i in order:
                p = normalised[i, 0]
                shares = (p - normalised[i, 1:]) / p
                # Shares within 0.005 of each other tie (shown to two decimals).
                ranked = [j for j in np.lexsort((priority, -np.round(shares, 2)))
                          if shares[j] >= MIN_SHARE][:MAX_REASONS]
                explanations.append(Explanation(
                    answer=NAMES[q][i], probability=float(probabilities[i]),
                    reasons=[(reasons[j][0], float(min(shares[j], 1.0))) for j in ranked]))
            out[q] = explanations
        return out


# The files of the model each query is about, preferred among reasons of equal share.
_OWN_FILES = {"category": "category_", "task": "affordances", "part": "grasp_"}


def _key(config: TheoryConfig, directory: Path | None):
    directory = rules_dir() if directory is None else Path(directory)
    stamps = tuple(p.stat().st_mtime_ns if p.exists() else 0
                   for p in theory_paths(config, directory))
    return config, str(directory), stamps


@functools.lru_cache(maxsize=8)
def _compiled(key) -> CompiledTheory:
    config, directory, _ = key
    # Compiled once per machine (tg_drake.logic.cache), then loaded by every process.
    return cached(config, theory_paths(config, Path(directory)),
                  lambda: CompiledTheory(config, Path(directory)))


def compiled_theory(config: TheoryConfig = DEFAULT_THEORY,
                    directory: Path | None = None) -> CompiledTheory:
    """The compiled theory for a variant, compiled once per machine and loaded once per process
    (and again if a theory file changes)."""
    return _compiled(_key(config, directory))


@dataclass
class LogicQueryConfig:
    """Parameters of the logic stage (LogicQuerySystem; paper IV and VI)."""

    category: str = "specific"  # category model variant: "specific" or "general".
    grasp: str = "specific"  # task-dependent grasp model variant: "specific" or "general".
    exclusive: bool = True  # mutually exclusive outcomes (the paper) or normalised marginals.
    use_prior: bool = True  # use the kernel's category prior (PLM); False: uniform (PLM_uniform).
    prior_floor: float | None = 0.0  # mix the kernel prior with this much of the uniform prior:
    # p = (1 − floor)·p_kernel + floor/11. A retrieval prior from 10 neighbours weighted
    # exp(−rank) puts 0.63 on its first neighbour alone and can miss the true category entirely;
    # without a floor, a wrong first neighbour outweighs the perceived evidence, and parts that
    # rule out every category it names make the observations impossible (probability 0). 0 is the
    # paper's prior exactly; None (the pipeline's default): the floor the kernel database fitted
    # for this kind of query (CategoryDistribution.floor, KernelDatabase.floor).
    explain: bool = True  # attach explanations (one batched circuit pass more per query).

    def theory(self) -> TheoryConfig:
        return TheoryConfig(category=self.category, grasp=self.grasp, exclusive=self.exclusive)


class LogicEngine:
    """Answers the three queries for scenes, on a theory compiled once."""

    def __init__(self, config: TheoryConfig = DEFAULT_THEORY, *,
                 directory: Path | None = None):
        self.config = config
        self.theory = compiled_theory(config, directory)

    def query(self, obs: Observations, *, explain: bool = False) -> LogicAnswer:
        params = self.theory.parameters(obs)
        joints, evidence = self.theory.split(self.theory.evaluate(params))
        if evidence > EVIDENCE_FLOOR:  # P(q | e), as the reference path gets from ProbLog.
            joints = {q: v / evidence for q, v in joints.items()}
        answer = _answer(obs, joints, float(evidence), self.config)
        if explain:
            answer.explanations = self.theory.explain(obs, params, answer)
        return answer


def reference_query(obs: Observations, config: TheoryConfig = DEFAULT_THEORY, *,
                    directory: Path | None = None, with_evidence: bool = False) -> LogicAnswer:
    """The same answers from plain ProbLog: the scene as a program, ground, compiled and
    evaluated once per query (no explanations). `with_evidence` also computes P(e) (one more
    grounding); otherwise `evidence` is NaN."""
    theory = plain_clauses(load_theory(config, directory))
    scene = observation_clauses(obs)
    atoms = _ATOMS[config.exclusive]
    evidence_atom = Term(atoms["evidence"])
    joints, evidence = {}, 1.0
    for q in QUERIES:
        program = SimpleProgram()
        for clause in theory + scene:
            program.add_clause(clause)
        outcomes = [Term(atoms[q], o) for o in _OUTCOMES[q]]
        for atom in outcomes:
            program.add_clause(Term("query", atom))
        program.add_clause(Term("evidence", evidence_atom, Term("true")))
        try:
            result = get_evaluatable("sdd").create_from(program).evaluate()
        except InconsistentEvidenceError:
            evidence = 0.0
            break
        # P(q | e): the ratio to the sum is the same as for P(q, e).
        joints[q] = np.array([result.get(a, 0.0) for a in outcomes], dtype=float)
    if evidence == 0.0:
        raise _inconsistent(obs, config)
    evidence = float("nan")
    if with_evidence:  # P(e) itself, for the record: one more grounding.
        program = SimpleProgram()
        for clause in theory + scene:
            program.add_clause(clause)
        program.add_clause(Term("query", evidence_atom))
        evidence = float(get_evaluatable("sdd").create_from(program).evaluate()[evidence_atom])
    return _answer(obs, joints, evidence, config)


__all__ = ["LogicEngine", "LogicQueryConfig", "LogicAnswer", "CompiledTheory", "compiled_theory",
           "reference_query", "QUERIES"]
