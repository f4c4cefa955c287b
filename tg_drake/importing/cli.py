"""`tg-drake import-object`: meshes or model folders → objects of a library folder.

    tg-drake import-object mugs/blue_mug.obj --category cup --out my_objects
    tg-drake import-object scans/*.ply --units mm --up-axis y --category bowl --out my_objects

Prints the report of each import (scale and why, up axis, repairs, pieces, mass, resting poses,
collision pieces) and writes a picture of each resting pose to DIR/pictures/. A scenario then names
the folder in `object_libraries:`.
"""

from __future__ import annotations

from pathlib import Path

from tg_drake.errors import ModelError
from tg_drake.types import CATEGORIES

HELP = "import meshes (OBJ STL PLY GLB DAE, GSO / YCB folders, SDF / URDF) into an object library"

UNITS = ("auto", "m", "cm", "mm", "inch")  # as tg_drake.importing.mesh.UNITS (checked there)
UP_AXES = ("z", "y", "x", "-z", "-y", "-x")
BACKENDS = ("coacd", "vhacd")


def add_arguments(parser) -> None:
    parser.add_argument("sources", nargs="+", type=Path, metavar="MESH_OR_FOLDER",
                        help="mesh file, model folder (Google Scanned Objects, YCB) or SDF/URDF")
    parser.add_argument("--category", choices=CATEGORIES,
                        help="ground-truth category (evaluation only; also picks the density "
                             "prior and the frame's kind)")
    parser.add_argument("--id", dest="obj_id", help="object id (one source only; default: the "
                                                    "file or folder name)")
    parser.add_argument("--units", choices=UNITS, default="auto",
                        help="length unit of the file (auto: inferred from the size, warned)")
    parser.add_argument("--up-axis", choices=UP_AXES, default="z", help="the file's up axis")
    mass = parser.add_mutually_exclusive_group()
    mass.add_argument("--mass", type=float, help="mass [kg]")
    mass.add_argument("--density", type=float, help="density [kg/m³]")
    parser.add_argument("--labels", type=Path,
                        help="per-vertex part labels (.npy, one source only)")
    parser.add_argument("--collision", choices=BACKENDS, default="coacd",
                        help="convex decomposition for contact")
    parser.add_argument("--no-pictures", action="store_true",
                        help="skip the PNG of each resting pose")
    parser.add_argument("--out", type=Path, required=True, help="library folder to write into")


def main(args) -> int:
    # Start-up: `tg-drake --help` imports this module; trimesh, CoACD and pydrake are slow.
    from tg_drake.importing.library import ImportOptions, import_object

    if len(args.sources) > 1 and (args.obj_id or args.labels):
        raise ModelError("--id and --labels name one object; allowed with one MESH_OR_FOLDER "
                         f"(got {len(args.sources)})", field="id" if args.obj_id else "labels")
    options = ImportOptions(category=args.category, obj_id=args.obj_id, units=args.units,
                            up_axis=args.up_axis, mass=args.mass, density=args.density,
                            labels=args.labels, collision=args.collision)
    for k, source in enumerate(args.sources):
        result = import_object(source, options, args.out, pictures=not args.no_pictures)
        if k:
            print()
        print(result.report)
        if result.pictures:
            print(f"  pictures  {result.pictures[0].parent}/ ({len(result.pictures)} PNG)")
    print(f"library: {args.out / 'library.yaml'} "
          f"(use it with `object_libraries: [{args.out}]` in a scenario)")
    return 0
