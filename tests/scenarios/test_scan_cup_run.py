"""A user's own mesh through the whole pipeline: the default scenario with its cup replaced by a
scan-like version of it (tg_drake.scanlike: ~50k triangles, noise, holes, pieces, mm, y up, flipped
and zero-area triangles), given as a `mesh:` entry relative to the scenario file. Issue 18: the run
places it, as the library cup is placed; a second load imports nothing (the content-hash cache)."""

from __future__ import annotations

import pytest

from tg_drake.run import run_scenario
from tg_drake.scanlike import write_scanlike
from tg_drake.scenario import load_scenario

SCENARIO = """\
objects:
  - {mesh: meshes/scan_cup.obj, category: cup, units: auto, up_axis: y, pose: upright,
     xy: [0.0, 0.0], yaw: 0, name: scan_cup}
task:
  task: p&pInUpright
  place_xy: [0.0, -0.3]
"""
# (p&pInUpright of an upright cup is the pick-and-place the default scenario's pass was before
# the pass handed the object over to a receiver: what this test checks is the mesh's way in.)


@pytest.fixture(scope="module")
def scenario_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("own_object")
    write_scanlike("cup_01", d / "meshes" / "scan_cup.obj", seed=0)
    (d / "scenario.yaml").write_text(SCENARIO)
    return d / "scenario.yaml"


@pytest.fixture(autouse=True, scope="module")
def _cache(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("TG_DRAKE_CACHE", str(tmp_path_factory.mktemp("cache")))
        yield


@pytest.fixture(scope="module")
def result(scenario_file):
    scenario = load_scenario(scenario_file)
    return run_scenario(scenario, scenario_path=str(scenario_file))


def test_scan_like_cup_is_imported_once_and_placed(scenario_file, result, monkeypatch):
    scenario = load_scenario(scenario_file)
    obj_id = scenario.objects[0].id
    assert obj_id and scenario.objects[0].instance_name == "scan_cup"

    import tg_drake.importing.library as library

    def no_import(*args, **kwargs):
        raise AssertionError("the second load imported the mesh again")

    monkeypatch.setattr(library, "import_object", no_import)
    again = load_scenario(scenario_file)
    assert again.objects[0].id == obj_id
    monkeypatch.undo()

    outcome = result["outcome"]
    assert outcome["status"] == "placed", outcome
    # What the pipeline believed: a container with one handle seen (cup, pot or pan), the
    # handle part among the parts it perceived.
    category = result["category"]
    assert max(category, key=category.get) in ("cup", "pot", "pan"), category
    assert result["perception"]["parts"].get("handle", 0) > 0.5, result["perception"]


@pytest.mark.xfail(reason="the kernel prior takes this scan-like cup, seen with its handle towards "
                          "the camera, for a pot (0.65, glass 0.26, cup 0.002); with one handle "
                          "seen and 70 % of the far side unseen, a pot's second handle could be "
                          "there (P(pair) 0.26), so the logic believes pot 0.86", strict=False)
def test_scan_like_cup_is_taken_for_a_cup(result):
    category = result["category"]
    assert max(category, key=category.get) == "cup", category
