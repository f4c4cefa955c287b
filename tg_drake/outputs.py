"""Output paths checked before any work: a folder that can be made and written into, a file that
can be created or appended to.

Every command that writes calls these first (`tg_drake.cli` does it for each command's `--out`), so
that a path that is a file, lies below a file, is not writable or is on a virtual file system
(/proc) is answered at once, not after a long run. A failure is an `OutputError` naming the path and
the reason.
"""

from __future__ import annotations

import errno
import os
import tempfile
from pathlib import Path

from tg_drake.errors import OutputError


def _reason(e: OSError) -> str:
    if e.errno == errno.ENOENT:  # in a folder that exists: a virtual file system such as /proc
        return "this file system does not hold files (No such file or directory)"
    return e.strerror or type(e).__name__


def _file_above(path: Path) -> Path | None:
    """The nearest ancestor of `path` (or `path` itself) that exists and is not a folder."""
    for p in (path, *path.parents):
        if p.exists() or p.is_symlink():
            return None if p.is_dir() else p
    return None


def check_output_dir(path: Path | str, *, what: str = "output folder") -> Path:
    """Checks that the folder `path` exists and a file can be created in it, or that it can be made
    (its nearest existing parent is a folder in which a folder can be created). Creates nothing
    that stays: a mistyped command leaves no empty folder behind. Raises OutputError saying why."""
    path = Path(path)
    blocker = _file_above(path)
    if blocker == path:
        raise OutputError(f"the {what} is a file, not a folder", file=str(path))
    if blocker is not None:
        raise OutputError(f"the {what} cannot be made: {blocker} is a file, not a folder",
                          file=str(path))
    if path.is_dir():
        try:
            with tempfile.NamedTemporaryFile(dir=path, prefix=".tg-drake-write-test-"):
                pass
        except OSError as e:
            raise OutputError(f"cannot write in the {what}: {_reason(e)}",
                              file=str(path)) from None
        return path
    parent = next(p for p in path.absolute().parents if p.is_dir())
    try:
        os.rmdir(tempfile.mkdtemp(dir=parent, prefix=".tg-drake-write-test-"))
    except OSError as e:
        raise OutputError(f"the {what} cannot be made in {parent}: {_reason(e)}",
                          file=str(path)) from None
    return path


def prepare_output_dir(path: Path | str, *, what: str = "output folder") -> Path:
    """Checks the folder `path` (check_output_dir) and creates it with its parents."""
    path = check_output_dir(path, what=what)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise OutputError(f"the {what} cannot be made: {_reason(e)}", file=str(path)) from None
    return path


def check_output_file(path: Path | str, *, what: str = "output file") -> Path:
    """Checks that the file `path` can be written: not a folder, its folder made and writable,
    the file itself (if it exists) open for appending. The file's content is left as it is, and
    no folder is made."""
    path = Path(path)
    if path.is_dir():
        raise OutputError(f"the {what} is a folder, not a file", file=str(path))
    try:
        check_output_dir(path.parent, what="folder")
    except OutputError as e:
        raise OutputError(f"the {what} cannot be written: {e}", file=str(path)) from None
    if path.exists():
        try:
            with path.open("ab"):
                pass
        except OSError as e:
            raise OutputError(f"the {what} cannot be written: {_reason(e)}",
                              file=str(path)) from None
    return path
