"""`tg-drake eval SUITE... --out DIR`: run suites, stream their records, write the paper's tables.

    tg-drake eval scenarios/suites/s_syn.yaml --out out/eval
    tg-drake eval scenarios/suites/*.yaml --out out/eval --executor ray --address auto

Writes, in DIR: `results.jsonl` (one line per case as it finishes — perceived cases one per
setting; a rerun skips finished cases; a crashed case is recorded as an error and counts as a
failure), then `tables.json`, `tables.md` and PNG plots derived from every record of the suites
given (`--name logic`: logic.json, logic.md, logic_*.png), and prints the task success per task
and variant when the task suites are among them. `--tables-only` derives the tables from the
records already there.

`--cases PATTERN` keeps the cases whose key matches a shell-style pattern (repeatable), e.g.
`--cases 's_grasp/pan_03_*@pipeline'`; `--list` prints the keys and stops; `--export DIR` writes
each executed case as a scenario file that `tg-drake run` runs as the sweep would (the case's
scene, task scene and variant's pipeline), to reproduce and inspect one case.

`--shard I/N` runs the I-th of N deterministic slices of the cases into `results-I-of-N.jsonl`
(tg_drake.evaluation.shards); the tables are always derived from every results file in DIR (and
any given with `--merge`), duplicates and missing cases reported.
"""

from __future__ import annotations

import dataclasses
import fnmatch
import json
import re
import shlex
import sys
import zlib
from pathlib import Path

from tg_drake.errors import ScenarioError, unknown_name
from tg_drake.evaluation.shards import (
    merge,
    object_set,
    parse_shard,
    results_files,
    shard,
    shard_file,
)
from tg_drake.executor import EXECUTORS, Job, make_executor, run_jobs
from tg_drake.executor import read_records as read_results
from tg_drake.types import THEORY_VARIANTS as VARIANTS

# Start-up: `tg-drake --help` imports this module, so the suite, scenario, table and job modules
# (which import pydrake) are imported inside the functions that use them.

HELP = "run evaluation suites (progress bar, resumable results.jsonl) and write the paper's tables"


def add_arguments(parser) -> None:
    parser.add_argument("suites", type=Path, nargs="+", metavar="SUITE",
                        help="suite YAML files (scenarios/suites/)")
    parser.add_argument("--out", type=Path, default=None,
                        help="output folder (needed unless --list or --export)")
    parser.add_argument("--executor", choices=EXECUTORS, default="local",
                        help="local process pool (default) or a Ray cluster")
    parser.add_argument("--workers", type=int, default=None,
                        help="worker processes (local; default one per core; 0 = in this process)"
                             " or jobs in flight (ray)")
    parser.add_argument("--address", default=None, help="Ray cluster address (e.g. auto)")
    parser.add_argument("--theory", default="specific",
                        help="model variant in place of the specific one for PLM and the pipeline "
                             "(tg_drake.logic.theory.VARIANTS, e.g. learned); a case's key "
                             "gets '#<theory>' unless it is specific")
    parser.add_argument("--retry-errors", action="store_true",
                        help="run again the cases recorded as errors")
    parser.add_argument("--tables", type=Path, default=None,
                        help="folder for tables.json, tables.md and the plots (default: --out)")
    parser.add_argument("--name", default="tables",
                        help="file stem of the tables (NAME.json, NAME.md) and, unless 'tables', "
                             "prefix of the plots (NAME_accuracy.png, ...)")
    parser.add_argument("--tables-only", action="store_true",
                        help="only derive the tables and plots from the results files in DIR "
                             "(results.jsonl and the shards' results-I-of-N.jsonl)")
    parser.add_argument("--shard", default=None, metavar="I/N",
                        help="run only the I-th of N deterministic slices of the cases (1 ≤ I ≤ "
                             "N), into DIR/results-I-of-N.jsonl; merge with --tables-only")
    parser.add_argument("--cases", action="append", default=[], metavar="PATTERN",
                        help="only the cases whose key matches this shell-style pattern "
                             "(repeatable; e.g. 's_grasp/pan_03_*@pipeline')")
    parser.add_argument("--list", action="store_true",
                        help="print the (selected) cases' keys and stop")
    parser.add_argument("--export", type=Path, default=None, metavar="DIR",
                        help="write each (selected) executed case as a scenario file for "
                             "`tg-drake run`, and stop")
    parser.add_argument("--merge", type=Path, action="append", default=[], metavar="PATH",
                        help="with the tables: also read this results file, or the results "
                             "files of this folder (repeatable)")


def load_cases(paths) -> list:
    """The cases of several suites, executed runs grouped by scenario (their variants side by
    side, so that a sweep cut short still compares the variants on the scenarios it ran)."""
    from tg_drake.evaluation.suite import load_suite  # start-up (pydrake)

    cases = []
    for path in paths:
        cases += load_suite(path)[1]
    return _ordered(cases)


def suite_notes(paths) -> str:
    """A Markdown list of the suites: name, cases, description."""
    from tg_drake.evaluation.suite import load_suite  # start-up (pydrake)

    lines = ["Suites:", ""]
    for path in paths:
        suite, cases = load_suite(path)
        lines.append(f"- `{path}` ({len(cases)} cases): {' '.join(suite.description.split())}")
    return "\n".join(lines)


def _ordered(cases) -> list:
    keys = [c.key for c in cases]
    if len(set(keys)) != len(keys):
        dup = sorted({k for k in keys if keys.count(k) > 1})
        raise ScenarioError(f"the same case in two suites (a suite given twice?): {dup[0]}")
    # Executed runs in a fixed shuffled order of their object sets (a sweep cut short is a sample
    # of every category and scene), each set's scenarios together (a warm worker meets its objects
    # again), each scenario's variants together.
    order = {"synthetic": 0, "perceived": 1, "executed": 2}

    def crc(text: str) -> int:
        return zlib.crc32(text.encode())

    return sorted(cases, key=lambda c: (order[c.kind], *(
        (crc(repr(object_set(c))), crc(c.key.split("/", 1)[1].split("@")[0]))
        if c.kind == "executed" else (0, 0))))


def read_records(out: Path, cases) -> list[dict]:
    """The records of `cases` in results.jsonl (records_of)."""
    return records_of(read_results(out), cases)  # a malformed file is a clear error


def records_of(lines: list[dict], cases) -> list[dict]:
    """The records of `cases` among results lines; a case recorded as an error becomes a record
    with its metadata and "error" (one per setting for a perceived case)."""
    from tg_drake.evaluation.suite import DATASET_OF_SETTING  # start-up (pydrake)

    by_key = {c.key: c for c in cases}
    grouped: dict[str, list[dict]] = {}
    for r in lines:
        if r["job"] in by_key:
            grouped.setdefault(r["job"], []).append(r)
    records = []
    for key, rs in grouped.items():
        ok = [r for r in rs if r.get("status") != "error"]
        if ok:  # a case rerun after an error (--retry-errors) keeps its good records
            records += ok
            continue
        case, meta = by_key[key], by_key[key].meta()
        for setting in case.settings or [None]:
            records.append({"job": key, **meta, "error": rs[-1].get("reason", ""),
                            **({"setting": setting, "dataset": DATASET_OF_SETTING[setting]}
                               if setting else {})})
    return records


def write_tables(out_dir: Path, records: list[dict], command: str, notes: str = "",
                 name: str = "tables") -> dict:
    from tg_drake.evaluation.plots import save_plots  # start-up (pydrake)
    from tg_drake.evaluation.tables import compute, markdown  # start-up (pydrake)

    tables = compute(records)
    tables["command"] = command
    (out_dir / f"{name}.json").write_text(json.dumps(tables, indent=1) + "\n")
    (out_dir / f"{name}.md").write_text(markdown(tables, command=command, notes=notes))
    save_plots(tables, out_dir, prefix="" if name == "tables" else f"{name}_")
    return tables


def progress_label(suites, sharded=None) -> str:
    """The progress bar's name for the work: the suites' file stems (and the shard)."""
    names = ", ".join(Path(s).stem for s in suites)
    if len(names) > 40:
        names = f"{len(suites)} suites"
    return f"{names} [{sharded[0]}/{sharded[1]}]" if sharded else names


def main(args) -> int:
    if not re.fullmatch(r"[\w.-]+", args.name):
        raise ScenarioError(f"--name is a file stem (letters, digits, '_', '-', '.'), got "
                            f"{args.name!r}", field="--name")
    if args.out is None and not (args.list or args.export is not None):
        raise ScenarioError("the output folder is missing: give --out DIR (only --list and "
                            "--export need none)", field="--out")
    sharded = None
    if args.shard is not None:
        if args.tables_only:
            raise ScenarioError("--tables-only merges every shard's results: leave --shard out",
                                field="--shard")
        sharded = parse_shard(args.shard)
    cases = load_cases(args.suites)
    if args.theory != "specific":

        if args.theory not in VARIANTS:
            raise unknown_name("theory", args.theory, VARIANTS, error=ScenarioError,
                               field="--theory")
        cases = [dataclasses.replace(c, key=f"{c.key}#{args.theory}", theory=args.theory)
                 for c in cases]
    if args.cases:
        cases = select_cases(cases, args.cases)
    if args.list:
        for c in cases:
            print(c.key)
        return 0
    if args.export is not None:
        written = export_cases(cases, args.export)
        print(f"{len(written)} scenario files in {args.export} (run one: tg-drake run "
              f"{written[0] if written else args.export / '<case>.yaml'} --out out/case)",
              file=sys.stderr)
        return 0
    out = shard_file(args.out, *sharded) if sharded else args.out / "results.jsonl"
    if not args.tables_only:
        todo = shard(cases, *sharded) if sharded else cases
        executor = make_executor(args.executor, workers=args.workers, address=args.address)
        summary = run_jobs(_run, [Job(c.key, c) for c in todo], out=out, executor=executor,
                           retry_errors=args.retry_errors, outcome_of=outcome_label,
                           label=progress_label(args.suites, sharded))
        where = f"shard {sharded[0]}/{sharded[1]}: " if sharded else ""
        print(f"{where}{summary.n_jobs} cases: {summary.n_skipped} already done, {summary.n_ran} "
              f"run now ({summary.n_errors} recorded as errors)", file=sys.stderr)
        if sharded:
            print(f"{where}results in {out}; when every shard is done and its results file is in "
                  f"{args.out}, write the tables with --tables-only", file=sys.stderr)
            return 0
    merged = merge(results_files(args.out, args.merge), cases)
    if merged.duplicates or merged.missing or len(merged.files) > 1 or merged.foreign:
        print(merged.report(), file=sys.stderr)
    records = records_of(merged.records, cases)
    # The command that regenerates the tables: the sweep itself (it resumes, then derives them).
    argv = [a for a in sys.argv[2:] if a != "--tables-only"]
    command = "tg-drake eval " + " ".join(shlex.quote(a) for a in argv) \
        if sys.argv[1:2] == ["eval"] else "tg-drake eval " + " ".join(map(str, args.suites))
    folder = args.tables or args.out
    folder.mkdir(parents=True, exist_ok=True)
    done = {r["job"] for r in records}
    per_suite = {}
    for c in cases:
        n = per_suite.setdefault(c.suite, [0, 0])
        n[0] += c.key in done
        n[1] += 1
    coverage = (f"Cases with records: {len(done)} of {len(cases)} ("
                + ", ".join(f"{s} {a}/{b}" for s, (a, b) in per_suite.items()) + ").")
    if len(merged.files) > 1 or merged.duplicates:
        coverage += " " + " ".join(line.rstrip(".") + "." for line in
                                   merged.report().splitlines())
    tables = write_tables(folder, records, command,
                          notes=suite_notes(args.suites) + "\n\n" + coverage, name=args.name)
    from tg_drake.evaluation.tables import task_success_text  # start-up (pydrake)

    if text := task_success_text(tables):
        print(text)
    print(f"{len(done)} of {len(cases)} cases have records; tables in {folder}/{args.name}.md "
          f"({tables['n_errors']} crashed cases counted as failures)")
    return 0


def select_cases(cases, patterns) -> list:
    """The cases whose key matches one of the shell-style patterns; ScenarioError naming --cases
    and some of the keys when none does."""
    chosen = [c for c in cases if any(fnmatch.fnmatchcase(c.key, p) for p in patterns)]
    if not chosen:
        some = ", ".join(c.key for c in cases[:3])
        raise ScenarioError(f"no case's key matches {', '.join(map(repr, patterns))} (of "
                            f"{len(cases)} cases, e.g. {some}; --list prints them all)",
                            field="--cases")
    return chosen


def export_file_name(key: str) -> str:
    """A case key as a file name: '/', '@', '#' and other non-word characters become '_'."""
    return re.sub(r"[^\w.-]+", "_", key).strip("_") + ".yaml"


def export_cases(cases, folder: Path) -> list[Path]:
    """Writes every executed case's scenario (as the sweep runs it: tg_drake.evaluation.jobs.
    scenario_of) to `folder` as YAML for `tg-drake run`; ScenarioError when no case is executed."""
    from pydrake.common.yaml import yaml_dump_typed  # start-up (pydrake)

    from tg_drake.evaluation.jobs import scenario_of  # start-up (pydrake)

    executed = [c for c in cases if c.kind == "executed"]
    if not executed:
        raise ScenarioError("only executed cases are scenarios; the selection has none "
                            f"(kinds: {sorted({c.kind for c in cases})})", field="--export")
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for case in executed:
        path = folder / export_file_name(case.key)
        header = (f"# Case {case.key} of the suite {case.suite} ({case.kind}, variant "
                  f"{case.variant}), written by tg-drake eval --export.\n"
                  f"# Runs as the sweep runs it: tg-drake run {path} --out out/case\n")
        path.write_text(header + yaml_dump_typed(scenario_of(case)))
        written.append(path)
    return written


def outcome_label(records: list[dict]) -> str:
    """A finished case's word in the progress bar: an executed run's outcome status (placed,
    lifted, grasped, failed), else "done"."""
    statuses = [r["outcome"].get("status") for r in records
                if isinstance(r.get("outcome"), dict)]
    return statuses[0] if statuses and statuses[0] else "done"


def _run(case):
    from tg_drake.evaluation.jobs import run_case  # start-up (pydrake)

    return run_case(case)
