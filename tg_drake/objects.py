"""The object library: generated household objects of the paper's 11 categories, four or more each.

Files live in the `tg_drake_models` package (``models/objects/<id>/``): ``<id>.obj`` (the visual and
collision mesh: closed, outward-oriented triangles), ``<id>.sdf`` (one model and one body with
mass properties from the mesh volume and material densities, rigid-hydroelastic collision),
``<id>_parts.npy`` (uint8 part label per mesh vertex, an index into PART_LABELS) and one
``library.yaml`` describing every object. They are written by ``tools/make_objects.py``.

Object frame O:

- containers (pan, pot, cup, glass, bowl, bottle, can): origin at the centre of the bottom, z along
  the symmetry axis towards the opening (or neck), handles towards +x;
- tools (hammer, knife, screwdriver, cooking_tool): x along the long axis from the handle towards
  the usable area, z normal to the face the tool lies on (up when lying flat), origin at the centre
  of the bottom face of the bounding box.

Part ground truth: containers are cut in thirds along z — bottom, middle, top (top is the open or
neck end) — plus the handle; tools have a handle and a usable area (head, blade, shaft and tip,
spatula head or ladle bowl).

Each object lists the poses that suit it (upright / sideways / upsidedown; tools only "sideways",
lying flat) with its resting transform X_TO (table-top frame T → object frame O): the object then
rests on z = 0 of T with its origin above T's origin.

User libraries (``tg-drake import-object --out DIR`` writes one) have the same format in a folder
DIR of its own: ``DIR/library.yaml`` and ``DIR/<id>/``, plus imported objects' convex collision
pieces ``<id>_collision_<k>.obj``. Their entries may add ``source`` (where the mesh came from),
``labels`` (``derived`` | ``given``; absent = generated) and ``stable_poses`` (every resting pose
found, most probable first). `add_library` registers one, `register_object` a single imported
object; `get_object` looks in the shipped library first, then in the registered ones.

    tg-drake objects            # a table: id, category, size, mass, parts
    tg-drake objects --json
    tg-drake objects --library DIR
"""

from __future__ import annotations

import functools
import importlib.resources
import json
import math
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import numpy as np
import yaml

from tg_drake.errors import ModelError, ScenarioError, unknown_name
from tg_drake.types import CATEGORIES, PART_LABELS, POSES

SAFE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml's: ~10× faster, same data

HELP = "list the object library (id, category, size, mass, parts)"

PACKAGE = "tg_drake_models"
WATER_DENSITY = 1000.0  # [kg/m³]


@dataclass(frozen=True)
class RestingPose:
    """How an object rests on a table in one pose: X_TO as xyz [m] + roll-pitch-yaw [rad]."""

    pose: str  # an entry of POSES.
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]  # Drake's RollPitchYaw: R = Rz(yaw)·Ry(pitch)·Rx(roll).
    support_margin: float  # [m] how far the COM projects inside the support polygon.

    @property
    def X_TO(self) -> np.ndarray:
        """4×4 pose of the object frame O in the table-top frame T."""
        r, p, y = self.rpy
        cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(p), math.sin(p),
                                  math.cos(y), math.sin(y))
        X = np.eye(4)
        X[:3, :3] = [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]]
        X[:3, 3] = self.xyz
        return X


@dataclass(frozen=True)
class StablePose(RestingPose):
    """One stable resting pose found for an imported object; `pose` is its name among POSES, or
    None when it is none of them (an object lying on an odd face)."""

    probability: float = 0.0  # [1] of coming to rest in this pose when dropped at random


LABEL_SOURCES = ("generated", "derived", "given")


@dataclass(frozen=True)
class LibraryObject:
    """One object of the library (fields as in library.yaml; SI units)."""

    id: str
    category: str | None  # an entry of CATEGORIES; None for an object imported without one
    # (its true category unknown: ground truth only, perception never reads it)
    material: str  # main material (the body; for a tool, its usable area).
    density: float  # [kg/m³] mass / volume (the material's density when the object has one).
    part_materials: dict  # part name → material, for parts of another material.
    mass: float  # [kg]
    volume: float  # [m³] volume of material (a closed bottle's or can's cavity excluded).
    cavity_volume: float | None  # [m³] containers: water volume when "full"; None otherwise.
    # [m] in O: centroid of that water (upright).
    cavity_centroid: tuple[float, float, float] | None
    com: tuple[float, float, float]  # [m] centre of mass in O.
    inertia: np.ndarray  # (3, 3) [kg·m²] about the centre of mass, O's axes.
    extents: tuple[float, float, float]  # [m] bounding-box side lengths along O's x, y, z.
    dimensions: dict  # category-specific sizes [m]: height, diameter, handle_length, ...
    parts: tuple[str, ...]  # part names present, in PART_LABELS order.
    grasp_widths: dict  # part → [m] smallest width across the part (open container top: rim wall).
    poses: dict  # pose name → RestingPose, for the poses that suit the object.
    n_vertices: int
    n_triangles: int
    root: Path | None = None  # the library folder (library.yaml and <id>/); the shipped one's
    # when None
    labels_source: str = "generated"  # an entry of LABEL_SOURCES: how the part labels were made
    stable_poses: tuple = ()  # StablePose, most probable first; empty when the library lists none
    source: dict | None = None  # where an imported object came from (file, sha256, units, ...)

    @property
    def shipped(self) -> bool:
        return self.root is None or self.root == shipped_root()

    @property
    def is_tool(self) -> bool:
        return "usable_area" in self.parts

    @property
    def is_container(self) -> bool:
        return self.cavity_volume is not None

    @property
    def water_mass(self) -> float:
        """[kg] of water that fills the cavity ("full" containment); 0 for other objects."""
        return WATER_DENSITY * (self.cavity_volume or 0.0)

    @property
    def directory(self) -> Path:
        return (shipped_root() if self.root is None else self.root) / self.id

    @property
    def sdf_path(self) -> Path:
        return self.directory / f"{self.id}.sdf"

    @property
    def mesh_path(self) -> Path:
        return self.directory / f"{self.id}.obj"

    @property
    def parts_path(self) -> Path:
        return self.directory / f"{self.id}_parts.npy"

    @property
    def sdf_url(self) -> str:
        """package:// URL of the SDF for the shipped library (Drake resolves it through
        models/package.xml), file:///absolute/path for a user library."""
        if self.shipped:
            return f"package://{PACKAGE}/objects/{self.id}/{self.id}.sdf"
        return self.sdf_path.resolve().as_uri()

    @property
    def mesh_url(self) -> str:
        if self.shipped:
            return f"package://{PACKAGE}/objects/{self.id}/{self.id}.obj"
        return self.mesh_path.resolve().as_uri()

    def resting_pose(self, pose: str) -> RestingPose:
        """The resting transform for `pose`; ScenarioError naming the poses that suit the object."""
        if pose not in self.poses:
            if pose not in POSES:
                raise unknown_name("pose", pose, POSES, error=ScenarioError)
            raise ScenarioError(f"pose {pose!r} does not suit {self.id} ({self.category}); "
                                f"allowed: {', '.join(self.poses)}")
        return self.poses[pose]

    def stable_pose(self, k: int) -> StablePose:
        """The k-th most probable stable pose (0 = the most probable); ScenarioError naming the
        stable poses the object has."""
        if not self.stable_poses:
            raise ScenarioError(f"{self.id} lists no stable poses; give a `pose` among "
                                + ", ".join(self.poses))
        if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k < len(self.stable_poses):
            raise ScenarioError(f"{self.id} has no stable pose {k!r}; allowed: "
                                + describe_stable_poses(self))
        return self.stable_poses[k]


def describe_stable_poses(obj: LibraryObject) -> str:
    """"0 (upright, p=0.61), 1 (sideways, p=0.30), ..." for messages."""
    return ", ".join(f"{k} ({s.pose or 'unnamed'}, p={s.probability:.2f})"
                     for k, s in enumerate(obj.stable_poses))


def shipped_root() -> Path:
    """The shipped library's folder (objects/ in the tg_drake_models package)."""
    return Path(str(importlib.resources.files(PACKAGE))) / "objects"


def library_path() -> Path:
    return shipped_root() / "library.yaml"


def _stable_poses(entries) -> tuple:
    out = []
    for v in entries:
        pose = v.get("pose")
        if pose is not None and pose not in POSES:
            raise ValueError(f"stable pose name {pose!r} is none of {', '.join(POSES)}")
        out.append(StablePose(pose, tuple(v["xyz"]), tuple(v["rpy"]), v["support_margin"],
                              float(v["probability"])))
    return tuple(out)


def _object(obj_id: str, d: dict, root: Path | None = None) -> LibraryObject:
    iu = np.triu_indices(3)
    inertia = np.zeros((3, 3))
    inertia[iu] = d["inertia"]
    inertia = inertia + np.triu(inertia, 1).T
    inertia.setflags(write=False)
    poses = {p: RestingPose(p, tuple(v["xyz"]), tuple(v["rpy"]), v["support_margin"])
             for p, v in d["poses"].items()}
    return LibraryObject(
        id=obj_id, category=d["category"], material=d["material"], density=d["density"],
        part_materials=MappingProxyType(dict(d["part_materials"])), mass=d["mass"],
        volume=d["volume"], cavity_volume=d["cavity_volume"],
        cavity_centroid=None if d["cavity_centroid"] is None else tuple(d["cavity_centroid"]),
        com=tuple(d["com"]),
        inertia=inertia, extents=tuple(d["extents"]),
        dimensions=MappingProxyType(dict(d["dimensions"])),
        parts=tuple(p for p in PART_LABELS if p in d["parts"]),
        grasp_widths=MappingProxyType(dict(d["grasp_widths"])),
        poses=MappingProxyType(poses), n_vertices=d["n_vertices"], n_triangles=d["n_triangles"],
        root=root, labels_source=d.get("labels", "generated"),
        stable_poses=_stable_poses(d.get("stable_poses") or ()),
        source=None if d.get("source") is None else MappingProxyType(dict(d["source"])))


def load_library(path: str | Path | None = None) -> MappingProxyType:
    """Object id → LibraryObject of one library, in its order (the shipped one, by category then
    instance, when `path` is None; else the library folder `path` or its library.yaml). Cached
    per folder and library.yaml version (a library written again is read again); does not
    register a user library (`add_library` does)."""
    if path is None:
        return _load_shipped()
    root = Path(path).expanduser()
    if root.name == "library.yaml":
        root = root.parent
    root = root.resolve()
    try:
        st = (root / "library.yaml").stat()
        version = (st.st_mtime_ns, st.st_size)
    except OSError:
        version = None  # _load_folder says what is missing
    return _load_folder(root, version)


@functools.cache
def _load_shipped() -> MappingProxyType:
    path = library_path()
    if not path.is_file():
        raise ModelError("object library missing; run `python tools/make_objects.py`",
                         file=str(path))
    with open(path) as f:
        data = yaml.load(f, Loader=SAFE_LOADER)
    try:
        objects = {k: _object(k, v, shipped_root()) for k, v in data["objects"].items()}
    except (KeyError, TypeError) as e:
        raise ModelError(f"malformed object library entry: {e}", file=str(path)) from None
    for o in objects.values():
        if o.category not in CATEGORIES:
            raise unknown_name("category", o.category, CATEGORIES, error=ModelError,
                               file=str(path), field=f"objects.{o.id}.category")
    return MappingProxyType(objects)


@functools.cache
def _load_folder(root: Path, version) -> MappingProxyType:
    """A user library; ModelError naming library.yaml and the field for a malformed one."""
    path = root / "library.yaml"
    if not root.is_dir():
        raise ModelError("no such object library folder", file=str(root))
    if not path.is_file():
        raise ModelError("not an object library: it has no library.yaml (`tg-drake "
                         "import-object --out DIR` writes one)", file=str(path))
    try:
        data = yaml.load(path.read_text(encoding="utf-8"), Loader=SAFE_LOADER)
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as e:
        raise ModelError(f"cannot read the object library: {' '.join(str(e).split())}",
                         file=str(path)) from None
    entries = data.get("objects") if isinstance(data, dict) else None
    if not isinstance(entries, dict):
        raise ModelError("expected a mapping `objects: {id: entry}`", file=str(path),
                         field="objects")
    objects = {}
    for obj_id, d in entries.items():
        field = f"objects.{obj_id}"
        if not isinstance(d, dict):
            raise ModelError("expected a mapping of the entry's fields", file=str(path),
                             field=field)
        missing = [k for k in REQUIRED_FIELDS if k not in d]
        if missing:
            raise ModelError(f"missing {', '.join(missing)}", file=str(path),
                             field=f"{field}.{missing[0]}")
        try:
            o = _object(str(obj_id), d, root)
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as e:
            raise ModelError(f"malformed entry: {e}", file=str(path), field=field) from None
        if o.category is not None and o.category not in CATEGORIES:
            raise unknown_name("category", o.category, CATEGORIES, error=ModelError,
                               file=str(path), field=f"{field}.category")
        if o.labels_source not in LABEL_SOURCES:
            raise unknown_name("label source", o.labels_source, LABEL_SOURCES,
                               error=ModelError, file=str(path), field=f"{field}.labels")
        objects[o.id] = o
    return MappingProxyType(objects)


# The fields every library.yaml entry has (models/objects/library.yaml).
REQUIRED_FIELDS = ("category", "material", "density", "part_materials", "mass", "volume",
                   "cavity_volume", "cavity_centroid", "com", "inertia", "extents", "dimensions",
                   "parts", "grasp_widths", "poses", "n_vertices", "n_triangles")

# Registered user libraries (folder → objects) and single imported objects (id → object).
_LIBRARIES: dict[Path, MappingProxyType] = {}
_OBJECTS: dict[str, LibraryObject] = {}


def _where(obj: LibraryObject) -> str:
    return "the shipped library" if obj.shipped else f"the library {obj.root}"


def _holder(obj_id: str) -> LibraryObject | None:
    """The object registered (or shipped) under `obj_id`, or None."""
    if obj_id in _load_shipped():
        return _load_shipped()[obj_id]
    for lib in _LIBRARIES.values():
        if obj_id in lib:
            return lib[obj_id]
    return _OBJECTS.get(obj_id)


def _check_clash(obj: LibraryObject) -> None:
    other = _holder(obj.id)
    if other is not None and other.directory.resolve() != obj.directory.resolve():
        raise ModelError(f"object id {obj.id!r} is in both {_where(other)} and {_where(obj)}; "
                         "give one of them another id")


def add_library(path: str | Path) -> MappingProxyType:
    """Registers the user library at folder `path` (get_object then finds its objects) and returns
    its objects. Registering it again does nothing unless its library.yaml changed (then its
    objects are read again); an id another library holds is a ModelError naming both libraries."""
    lib = load_library(path)
    root = next(iter(lib.values())).root if lib else Path(path).expanduser().resolve()
    if _LIBRARIES.get(root) is lib:
        return lib
    for obj in lib.values():
        if not obj.sdf_path.is_file():
            raise ModelError(f"{obj.id}'s SDF is missing (the library lists it; its folder "
                             "holds no model)", file=str(obj.sdf_path))
        _check_clash(obj)
    _LIBRARIES[root] = lib
    return lib


def register_object(obj: LibraryObject) -> LibraryObject:
    """Registers one (imported) object so that get_object finds it; again the same object does
    nothing, another object under a registered id is a ModelError naming both."""
    _check_clash(obj)
    if _holder(obj.id) is None:
        _OBJECTS[obj.id] = obj
    return obj


def registered_libraries() -> tuple[Path, ...]:
    return tuple(_LIBRARIES)


def forget_registered() -> None:
    """Drops every registered library and object (tests)."""
    _LIBRARIES.clear()
    _OBJECTS.clear()


def get_object(obj_id: str) -> LibraryObject:
    """The object `obj_id` of the shipped library or a registered one; ScenarioError listing the
    valid ids when unknown."""
    obj = _holder(obj_id)
    if obj is None:
        known = list(_load_shipped()) + [i for lib in _LIBRARIES.values() for i in lib] \
            + list(_OBJECTS)
        raise unknown_name("object", obj_id, known, error=ScenarioError)
    return obj


def library_by_category() -> dict[str, tuple[LibraryObject, ...]]:
    """Category → its objects, for every entry of CATEGORIES (in that order)."""
    lib = load_library().values()
    return {c: tuple(o for o in lib if o.category == c) for c in CATEGORIES}


def _as_object(obj: LibraryObject | str) -> LibraryObject:
    return get_object(obj) if isinstance(obj, str) else obj


@functools.cache
def _mesh(directory: Path, obj_id: str):
    mesh_path, parts_path = directory / f"{obj_id}.obj", directory / f"{obj_id}_parts.npy"
    try:
        text = mesh_path.read_text()
        labels = np.load(parts_path)
    except OSError as e:
        raise ModelError(f"cannot read {obj_id}'s mesh: {e}", file=str(directory)) from None
    lines = text.splitlines()
    V = np.array([ln.split()[1:4] for ln in lines if ln.startswith("v ")], float)
    F = np.array([[t.split("/")[0] for t in ln.split()[1:4]]
                  for ln in lines if ln.startswith("f ")],
                 np.int64) - 1
    if len(labels) != len(V) or F.min() < 0 or F.max() >= len(V):
        raise ModelError(f"{obj_id}: {len(V)} vertices, {len(labels)} part labels, face indices "
                         f"{F.min()}..{F.max()}", file=str(mesh_path))
    for a in (V, F, labels):
        a.setflags(write=False)
    return V, F, labels


def obj_text(V: np.ndarray, F: np.ndarray, *, name: str, comment: str) -> str:
    """Wavefront OBJ of the triangles (V, F) (V [m] at 1 nm, F 0-based): the `v` and `f` lines
    `mesh` reads, under a `# {name}: {comment}` line and an object named `name`."""
    v = "\n".join(f"v {x:.9f} {y:.9f} {z:.9f}" for x, y, z in np.asarray(V, float).tolist())
    f = "\n".join(f"f {a} {b} {c}" for a, b, c in (np.asarray(F) + 1).tolist())
    return f"# {name}: {comment}\no {name}\n{v}\n{f}\n"


def mesh(obj: LibraryObject | str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertices (V, 3) [m] in O, triangles (F, 3) int, part label per vertex (V,) uint8).

    Read-only arrays, cached per object folder. Triangles are anticlockwise seen from outside
    (outward normals).
    """
    o = _as_object(obj)
    return _mesh(o.directory, o.id)


def box_centre(obj: LibraryObject | str) -> np.ndarray:
    """(3,) the centre of the object's bounding box in its frame O [m]. O's origin sits at the
    object's base, so a lying object's centre is half a length from it."""
    V = mesh(obj)[0]
    return 0.5 * (V.min(axis=0) + V.max(axis=0))


def sample_surface(obj: LibraryObject | str, *, n: int | None = None,
                   spacing: float | None = None, rng: np.random.Generator):
    """Points uniformly distributed on the object's surface (the paper's S_SYN point clouds).

    Give either `n` points or a `spacing` [m]: then n = surface area / spacing², so the number of
    points grows with the object's size. Triangles are drawn in proportion to their area and points
    uniformly inside them. Returns (p_O (n, 3) [m], n_O (n, 3) outward unit normals, labels (n,)
    int part labels: that of the triangle's vertex nearest to the point).
    """
    if (n is None) == (spacing is None):
        raise ValueError("give exactly one of n and spacing")
    V, F, L = mesh(obj)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    cross = np.cross(b - a, c - a)
    area2 = np.linalg.norm(cross, axis=1)
    if spacing is not None:
        if not spacing > 0:
            raise ValueError(f"spacing must be positive, got {spacing}")
        n = max(1, int(round(0.5 * area2.sum() / spacing ** 2)))
    if n < 1:
        raise ValueError(f"n must be at least 1, got {n}")
    tri = rng.choice(len(F), size=n, p=area2 / area2.sum())
    r1, r2 = rng.random(n), rng.random(n)
    s = np.sqrt(r1)
    w = np.stack([1 - s, s * (1 - r2), s * r2], 1)  # barycentric weights, uniform on the triangle
    p_O = w[:, :1] * a[tri] + w[:, 1:2] * b[tri] + w[:, 2:] * c[tri]
    n_O = cross[tri] / area2[tri, None]
    labels = L[F[tri, np.argmax(w, axis=1)]].astype(np.int64)
    return p_O, n_O, labels


# ------------------------------------------------------------------------------------------------
# tg-drake objects


def add_arguments(parser) -> None:
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument("--category", choices=CATEGORIES, help="only this category")
    parser.add_argument("--library", metavar="DIR",
                        help="list the user library in folder DIR instead of the shipped one")


def _row(o: LibraryObject) -> dict:
    row = {"id": o.id, "category": o.category, "material": o.material,
           "extents": list(o.extents), "mass": o.mass, "parts": list(o.parts),
           "poses": list(o.poses), "cavity_volume": o.cavity_volume,
           "sdf": o.sdf_url}
    if not o.shipped:
        row.update(labels=o.labels_source,
                   stable_poses=[{"pose": p.pose, "probability": p.probability}
                                 for p in o.stable_poses],
                   source=None if o.source is None else dict(o.source))
    return row


def main(args) -> int:
    library = getattr(args, "library", None)
    objs = [o for o in load_library(library).values()
            if args.category is None or o.category == args.category]
    if args.json:
        print(json.dumps([_row(o) for o in objs], indent=1))
        return 0
    print(f"{'id':16s} {'category':12s} {'material':10s} {'size x×y×z [cm]':18s} "
          f"{'mass [kg]':>9s}  parts")
    for o in objs:
        size = "×".join(f"{100 * e:.1f}" for e in o.extents)
        print(f"{o.id:16s} {o.category or '-':12s} {o.material:10s} {size:18s} {o.mass:9.3f}  "
              f"{', '.join(o.parts)}")
    print(f"{len(objs)} objects")
    return 0
