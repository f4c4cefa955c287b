"""Splitting a sweep without Ray: `--shard I/N` and merging the shards' results files.

    tg-drake eval SUITES --out DIR --shard 1/3     # on machine 1 (2/3, 3/3 on the others)
    tg-drake eval SUITES --out DIR --tables-only   # all results-*-of-3.jsonl copied into DIR

A shard's cases are a deterministic function of the sweep's case list (the suites and `--theory`,
as given): cases are grouped by the objects they use (so that a shard's warm workers see each
object set together), and the groups, largest first and in a fixed hashed order among equals, go
each to the shard with the fewest cases so far. The same command on any machine gives the same
slices; rerunning a shard resumes its own results file (`results-I-of-N.jsonl`).

Merging reads `results.jsonl` and every `results-*-of-*.jsonl` in the folder (and any other file
given): a case with records in two files is a duplicate (one file's records kept: a good one before
an error, else the first file's), a case with none is missing; both are reported.
"""

from __future__ import annotations

import re
import zlib
from dataclasses import dataclass, field
from pathlib import Path

from tg_drake.errors import ScenarioError
from tg_drake.executor import read_records

SHARD_FILE = "results-{i}-of-{n}.jsonl"
SHARD_GLOB = "results-*-of-*.jsonl"
MAX_LISTED = 5  # case keys quoted in a report line


def parse_shard(text: str) -> tuple[int, int]:
    """(I, N) of "--shard I/N": 1 ≤ I ≤ N; a ScenarioError naming the option otherwise."""
    m = re.fullmatch(r"\s*(-?\d+)\s*/\s*(-?\d+)\s*", str(text))
    if m is None:
        raise ScenarioError(f"expected I/N, the I-th of N slices of the sweep (e.g. 1/4), got "
                            f"{text!r}", field="--shard")
    i, n = int(m.group(1)), int(m.group(2))
    if n < 1:
        raise ScenarioError(f"the number of shards N must be ≥ 1, got {text!r}", field="--shard")
    if not 1 <= i <= n:
        raise ScenarioError(f"shards are numbered 1 to {n}, got {text!r}", field="--shard")
    return i, n


def object_set(case) -> tuple[str, ...]:
    """The objects a case builds (library ids, or mesh paths not yet imported), sorted."""
    return tuple(sorted(p.id or p.mesh for p in case.objects))


def _hash(text: str) -> int:
    return zlib.crc32(text.encode())


def shard(cases: list, i: int, n: int) -> list:
    """The cases of shard I of N (1-based), in their order in `cases`."""
    groups: dict[tuple, list[int]] = {}
    for index, case in enumerate(cases):
        groups.setdefault((case.kind, object_set(case)), []).append(index)
    order = sorted(groups, key=lambda g: (-len(groups[g]), _hash(repr(g)), repr(g)))
    load = [0] * n
    mine: list[int] = []
    for g in order:
        k = min(range(n), key=lambda s: (load[s], s))
        load[k] += len(groups[g])
        if k == i - 1:
            mine += groups[g]
    return [cases[j] for j in sorted(mine)]


def shard_file(out_dir: Path, i: int, n: int) -> Path:
    return out_dir / SHARD_FILE.format(i=i, n=n)


@dataclass
class Merged:
    """The records of a sweep's cases gathered from several results files."""

    records: list[dict]  # raw lines (with "job"), at most one file's lines per case
    files: list[Path]
    duplicates: dict[str, list[Path]] = field(default_factory=dict)  # case → files with records
    missing: list[str] = field(default_factory=list)  # case keys with no record anywhere
    foreign: int = 0  # records of jobs that are not cases of these suites (left out)

    def report(self) -> str:
        """What the merge found, one line each (for stderr and the tables' notes)."""
        lines = [f"merged {len(self.files)} results file(s): "
                 + ", ".join(p.name for p in self.files)]
        if self.duplicates:
            first = next(iter(self.duplicates.items()))
            lines.append(f"{len(self.duplicates)} case(s) recorded in more than one file, one "
                         f"file's records kept (e.g. {first[0]} in "
                         + " and ".join(p.name for p in first[1]) + ")")
        if self.missing:
            listed = ", ".join(self.missing[:MAX_LISTED])
            more = f", … ({len(self.missing) - MAX_LISTED} more)" \
                if len(self.missing) > MAX_LISTED else ""
            lines.append(f"{len(self.missing)} case(s) with no record in any file: {listed}{more}")
        if self.foreign:
            lines.append(f"{self.foreign} record(s) of jobs not in these suites left out")
        return "\n".join(lines)


def results_files(out_dir: Path, extra: list[Path] = ()) -> list[Path]:
    """DIR/results.jsonl and DIR's shard files (sorted), then each extra file (a folder: its
    results files); each once."""
    found = []
    for p in [out_dir, *extra]:
        if p.is_dir():
            found += [f for f in [p / "results.jsonl", *sorted(p.glob(SHARD_GLOB))] if f.is_file()]
        elif p.exists():
            found.append(p)
        elif p is not out_dir:  # DIR itself may not exist yet: no records
            raise ScenarioError("no such results file or folder", file=str(p), field="--merge")
    unique = []
    for f in found:
        if f.resolve() not in {u.resolve() for u in unique}:
            unique.append(f)
    return unique


def merge(files: list[Path], cases: list) -> Merged:
    """Each case's records from the first file that has a good (non-error) record of it, else from
    the first file that has any."""
    keys = {c.key for c in cases}
    per_file: list[tuple[Path, dict[str, list[dict]]]] = []
    foreign = 0
    for f in files:
        by_job: dict[str, list[dict]] = {}
        for r in read_records(f):  # a malformed file is a clear error naming it and the line
            if r["job"] in keys:
                by_job.setdefault(r["job"], []).append(r)
            else:
                foreign += 1
        per_file.append((f, by_job))
    records, duplicates, missing = [], {}, []
    for c in cases:
        having = [(f, rs) for f, rs in per_file if c.key in rs]
        if not having:
            missing.append(c.key)
            continue
        if len(having) > 1:
            duplicates[c.key] = [f for f, _ in having]
        good = [(f, rs) for f, rs in having if any(r.get("status") != "error" for r in rs[c.key])]
        records += (good or having)[0][1][c.key]
    return Merged(records, files, duplicates, missing, foreign)
