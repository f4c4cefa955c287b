"""Writes docs/results/generalization.{json,md}: issue 20's measures on training versus held-out
objects (scenarios/suites/split.yaml), generated and scan-like, from the records of sweeps.

    nice -n 10 tg-drake eval scenarios/suites/generalization.yaml --out /tmp/gen
    python tools/generalization.py /tmp/gen/results.jsonl --out docs/results/generalization

Give every results.jsonl that holds cases of the protocol (perceived suites give the perception
rows, executed suites over the split's objects the executed rows; scan-like objects are those of
a library written by tools/make_scanlike.py --import). Records of objects in no set of the split
are left out and listed. Without records, the table is the protocol's skeleton: every cell "not
measured yet".
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from tg_drake.evaluation.generalization import compute, markdown
from tg_drake.evaluation.split import load_split

COMMAND = ("nice -n 10 tg-drake eval scenarios/suites/generalization.yaml --out /tmp/gen\n"
           "nice -n 10 tg-drake eval scenarios/suites/generalization_executed.yaml --out "
           "/tmp/gen_exec\n"
           "# scan-like columns: their libraries, then their suite\n"
           "python tools/make_scanlike.py --all --import\n"
           "python tools/make_scanlike.py --all --import --library models/objects_b\n"
           "nice -n 10 tg-drake eval scenarios/suites/generalization_scanlike.yaml --out "
           "/tmp/gen_scan\n"
           "nice -n 10 tg-drake eval scenarios/suites/generalization_scanlike_executed.yaml "
           "--out /tmp/gen_scan_exec\n"
           "python tools/generalization.py /tmp/gen/results.jsonl /tmp/gen_exec/results.jsonl "
           "/tmp/gen_scan/results.jsonl /tmp/gen_scan_exec/results.jsonl "
           "--out docs/results/generalization")


def read_records(paths) -> list[dict]:
    records = []
    for path in paths:
        with open(path, encoding="utf-8") as f:
            for line in f:
                if line.strip():
                    r = json.loads(line)
                    records += r if isinstance(r, list) else [r]
    return [r for r in records if "object" in r and "truth" in r]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("results", nargs="*", type=Path, help="results.jsonl files of tg-drake eval")
    p.add_argument("--out", type=Path, default=Path("docs/results/generalization"),
                   help="file stem: writes OUT.json and OUT.md (default: %(default)s)")
    p.add_argument("--notes", default="", help="a paragraph for the Markdown (what was run)")
    args = p.parse_args(argv)
    table = compute(read_records(args.results), load_split())
    table["command"] = COMMAND
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.with_suffix(".json").write_text(json.dumps(table, indent=1) + "\n")
    args.out.with_suffix(".md").write_text(markdown(table, command=COMMAND, notes=args.notes))
    print(f"wrote {args.out.with_suffix('.json')} and {args.out.with_suffix('.md')} "
          f"({table['n_records']} records)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
