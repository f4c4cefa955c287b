"""The completion keeps a rotated point only where the camera could not have seen it.

`seen_free` on hand-made points with known answers, then a knife-like tool ray cast on the
table: one symmetry axis at the height of its thick handle puts a copy of its thin blade in
the air above the blade, where the camera saw the table.
"""

import numpy as np
import pytest

from tg_drake.perception import synthetic as S
from tg_drake.perception.completion import seen_free
from tg_drake.perception.config import PerceptionConfig
from tg_drake.perception.geometry import Intrinsics, inverse, transform
from tg_drake.perception.pipeline import describe_scene

CAMERA = np.array([0.0, 0.0, 1.0])  # looking down −z at a patch of the plane z = 0


def plane(half=0.05, step=0.004):
    g = np.arange(-half, half + 1e-9, step)
    x, y = np.meshgrid(g, g)
    return np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])


def test_seen_free_tells_points_in_front_of_a_surface_from_points_behind_or_beside_it():
    seen = plane()
    q = np.array([[0.0, 0.0, 0.02],     # 2 cm in front of the seen surface: the camera saw through
                  [0.0, 0.0, -0.02],    # behind it: hidden
                  [0.0, 0.0, 0.002],    # on it, within the depth margin
                  [0.2, 0.0, 0.0],      # beside it, where nothing of the object was seen
                  [0.0, 0.0, 2.0],      # behind the camera: never seen
                  [3.0, 0.0, 0.999]])   # far off to the side, at the camera's height: seen
    free = seen_free(q, seen, CAMERA, radius=0.006, margin=0.004)
    assert free.tolist() == [True, False, False, True, False, True]
    # Another object between the camera and the point beside this one hides it.
    occluder = plane(0.01) + [0.14, 0.0, 0.3]  # on its line of sight, 0.7 of the way
    free = seen_free(q, seen, CAMERA, radius=0.006, margin=0.004, occluders=occluder)
    assert free.tolist() == [True, False, False, False, False, True]
    # A zero radius carves nothing.
    assert not seen_free(q, seen, CAMERA, radius=0.0, margin=0.004).any()


BLADE = 0.005  # [m] thickness of the blade lying flat on the table


@pytest.fixture(scope="module")
def knife_scene():
    """A handle 24 mm thick and a blade 5 mm thick lying on the table, from 45° above."""
    handle = S.box((0.10, 0.025, 0.024))
    handle.translate((-0.05, 0.0, 0.0))
    blade = S.box((0.12, 0.025, BLADE))
    blade.translate((0.06, 0.0, 0.0))
    K = Intrinsics.from_fov(640, 480, np.pi / 4)
    X_WC = S.look_at(np.array([0.1, -0.6, 0.6]), np.array([0.0, 0.0, 0.0]))
    depth = S.render_depth([S.table_mesh(), handle, blade], K, X_WC)
    return depth, K, X_WC


def blade_heights(knife_scene, carve: bool) -> np.ndarray:
    depth, K, X_WC = knife_scene
    cfg = PerceptionConfig()
    if not carve:
        cfg.completion.free_space_radius = 0.0
    scene = describe_scene(depth, K, X_WC, cfg)
    assert len(scene.objects) == 1
    o = scene.objects[0]
    p_T = transform(inverse(scene.X_WT), o.p_W)
    over_blade = p_T[:, 0] > 0.03  # [m] the blade's footprint, clear of the handle
    return p_T[over_blade, 2]


def test_a_thin_blade_is_not_completed_into_the_air_above_it(knife_scene):
    # The paper's single axis, at half the handle's height, puts the blade's copy ~2 cm up:
    # the completed blade is as tall as the handle.
    assert np.percentile(blade_heights(knife_scene, carve=False), 90) > 0.015
    # With the free-space test the completed blade is the blade, within a voxel (4 mm).
    assert blade_heights(knife_scene, carve=True).max() < BLADE + 0.004
