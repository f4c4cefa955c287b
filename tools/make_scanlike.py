"""Writes scan-like versions of library objects (tg_drake.scanlike) into a folder, for tests and
experiments. The meshes are generated, never committed.

    python tools/make_scanlike.py cup_01 glass_01 --out /tmp/scans          # chosen objects
    python tools/make_scanlike.py --all --out /tmp/scans --format ply       # every object
    python tools/make_scanlike.py cup_01 --out /tmp/scans --triangles 20000 --sigma 0.5e-3 --seed 3

Each object gives DIR/<id>_scan.<format> (millimetres, y up, placed at a random offset), its
record DIR/<id>_scan_scanlike.json (scale, up axis, X_SO, numbers of holes, pieces, flipped and
zero-area faces) and, for obj and ply, DIR/<id>_scan_parts.npy (uint8 part label per vertex, in
the file's vertex order: load with trimesh's process=False).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from tg_drake.errors import TgDrakeError
from tg_drake.objects import load_library
from tg_drake.scanlike import FORMATS, ScanLikeConfig, write_scanlike


def main(argv=None) -> int:
    d = ScanLikeConfig()
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("ids", nargs="*", help="library object ids")
    p.add_argument("--all", action="store_true", help="every library object")
    p.add_argument("--out", type=Path, required=True, help="output folder")
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
    ids = list(load_library()) if args.all else args.ids
    try:
        config = dataclasses.replace(d, n_triangles=args.triangles, noise_sigma=args.sigma,
                                     n_holes=args.holes, n_pieces=args.pieces,
                                     flip_fraction=args.flip,
                                     degenerate_fraction=args.degenerate)
        from tqdm import tqdm  # a progress bar for one output

        for obj_id in tqdm(ids, desc="scan-like", unit="object"):
            path = args.out / f"{obj_id}_scan.{args.format}"
            write_scanlike(obj_id, path, args.format, seed=args.seed, config=config)
    except TgDrakeError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(f"{len(ids)} scan-like meshes in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
