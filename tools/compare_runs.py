"""Compares two sweeps of the same suites case by case (tg_drake.evaluation.compare): which cases
a change gained or lost, and the lost deliveries by class of failure.

    python tools/compare_runs.py BASE NOW --base-name b5d520b --now-name fc527df \
        --out docs/results/rerun_compare.md [--json compare.json]

BASE and NOW are results files (results.jsonl) or folders of them (a sweep's --out, shards
included). Prints the page (Markdown) unless --out is given.
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from pathlib import Path

from tg_drake.evaluation.compare import compare, markdown
from tg_drake.evaluation.shards import results_files
from tg_drake.executor import read_records


def records(path: Path) -> list[dict]:
    files = results_files(path, []) if path.is_dir() else [path]
    if not files:
        raise SystemExit(f"compare_runs.py: no results file in {path}")
    return [r for f in files for r in read_records(f) if r.get("status") != "error"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("base", type=Path)
    parser.add_argument("now", type=Path)
    parser.add_argument("--base-name", default="base")
    parser.add_argument("--now-name", default="now")
    parser.add_argument("--out", type=Path, help="write the Markdown page here")
    parser.add_argument("--json", type=Path, help="also write the comparison as JSON")
    args = parser.parse_args(argv)
    result = compare(records(args.base), records(args.now))
    command = "python tools/compare_runs.py " + " ".join(
        shlex.quote(a) for a in (argv if argv is not None else sys.argv[1:]))
    page = markdown(result, base_name=args.base_name, now_name=args.now_name, command=command)
    if args.out:
        args.out.write_text(page)
    else:
        print(page)
    if args.json:
        args.json.write_text(json.dumps(result, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
