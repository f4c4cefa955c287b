"""Where the packages are, for setuptools (everything else is in pyproject.toml).

Three roots, each folder below them a package of its own (namespace packages, so the data folders
need no __init__.py), whose files ship as its data (pyproject.toml's package-data):

- tg_drake/;
- rules/, installed as `tg_drake.rules` (the ProbLog theories and their examples);
- models/, installed as `tg_drake_models` (installed copies find it through importlib.resources,
  and Drake resolves package://tg_drake_models/... through its package.xml).
"""

from setuptools import find_namespace_packages, setup

ROOTS = {"tg_drake": "tg_drake", "tg_drake.rules": "rules", "tg_drake_models": "models"}


def packages() -> list[str]:
    """Every package of the three roots: the root and each folder below it, __pycache__ aside."""
    found = []
    for name, folder in ROOTS.items():
        found += [name] + [f"{name}.{p}" for p in find_namespace_packages(
            where=folder, exclude=["__pycache__", "*.__pycache__"])]
    return found


if __name__ == "__main__":
    setup(packages=packages(), package_dir={n: f for n, f in ROOTS.items() if n != f})
