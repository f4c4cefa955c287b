"""Compiled theories kept on disk, so that a process (a sweep's worker, a `tg-drake run`) loads a
theory variant in a fraction of a second instead of grounding and compiling it again.

The file is named by a hash of everything the compiled theory depends on: the variant, the bytes of
its theory files, the source of this package (tg_drake/logic/*.py) and the versions of Python,
ProbLog and PySDD. Any change gives another name, so a stale file is never read. A file that cannot
be read back (torn, another format) is compiled again and replaced. Writes are atomic (a temp file
renamed into place): workers compiling the same variant at once each write a whole file.

Folder: $TG_DRAKE_THEORY_CACHE, else ~/.cache/tg_drake/theories; TG_DRAKE_THEORY_CACHE=off keeps
nothing on disk. The files are pickles: the folder is the user's own, like any cache of compiled
code.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import sys
import tempfile
from collections.abc import Callable
from importlib import metadata
from pathlib import Path
from typing import TypeVar

ENV = "TG_DRAKE_THEORY_CACHE"
T = TypeVar("T")


def cache_dir() -> Path | None:
    """The folder of compiled theories, or None when caching is off."""
    env = os.environ.get(ENV)
    if env and env.lower() == "off":
        return None
    return Path(env) if env else Path.home() / ".cache" / "tg_drake" / "theories"


def _versions() -> str:
    found = []
    for dist in ("problog", "pysdd"):
        try:
            found.append(f"{dist}={metadata.version(dist)}")
        except metadata.PackageNotFoundError:
            found.append(f"{dist}=?")
    return f"python={sys.version_info[:3]};" + ";".join(found)


def theory_key(config: object, theory_files: list[Path]) -> str:
    """The hash naming a compiled theory's file (see the module's docstring)."""
    h = hashlib.sha256()
    h.update(repr(config).encode() + b"\0" + _versions().encode() + b"\0")
    for path in sorted(Path(__file__).parent.glob("*.py")):
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    for path in theory_files:
        h.update(str(path.name).encode() + b"\0")
        h.update(path.read_bytes() if path.exists() else b"<missing>")
        h.update(b"\0")
    return h.hexdigest()[:32]


def cached(config: object, theory_files: list[Path], build: Callable[[], T]) -> T:
    """The compiled theory of `config` from the cache, else `build()` (then stored)."""
    folder = cache_dir()
    if folder is None:
        return build()
    path = folder / f"{theory_key(config, theory_files)}.pickle"
    try:
        with path.open("rb") as f:
            return pickle.load(f)
    except FileNotFoundError:
        pass
    except Exception:  # noqa: BLE001 - a torn or foreign file: compile again and replace it
        pass
    value = build()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".tmp-", suffix=".pickle")
        try:
            with os.fdopen(fd, "wb") as f:
                pickle.dump(value, f, protocol=pickle.HIGHEST_PROTOCOL)
            os.replace(tmp, path)
        except BaseException:
            os.unlink(tmp)
            raise
    except OSError:  # a read-only home: run on without the cache
        pass
    return value
