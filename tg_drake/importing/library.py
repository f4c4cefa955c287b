"""Importing an object: a user's mesh → an entry of a library folder in the shipped library's
format.

    import_object("mugs/blue_mug.obj", ImportOptions(category="cup"), Path("my_objects"))

writes my_objects/library.yaml (the entry merged into the file if it exists) and my_objects/<id>/
with <id>.obj (the repaired full-resolution mesh in the object frame O: visual and perception
mesh), <id>_parts.npy (uint8 part label per vertex of <id>.obj), <id>_collision_<k>.obj (convex
pieces) and <id>.sdf (mass properties, visual = the mesh, collision = the pieces), and a picture
of each resting pose in my_objects/pictures/. `import_cached` does the same into a cache folder
named by the content hash of the source files and the options, once.

Steps: source.resolve → mesh.load → mesh.to_metres_z_up → mesh.repair → frame.derive_frame →
mass.mass_properties → poses.stable_poses → collision.decompose → files → report.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import shutil
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh
import yaml
from scipy.spatial import cKDTree

from tg_drake import objects
from tg_drake.errors import ModelError, unknown_name
from tg_drake.importing import cache, collision, report
from tg_drake.importing.cache import default_cache_root
from tg_drake.importing.frame import derive_frame
from tg_drake.importing.mass import mass_properties
from tg_drake.importing.mesh import UNITS, UP_AXES, load, repair, to_metres_z_up
from tg_drake.importing.poses import named_poses, stable_poses
from tg_drake.importing.source import resolve, sanitise_id
from tg_drake.types import CATEGORIES, PART_LABELS, POSES

MATERIAL = "unknown"  # an imported object's material (its density is what matters)
FORMAT_VERSION = 2  # of the cache: a change of what an import writes bumps it
HEADER = ("# An object library written by `tg-drake import-object` (tg_drake.importing), in the\n"
          "# format of the shipped models/objects/library.yaml (see its header for the fields\n"
          "# and units); source, labels and stable_poses say where each entry came from.\n")


@dataclass(frozen=True)
class ImportOptions:
    category: str | None = None  # among tg_drake.types.CATEGORIES, or None (ground truth only)
    obj_id: str | None = None  # default: from the file or folder name, sanitised
    units: str = "auto"  # auto | m | cm | mm | inch
    up_axis: str = "z"  # z | y | x | -z | -y | -x: the file's up axis
    mass: float | None = None  # [kg] (exactly one of mass / density, or neither: a prior)
    density: float | None = None  # [kg/m³]
    labels: Path | None = None  # per-vertex part labels (.npy, uint8 into PART_LABELS)
    collision: str = "coacd"  # convex decomposition backend: coacd | vhacd

    def check(self) -> None:
        """ModelError naming the field and the allowed values for a bad option."""
        if self.category is not None and self.category not in CATEGORIES:
            raise unknown_name("category", self.category, CATEGORIES, error=ModelError,
                               field="category")
        if self.units != "auto" and self.units not in UNITS:
            raise unknown_name("units", self.units, ("auto", *UNITS), error=ModelError,
                               field="units")
        if self.up_axis not in UP_AXES:
            raise unknown_name("up axis", self.up_axis, UP_AXES, error=ModelError,
                               field="up_axis")
        if self.collision not in collision.BACKENDS:
            raise unknown_name("collision backend", self.collision, collision.BACKENDS,
                               error=ModelError, field="collision")
        if self.mass is not None and self.density is not None:
            raise ModelError("both mass and density given; allowed: one of them or neither",
                             field="mass")
        if self.obj_id is not None and sanitise_id(self.obj_id) != self.obj_id:
            raise ModelError(f"object id {self.obj_id!r}; allowed: lower-case letters, digits "
                             f"and _, starting with a letter (e.g. {sanitise_id(self.obj_id)!r})",
                             field="id")


@dataclass(frozen=True)
class ImportResult:
    object: objects.LibraryObject  # loaded back from the written library
    library_dir: Path
    report: str  # the one-screen report
    warnings: tuple[str, ...]
    pictures: tuple[Path, ...]


def import_object(source: str | Path, options: ImportOptions, out_dir: Path, *,
                  pictures: bool = True) -> ImportResult:
    """Imports `source` into the library folder `out_dir` (created or merged into)."""
    options.check()
    out_dir = Path(out_dir)
    t = {"start": time.perf_counter()}
    seconds = {}

    def lap(stage):
        now = time.perf_counter()
        seconds[stage] = now - t["start"]
        t["start"] = now

    src = resolve(source)
    obj_id = options.obj_id or src.name
    file = str(src.mesh_file)
    loaded = load(src.mesh_file)
    given_labels, label_points = _read_labels(options.labels, loaded, src.mesh_file)
    V_m, placement = to_metres_z_up(loaded.vertices, units=options.units,
                                    up_axis=options.up_axis, scale=src.scale, file=file)
    repaired = repair(V_m, loaded.faces, file=file)
    lap("load+repair")
    labels_in = None
    if given_labels is not None:  # each repaired vertex takes the label of the nearest labelled
        P_m = (label_points * np.asarray(src.scale) * placement.factor) @ UP_AXES[
            placement.up_axis].T
        labels_in = given_labels[cKDTree(P_m).query(repaired.vertices)[1]]
    frame = derive_frame(repaired.vertices, repaired.faces, options.category, labels=labels_in)
    X_OM = np.asarray(frame.X_OM, float)
    V_O = repaired.vertices @ X_OM[:3, :3].T + X_OM[:3, 3]
    normals_O = repaired.vertex_normals @ X_OM[:3, :3].T
    F = repaired.faces
    labels = np.asarray(frame.labels, np.uint8)
    lap("frame")
    mp = mass_properties(V_O, F, watertight=repaired.watertight, category=options.category,
                         mass=options.mass, density=options.density, file=file)
    lap("mass")
    pieces = collision.decompose(V_O, F, options.collision)
    lap("collision")
    # The object rests in physics on its collision pieces: the resting poses are those of their
    # convex hull (a piece's few vertices facet a round body: a pose from the full mesh would
    # roll to the nearest facet), with the full mesh's centre of mass.
    hull = trimesh.convex.convex_hull(np.vstack([p.vertices for p in pieces]))
    poses = stable_poses(np.asarray(hull.vertices), np.asarray(hull.faces), mp.com,
                         is_tool=frame.kind == "tool")
    lap("poses")
    warnings = [*placement.warnings, *mp.warnings]
    if repaired.n_pieces > 1:
        warnings.append(f"{repaired.n_pieces} separate pieces: imported as one rigid object "
                        "(their solids summed)")
    if not named_poses(poses):
        warnings.append("no resting pose matches upright, sideways or upsidedown: place it "
                        "with `resting: K`")
    d = report.Decisions(
        obj_id=obj_id, category=options.category, source=src,
        n_input_vertices=len(loaded.vertices), n_input_triangles=len(loaded.faces),
        n_geometries=loaded.n_geometries, placement=placement, mesh=repaired, vertices_O=V_O,
        labels=labels, labels_source="given" if given_labels is not None else "derived",
        frame_kind=frame.kind, frame_notes=tuple(frame.notes), mass=mp, poses=tuple(poses),
        pieces=tuple(pieces), backend=options.collision, seconds=seconds)
    entry = _entry(d, frame, options, src)
    # The file's texture, when it has one, on its own vertices carried into O by the same
    # scale, turn and shift (a similarity: the repair only merges and drops): illustration only.
    A_OF = X_OM[:3, :3] @ UP_AXES[placement.up_axis] * (np.asarray(src.scale, float)
                                                        * placement.factor)
    textured = (None if loaded.textured is None else
                _textured_in_O(loaded.textured, A_OF, X_OM[:3, 3]))
    write_object(out_dir, obj_id, entry, V_O, normals_O, F, labels, pieces, mp,
                 textured=textured)
    lap("write")
    pics = report.pictures(d, out_dir / "pictures") if pictures else ()
    if pictures:
        lap("pictures")
    warnings = tuple(warnings)
    return ImportResult(load_object(out_dir, obj_id), out_dir, report.text(d, warnings),
                        warnings, pics)


def _read_labels(path: Path | None, loaded, mesh_file: Path):
    """(labels (N,) uint8, the N points of the file they label) or (None, None). A label file
    holds one label per vertex of the file: an OBJ's `v` lines, else the vertices as loaded."""
    if path is None:
        return None, None
    try:
        labels = np.load(Path(path), allow_pickle=False)
    except (OSError, ValueError) as e:
        raise ModelError(f"cannot read the part labels: {e}; allowed: a .npy array of one "
                         "label per vertex", file=str(path), field="labels") from None
    points = loaded.vertices
    if mesh_file.suffix.lower() == ".obj" and len(labels) != len(points):
        points = _obj_vertices(mesh_file)
    if labels.ndim != 1 or len(labels) != len(points):
        raise ModelError(f"{labels.shape} labels for a mesh of {len(points)} vertices; allowed: "
                         "one label per vertex, in the file's vertex order", file=str(path),
                         field="labels")
    if not np.issubdtype(labels.dtype, np.integer) or labels.min() < 0 or \
            labels.max() >= len(PART_LABELS):
        raise ModelError(f"labels {labels.min()}..{labels.max()} ({labels.dtype}); allowed: "
                         f"integers 0..{len(PART_LABELS) - 1} ({', '.join(PART_LABELS)})",
                         file=str(path), field="labels")
    return labels.astype(np.uint8), points


def _obj_vertices(path: Path) -> np.ndarray:
    """The points of an OBJ file's `v` lines, in file order (trimesh drops unused ones)."""
    rows = [ln.split()[1:4] for ln in path.read_text(errors="replace").splitlines()
            if ln.startswith("v ")]
    try:
        return np.array(rows, float).reshape(-1, 3)
    except ValueError:
        raise ModelError("malformed `v` lines", file=str(path)) from None


def _rnd(x, digits: int) -> float:
    return round(float(x), digits) + 0.0


def _sig(x, digits: int = 7) -> float:
    return float(f"{float(x):.{digits}g}") + 0.0


def _entry(d: report.Decisions, frame, options: ImportOptions, src) -> dict:
    """The library.yaml entry: the shipped entry's fields, then source, labels, stable_poses."""
    mp, V = d.mass, d.vertices_O
    order = {p: k for k, p in enumerate(POSES)}
    named = named_poses(list(d.poses))
    poses = {name: {"xyz": list(r.xyz), "rpy": list(r.rpy), "support_margin": r.support_margin}
             for name, r in sorted(named.items(), key=lambda kv: order[kv[0]])}
    return {
        "category": options.category,
        "material": MATERIAL,
        "density": _rnd(mp.density, 2),
        "part_materials": {},
        "mass": _sig(mp.mass),
        "volume": _sig(mp.volume),
        "cavity_volume": None if frame.cavity_volume is None else _sig(frame.cavity_volume),
        "cavity_centroid": None if frame.cavity_centroid is None
        else [_rnd(c, 6) for c in frame.cavity_centroid],
        "com": [_rnd(c, 6) for c in mp.com],
        "inertia": [_sig(x) for x in mp.inertia[np.triu_indices(3)]],
        "extents": [_rnd(x, 4) for x in V.max(0) - V.min(0)],
        "dimensions": {k: _rnd(v, 6) for k, v in frame.dimensions.items()},
        "parts": [p for k, p in enumerate(PART_LABELS) if (d.labels == k).any()],
        "grasp_widths": {k: _rnd(v, 4) for k, v in frame.grasp_widths.items()},
        "poses": poses,
        "n_vertices": int(len(V)),
        "n_triangles": int(len(d.mesh.faces)),
        "source": {"file": str(Path(src.given).resolve()), "sha256": src.sha256(),
                   "units": d.placement.units,
                   # [m per file unit]: the units' factor times a model file's <scale>
                   "scale": _sig(d.placement.factor) if src.scale == (1.0, 1.0, 1.0)
                   else [_sig(d.placement.factor * s) for s in src.scale],
                   "up_axis": d.placement.up_axis},
        "labels": d.labels_source,
        "stable_poses": [{"pose": s.name, "probability": _rnd(s.probability, 4),
                          "xyz": list(s.resting.xyz), "rpy": list(s.resting.rpy),
                          "support_margin": s.resting.support_margin} for s in d.poses],
    }


def obj_text(obj_id: str, V: np.ndarray, normals: np.ndarray, F: np.ndarray) -> str:
    """Wavefront OBJ: vertices (0.1 µm resolution), one shading normal per vertex, triangles.
    tg_drake.objects.mesh reads its `v` and `f` lines; Drake's renderer uses the normals."""
    head = f"# {obj_id}: imported by tg-drake import-object (metres, object frame O)\n"
    v = "\n".join(f"v {x:.7f} {y:.7f} {z:.7f}" for x, y, z in V.tolist())
    vn = "\n".join(f"vn {x:.4f} {y:.4f} {z:.4f}" for x, y, z in normals.tolist())
    f = "\n".join(f"f {a}//{a} {b}//{b} {c}//{c}" for a, b, c in (F + 1).tolist())
    return head + f"o {obj_id}\n" + v + "\n" + vn + "\n" + f + "\n"


def _textured_in_O(mesh: trimesh.Trimesh, A: np.ndarray, t: np.ndarray) -> trimesh.Trimesh:
    """A copy of the textured file mesh with its vertices A·v + t (object frame O, metres), its
    material white (the texture's colours as they are: a tint would darken them)."""
    m = mesh.copy()
    m.vertices = np.asarray(mesh.vertices, float) @ np.asarray(A).T + np.asarray(t)
    material = m.visual.material
    if isinstance(material, trimesh.visual.material.PBRMaterial):
        material = material.to_simple()
    material.diffuse = [255, 255, 255, 255]
    material.ambient = [255, 255, 255, 255]
    m.visual.material = material
    return m


def textured_visual_files(obj_id: str, mesh: trimesh.Trimesh) -> dict[str, bytes]:
    """file name → bytes of the textured visual: `<id>_textured.obj`, its .mtl and image."""
    text, files = trimesh.exchange.obj.export_obj(
        mesh, include_normals=False, return_texture=True, mtl_name=f"{obj_id}_textured.mtl",
        header=f"{obj_id}: the imported file's textured mesh (metres, object frame O)")
    return {f"{obj_id}_textured.obj": text.encode(), **files}


def _textured_visual_sdf(uri: str) -> str:
    return f"""      <visual name="visual_textured">
        <geometry>
          <mesh><uri>{uri}</uri></mesh>
        </geometry>
        <drake:perception_properties enabled="false"/>
      </visual>
"""


def sdf_text(obj_id: str, entry: dict, mp, piece_uris: list[str], *,
             textured_uri: str | None = None) -> str:
    """The object's SDF: inertia, the repaired mesh as the visual that cameras see (grey; hidden
    from the illustration when the file's texture is kept as a second visual), the pieces."""
    J, c = mp.inertia, mp.com
    hide = ('\n        <drake:illustration_properties enabled="false"/>' if textured_uri
            else "")
    textured = _textured_visual_sdf(textured_uri) if textured_uri else ""
    return f"""<?xml version="1.0"?>
<!-- Written by tg-drake import-object from {Path(entry['source']['file']).name}:
     mass {mp.mass:.4f} kg ({mp.solid}); collision: {len(piece_uris)} convex pieces. -->
<sdf version="1.9" xmlns:drake="http://drake.mit.edu">
  <model name="{obj_id}">
    <link name="{obj_id}">
      <inertial>
        <pose>{c[0]:.6f} {c[1]:.6f} {c[2]:.6f} 0 0 0</pose>
        <mass>{mp.mass:.9g}</mass>
        <inertia>
          <ixx>{J[0, 0]:.9e}</ixx>
          <ixy>{J[0, 1]:.9e}</ixy>
          <ixz>{J[0, 2]:.9e}</ixz>
          <iyy>{J[1, 1]:.9e}</iyy>
          <iyz>{J[1, 2]:.9e}</iyz>
          <izz>{J[2, 2]:.9e}</izz>
        </inertia>
      </inertial>
      <visual name="visual">
        <geometry>
          <mesh><uri>{obj_id}.obj</uri></mesh>
        </geometry>
        <material>
          <diffuse>0.700 0.700 0.700 1</diffuse>
        </material>{hide}
      </visual>
{textured}{collision.collision_sdf(piece_uris)}
    </link>
  </model>
</sdf>
"""


def write_object(out_dir: Path, obj_id: str, entry: dict, V, normals, F, labels, pieces,
                 mp, *, textured: trimesh.Trimesh | None = None) -> None:
    """Writes DIR/<id>/ (with the textured visual's files when `textured` is given) and merges
    the entry into DIR/library.yaml."""
    d = out_dir / obj_id
    if d.exists():
        shutil.rmtree(d)  # a re-import replaces the object's files (stale pieces go)
    d.mkdir(parents=True)
    (d / f"{obj_id}.obj").write_text(obj_text(obj_id, V, normals, F))
    with open(d / f"{obj_id}_parts.npy", "wb") as fh:
        np.save(fh, np.asarray(labels, np.uint8))
    uris = []
    for k, p in enumerate(pieces):
        uri = f"{obj_id}_collision_{k}.obj"
        (d / uri).write_text(collision.piece_obj_text(p, f"{obj_id}_collision_{k}"))
        uris.append(uri)
    textured_uri = None
    if textured is not None:
        for name, data in textured_visual_files(obj_id, textured).items():
            (d / name).write_bytes(data)
        textured_uri = f"{obj_id}_textured.obj"
    (d / f"{obj_id}.sdf").write_text(sdf_text(obj_id, entry, mp, uris,
                                              textured_uri=textured_uri))
    merge_entry(out_dir / "library.yaml", obj_id, entry)


def merge_entry(path: Path, obj_id: str, entry: dict) -> None:
    """Adds (or replaces) `obj_id` in the library file at `path`."""
    library = {}
    if path.is_file():
        try:
            data = yaml.safe_load(path.read_text()) or {}
        except yaml.YAMLError as e:
            raise ModelError(f"the library file is not YAML: {e}", file=str(path)) from None
        if not isinstance(data, dict) or not isinstance(data.get("objects", {}), dict):
            raise ModelError("not an object library (no `objects:` mapping)", file=str(path))
        library = dict(data.get("objects") or {})
    library[obj_id] = entry
    text = HEADER + yaml.safe_dump({"objects": library}, sort_keys=False,
                                   default_flow_style=None, width=100, allow_unicode=True)
    tmp = path.with_suffix(".yaml.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def load_object(library_dir: Path, obj_id: str) -> objects.LibraryObject:
    """The object `obj_id` of the library folder, read back through tg_drake.objects (which
    reads a folder again when its library.yaml has changed)."""
    return objects.load_library(Path(library_dir))[obj_id]


# ------------------------------------------------------------------------------------------------
# cache


def cache_key(source: str | Path, options: ImportOptions) -> str:
    """Content hash of the source files and the options (a label file by its content)."""
    src = resolve(source)
    opts = dataclasses.asdict(options)
    if options.labels is not None:
        opts["labels"] = hashlib.sha256(Path(options.labels).read_bytes()).hexdigest()
    opts["obj_id"] = options.obj_id or src.name
    text = json.dumps({"format": FORMAT_VERSION, "source": src.sha256(), "options": opts},
                      sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:20]


def unclaimed_id(source: str | Path, options: ImportOptions, *,
                 cache_root: Path | None = None) -> ImportOptions:
    """`options` with an object id no other known object holds. Without an `obj_id` the id is
    the file's (or folder's) name; when the shipped library or a registered object already holds
    that name for another object (the same file imported with other options, or a mesh named like
    a library object), the name is followed by the first 6 hex digits of this import's cache key,
    which is the same on every call."""
    if options.obj_id is not None:
        return options
    name = resolve(source).name
    try:
        holder = objects.get_object(name)
    except ModelError:
        raise
    except ValueError:  # unknown: the name is free
        return options
    root = Path(cache_root) if cache_root is not None else default_cache_root()
    key = cache_key(source, options)
    if holder.root is not None and holder.root.resolve() == (root / key).resolve():
        return options  # this very import, registered before
    return dataclasses.replace(options, obj_id=f"{name}_{key[:6]}")


def import_cached(source: str | Path, options: ImportOptions, *,
                  cache_root: Path | None = None) -> objects.LibraryObject:
    """The imported object, from the cache folder of its content hash; imports it (once, without
    pictures) when that folder holds no complete import."""
    options.check()
    root = Path(cache_root) if cache_root is not None else default_cache_root()
    folder = root / cache_key(source, options)
    obj_id = options.obj_id or resolve(source).name
    if (folder / "library.yaml").is_file():
        cache.touch(folder)
        return load_object(folder, obj_id)
    root.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=".import-", dir=root))
    try:
        import_object(source, options, tmp, pictures=False)
        try:
            os.replace(tmp, folder)  # complete imports only: a concurrent one may have won
        except OSError:
            if not (folder / "library.yaml").is_file():
                raise
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return load_object(folder, obj_id)
