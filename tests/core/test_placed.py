"""The place judgment (`outcome.placed`): the resting pose is the axis' angle to the table, not
the way the object faces about the vertical."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.math import RigidTransform, RollPitchYaw

from tg_drake.outcome import PLACE_TILT_TOLERANCE, axis_elevation, placed

LYING = RollPitchYaw(np.pi / 2, 0.0, 0.0)  # z_O along −y: the object's axis on the table


def pose(rpy: RollPitchYaw, xyz=(0.7, -0.3, 0.03)) -> RigidTransform:
    return RigidTransform(rpy, list(xyz))


@pytest.mark.parametrize("yaw_deg", [0.0, 30.0, 90.0, 170.0])
def test_a_lying_object_turned_about_the_vertical_still_lies_where_it_was_put(yaw_deg):
    picked = pose(LYING, (0.75, 0.0, 0.03))
    turned = RollPitchYaw(np.pi / 2, 0.0, np.deg2rad(yaw_deg))
    ok, detail = placed(picked, pose(turned), (0.7, -0.3), released=True)
    assert ok, detail
    assert abs(axis_elevation(pose(turned))) < 1e-12


def test_a_lying_object_stood_on_end_has_tipped():
    picked = pose(LYING)
    ok, detail = placed(picked, pose(RollPitchYaw(0.0, 0.0, 0.4)), (0.7, -0.3), released=True)
    assert not ok and detail.startswith("tipped over (its axis 90°")


@pytest.mark.parametrize("tilt_deg, expected", [(15.0, True), (25.0, False), (180.0, False)])
def test_an_upright_object_tilted_is_judged_by_its_tilt_in_any_direction(tilt_deg, expected):
    picked = pose(RollPitchYaw(0.0, 0.0, 0.0))
    for rpy in (RollPitchYaw(np.deg2rad(tilt_deg), 0.0, 0.0),
                RollPitchYaw(0.0, np.deg2rad(tilt_deg), 1.0)):
        ok, _ = placed(picked, pose(rpy), (0.7, -0.3), released=True)
        assert ok == expected
    assert np.deg2rad(15.0) < PLACE_TILT_TOLERANCE < np.deg2rad(25.0)


def test_distance_and_release_are_judged_before_the_pose():
    picked = pose(LYING)
    assert placed(picked, pose(LYING, (0.7, -0.24, 0.03)), (0.7, -0.3),
                  released=True) == (False, "6.0 cm from the place target")
    assert placed(picked, pose(LYING), (0.7, -0.3), released=False)[1].startswith("not let go")
