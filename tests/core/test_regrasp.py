"""Place-and-regrasp's choice of an intermediate resting pose, on arrays: which poses are tried
and in which order, the perceived object moved there, the first leg's exact place orientation,
the finger-swapped twins. (The whole sequence in physics: tests/scenarios/test_tasks.py.)"""

import dataclasses

import numpy as np
from grasp_helpers import grasp_pose, ranked, scene_with_box

from tg_drake.planning.planner import place_pose
from tg_drake.planning.regrasp import (
    SWAP_FINGERS,
    finger_swapped,
    intermediate_poses,
    intermediates,
    moved_object,
)
from tg_drake.planning.task_motion import axis_angle, perceived_pose, task_placing
from tg_drake.robot import WSG_GRASP_POINT_G
from tg_drake.types import PART_LABELS

LYING = np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], float)  # z along +x
YAWS = np.deg2rad([90.0, -90.0, 180.0])


def lying_box():
    """The helpers' upright box laid on its side (z along +x), its box centre 3.5 cm up."""
    scene = scene_with_box([0.8, 0.05, 0.0])
    box = scene.objects[0]
    X = np.eye(4)
    X[:3, :3] = LYING
    X[:3, 3] = [0.8, 0.05, 0.035]
    return moved_object(box, X)


def turn_angle(R):
    return float(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1)))


def test_intermediate_poses_never_the_tasks_own_and_the_pose_it_is_in_first():
    box = lying_box()
    poses = intermediate_poses(box.X_WO, box.extents, task_pose="upright", is_tool=False,
                               support_z=0.0, yaws=YAWS)
    labels = [p.pose for p in poses]
    assert "upright" not in labels
    assert labels[:3] == ["sideways"] * 3  # turned about the vertical only: no 0° where it is
    assert set(labels[3:]) == {"upsidedown"}
    for p in poses:
        assert perceived_pose(p.X_WO[:3, :3], is_tool=False) == p.pose
        assert np.allclose(p.X_WO[:2, 3], box.X_WO[:2, 3])  # where it stands now
        # resting on the support: the box's lowest corner at the table
        assert np.isclose(place_pose(p.X_WO, box.extents, p.X_WO[:2, 3],
                                     release_height=0.0)[2, 3], p.X_WO[2, 3])
    sideways = [p.X_WO[:3, :3] @ box.X_WO[:3, :3].T for p in poses[:3]]
    assert all(np.allclose(R[:, 2], [0, 0, 1]) for R in sideways)  # turns about the vertical


def test_a_tool_only_lies_flat_and_lying_flat_is_its_task_no_intermediate():
    box = lying_box()
    assert intermediate_poses(box.X_WO, box.extents, task_pose="sideways", is_tool=True,
                              support_z=0.0, yaws=YAWS) == []


def test_intermediates_try_the_smallest_turn_first_then_the_spots():
    box = lying_box()
    placing = dataclasses.replace(
        task_placing("p&pInUpright", place_xy=(0.6, -0.3), table_z=0.0),
        regrasp_yaws=tuple(YAWS), regrasp_spots=(0.0, 0.5, 1.0))
    found = intermediates(box, placing)
    turns = [turn_angle(i.X_WO[:3, :3] @ box.X_WO[:3, :3].T) for i in found]
    assert turns == sorted(turns)
    # No turn: moved halfway, then to the target (where it is, unturned, is no intermediate).
    assert [tuple(np.round(i.X_WO[:2, 3], 3)) for i in found[:2]] == [(0.7, -0.125),
                                                                        (0.6, -0.3)]
    assert turns[:2] == [0.0, 0.0] and turns[2] > 0
    # A spot where another perceived object stands is left out.
    other = dataclasses.replace(box, X_WO=found[0].X_WO.copy())
    assert all(not np.allclose(i.X_WO[:2, 3], (0.7, -0.125)) for i in
               intermediates(box, placing, [other]))


def test_the_moved_object_is_moved_rigidly_and_gets_its_new_pregrasps():
    scene = scene_with_box([0.8, 0.05, 0.10])
    box = dataclasses.replace(scene.objects[0], p_W=np.array([[0.8, 0.05, 0.2], [0.83, 0.05, 0.1]]),
                              n_W=np.array([[0, 0, 1.0], [1.0, 0, 0]]), labels=np.zeros(2, int),
                              visible=np.ones(2, bool))
    X = np.eye(4)
    X[:3, :3] = LYING
    X[:3, 3] = [0.6, 0.0, 0.035]
    moved = moved_object(box, X)
    T = X @ np.linalg.inv(box.X_WO)
    assert np.allclose(moved.p_W, (T[:3, :3] @ box.p_W.T).T + T[:3, 3])
    assert np.allclose(moved.n_W, (T[:3, :3] @ box.n_W.T).T)
    assert moved.pose == "sideways" and np.allclose(moved.X_WO, X)
    for name, b in moved.part_boxes.items():
        assert np.allclose(b.X_WB, T @ box.part_boxes[name].X_WB)
    # Twelve face grasps per part box, their grasp points at the moved boxes.
    assert len(moved.pregrasp_X_WG) >= 12 * len(moved.part_boxes)
    middle = moved.part_boxes["middle"].X_WB[:3, 3]
    X_WG = moved.pregrasp_X_WG[moved.pregrasp_parts == PART_LABELS.index("middle")]
    p_grasp = X_WG[:, :3, 3] + np.einsum("nij,j->ni", X_WG[:, :3, :3], WSG_GRASP_POINT_G)
    assert np.all(np.linalg.norm(p_grasp - middle, axis=1) < 0.05)


def test_the_first_leg_places_in_exactly_the_intermediate_orientation():
    box = lying_box()
    R_place = axis_angle([0, 0, 1], np.pi / 2) @ box.X_WO[:3, :3]
    placing = dataclasses.replace(
        task_placing("p&pInUpright", place_xy=(0.6, -0.3), table_z=0.0),
        pose="sideways", R_place=tuple(map(tuple, R_place)))
    top = grasp_pose(box.X_WO[:3, 3] + [0, 0, 0.03], [0, 0, -1], [0, 1, 0])
    variants = placing.place_poses(box.X_WO, top, box.extents, is_tool=False,
                                   release_height=0.01, place_pose=place_pose)
    assert len(variants) == len(placing.turned_release_heights)
    for R_turn, X in variants:
        assert np.allclose(X[:3, :3], R_place) and np.allclose(R_turn @ box.X_WO[:3, :3], R_place)
        assert np.allclose(X[:2, 3], (0.6, -0.3))
    kept = dataclasses.replace(placing, R_place=tuple(map(tuple, box.X_WO[:3, :3])))
    (R_turn, X), = kept.place_poses(box.X_WO, top, box.extents, is_tool=False,
                                    release_height=0.01, place_pose=place_pose)
    assert R_turn is None  # no turn: the orientation kept


def test_finger_swapped_twins_follow_each_candidate_with_the_same_grasp_point():
    X = grasp_pose([0.8, 0.0, 0.1], [0, 0, -1], [0, 1, 0])
    Y = grasp_pose([0.8, 0.1, 0.1], [1, 0, 0], [0, 1, 0])
    c = ranked([(X, "middle"), (Y, "top")])
    twins = finger_swapped(c)
    assert len(twins.score) == 4 and list(twins.source) == [0, 0, 1, 1]
    assert np.allclose(twins.X_WG[0], X) and np.allclose(twins.X_WG[1], X @ SWAP_FINGERS)
    for k in range(4):
        g = twins.X_WG[k]
        assert np.isclose(np.linalg.det(g[:3, :3]), 1.0)
    grasp_point = [g[:3, :3] @ WSG_GRASP_POINT_G + g[:3, 3] for g in twins.X_WG[:2]]
    assert np.allclose(*grasp_point)
    assert np.allclose(twins.X_WG[1][:3, 1], X[:3, 1])  # the same approach
    assert np.allclose(twins.X_WG[1][:3, 0], -X[:3, 0])  # the fingers swapped
