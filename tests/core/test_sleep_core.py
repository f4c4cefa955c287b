"""The contents' sleep rules on arrays (tg_drake.simulation.sleep): speed bounds, which bodies
are near the spheres, how far a body moved."""

import numpy as np
import pytest

from tg_drake.simulation.sleep import (
    STRAY_HEIGHT,
    ContentsSleep,
    inside,
    near_spheres,
    shifted,
    speeds,
    workspace,
)
from tg_drake.table import FLOOR_MARGIN, TABLE_HEIGHT


def test_a_body_s_speed_bound_adds_its_spin_times_its_reach():
    v = np.array([[0.003, 0.004, 0.0], [0.0, 0.0, 0.0]])  # [m/s]
    w = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 2.0]])  # [rad/s]
    assert speeds(v, w, np.array([0.5, 0.1])) == pytest.approx([0.005, 0.2])


def test_a_body_is_near_when_its_bounding_sphere_comes_within_the_margin_of_a_sphere():
    p_spheres = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])
    centres = np.array([[0.1, 0.15, 0.0],    # 0.15 from the nearest sphere
                        [-0.3, 0.0, 0.0],    # 0.3
                        [0.5, 0.0, 0.0]])    # 0.4
    radii = np.array([0.1, 0.2, 0.1])
    # reach: radius 0.1 + sphere 0.01 + margin 0.03 = 0.14 < 0.15; 0.2 + 0.04 = 0.24 < 0.3
    assert list(near_spheres(p_spheres, 0.01, centres, radii, 0.03)) == [False, False, False]
    assert list(near_spheres(p_spheres, 0.01, centres, radii, 0.05)) == [True, False, False]
    assert list(near_spheres(p_spheres, 0.01, centres, radii, 0.1)) == [True, True, False]
    assert near_spheres(np.zeros((0, 3)), 0.01, centres, radii, 0.1).tolist() == [False] * 3


def test_a_body_s_shift_is_its_displacement_plus_its_turn_times_its_reach():
    X0 = np.tile(np.eye(4), (2, 1, 1))
    X1 = X0.copy()
    X1[0, :3, 3] = [0.003, 0.0, 0.004]  # moved 5 mm
    c, s = np.cos(0.01), np.sin(0.01)
    X1[1, :3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]  # turned 0.01 rad
    assert shifted(X0, X1, np.array([1.0, 0.2])) == pytest.approx([0.005, 0.002], abs=1e-9)
    assert shifted(X0, X0, np.array([1.0, 0.2])) == pytest.approx([0.0, 0.0], abs=1e-6)


def test_the_time_asleep_sums_each_sleep_to_its_wake_and_the_last_to_the_end():
    def sleeper(events):
        return ContentsSleep(plant=None, scene_graph=None, spheres=[], sphere_geometries=[],
                             radius=0.008, others=[], p_BC=np.zeros((0, 3)), radii=np.zeros(0),
                             config=None, events=events)

    assert sleeper([(0.5, "sleep"), (2.0, "wake"), (3.0, "sleep")]).asleep_time(4.25) == \
        pytest.approx(1.5 + 1.25)
    assert sleeper([]).asleep_time(4.25) == 0.0
    # A stray frozen while they sleep does not end their sleep.
    assert sleeper([(0.5, "sleep"), (1.0, "froze 1 strayed"), (2.0, "wake")]).asleep_time(
        4.25) == pytest.approx(1.5)


def test_the_workspace_is_the_floor_s_footprint_from_its_top_to_above_the_table():
    X_WT = np.eye(4)
    X_WT[:3, 3] = [0.75, 0.0, 0.0]
    lo, hi = workspace(X_WT, (0.8, 1.2))
    assert lo == pytest.approx([0.35 - FLOOR_MARGIN, -0.6 - FLOOR_MARGIN, -TABLE_HEIGHT - 0.05])
    assert hi == pytest.approx([1.15 + FLOOR_MARGIN, 0.6 + FLOOR_MARGIN, STRAY_HEIGHT])
    p = np.array([[0.75, 0.0, 0.1], [0.75, 0.0, STRAY_HEIGHT + 0.1], [0.75, 0.0, -0.5],
                  [3.0, 0.0, 0.1]])
    assert inside(p, lo, hi).tolist() == [True, False, False, False]
