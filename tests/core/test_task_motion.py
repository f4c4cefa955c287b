"""The task motions' geometry on arrays: turns into a resting pose, the retreat after a turn,
surfaces in the world, the task's placing."""

import dataclasses

import numpy as np
import pytest

from tg_drake.errors import ScenarioError
from tg_drake.planning.planner import place_pose
from tg_drake.planning.task_motion import (
    TaskMotionConfig,
    lets_go_onto_support,
    perceived_pose,
    surfaces_in_world,
    task_placing,
    turned_retreat,
    turns_to_pose,
)
from tg_drake.scenario import SurfaceConfig

# A side grasp from the robot (approach +x, closing along y), tilted 20° down.
TILT = np.deg2rad(20)
R_SIDE = np.column_stack([[0, 1, 0], [np.cos(TILT), 0, -np.sin(TILT)],
                          np.cross([0, 1, 0], [np.cos(TILT), 0, -np.sin(TILT)])])
R_TOP = np.column_stack([[0, 1, 0], [0, 0, -1], np.cross([0, 1, 0], [0, 0, -1])])  # from above
UPRIGHT = np.eye(3)
LYING = np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], float)  # z along +x


@pytest.mark.parametrize("R_WO, R_WG, pose", [
    (UPRIGHT, R_SIDE, "upsidedown"), (UPRIGHT, R_SIDE, "sideways"), (LYING, R_TOP, "upright"),
    (LYING, R_SIDE, "upsidedown")])
def test_every_turn_puts_the_object_in_the_pose(R_WO, R_WG, pose):
    turns = turns_to_pose(R_WO, R_WG, pose, is_tool=False)
    assert turns
    for R in turns:
        assert np.allclose(R @ R.T, np.eye(3)) and np.isclose(np.linalg.det(R), 1.0)
        assert perceived_pose(R @ R_WO, is_tool=False) == pose


def test_the_first_turn_is_a_turn_of_the_wrist():
    (R, *_) = turns_to_pose(UPRIGHT, R_SIDE, "upsidedown", is_tool=False)
    # About the horizontal part of the approach: the approach's horizontal part is kept.
    y = R @ R_SIDE[:, 1]
    assert np.allclose(y[:2], R_SIDE[:2, 1]) and np.isclose(y[2], -R_SIDE[2, 1])


def test_in_the_pose_already_no_turn_and_a_tool_only_lies_flat():
    assert [np.allclose(R, np.eye(3)) for R in turns_to_pose(UPRIGHT, R_SIDE, "upright",
                                                              is_tool=False)] == [True]
    assert turns_to_pose(UPRIGHT, R_TOP, "upright", is_tool=True) == []
    assert len(turns_to_pose(UPRIGHT, R_TOP, "sideways", is_tool=True)) == 1


def test_a_turn_that_would_leave_the_object_on_the_lower_finger_is_not_placed():
    """An upright can in a side grasp laid sideways by the wrist alone turns the closing axis
    vertical (a finger under the can: opening lowers it onto that finger); the placing keeps
    only the turns whose closing axis stays nearer level than vertical."""
    (wrist, *_) = turns_to_pose(UPRIGHT, R_SIDE, "sideways", is_tool=False)
    assert abs((wrist @ R_SIDE[:, 0])[2]) > 0.99 and not lets_go_onto_support(wrist, R_SIDE)
    placing = task_placing("p&pInSideways", place_xy=(0.75, -0.3), table_z=0.0)
    poses = placing.place_poses(np.eye(4), R_SIDE, [0.06, 0.06, 0.12], is_tool=False,
                                release_height=0.01, place_pose=place_pose)
    assert poses
    for R, X in poses:
        x_G = R @ R_SIDE[:, 0]
        assert abs(x_G[2]) <= np.cos(np.pi / 4) + 1e-9  # the fingers open sideways
        assert perceived_pose(X[:3, :3], is_tool=False) == "sideways"
    # Turned upside down by the wrist, the closing axis stays level: that turn is kept.
    (flip, *_) = turns_to_pose(UPRIGHT, R_SIDE, "upsidedown", is_tool=False)
    assert lets_go_onto_support(flip, R_SIDE)
    # A place-and-regrasp's exact intermediate orientation is refused on the same ground.
    exact = dataclasses.replace(placing, R_place=tuple(map(tuple, wrist)))
    assert exact.place_poses(np.eye(4), R_SIDE, [0.06, 0.06, 0.12], is_tool=False,
                             release_height=0.01, place_pose=place_pose) == []


def test_the_retreat_after_a_turn_never_goes_down():
    up_approach = np.array([np.cos(TILT), 0.0, np.sin(TILT)])  # a side grasp turned over
    r = turned_retreat(up_approach)
    assert r[2] >= 0 and np.isclose(np.linalg.norm(r), 1) and r[0] < 0
    assert np.allclose(turned_retreat(np.array([0.0, 0.0, 1.0])), [0, 0, 1])


def test_surfaces_in_the_world_and_the_placing_on_one():
    X_WT = np.eye(4)
    X_WT[:3, 3] = [0.75, 0.0, 0.0]
    (shelf,) = surfaces_in_world([SurfaceConfig("shelf", [0.1, -0.3], [0.2, 0.2, 0.08])], X_WT)
    assert np.allclose(shelf.xy, (0.85, -0.3)) and np.isclose(shelf.top_z, 0.08)
    assert np.allclose(shelf.X_WB[:3, 3], [0.85, -0.3, 0.04])
    placing = task_placing("p&pOn", place_xy=(0.75, 0.3), table_z=0.0, surface=shelf)
    assert placing.pose is None and placing.surface == "shelf"
    ((R, X),) = placing.place_poses(np.eye(4), R_SIDE, [0.06, 0.06, 0.12], is_tool=False,
                                    release_height=0.01, place_pose=place_pose)
    assert R is None and np.allclose(X[:3, 3], [0.85, -0.3, 0.08 + 0.01 + 0.06])


def test_an_upside_down_placing_tries_higher_releases():
    placing = task_placing("p&pInUpsidedown", place_xy=(0.75, -0.3), table_z=0.0)
    poses = placing.place_poses(np.eye(4), R_SIDE, [0.06, 0.06, 0.12], is_tool=False,
                                release_height=0.01, place_pose=place_pose)
    heights = sorted({round(X[2, 3] - 0.06, 4) for _, X in poses})
    assert heights == [0.01, 0.03, 0.05]
    assert all(R is not None and X[2, 2] < -0.99 for R, X in poses)
    kept = task_placing("p&pInUpsidedown", place_xy=(0.75, -0.3), table_z=0.0,
                        config=TaskMotionConfig(reorient=False))
    assert kept.pose is None


@pytest.mark.parametrize("field, value", [("pour_tilt", 0.0), ("pour_hold", -1.0),
                                          ("pour_drop", -0.01), ("turned_release_heights", [])])
def test_a_bad_task_motion_config_names_its_field(field, value):
    with pytest.raises(ScenarioError, match=field):
        TaskMotionConfig(**{field: value}).validate()


def test_a_pour_puts_the_opening_over_the_bowl_and_tilts_it_there():
    from tg_drake.planning.task_motion import pour_poses

    X_WO = np.eye(4)
    X_WO[:3, 3] = [0.75, 0.0, 0.05]
    X_WG = np.eye(4)
    X_WG[:3, :3] = R_SIDE
    extents, bowl_xy, bowl_top = [0.08, 0.08, 0.1], (0.7, -0.25), 0.06
    pours = pour_poses(X_WO, extents, X_WG, bowl_xy=bowl_xy, bowl_top=bowl_top,
                       tilt=np.deg2rad(110), clearance=0.05, yaws=(0.0, np.pi / 2))
    assert len(pours) == 8  # 2 axes × 2 ways × 2 yaws
    for X_pour, X_tilted in pours:
        assert np.isclose(X_pour[2, 3] - 0.05, bowl_top + 0.05)  # the box bottom clears the bowl
        assert X_pour[2, 2] > 0.99  # upright
        assert np.isclose(X_tilted[:3, 2] @ [0, 0, 1], np.cos(np.deg2rad(110)))
        # The opening's edge where it leans (the point the tilt keeps) is over the bowl's centre.
        rim_centre = X_pour[:3, 3] + X_pour[:3, 2] * 0.05
        lean = X_tilted[:3, 2] - (X_tilted[:3, 2] @ [0, 0, 1]) * np.array([0, 0, 1])
        lean /= np.linalg.norm(lean)
        assert np.allclose(rim_centre[:2] + 0.04 * lean[:2], bowl_xy, atol=1e-9)
    lying = X_WO.copy()
    lying[:3, :3] = LYING
    assert pour_poses(lying, extents, X_WG, bowl_xy=bowl_xy, bowl_top=bowl_top,
                      tilt=1.9, clearance=0.05) == []


@pytest.mark.parametrize("tilt_deg", [110.0, 135.0, 150.0])
def test_a_tilted_pour_is_lowered_to_pour_from_just_above_the_bowl(tilt_deg):
    from tg_drake.planning.task_motion import box_bottom, pour_poses

    X_WO = np.eye(4)
    X_WO[:3, 3] = [0.75, 0.0, 0.05]
    X_WG = np.eye(4)
    X_WG[:3, :3] = R_SIDE
    extents, bowl_xy, bowl_top = [0.08, 0.08, 0.1], (0.7, -0.25), 0.06
    kept = pour_poses(X_WO, extents, X_WG, bowl_xy=bowl_xy, bowl_top=bowl_top,
                      tilt=np.deg2rad(tilt_deg), clearance=0.05)
    lowered = pour_poses(X_WO, extents, X_WG, bowl_xy=bowl_xy, bowl_top=bowl_top,
                         tilt=np.deg2rad(tilt_deg), clearance=0.05, drop=0.03)
    for (X_pour, X_kept), (X_pour2, X_tilted) in zip(kept, lowered, strict=True):
        assert np.allclose(X_pour, X_pour2)  # the upright pose above the bowl is the same
        assert np.isclose(box_bottom(X_tilted, extents), bowl_top + 0.03)
        assert np.allclose(X_tilted[:3, :3], X_kept[:3, :3])  # turned alike, only moved down
        assert np.allclose(X_tilted[:2, 3], X_kept[:2, 3])
        # Tilted past level, the opening's edge (the lowest corner) falls 0.03 m to the rim's
        # height, not the upright container's height more.
        assert X_tilted[2, 3] < X_kept[2, 3] - 0.05


@pytest.mark.parametrize("task, where", [("pourOut", dict(pour_at=(0.7, -0.25))),
                                         ("pourIn", dict(fill_at=(0.65, -0.25, 0.3)))])
def test_a_pour_places_at_the_target_else_back_where_it_was_picked(task, where):
    # A pour is judged at the bowl or the dispenser: the container's place target (here 0.9 m
    # out, past where a side grasp reaches) comes first, then its own pick spot.
    X_WO = np.eye(4)
    X_WO[:3, 3] = [0.75, 0.05, 0.061]
    extents = [0.08, 0.08, 0.1]
    placing = task_placing(task, place_xy=(0.9, -0.3), table_z=0.0, **where)
    assert placing.pours
    (R0, X0), (R1, X1) = placing.place_poses(X_WO, R_SIDE, extents, is_tool=False,
                                             release_height=0.01, place_pose=place_pose)
    assert R0 is None and R1 is None
    assert np.allclose(X0[:3, 3], [0.9, -0.3, 0.06])
    assert np.allclose(X1[:3, 3], [0.75, 0.05, 0.06])  # the pick spot, 1 cm over the table
    assert np.allclose(X1[:3, :3], X_WO[:3, :3])
    # Already at the target, or not a pour: the one place target only.
    assert len(placing.place_poses(X0, R_SIDE, extents, is_tool=False, release_height=0.01,
                                   place_pose=place_pose)) == 1
    plain = task_placing("pass", place_xy=(0.9, -0.3), table_z=0.0)
    assert not plain.pours
    assert len(plain.place_poses(X_WO, R_SIDE, extents, is_tool=False, release_height=0.01,
                                 place_pose=place_pose)) == 1
