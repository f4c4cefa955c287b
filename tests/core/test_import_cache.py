"""`tg-drake cache`: the imports kept for mesh entries are listed, pruned by last use, cleared."""

from __future__ import annotations

import os
import time

import trimesh

from tg_drake.cli import main
from tg_drake.importing import ImportOptions, import_cached
from tg_drake.importing.cache import DAY, USED, cached_imports


def _two_imports(tmp_path):
    root = tmp_path / "cache"
    for name, size in (("carton", [0.08, 0.05, 0.12]), ("tin", [0.06, 0.06, 0.10])):
        trimesh.creation.box(size).export(tmp_path / f"{name}.stl")
        import_cached(tmp_path / f"{name}.stl", ImportOptions(units="m", collision="vhacd"),
                      cache_root=root)
    return root


def test_imports_are_listed_and_a_load_counts_as_a_use(tmp_path, capsys):
    root = _two_imports(tmp_path)
    (root / ".import-unfinished").mkdir()  # a stopped import: not listed
    imports = cached_imports(root)
    assert sorted(c.ids for c in imports) == [("carton",), ("tin",)]
    assert all(c.size > 0 and c.source.endswith(".stl") for c in imports)
    old = time.time() - 40 * DAY
    for c in imports:
        os.utime(c.folder / "library.yaml", (old, old))
    import_cached(tmp_path / "tin.stl", ImportOptions(units="m", collision="vhacd"),
                  cache_root=root)  # from the cache: marks it used now
    tin = next(c for c in cached_imports(root) if c.ids == ("tin",))
    assert (tin.folder / USED).exists() and time.time() - tin.last_used < DAY
    assert main(["cache", "--cache", str(root)]) == 0
    out = capsys.readouterr().out
    assert "carton" in out and "tin" in out and "2 imports" in out


def test_prune_removes_only_the_unused_and_clear_removes_all(tmp_path, capsys):
    root = _two_imports(tmp_path)
    carton = next(c for c in cached_imports(root) if c.ids == ("carton",))
    old = time.time() - 40 * DAY
    os.utime(carton.folder / "library.yaml", (old, old))
    assert main(["cache", "--cache", str(root), "--prune-days", "30"]) == 0
    assert [c.ids for c in cached_imports(root)] == [("tin",)]
    assert "removed 1 of 2 imports" in capsys.readouterr().out
    assert main(["cache", "--cache", str(root), "--clear"]) == 0
    assert cached_imports(root) == []


def test_a_negative_age_is_a_clear_error(tmp_path, capsys):
    assert main(["cache", "--cache", str(tmp_path), "--prune-days", "-1"]) == 2
    assert "--prune-days must be a number of days >= 0, got -1.0" in capsys.readouterr().err
