"""`tg-drake query OBSERVATIONS.yaml`: the logic module alone on given observations.

Prints the category, task and pre-grasp part distributions, each with the reasons that carry its
leading answers; `--json` prints the same as JSON. The file format is in
rules/examples/fig1_cup.yaml.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

from tg_drake.types import THEORY_VARIANTS as VARIANTS

HELP = "ask the ProbLog theory for category, task and pre-grasp part on given observations"


def add_arguments(parser) -> None:
    parser.add_argument("observations", type=Path, help="observations file (YAML)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")
    parser.add_argument("--theory", choices=VARIANTS,
                        default="specific",
                        help="category and grasp model variant (default: specific; learned: "
                        "fitted by tools/learn_theory.py)")
    parser.add_argument("--non-exclusive", action="store_true",
                        help="normalise marginals instead of mutually exclusive outcomes")
    parser.add_argument("--uniform", action="store_true",
                        help="ignore the file's category prior (PLM_uniform)")
    parser.add_argument("--no-explain", action="store_true", help="skip the explanations")


def main(args) -> int:
    # Start-up: `tg-drake --help` imports this module; ProbLog takes a second to import.
    from tg_drake.logic.engine import QUERIES, LogicEngine
    from tg_drake.logic.observations import Observations
    from tg_drake.logic.theory import TheoryConfig

    obs = Observations.from_file(args.observations)
    if args.uniform:
        obs = dataclasses.replace(obs, category_prior=None)
    config = TheoryConfig.named(args.theory, exclusive=not args.non_exclusive)
    answer = LogicEngine(config).query(obs, explain=not args.no_explain)
    if args.json:
        out = {q: answer.distribution(q) for q in QUERIES}
        out["given_task"] = answer.given_task
        out["theory"] = dataclasses.asdict(config)
        out["explanations"] = {
            q: [{"answer": e.answer, "probability": e.probability,
                 "reasons": [{"reason": r, "share": s} for r, s in e.reasons]} for e in ex]
            for q, ex in answer.explanations.items()}
        print(json.dumps(out, indent=2))
        return 0
    print(f"{args.observations}  (theory: {args.theory}, "
          f"{'non-exclusive' if args.non_exclusive else 'mutually exclusive'} outcomes)")
    for q in QUERIES:
        title = {"category": "category", "task": "task",
                 "part": f"pre-grasp part for {answer.given_task or 'the inferred task'}"}[q]
        dist = answer.distribution(q)
        print(f"\n{title}:")
        if not any(v > 0 for v in dist.values()):
            print("  (every grasp is ruled out)")
        for name, p in sorted(dist.items(), key=lambda kv: -kv[1]):
            if p > 0:
                print(f"  {p:6.3f}  {name}")
        for e in answer.explanations.get(q, [])[:1]:
            print(f"  why {e.answer}:")
            for reason, share in e.reasons:
                print(f"    {share:4.2f}  {reason}")
    return 0
