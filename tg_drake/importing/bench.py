"""Speed figures of the object import (issue 18).

- `import_s`: seconds to import the scan-like cup (tg_drake.scanlike of the library's cup_01, seed
  0: ~50k triangles, in mm, y up, with holes, pieces, flipped and zero-area triangles) into a fresh
  library folder, pictures off, median of 3. Reference: loading the same file with trimesh alone
  (`trimesh.load`, processing on), median of 3; `speedup` = reference / ours (< 1: the import is
  that many times the bare load).
- `scan_run_ratio`: in `tg_drake.run` (it runs the pipeline).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import trimesh

from tg_drake.bench import Figure, figure, median_time
from tg_drake.importing.library import ImportOptions, import_object
from tg_drake.scanlike import write_scanlike

SCAN_OBJECT = "cup_01"  # the default scenario's cup
SCAN_SEED = 0


def write_scan_cup(folder: Path) -> Path:
    """The benchmark's scan-like cup as an OBJ file in `folder`."""
    path = Path(folder) / "scan_cup.obj"
    write_scanlike(SCAN_OBJECT, path, seed=SCAN_SEED)
    return path


def import_s() -> Figure:
    with tempfile.TemporaryDirectory(prefix="tg_drake_bench_import_") as tmp:
        path = write_scan_cup(Path(tmp))
        n = iter(range(1000))

        def one():
            import_object(path, ImportOptions(category="cup", up_axis="y"),
                          Path(tmp) / f"lib{next(n)}", pictures=False)

        ours = median_time(one, repeats=3, warmup=0)
        reference = median_time(lambda: trimesh.load(path, force="mesh"), repeats=3, warmup=0)
    return figure(ours, "s", reference="trimesh.load of the same file (processing on)",
                  reference_median=reference)
