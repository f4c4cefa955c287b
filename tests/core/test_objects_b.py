"""Object set b (models/objects_b/, `tools/make_objects.py --set b`): the library tests of the
shipped set, run on every set-b object, and what the wider shape families must be.

The per-object checks are those of tests/core/test_objects.py (closed oriented labelled mesh, part
rules, mass and inertia, a part that fits the gripper, resting poses on the table, surface
sampling); the set's own: its families, its ids, its generator."""

from __future__ import annotations

import subprocess
import sys
from argparse import Namespace
from pathlib import Path

import numpy as np
import pytest

from tests.core import test_objects as base
from tg_drake.objects import add_library, forget_registered, get_object, load_library, main, mesh
from tg_drake.perception.ground_truth import interior_visible
from tg_drake.robot import WSG_MAX_OPENING
from tg_drake.types import CATEGORIES, PART_LABELS

REPO = Path(__file__).resolve().parents[2]
FOLDER = REPO / "models" / "objects_b"
LIB = load_library(FOLDER)
IDS = list(LIB)
# Plausible masses [kg] of real products of the wider families: the shipped set's ranges, up to
# 2 kg for a club (lump) hammer, from 25 g for a flat table knife.
MASS_RANGE = dict(base.MASS_RANGE, hammer=(0.25, 2.0), knife=(0.025, 0.35))


@pytest.fixture(autouse=True)
def set_b_registered():
    """get_object finds set b's objects (other tests may drop registered libraries)."""
    add_library(FOLDER)
    yield


def _families():
    import yaml
    data = yaml.safe_load((FOLDER / "library.yaml").read_text())["objects"]
    return {k: v["family"] for k, v in data.items()}


FAMILY = _families()


def test_set_b_covers_every_category_with_ids_of_its_own():
    by_cat = {c: [o for o in LIB.values() if o.category == c] for c in CATEGORIES}
    assert all(len(objs) == 4 for objs in by_cat.values())
    assert all(i.startswith(f"{LIB[i].category}_b") for i in IDS)
    assert not set(IDS) & set(load_library())  # never an id of the shipped set
    for objs in by_cat.values():  # instances differ in size (2 mm)
        ext = np.array([o.extents for o in objs])
        d = np.abs(ext[:, None] - ext[None]).max(2) + np.eye(len(objs))
        assert d.min() > 0.002


@pytest.mark.parametrize("obj_id", IDS)
def test_mesh_is_closed_oriented_and_labelled(obj_id):
    obj = get_object(obj_id)
    if "lid_height" not in obj.dimensions:
        base.test_mesh_is_closed_oriented_and_labelled(obj_id)
        return
    # a lidded pot: closed like a bottle, its cavity air (the shipped set's test takes the
    # closed containers by category)
    V, F, L = mesh(obj)
    assert V.shape == (obj.n_vertices, 3) and len(F) <= 5000
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    key = e[:, 0] * len(V) + e[:, 1]
    assert len(np.unique(key)) == len(key) and np.isin(e[:, 1] * len(V) + e[:, 0], key).all()
    assert obj.volume == pytest.approx(base.mesh_volume(V, F) - obj.cavity_volume, rel=1e-3)
    assert {PART_LABELS[k] for k in np.unique(L)} == set(obj.parts) == base.REQUIRED["pot"]


@pytest.mark.slow
@pytest.mark.parametrize("obj_id", IDS)
def test_mesh_does_not_intersect_itself(obj_id):
    base.test_mesh_does_not_intersect_itself(obj_id)


@pytest.mark.parametrize("obj_id", IDS)
def test_part_labels_follow_the_ground_truth_rules(obj_id):
    base.test_part_labels_follow_the_ground_truth_rules(obj_id)


@pytest.mark.parametrize("obj_id", IDS)
def test_mass_and_inertia_are_plausible(obj_id, monkeypatch):
    monkeypatch.setattr(base, "MASS_RANGE", MASS_RANGE)
    base.test_mass_and_inertia_are_plausible(obj_id)


@pytest.mark.parametrize("obj_id", IDS)
def test_some_part_fits_the_gripper(obj_id, monkeypatch):
    obj = get_object(obj_id)
    if "lid_height" in obj.dimensions:  # a lid closes the top: no rim to pinch
        monkeypatch.setattr(base, "OPEN", ())
    base.test_some_part_fits_the_gripper(obj_id)


@pytest.mark.parametrize("obj_id", IDS)
def test_resting_poses_put_the_object_on_the_table(obj_id):
    base.test_resting_poses_put_the_object_on_the_table(obj_id)


@pytest.mark.parametrize("obj_id", IDS[::4])
def test_sample_surface_is_uniform_with_outward_normals(obj_id):
    base.test_sample_surface_is_uniform_with_outward_normals(obj_id)


def test_the_wider_families_have_their_shapes():
    d = {i: LIB[i].dimensions for i in IDS}
    lidded = [i for i in IDS if "lid_height" in d[i]]
    assert lidded == ["pot_b01", "pot_b03"]
    for i in lidded:  # a closed top: the interior is not seen upright; two side handles
        assert interior_visible(i, "upright") == 0.0
        assert "upsidedown" not in LIB[i].poses
        V, _, L = mesh(LIB[i])
        h = V[L == PART_LABELS.index("handle")]
        assert h[:, 0].max() > 0 > h[:, 0].min()  # handles at +x and -x
        assert LIB[i].grasp_widths["top"] > WSG_MAX_OPENING  # the lid: wider than the gripper
    stemmed = [i for i in IDS if "stem_height" in d[i]]
    assert stemmed == ["glass_b01", "glass_b03"]
    for i in stemmed:  # a foot wider than the stem, the stem under the bowl
        assert d[i]["foot_diameter"] > 4 * d[i]["stem_diameter"]
        assert d[i]["stem_height"] > d[i]["height"] / 3
    cans = sorted(LIB[i].extents[2] for i in IDS if LIB[i].category == "can")
    assert cans[0] < 0.04 and cans[-1] > 0.15  # squat (3 cm) and tall cans
    square = [i for i in IDS if "section_exponent" in d[i]]
    assert square == ["bottle_b01", "bottle_b03"]
    for i in square:  # flat sides: the section's corners stick out beyond its half width
        V, _, _ = mesh(LIB[i])
        body = V[(V[:, 2] > 0.02) & (V[:, 2] < d[i]["height"] / 2)]
        assert np.hypot(body[:, 0], body[:, 1]).max() > 1.15 * d[i]["diameter"] / 2
    flat = [i for i in IDS if FAMILY[i].startswith("flat knife")]
    assert flat == ["knife_b01", "knife_b03"]
    for i in flat:
        assert 0.002 - 1e-4 <= LIB[i].extents[2] <= 0.005 + 1e-4  # 2–5 mm thick, whole knife
    heavy = [LIB[i].mass for i in IDS if FAMILY[i] == "heavy hammer"]
    assert len(heavy) == 2 and min(heavy) > 1.0  # [kg]
    handles = {FAMILY[i] for i in IDS if LIB[i].category == "cup"}
    assert len(handles) == 2
    assert any(LIB[i].dimensions.get("bowl_depth") for i in IDS)  # ladles


def test_objects_command_lists_set_b(capsys):
    assert main(Namespace(json=False, category="glass", library=str(FOLDER))) == 0
    out = capsys.readouterr().out
    assert "glass_b01" in out and "glass_01" not in out and out.strip().endswith("4 objects")


def test_generator_reproduces_set_b_bit_for_bit():
    run = subprocess.run([sys.executable, str(REPO / "tools" / "make_objects.py"), "--set", "b",
                          "--check"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "every file matches" in run.stdout


def teardown_module():
    forget_registered()
