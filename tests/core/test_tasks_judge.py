"""The task judges on arrays: pose classification, placing, surfaces, pours."""

import numpy as np
import pytest

from tg_drake.tasks.judge import (
    judge_on_surface,
    judge_pour,
    judge_rest_pose,
    rest_pose,
)
from tg_drake.tasks.outcome import TaskOutcome

X_WT = np.eye(4)


def rot_x(deg):
    a = np.deg2rad(deg)
    X = np.eye(4)
    X[1:3, 1:3] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
    return X


@pytest.mark.parametrize("deg, pose", [(0, "upright"), (30, "upright"), (90, "sideways"),
                                       (-90, "sideways"), (180, "upsidedown"),
                                       (150, "upsidedown")])
def test_rest_pose_of_a_container(deg, pose):
    assert rest_pose(rot_x(deg), X_WT, is_tool=False) == pose


def test_a_tool_lies_sideways():
    assert rest_pose(rot_x(180), X_WT, is_tool=True) == "sideways"


def test_rest_pose_judge():
    X = rot_x(180)
    X[:3, 3] = [0.5, 0.1, 0.05]
    ok = judge_rest_pose("p&pInUpsidedown", X, X_WT, is_tool=False, p_WC=X[:3, 3],
                         target_xy=(0.51, 0.1), released=True)
    assert ok.success and ok.measure == {"rest_pose": "upsidedown", "distance_m": 0.01}
    wrong = judge_rest_pose("p&pInUpright", X, X_WT, is_tool=False, p_WC=X[:3, 3],
                            target_xy=(0.51, 0.1), released=True)
    assert not wrong.success and "asks upright" in wrong.detail
    far = judge_rest_pose("p&pInUpsidedown", X, X_WT, is_tool=False, p_WC=X[:3, 3],
                          target_xy=(0.6, 0.1), released=True)
    assert not far.success and "cm from the target" in far.detail
    held = judge_rest_pose("p&pInUpsidedown", X, X_WT, is_tool=False, p_WC=X[:3, 3],
                           target_xy=(0.5, 0.1), released=False)
    assert not held.success


def test_surface_judge():
    assert judge_on_surface("shelf", on_surface=True, on_table=False, released=True).success
    assert not judge_on_surface("shelf", on_surface=False, on_table=True, released=True).success
    assert not judge_on_surface("shelf", on_surface=True, on_table=True, released=True).success
    assert not judge_on_surface("shelf", on_surface=True, on_table=False, released=False).success


def test_pour_judge():
    counts = {"cup": 2, "bowl": 17, "table": 1, "floor": 0, "elsewhere": 0}
    out = judge_pour("pourOut", counts, into="bowl", held=True)
    assert out.success and out.measure["poured_fraction"] == 0.85
    assert not judge_pour("pourOut", {**counts, "bowl": 15, "table": 3}, into="bowl",
                          held=True).success
    assert not judge_pour("pourOut", counts, into="bowl", held=False).success
    assert not judge_pour("pourIn", {"cup": 0, "table": 0}, into="cup", held=True).success


def test_outcome_as_dict_and_task_names():
    o = TaskOutcome("p&pOn", True, {"surface": "shelf"}, "resting on shelf")
    assert o.as_dict() == {"task": "p&pOn", "success": True, "measure": {"surface": "shelf"},
                           "detail": "resting on shelf"}
    with pytest.raises(ValueError, match="allowed"):
        TaskOutcome("juggle", True)


def test_the_contents_counter_reads_the_containers_poses_from_body_poses():
    from tg_drake.objects import get_object
    from tg_drake.tasks.contents import ContentsModel
    from tg_drake.tasks.judge import contents_counter

    cup = get_object("cup_01")
    X_WO = np.eye(4)
    X_WO[:3, 3] = [0.7, 0.1, 0.0]
    inside = np.eye(4)
    inside[:3, 3] = X_WO[:3, 3] + np.asarray(cup.cavity_centroid)
    on_table = np.eye(4)
    on_table[:3, 3] = [0.5, -0.2, 0.005]
    body_poses = [np.eye(4), X_WO, inside, on_table]  # body 1: the cup; 2, 3: spheres
    count = contents_counter(ContentsModel("cup", (2, 3), 0.005),
                             containers={"cup": (1, cup)}, table_z=0.0)
    assert count(body_poses) == {"cup": 1, "table": 1, "floor": 0, "elsewhere": 0}
    out = judge_pour("pourIn", count(body_poses), into="cup", held=True)
    assert not out.success and out.measure["poured_fraction"] == 0.5
