"""Import of a 50k-triangle scan-like cup (the bench's import_s case), with each backend: mass
within 10 % of the library original at its density, the same named resting poses, convex pieces.
Slow: a full import of a scan takes tens of seconds."""

from __future__ import annotations

import numpy as np
import pytest

from tg_drake.importing import ImportOptions, import_object
from tg_drake.importing import mesh as M
from tg_drake.importing.collision import BACKENDS
from tg_drake.objects import get_object, mesh
from tg_drake.scanlike import write_scanlike


@pytest.mark.slow
@pytest.mark.parametrize("backend", list(BACKENDS))
def test_50k_scan_like_cup_imports(tmp_path, backend):
    scan = write_scanlike("cup_01", tmp_path / "cup.obj", seed=0)
    assert 40_000 < len(scan.mesh.faces) < 60_000
    lib = get_object("cup_01")
    Vl, Fl, _ = mesh(lib)
    density = lib.mass / M.capped_moments(np.asarray(Vl), np.asarray(Fl))[0]
    r = import_object(tmp_path / "cup.obj", ImportOptions(category="cup", up_axis="y",
                                                          density=density, collision=backend),
                      tmp_path / "lib", pictures=False)
    assert r.object.mass == pytest.approx(lib.mass, rel=0.10)
    assert set(r.object.poses) == set(lib.poses)
    pieces = list((tmp_path / "lib" / "cup").glob("cup_collision_*.obj"))
    assert 1 < len(pieces) <= 16
    assert r.object.parts == lib.parts
