"""The object-wise split: which objects a model or a threshold may be fit on, which are held out.

Every fitted figure (the hold model, a perception likelihood, the kernel database, a learned
theory) is fit on `train` objects only and reported on `held_out` ones; nothing is tuned on
the suites we report (docs/results/generalization.md, the protocol). The split is one file,
`scenarios/suites/split.yaml`, with one entry per object set:

    sets:
      a:                          # the shipped library (tools/make_objects.py)
        library: objects          # a folder of the tg_drake_models package (models/)
        train: [pan_01, ...]
        held_out: [pan_04, ...]
      b: {library: objects_b, train: [...], held_out: [...]}

`load_split()` reads and checks it: every object of a set's library is in exactly one of its
`train` and `held_out`, no id is in two sets, and every category of a set has objects on both
sides (a per-category, object-wise split). A scan-like version of an object (`<id>_scan`, written
by tools/make_scanlike.py) is on the side of its original.

    from tg_drake.evaluation.split import load_split
    split = load_split()                 # every set
    split.train, split.held_out          # object ids (tuples)
    load_split("a").held_out             # one set: ('pan_04', 'pot_04', ...)
    split.role("cup_b03_scan")           # 'held_out'
    split.register_libraries()           # get_object then finds the objects of every set
"""

from __future__ import annotations

import importlib.resources
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import yaml

from tg_drake.errors import ScenarioError, TgDrakeError, unknown_name
from tg_drake.objects import PACKAGE, add_library, load_library, shipped_root
from tg_drake.types import SCANLIKE_SUFFIX  # noqa: F401 (the split's ids; re-exported)

SPLIT_PATH = Path(__file__).resolve().parents[2] / "scenarios" / "suites" / "split.yaml"
ROLES = ("train", "held_out")


@dataclass(frozen=True)
class ObjectSet:
    """One object set of the split: its library folder and its two sides."""

    name: str
    library: Path  # the library folder (library.yaml and <id>/)
    train: tuple[str, ...]
    held_out: tuple[str, ...]

    @property
    def shipped(self) -> bool:
        return self.library.resolve() == shipped_root().resolve()

    @property
    def ids(self) -> tuple[str, ...]:
        return self.train + self.held_out


@dataclass(frozen=True)
class Split:
    """The split of the sets asked for: ids on each side (in the file's order, set by set)."""

    train: tuple[str, ...]
    held_out: tuple[str, ...]
    sets: Mapping[str, ObjectSet]

    def role(self, obj_id: str) -> str:
        """"train" or "held_out" for an object id or its scan-like version (<id>_scan);
        ScenarioError for an id of none of the sets."""
        for oid in (obj_id, obj_id.removesuffix(SCANLIKE_SUFFIX)):
            if oid in self.train:
                return "train"
            if oid in self.held_out:
                return "held_out"
        raise ScenarioError(f"object {obj_id!r} is in no object set of the split "
                            f"({', '.join(self.sets)})")

    def set_of(self, obj_id: str) -> ObjectSet:
        """The object set holding `obj_id` (or the original of a scan-like version)."""
        base = obj_id.removesuffix(SCANLIKE_SUFFIX)
        for s in self.sets.values():
            if obj_id in s.ids or base in s.ids:
                return s
        raise ScenarioError(f"object {obj_id!r} is in no object set of the split "
                            f"({', '.join(self.sets)})")

    def register_libraries(self) -> None:
        """Registers the user libraries of the split's sets (tg_drake.objects.add_library), so that
        get_object finds every id of the split."""
        for s in self.sets.values():
            if not s.shipped:
                add_library(s.library)


def library_folder(name: str) -> Path:
    """A set's `library:` value → its folder: a folder of the tg_drake_models package (models/),
    or an absolute path."""
    p = Path(name).expanduser()
    return p if p.is_absolute() else Path(str(importlib.resources.files(PACKAGE))) / p


def _ids(value, path: Path, field: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ScenarioError("expected a list of object ids", file=str(path), field=field)
    dup = sorted({v for v in value if value.count(v) > 1})
    if dup:
        raise ScenarioError(f"listed twice: {', '.join(dup)}", file=str(path), field=field)
    return tuple(value)


def _object_set(name: str, d, path: Path) -> ObjectSet:
    where = f"sets.{name}"
    if not isinstance(d, dict):
        raise ScenarioError("expected a mapping with library, train, held_out", file=str(path),
                            field=where)
    extra = sorted(set(d) - {"library", "train", "held_out", "description"})
    if extra:
        raise unknown_name("key", extra[0], ("library", "train", "held_out", "description"),
                           error=ScenarioError, file=str(path), field=where)
    for key in ("library", "train", "held_out"):
        if key not in d:
            raise ScenarioError(f"missing {key}", file=str(path), field=f"{where}.{key}")
    train = _ids(d["train"], path, f"{where}.train")
    held = _ids(d["held_out"], path, f"{where}.held_out")
    both = sorted(set(train) & set(held))
    if both:
        raise ScenarioError(f"on both sides: {', '.join(both)}", file=str(path),
                            field=f"{where}.held_out")
    folder = library_folder(str(d["library"]))
    try:
        lib = load_library(folder)
    except TgDrakeError as e:
        raise ScenarioError(f"cannot read the set's library: {e}", file=str(path),
                            field=f"{where}.library") from None
    unknown = [i for i in train + held if i not in lib]
    if unknown:
        raise unknown_name("object", unknown[0], list(lib), error=ScenarioError, file=str(path),
                           field=where)
    missing = [i for i in lib if i not in train + held]
    if missing:
        raise ScenarioError(f"the library's objects {', '.join(missing)} are on neither side",
                            file=str(path), field=where)
    for cat in dict.fromkeys(o.category for o in lib.values()):
        sides = [any(lib[i].category == cat for i in ids) for ids in (train, held)]
        if not all(sides):
            raise ScenarioError(f"category {cat} has no {ROLES[sides.index(False)]} object "
                                "(the split is per category)", file=str(path), field=where)
    return ObjectSet(name, folder, train, held)


def load_split(sets: str | Iterable[str] | None = None, *, path: str | Path | None = None
               ) -> Split:
    """The split of `sets` (a set name, several, or every set of the file when None) from
    `path` (default scenarios/suites/split.yaml); ScenarioError naming the file and field."""
    path = Path(path) if path is not None else SPLIT_PATH
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as e:
        raise ScenarioError(f"cannot read the split: {' '.join(str(e).split())}",
                            file=str(path)) from None
    entries = data.get("sets") if isinstance(data, dict) else None
    if not isinstance(entries, dict) or not entries:
        raise ScenarioError("expected `sets: {name: {library, train, held_out}}`", file=str(path),
                            field="sets")
    names = list(entries) if sets is None else [sets] if isinstance(sets, str) else list(sets)
    for n in names:
        if n not in entries:
            raise unknown_name("object set", n, list(entries), error=ScenarioError,
                               file=str(path), field="sets")
    chosen = {n: _object_set(str(n), entries[n], path) for n in names}
    seen: dict[str, str] = {}
    for s in chosen.values():
        for i in s.ids:
            if i in seen:
                raise ScenarioError(f"object {i!r} is in sets {seen[i]} and {s.name}",
                                    file=str(path), field=f"sets.{s.name}")
            seen[i] = s.name
    return Split(train=tuple(i for s in chosen.values() for i in s.train),
                 held_out=tuple(i for s in chosen.values() for i in s.held_out),
                 sets=MappingProxyType(chosen))
