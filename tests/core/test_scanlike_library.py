"""tools/make_scanlike.py over a library: scan-like meshes of a set-b object, and (slow: a convex
decomposition takes ~30 s) their import into a library of scan-like objects, <id>_scan, with the
original's category, parts, mass and poses, on the original's side of the split."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest
import trimesh

from tg_drake.evaluation.split import load_split
from tg_drake.objects import forget_registered, load_library

REPO = Path(__file__).resolve().parents[2]
SET_B = REPO / "models" / "objects_b"
spec = importlib.util.spec_from_file_location("make_scanlike", REPO / "tools" / "make_scanlike.py")
make_scanlike = importlib.util.module_from_spec(spec)
spec.loader.exec_module(make_scanlike)


@pytest.fixture(autouse=True)
def _forget():
    yield
    forget_registered()


def test_scan_like_meshes_of_a_set_b_object(tmp_path):
    assert make_scanlike.main(["can_b01", "--library", str(SET_B), "--out", str(tmp_path),
                               "--triangles", "3000"]) == 0
    scan = trimesh.load(tmp_path / "can_b01_scan.obj", process=False)
    labels = np.load(tmp_path / "can_b01_scan_parts.npy")
    record = json.loads((tmp_path / "can_b01_scan_scanlike.json").read_text())
    assert record["object"] == "can_b01" and record["units"] == "mm"
    assert len(labels) == len(scan.vertices) and set(np.unique(labels)) == {0, 1, 2}
    # in mm: the squat can's 4.5 cm height is along the scan's y (up)
    ext = scan.vertices.max(0) - scan.vertices.min(0)
    assert ext[1] == pytest.approx(1000 * load_library(SET_B)["can_b01"].extents[2], abs=2.0)


def test_a_library_object_that_is_not_in_the_library_is_named(tmp_path, capsys):
    with pytest.raises(SystemExit):
        make_scanlike.main(["cup_01", "--library", str(SET_B), "--out", str(tmp_path)])
    assert "not in the library: cup_01" in capsys.readouterr().err


def test_default_library_folder_is_in_the_cache(monkeypatch, tmp_path):
    monkeypatch.setenv("TG_DRAKE_CACHE", str(tmp_path / "objects"))
    assert make_scanlike.default_out(SET_B) == tmp_path / "scanlike" / "objects_b"
    assert make_scanlike.default_out(None) == tmp_path / "scanlike" / "objects"


@pytest.mark.slow
def test_a_set_b_object_becomes_a_scan_like_library_object(tmp_path):
    out = tmp_path / "scanlike_b"
    args = ["can_b01", "--library", str(SET_B), "--import", "--out", str(out), "--triangles",
            "3000"]
    assert make_scanlike.main(args) == 0
    original = load_library(SET_B)["can_b01"]
    obj = load_library(out)["can_b01_scan"]
    assert obj.category == original.category and obj.parts == original.parts
    assert obj.labels_source == "given"
    assert obj.mass == pytest.approx(original.mass, rel=0.10)
    assert set(obj.poses) == set(original.poses)
    assert np.allclose(obj.extents, original.extents, atol=0.004)
    assert load_split().role(obj.id) == load_split().role(original.id) == "train"
    assert make_scanlike.main(args) == 0  # a rerun skips what the library holds
    assert list(load_library(out)) == ["can_b01_scan"]
