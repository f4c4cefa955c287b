"""The layers of tg_drake, checked on its import graph.

Every `import` and `from ... import` statement in tg_drake/ is read with `ast`, wherever it stands
(module level, inside functions or methods, under `if TYPE_CHECKING:`), and resolved to an
absolute module name. Two rules:

1. The cores (tg_drake.perception, kernels, logic, grasping, planning, importing, tasks) import
   neither the Drake systems framework (pydrake.systems.*), the simulation (tg_drake.station,
   tg_drake.simulation), the systems (tg_drake.systems), evaluation (tg_drake.evaluation,
   tg_drake.executor) nor the application (tg_drake.run, cli, diagram, render).
2. There is no import cycle between the units of tg_drake, a unit being one entry of the package's
   top level: a subpackage (tg_drake.perception with everything below it) or a module
   (tg_drake.station). Nor is there a cycle between the modules inside a subpackage.

And one policy: an import inside a function is kept only where start-up time or an optional
dependency needs it — in the command modules that `tg-drake --help` imports (cli.COMMANDS), or
of an optional or slow library (OPTIONAL_OR_SLOW); every other import stands at module level, where
the dependency graph can be read.

Imports by name at run time (`importlib.import_module` in cli.COMMANDS and bench.FIGURES) are not
statements and are not checked.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

import pytest

import tg_drake

CORES = ("perception", "kernels", "logic", "grasping", "planning", "importing", "tasks")
FORBIDDEN_IN_CORES = (
    "pydrake.systems",
    "tg_drake.station", "tg_drake.simulation", "tg_drake.systems",
    "tg_drake.evaluation", "tg_drake.executor",
    "tg_drake.run", "tg_drake.cli", "tg_drake.diagram", "tg_drake.render",
)


# Libraries imported inside functions anywhere: optional extras (ray, grakel), the slow ones
# used for one output (matplotlib for pictures, tqdm for a progress bar) and the object import
# (trimesh, a convex decomposition), which only a scenario's `mesh:` entries need.
OPTIONAL_OR_SLOW = ("ray", "grakel", "matplotlib", "tqdm", "tg_drake.importing")


@dataclass(frozen=True)
class Import:
    source: str  # the importing module, e.g. "tg_drake.kernels.library"
    target: str  # the imported module, e.g. "tg_drake.perception.render"
    path: Path
    line: int
    local: bool = False  # inside a function

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: {self.source} imports {self.target}"


def modules_of(root: Path, package: str) -> dict[str, Path]:
    """Dotted module name → file, for every .py file of the package at `root`."""
    modules = {}
    for path in sorted(root.rglob("*.py")):
        parts = (package, *path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        modules[".".join(parts)] = path
    return modules


def imports_of(root: Path, package: str) -> list[Import]:
    """Every import statement of the package at `root`, resolved to absolute module names.

    `from a.b import c` imports a.b, and a.b.c too when that is a module of the package.
    """
    modules = modules_of(root, package)
    found = []
    for source, path in modules.items():
        is_package = path.name == "__init__.py"
        tree = ast.parse(path.read_text(), filename=str(path))
        in_function = {id(n) for f in ast.walk(tree)
                       if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
                       for n in ast.walk(f) if n is not f}
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:  # relative: from the importing module's package upwards
                    here = source.split(".") if is_package else source.split(".")[:-1]
                    here = here[:len(here) - (node.level - 1)]
                    base = ".".join(here + ([base] if base else []))
                targets = [base] + [f"{base}.{a.name}" for a in node.names
                                    if f"{base}.{a.name}" in modules]
            else:
                continue
            found += [Import(source, t, path, node.lineno, id(node) in in_function)
                      for t in targets]
    return found


def _within(name: str, prefix: str) -> bool:
    return name == prefix or name.startswith(prefix + ".")


def core_violations(imports: list[Import], package: str = "tg_drake") -> list[Import]:
    """Imports of a core that break rule 1."""
    cores = [f"{package}.{c}" for c in CORES]
    forbidden = [f.replace("tg_drake", package, 1) for f in FORBIDDEN_IN_CORES]
    return [i for i in imports
            if any(_within(i.source, c) for c in cores)
            and any(_within(i.target, f) for f in forbidden)]


def misplaced_local_imports(imports: list[Import], command_modules) -> list[Import]:
    """Imports inside functions that neither a command module's start-up nor an optional or slow
    library explains."""
    return [i for i in imports if i.local and i.source not in command_modules
            and not any(_within(i.target, m) for m in OPTIONAL_OR_SLOW)]


def unit_of(module: str, package: str, depth: int) -> str | None:
    """The first `depth` components below `package` ("tg_drake.kernels" for depth 1), or None
    for a module outside the package."""
    parts = module.split(".")
    if parts[0] != package:
        return None
    return ".".join(parts[:1 + depth])


def cycles(imports: list[Import], units) -> list[list[Import]]:
    """Import cycles between units: one list of imports (u1 → u2 → … → u1) per strongly
    connected component of more than one unit. `units(module)` names a module's unit, or None
    for modules outside the graph."""
    edges: dict[str, dict[str, Import]] = {}
    for i in imports:
        a, b = units(i.source), units(i.target)
        if a and b and a != b:
            edges.setdefault(a, {}).setdefault(b, i)
    # Tarjan's strongly connected components.
    index, low, stack, on_stack, components = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in edges.get(v, {}):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = set()
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.add(w)
                if w == v:
                    break
            if len(component) > 1:
                components.append(component)

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return [_shortest_cycle(edges, component) for component in components]


def _shortest_cycle(edges: dict[str, dict[str, Import]], component: set[str]) -> list[Import]:
    """A shortest closed path through the first unit of a strongly connected component, as the
    imports along it (a breadth-first search inside the component)."""
    start = min(component)
    came_from = {start: None}
    frontier = [start]
    while frontier:
        nxt = []
        for u in frontier:
            for w in sorted(edges.get(u, {})):
                if w not in component:
                    continue
                if w == start:  # closed: walk back to the start
                    path, v = [edges[u][start]], u
                    while came_from[v] is not None:
                        path.append(edges[came_from[v]][v])
                        v = came_from[v]
                    return path[::-1]
                if w not in came_from:
                    came_from[w] = u
                    nxt.append(w)
        frontier = nxt
    raise AssertionError(f"{sorted(component)} is not a cycle")


def check(root: Path, package: str) -> list[str]:
    """Every break of the two rules in the package at `root`, as readable lines."""
    imports = imports_of(root, package)
    problems = [f"a core imports a higher layer: {i}" for i in core_violations(imports, package)]
    for cycle in cycles(imports, lambda m: unit_of(m, package, 1)):
        problems.append("import cycle between units: " + _path(cycle, package, 1))
    subpackages = {unit_of(m, package, 1) for m, p in modules_of(root, package).items()
                   if p.name == "__init__.py" and m != package}
    for sub in sorted(subpackages):
        def unit(m, sub=sub):
            return m if _within(m, sub) and m != sub else None

        for cycle in cycles(imports, unit):
            problems.append(f"import cycle inside {sub}: " + _path(cycle, package, None))
    return problems


def _path(cycle: list[Import], package: str, depth: int | None) -> str:
    """`a -> b -> a` over the cycle's units (modules when depth is None), then its imports."""
    names = [i.source if depth is None else unit_of(i.source, package, depth) for i in cycle]
    return " -> ".join(names + names[:1]) + "".join(f"\n    {i}" for i in cycle)


ROOT = Path(tg_drake.__file__).parent


def test_tg_drake_keeps_its_layers():
    problems = check(ROOT, "tg_drake")
    assert not problems, "\n".join(problems)


def test_the_walk_sees_every_module_and_imports_inside_functions():
    imports = imports_of(ROOT, "tg_drake")
    sources = {i.source for i in imports}
    assert {"tg_drake.cli", "tg_drake.perception.pipeline",
            "tg_drake.simulation.episode"} <= sources
    # A core importing another core, and the CLI's run-time import of os inside main().
    assert any(i.source == "tg_drake.kernels.library" and i.target == "tg_drake.perception.render"
               for i in imports)
    assert any(i.source == "tg_drake.cli" and i.target == "os" for i in imports)


def test_imports_inside_functions_only_for_start_up_or_an_optional_library():
    from tg_drake.cli import COMMANDS

    misplaced = misplaced_local_imports(imports_of(ROOT, "tg_drake"), set(COMMANDS.values()))
    assert not misplaced, "imports to move to module level:\n" + "\n".join(map(str, misplaced))


def test_the_policy_on_imports_inside_functions_can_fail(tmp_path):
    root = tmp_path / "pkg"
    _write(root, {
        "__init__.py": "",
        "cli.py": "def main():\n    import pydrake.all\n",  # a command module: start-up
        "plots.py": "import numpy\n\ndef draw():\n    import matplotlib.pyplot\n",
        "station.py": "class Station:\n    def add(self):\n        from pkg.objects import get\n",
        "objects.py": "get = lambda: (lambda: __import__('os'))\n",
    })
    misplaced = misplaced_local_imports(imports_of(root, "pkg"), {"pkg.cli"})
    assert [(i.source, i.target, i.line) for i in misplaced] == [
        ("pkg.station", "pkg.objects", 3)]


def _write(root: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)


def test_the_check_finds_a_core_importing_the_systems_framework_inside_a_function(tmp_path):
    root = tmp_path / "pkg"
    _write(root, {
        "__init__.py": "",
        "kernels/__init__.py": "",
        "kernels/library.py": "import numpy\n\ndef views():\n"
                              "    from pkg.evaluation.jobs import perceive\n    return perceive\n",
        "planning/__init__.py": "",
        "planning/ik.py": "from pydrake.systems.framework import DiagramBuilder\n",
        "grasping/__init__.py": "from . import dgi\n",
        "grasping/dgi.py": "from ..station import make_parser\n",
        "evaluation/__init__.py": "",
        "evaluation/jobs.py": "perceive = None\n",
        "station.py": "",
    })
    problems = check(root, "pkg")
    assert sorted(p for p in problems if p.startswith("a core")) == sorted(
        f"a core imports a higher layer: {root / path}:{line}: {source} imports {target}"
        for path, line, source, target in [
            ("grasping/dgi.py", 1, "pkg.grasping.dgi", "pkg.station"),
            ("kernels/library.py", 4, "pkg.kernels.library", "pkg.evaluation.jobs"),
            ("planning/ik.py", 1, "pkg.planning.ik", "pydrake.systems.framework"),
        ])
    assert not [p for p in problems if "cycle" in p]


def test_the_check_finds_cycles_between_units_and_inside_a_package(tmp_path):
    root = tmp_path / "pkg"
    _write(root, {
        "__init__.py": "",
        "kernels/__init__.py": "",
        # kernels -> perception (module level) -> objects -> kernels (inside a function)
        "kernels/library.py": "from pkg.perception.render import perceive\n",
        "perception/__init__.py": "",
        "perception/render.py": "import pkg.objects\nperceive = None\n",
        "objects.py": "def f():\n    from pkg.kernels import library\n",
        # inside logic: engine -> theory -> engine, through a relative import
        "logic/__init__.py": "",
        "logic/engine.py": "from .theory import T\n",
        "logic/theory.py": "T = 1\ndef g():\n    from pkg.logic.engine import E\n",
        # no cycle: station -> types, types imports nothing of the package
        "station.py": "import pkg.types\n",
        "types.py": "import numpy\n",
    })
    problems = check(root, "pkg")
    between = [p for p in problems if p.startswith("import cycle between units")]
    inside = [p for p in problems if p.startswith("import cycle inside")]
    assert len(between) == 1 and len(inside) == 1, "\n".join(problems)
    assert between[0].splitlines()[0] == (
        "import cycle between units: pkg.kernels -> pkg.perception -> pkg.objects -> pkg.kernels")
    assert f"{root / 'objects.py'}:2: pkg.objects imports pkg.kernels" in between[0]
    assert inside[0].splitlines()[0] == (
        "import cycle inside pkg.logic: pkg.logic.engine -> pkg.logic.theory -> pkg.logic.engine")
    assert not [p for p in problems if p.startswith("a core")]


@pytest.mark.parametrize("module, unit", [
    ("tg_drake.kernels.library", "tg_drake.kernels"), ("tg_drake.station", "tg_drake.station"),
    ("tg_drake", "tg_drake"), ("numpy.linalg", None)])
def test_units_are_the_top_level_entries_of_the_package(module, unit):
    assert unit_of(module, "tg_drake", 1) == unit
