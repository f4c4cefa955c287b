"""`tg-drake cache`: the imported objects that scenarios' `mesh:` entries keep in the cache.

    tg-drake cache                      # one line per import: id, source, size, last used
    tg-drake cache --prune-days 30      # removes the imports not used for 30 days
    tg-drake cache --clear              # removes every import

The cache is `$TG_DRAKE_CACHE`, else ~/.cache/tg_drake/objects; each import is a folder named by
the content hash of its source files and options (tg_drake.importing.library.import_cached), and
its "last used" is the time a run last loaded it. A removed import is made again when a scenario
needs it.
"""

from __future__ import annotations

import os
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

import yaml

from tg_drake.errors import ModelError

HELP = "list or prune the imported objects cached for scenarios' mesh entries"

DAY = 86400.0  # [s]
USED = "last_used"  # a file in each import's folder; its modification time is the last use


def add_arguments(parser) -> None:
    action = parser.add_mutually_exclusive_group()
    action.add_argument("--prune-days", type=float, metavar="DAYS",
                        help="remove the imports not used for DAYS days")
    action.add_argument("--clear", action="store_true", help="remove every import")
    parser.add_argument("--cache", type=Path, default=None,
                        help="the cache folder (default: $TG_DRAKE_CACHE, else "
                             "~/.cache/tg_drake/objects)")


@dataclass(frozen=True)
class CachedImport:
    folder: Path
    ids: tuple  # the object ids in its library.yaml
    source: str  # the file it was imported from ("" if its entry does not say)
    size: int  # [bytes] on disk
    last_used: float  # [s since the epoch]


def default_cache_root() -> Path:
    """$TG_DRAKE_CACHE, else ~/.cache/tg_drake/objects."""
    env = os.environ.get("TG_DRAKE_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "tg_drake" / "objects"


def scanlike_library(library: Path | None = None) -> Path:
    """Where `tools/make_scanlike.py --import` writes the scan-like versions of a library's
    objects: the cache's scanlike/<library folder name> (None: the shipped library, "objects")."""
    name = "objects" if library is None else Path(library).resolve().name
    return default_cache_root().parent / "scanlike" / name


def touch(folder: Path) -> None:
    """Records that the import in `folder` was used now (a read-only cache is left as it is)."""
    try:
        (Path(folder) / USED).touch()
    except OSError:
        pass


def cached_imports(root: Path) -> list[CachedImport]:
    """The complete imports under `root`, most recently used first (unfinished imports, the
    `.import-*` folders of a run that stopped, are not listed)."""
    found = []
    if not root.is_dir():
        return found
    for folder in root.iterdir():
        library = folder / "library.yaml"
        if folder.name.startswith(".") or not library.is_file():
            continue
        try:
            entries = (yaml.safe_load(library.read_text()) or {}).get("objects") or {}
        except (OSError, yaml.YAMLError):
            entries = {}
        sources = [e.get("source", {}).get("file", "") for e in entries.values()
                   if isinstance(e, dict)]
        used = folder / USED
        last = (used if used.exists() else library).stat().st_mtime
        size = sum(f.stat().st_size for f in folder.rglob("*") if f.is_file())
        found.append(CachedImport(folder, tuple(entries), sources[0] if sources else "", size,
                                  last))
    return sorted(found, key=lambda c: -c.last_used)


def main(args) -> int:
    root = args.cache if args.cache is not None else default_cache_root()
    if args.prune_days is not None and not args.prune_days >= 0:
        raise ModelError(f"--prune-days must be a number of days >= 0, got {args.prune_days}",
                         field="prune-days")
    imports = cached_imports(root)
    if args.clear or args.prune_days is not None:
        cutoff = time.time() - (args.prune_days or 0.0) * DAY
        gone = [c for c in imports if args.clear or c.last_used < cutoff]
        for c in gone:
            shutil.rmtree(c.folder, ignore_errors=True)
        freed = sum(c.size for c in gone)
        print(f"removed {len(gone)} of {len(imports)} imports ({freed / 1e6:.1f} MB) from {root}")
        return 0
    if not imports:
        print(f"no imported objects in {root}")
        return 0
    now = time.time()
    print(f"{'id':24s} {'size [MB]':>9s} {'last used':>10s}  source")
    for c in imports:
        days = (now - c.last_used) / DAY
        print(f"{', '.join(c.ids) or '?':24s} {c.size / 1e6:9.1f} {days:8.1f} d  {c.source}")
    total = sum(c.size for c in imports)
    print(f"{len(imports)} imports, {total / 1e6:.1f} MB in {root}")
    return 0
