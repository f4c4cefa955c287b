"""What a user names → the mesh file to import and the scale its model file gives.

Accepted: a mesh file (OBJ, STL, PLY, GLB/GLTF, DAE); a Google Scanned Objects folder (model.sdf +
meshes/model.obj); a YCB object folder (google_16k/textured.obj, else tsdf/textured.obj); an SDF or
URDF file with exactly one body (the mesh of its visual, else of its collision, with its <scale>);
a folder holding exactly one of those. ``package://`` URIs resolve through the shipped models'
package and ROS_PACKAGE_PATH (Drake's PackageMap); ``file://`` and relative URIs against the file.
"""

from __future__ import annotations

import hashlib
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.multibody.parsing import PackageMap

from tg_drake.errors import ModelError
from tg_drake.models import models_root

MESH_SUFFIXES: tuple[str, ...] = (".obj", ".stl", ".ply", ".glb", ".gltf", ".dae")
MODEL_SUFFIXES: tuple[str, ...] = (".sdf", ".urdf")
# Folder layouts, in the order they are tried: (what it is, its mesh or model file).
FOLDER_LAYOUTS: tuple[tuple[str, str], ...] = (
    ("Google Scanned Objects", "model.sdf"),
    ("Google Scanned Objects", "meshes/model.obj"),
    ("YCB", "google_16k/textured.obj"),
    ("YCB", "tsdf/textured.obj"),
)
ALLOWED = (f"a mesh file ({', '.join(s[1:].upper() for s in MESH_SUFFIXES)}), an SDF or URDF "
           "with one body, a Google Scanned Objects folder (model.sdf, meshes/model.obj) or a YCB "
           "folder (google_16k/textured.obj or tsdf/textured.obj)")


@dataclass(frozen=True)
class Source:
    """The resolved input of one import."""

    given: Path  # what the user named (file or folder)
    mesh_file: Path  # the mesh file to load
    kind: str  # "mesh" | "sdf" | "urdf" | "Google Scanned Objects" | "YCB"
    scale: tuple[float, float, float]  # per-axis factor from the model file (1, 1, 1 if none)
    files: tuple[Path, ...]  # the files whose content defines the import (hashed for the cache)
    name: str  # a default object id: the file's or folder's name, sanitised

    def sha256(self) -> str:
        """Content hash of every file that defines the import (names excluded)."""
        h = hashlib.sha256()
        for f in self.files:
            h.update(f.read_bytes())
            h.update(b"\0")
        return h.hexdigest()


def sanitise_id(name: str) -> str:
    """A library id from a file or folder name: lower case, [a-z0-9_], starting with a letter."""
    s = re.sub(r"[^a-z0-9_]+", "_", name.lower()).strip("_")
    if not s:
        s = "object"
    if not s[0].isalpha():
        s = "obj_" + s
    return s


def resolve(path: str | Path) -> Source:
    """The Source for a path a user gave; ModelError naming the file and what is allowed."""
    given = Path(path).expanduser()
    if not given.exists():
        raise ModelError(f"no such file or folder; allowed: {ALLOWED}", file=str(given))
    if given.is_dir():
        return _folder(given)
    suffix = given.suffix.lower()
    if suffix in MESH_SUFFIXES:
        return Source(given, given, "mesh", (1.0, 1.0, 1.0), (given,), sanitise_id(given.stem))
    if suffix in MODEL_SUFFIXES:
        return _model_file(given, given, sanitise_id(given.stem))
    raise ModelError(f"unknown format {given.suffix or '(no suffix)'!r}; allowed: {ALLOWED}",
                     file=str(given))


def _folder(folder: Path) -> Source:
    name = sanitise_id(folder.name)
    for kind, rel in FOLDER_LAYOUTS:
        f = folder / rel
        if f.is_file():
            if f.suffix == ".sdf":
                s = _model_file(f, folder, name)
                return Source(folder, s.mesh_file, kind, s.scale, s.files, name)
            return Source(folder, f, kind, (1.0, 1.0, 1.0), (f,), name)
    found = sorted(p for p in folder.iterdir()
                   if p.is_file() and p.suffix.lower() in MESH_SUFFIXES + MODEL_SUFFIXES)
    models = [p for p in found if p.suffix.lower() in MODEL_SUFFIXES]
    candidates = models or found
    if len(candidates) == 1:
        s = resolve(candidates[0])
        return Source(folder, s.mesh_file, s.kind, s.scale, s.files, name)
    what = (f"{len(candidates)} candidates ({', '.join(p.name for p in candidates)})"
            if candidates else "no mesh or model file")
    raise ModelError(f"folder holds {what}; allowed: {ALLOWED}", file=str(folder))


def _model_file(model: Path, given: Path, name: str) -> Source:
    """The mesh and scale of an SDF's or URDF's single body."""
    try:
        root = ET.parse(model).getroot()
    except (ET.ParseError, OSError) as e:
        raise ModelError(f"cannot read the model file: {e}", file=str(model)) from None
    urdf = model.suffix.lower() == ".urdf"
    links = root.findall(".//link")
    if len(links) != 1:
        raise ModelError(f"{len(links)} bodies (<link>); allowed: a model with exactly one body",
                         file=str(model))
    link = links[0]
    meshes = []
    for tag in ("visual", "collision"):
        for g in link.findall(f"{tag}/geometry/mesh"):
            if urdf:
                uri, scale = g.get("filename"), g.get("scale")
            else:
                u, s = g.find("uri"), g.find("scale")
                uri, scale = (u.text if u is not None else None), (s.text if s is not None
                                                                  else None)
            if uri:
                meshes.append((uri.strip(), scale))
        if meshes:
            break
    if not meshes:
        raise ModelError("its body has no <visual> or <collision> mesh; allowed: a body whose "
                         "geometry is a mesh file", file=str(model))
    uris = {u for u, _ in meshes}
    if len(uris) > 1:
        raise ModelError(f"its body has {len(uris)} meshes ({', '.join(sorted(uris))}); "
                         "allowed: one mesh", file=str(model))
    uri, scale_text = meshes[0]
    mesh_file = _uri_path(uri, model)
    try:
        scale = (1.0, 1.0, 1.0) if scale_text is None else tuple(
            float(x) for x in scale_text.split())
    except ValueError:
        scale = ()
    if len(scale) != 3 or not all(np.isfinite(scale)) or min(scale) <= 0:
        raise ModelError(f"mesh scale {scale_text!r}; allowed: three positive numbers",
                         file=str(model))
    if not mesh_file.is_file():
        raise ModelError(f"its mesh {uri!r} does not exist ({mesh_file})", file=str(model))
    if mesh_file.suffix.lower() not in MESH_SUFFIXES:
        raise ModelError(f"its mesh {uri!r} has unknown format {mesh_file.suffix!r}; allowed: "
                         f"{', '.join(MESH_SUFFIXES)}", file=str(model))
    kind = "urdf" if urdf else "sdf"
    return Source(given, mesh_file, kind, scale, (model, mesh_file), name)


def _uri_path(uri: str, model: Path) -> Path:
    if uri.startswith("file://"):
        return Path(uri[len("file://"):])
    if uri.startswith("model://"):  # Gazebo: model://<model folder>/<path>
        rest = uri[len("model://"):].split("/", 1)
        return model.parent / (rest[1] if len(rest) == 2 else rest[0])
    if uri.startswith("package://"):
        return Path(resolve_package_uri(uri, file=str(model)))
    return model.parent / uri


def resolve_package_uri(uri: str, *, file: str | None = None) -> str:
    """A package://name/path URI as a file path: the shipped models' package, else a package
    on ROS_PACKAGE_PATH. ModelError naming the known packages if unknown."""
    name, _, rest = uri[len("package://"):].partition("/")
    packages = PackageMap.MakeEmpty()
    packages.AddPackageXml(f"{models_root()}/package.xml")
    packages.PopulateFromRosPackagePath()
    if not packages.Contains(name):
        raise ModelError(f"unknown package {name!r} in {uri!r}; allowed: "
                         f"{', '.join(sorted(packages.GetPackageNames()))}", file=file)
    return f"{packages.GetPath(name)}/{rest}"
