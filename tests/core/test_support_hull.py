"""The support hull: few faces, within its tolerance of the full convex hull."""

import numpy as np
import pytest
import trimesh
from scipy.spatial import ConvexHull

from tg_drake.support_hull import SUPPORT_TOLERANCE, _outside, support_hull


@pytest.mark.parametrize("sections", [64, 128])
def test_a_fine_cylinder_gets_a_coarser_hull_within_the_tolerance(sections):
    # A can of radius 33 mm, 120 mm tall: its rim a `sections`-gon.
    V = trimesh.creation.cylinder(radius=0.033, height=0.12, sections=sections).vertices
    full = ConvexHull(V)
    P = support_hull(V)
    coarse = ConvexHull(P)
    assert len(coarse.simplices) < len(full.simplices)
    # Both ways within the tolerance: the full hull's vertices outside the support hull, and the
    # support hull's outside the full one.
    assert _outside(V[full.vertices], coarse) <= SUPPORT_TOLERANCE
    assert _outside(P, full) <= SUPPORT_TOLERANCE
    # Its flat ends kept: the base still at the bottom, its rim within the tolerance.
    assert P[:, 2].min() == pytest.approx(V[:, 2].min(), abs=1e-9)
    base = P[np.isclose(P[:, 2], V[:, 2].min())]
    assert np.linalg.norm(base[:, :2], axis=1).max() == pytest.approx(0.033, abs=SUPPORT_TOLERANCE)


def test_a_tighter_tolerance_keeps_more_faces():
    V = trimesh.creation.cylinder(radius=0.033, height=0.12, sections=128).vertices
    loose = ConvexHull(support_hull(V, tolerance=0.002))
    tight = ConvexHull(support_hull(V, tolerance=0.0002))
    assert len(tight.simplices) > len(loose.simplices)


def test_a_box_is_its_own_support_hull():
    V = trimesh.creation.box(extents=[0.1, 0.05, 0.02]).vertices
    P = support_hull(V)
    assert len(P) == 8
    assert np.allclose(np.sort(np.abs(P), axis=0), np.sort(np.abs(V), axis=0))
