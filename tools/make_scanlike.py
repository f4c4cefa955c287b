"""Writes scan-like versions of library objects (tg_drake.scanlike) into a folder, for tests and
experiments, or imports them into a library of scan-like objects. The meshes are generated, never
committed.

    python tools/make_scanlike.py cup_01 glass_01 --out /tmp/scans          # chosen objects
    python tools/make_scanlike.py --all --out /tmp/scans --format ply       # every object
    python tools/make_scanlike.py cup_01 --out /tmp/scans --triangles 20000 --sigma 0.5e-3 --seed 3

    # a scan-like library (issue 20): every object of a library, made scan-like and imported
    python tools/make_scanlike.py --all --import                            # set a → the cache
    python tools/make_scanlike.py --all --import --library models/objects_b # set b → the cache

Each object gives DIR/<id>_scan.<format> (millimetres, y up, placed at a random offset), its
record DIR/<id>_scan_scanlike.json (scale, up axis, X_SO, numbers of holes, pieces, flipped and
zero-area faces) and, for obj and ply, DIR/<id>_scan_parts.npy (uint8 part label per vertex, in
the file's vertex order: load with trimesh's process=False).

With --import, the meshes go to OUT/meshes/ and each is imported (tg_drake.importing, as
`tg-drake import-object` does: repair, frame, convex collision pieces, resting poses) into the
library folder OUT as object <id>_scan — its category and part labels the original's (ground
truth), its density the original's mass over the original mesh's volume (so its mass is the
original's up to the scan's noise and holes), in mm with y up as the scan says. OUT defaults to
$TG_DRAKE_CACHE/../scanlike/<library folder name> (~/.cache/tg_drake/scanlike/objects_b for set b).
A scenario or suite names OUT in `object_libraries:`; the split (scenarios/suites/split.yaml) puts
<id>_scan on its original's side. Objects OUT already holds are skipped (a rerun resumes).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

from tg_drake.errors import TgDrakeError
from tg_drake.evaluation.split import SCANLIKE_SUFFIX
from tg_drake.importing.cache import scanlike_library
from tg_drake.objects import add_library, load_library, mesh
from tg_drake.scanlike import FORMATS, ScanLikeConfig, write_scanlike


def default_out(library: Path | None) -> Path:
    """Where --import writes by default: the cache's scanlike/<library folder name>."""
    return scanlike_library(library)


def import_scanlike(obj, path: Path, out: Path):
    """Imports the scan-like mesh `path` of library object `obj` into the library folder `out` as
    <id>_scan, with the original's category, part labels and mass (by density)."""
    from tg_drake.importing import ImportOptions, import_object
    from tg_drake.importing.mesh import capped_moments

    V, F, _ = mesh(obj)
    density = obj.mass / capped_moments(np.asarray(V), np.asarray(F))[0]  # [kg/m³]
    options = ImportOptions(category=obj.category, obj_id=f"{obj.id}{SCANLIKE_SUFFIX}",
                            units="mm", up_axis="y", density=density,
                            labels=path.with_name(f"{path.stem}_parts.npy"))
    return import_object(path, options, out, pictures=False)


def main(argv=None) -> int:
    d = ScanLikeConfig()
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("ids", nargs="*", help="library object ids")
    p.add_argument("--all", action="store_true", help="every object of the library")
    p.add_argument("--library", type=Path,
                   help="the library folder the objects come from (default: the shipped one)")
    p.add_argument("--out", type=Path, help="output folder (required without --import)")
    p.add_argument("--import", dest="do_import", action="store_true",
                   help="import each scan-like mesh into the library folder OUT as <id>_scan")
    p.add_argument("--format", choices=FORMATS, default="obj")
    p.add_argument("--seed", type=int, default=0, help="same seed, same meshes")
    p.add_argument("--triangles", type=int, default=d.n_triangles, help="target triangle count")
    p.add_argument("--sigma", type=float, default=d.noise_sigma,
                   help="[m] std of the surface noise along the normal")
    p.add_argument("--holes", type=int, default=d.n_holes, help="small holes cut")
    p.add_argument("--pieces", type=int, default=d.n_pieces, help="pieces the surface is cut in")
    p.add_argument("--flip", type=float, default=d.flip_fraction,
                   help="fraction of faces with reversed winding")
    p.add_argument("--degenerate", type=float, default=d.degenerate_fraction,
                   help="zero-area triangles added, relative to the face count")
    args = p.parse_args(argv)
    if args.all == bool(args.ids):
        p.error("give object ids or --all (not both)")
    if args.out is None and not args.do_import:
        p.error("--out is required (or --import, which defaults it to the cache)")
    if args.do_import and args.format == "stl":
        p.error("--import needs a format that keeps vertices (obj or ply) for the part labels")
    try:
        lib = load_library(args.library)
        if args.library is not None:
            add_library(args.library)  # tg_drake.scanlike finds the objects by id
        ids = list(lib) if args.all else args.ids
        unknown = [i for i in ids if i not in lib]
        if unknown:
            p.error(f"not in the library: {', '.join(unknown)}")
        out = args.out if args.out is not None else default_out(args.library)
        meshes = out / "meshes" if args.do_import else out
        done = set(load_library(out)) if (out / "library.yaml").is_file() else set()
        config = dataclasses.replace(d, n_triangles=args.triangles, noise_sigma=args.sigma,
                                     n_holes=args.holes, n_pieces=args.pieces,
                                     flip_fraction=args.flip,
                                     degenerate_fraction=args.degenerate)
        from tqdm import tqdm  # a progress bar for one output

        t0 = time.perf_counter()
        for obj_id in tqdm(ids, desc="scan-like", unit="object"):
            if args.do_import and f"{obj_id}{SCANLIKE_SUFFIX}" in done:
                continue
            path = meshes / f"{obj_id}{SCANLIKE_SUFFIX}.{args.format}"
            write_scanlike(obj_id, path, args.format, seed=args.seed, config=config)
            if args.do_import:
                import_scanlike(lib[obj_id], path, out)
    except TgDrakeError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    seconds = time.perf_counter() - t0
    if args.do_import:
        print(f"{len(ids)} scan-like objects in the library {out} ({seconds:.0f} s; use it with "
              f"`object_libraries: [{out}]`)")
    else:
        print(f"{len(ids)} scan-like meshes in {out} ({seconds:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
