"""The part a receiver takes in a pass (rules/receive.pl): a distribution over parts.

    receiver_parts({"knife": 0.9, "hammer": 0.1}, held="usable_area", parts=("handle", ...))
    → {"handle": 0.9, "usable_area": 0.1}

The robot's own grasp is the theory's grasp(X, T, Part); once the robot holds the object by a part,
`receiver_parts` asks the small program of rules/receive.pl (with the object ontology) for
receive(o, Part), the category given as an annotated disjunction over cat(o, C) weighted by the
logic's category distribution, and held(o, Part) as a fact. The answer is kept to the parts the
object shows (`parts`) and normalised; {} when the theory names none of them.
"""

from __future__ import annotations

import functools
import math

from problog import get_evaluatable
from problog.program import PrologString

from tg_drake.errors import RuleError
from tg_drake.logic.theory import rules_dir
from tg_drake.types import CATEGORIES, PART_LABELS

RECEIVE_FILES = ("object_ontology.pl", "receive.pl")
ROUND = 6  # decimals of the category probabilities in the cache key (1e-6: below any answer's use)


@functools.cache
def _theory_text() -> str:
    return "\n".join((rules_dir() / name).read_text(encoding="utf-8") for name in RECEIVE_FILES)


@functools.cache
def _receive(category: tuple, held: str) -> dict[str, float]:
    """receive(o, Part) for the category distribution `category` ((name, p), ...) and the held
    part."""
    heads = "; ".join(f"{p:.{ROUND}f}::cat(o, {c})" for c, p in category if p > 0)
    queries = "\n".join(f"query(receive(o, {part}))." for part in PART_LABELS)
    program = f"{_theory_text()}\n{heads}.\nheld(o, {held}).\n{queries}\n"
    try:
        result = get_evaluatable().create_from(PrologString(program)).evaluate()
    except Exception as e:  # ProbLog's parse and grounding errors share no base class
        raise RuleError(f"rules/receive.pl could not be evaluated: {e}") from None
    return {str(term.args[1]): float(p) for term, p in result.items()}


def receiver_parts(category: dict[str, float] | None, *, held: str,
                   parts=PART_LABELS) -> dict[str, float]:
    """P(the receiver takes Part | the category distribution, the robot holds `held`), over the
    `parts` the object shows, normalised ({} when none has a non-zero probability). A category
    distribution that is None or empty counts every category alike."""
    if held not in PART_LABELS:
        raise RuleError(f"unknown held part {held!r}; allowed: {', '.join(PART_LABELS)}")
    weights = {c: float((category or {}).get(c, 0.0)) for c in CATEGORIES}
    total = sum(weights.values())
    if total <= 0:
        weights, total = {c: 1.0 for c in CATEGORIES}, float(len(CATEGORIES))
    # Rounded down, so that the annotated disjunction's weights never sum above 1.
    key = tuple((c, math.floor(w / total * 10**ROUND) / 10**ROUND) for c, w in weights.items())
    answer = _receive(key, held)
    kept = {p: answer.get(p, 0.0) for p in parts if answer.get(p, 0.0) > 0}
    norm = sum(kept.values())
    return {p: v / norm for p, v in sorted(kept.items(), key=lambda kv: -kv[1])} if norm else {}
