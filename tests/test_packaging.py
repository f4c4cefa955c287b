"""The wheel holds the whole package: every module of tg_drake, the rules, the models and the data.

A cheap check asks setup.py for its package list and compares it with the folders on disk. The
full check (about 10 s) builds the wheel with the environment's own setuptools (no download:
--no-build-isolation; it skips where setuptools is older than the `test` extra asks), compares its
file list with the source tree, and runs `tg-drake --help` and `tg-drake objects` from the
unpacked wheel, outside the repository.
"""

from __future__ import annotations

import importlib.metadata
import importlib.util
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def _setup_module():
    spec = importlib.util.spec_from_file_location("tg_drake_setup", REPO / "setup.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # not as __main__: defines ROOTS and packages() only
    return module


SETUP = _setup_module()


def source_files() -> dict[str, Path]:
    """Where each file of the package tree lands in an installed copy → its source file, for
    every file below the roots of setup.py (compiled bytecode aside)."""
    files = {}
    for name, folder in SETUP.ROOTS.items():
        for path in sorted((REPO / folder).rglob("*")):
            if path.is_file() and "__pycache__" not in path.parts and path.suffix != ".pyc":
                rel = path.relative_to(REPO / folder)
                files["/".join([*name.split("."), *rel.parts])] = path
    return files


def test_every_folder_of_the_package_tree_is_a_package():
    packages = SETUP.packages()
    assert len(packages) == len(set(packages))
    folders = {"/".join(installed.split("/")[:-1]) for installed in source_files()}
    assert folders == {p.replace(".", "/") for p in packages}
    # What the review found missing, and what this change added.
    assert {"tg_drake.evaluation", "tg_drake.simulation", "tg_drake.data", "tg_drake.rules",
            "tg_drake.rules.examples", "tg_drake_models", "tg_drake_models.objects.cup_01",
            "tg_drake_models.wsg_50"} <= set(packages)


def test_the_installed_layout_has_the_files_the_package_reads():
    files = source_files()
    assert "tg_drake_models/package.xml" in files
    assert "tg_drake/data/kernel_db.npz" in files and "tg_drake/data/dgi_svm.joblib" in files
    assert "tg_drake/rules/grasp_specific.pl" in files
    assert "tg_drake/evaluation/jobs.py" in files and "tg_drake/cli.py" in files
    assert "tg_drake_models/objects/cup_01/cup_01.sdf" in files


def _setuptools_version() -> tuple[int, ...]:
    try:
        return tuple(int(p) for p in importlib.metadata.version("setuptools").split(".")[:2])
    except importlib.metadata.PackageNotFoundError:
        return (0,)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    if _setuptools_version() < (77,):
        pytest.skip("building the wheel offline needs setuptools>=77 in this environment "
                    "(the `test` extra: make setup)")
    out = tmp_path_factory.mktemp("wheel")
    # Built from a copy without the checkout's build/ (setuptools copies into build/lib and never
    # removes what is there: a file deleted from the source since an earlier build would ride
    # along) nor its environment and caches.
    source = tmp_path_factory.mktemp("source") / "tg_drake"
    shutil.copytree(REPO, source, ignore=shutil.ignore_patterns(
        "build", ".venv", ".git", "*.egg-info", "__pycache__", ".*_cache"))
    build = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--no-index",
         "-q", "-w", str(out), str(source)], capture_output=True, text=True)
    assert build.returncode == 0, build.stdout + build.stderr
    (path,) = out.glob("tg_drake-*.whl")
    return path


def test_the_wheel_holds_every_module_and_data_file(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    payload = {n for n in names if ".dist-info/" not in n}
    assert payload == set(source_files())
    entry_points = next(n for n in names if n.endswith(".dist-info/entry_points.txt"))
    assert "tg-drake = tg_drake.cli:main" in zipfile.ZipFile(wheel).read(entry_points).decode()


def test_the_commands_run_from_the_unpacked_wheel_outside_the_repository(wheel, tmp_path):
    site = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(site)
    env = {**os.environ, "PYTHONPATH": str(site)}
    where = subprocess.run([sys.executable, "-c", "import tg_drake; print(tg_drake.__file__)"],
                           cwd=tmp_path, env=env, capture_output=True, text=True, check=True)
    assert Path(where.stdout.strip()).is_relative_to(site)
    for args in (["--help"], ["objects"]):
        run = subprocess.run([sys.executable, "-m", "tg_drake.cli", *args], cwd=tmp_path,
                             env=env, capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
    assert "cup_01" in run.stdout
