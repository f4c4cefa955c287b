"""The rule that turns a grasp hypothesis into the poses that may be executed
(tg_drake.grasping.expansion), on arrays, and that the DGI's training data and inference use it
alike."""

import numpy as np
import pytest
from grasp_helpers import top_down

from tg_drake.errors import ScenarioError
from tg_drake.grasping.dataset import SamplingConfig, scene_grasps
from tg_drake.grasping.expansion import (
    ExpansionConfig,
    approach_variants,
    executed_poses,
    lowest_point,
    retreat_above_table,
)
from tg_drake.grasping.scoring import candidate_poses
from tg_drake.objects import get_object
from tg_drake.robot import WSG_GRASP_POINT_G, WSG_PAD_CENTRE_Y
from tg_drake.scenario import PipelineConfig
from tg_drake.types import ObjectDescription, SceneDescription

CONFIG = ExpansionConfig()


def grasp_point(X):
    return X[:3, 3] + X[:3, 1] * WSG_PAD_CENTRE_Y


def test_a_pose_below_the_table_retreats_up_its_approach_by_the_shortfall():
    X = top_down((0.6, 0.0, 0.01))  # the pad tips ~31 mm under the table top at z = 0
    short = CONFIG.table_clearance - lowest_point(X, 0.1)[0]
    assert 0.0 < short < CONFIG.max_retreat
    moved, ok = retreat_above_table(X, 0.0, approach_distance=0.1, config=CONFIG)
    assert ok[0]
    # Straight down, the retreat is the shortfall itself, along −y_G = +z_W.
    np.testing.assert_allclose(moved[0][:3, 3] - X[:3, 3], [0.0, 0.0, short], atol=1e-12)
    np.testing.assert_allclose(moved[0][:3, :3], X[:3, :3])
    assert lowest_point(moved[0], 0.1)[0] == pytest.approx(CONFIG.table_clearance)
    # A tilted approach (45° down) retreats by the shortfall / sin 45° along its approach.
    c = np.sqrt(0.5)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([[0, 1, 0], [c, 0, -c], [0, 0, -1]])
    T[:3, :3] = np.column_stack([T[:3, 0], T[:3, 1], np.cross(T[:3, 0], T[:3, 1])])
    T[:3, 3] = [0.6, 0.0, 0.06]  # its lowest corner ~15 mm under the table top
    short_t = CONFIG.table_clearance - lowest_point(T, 0.1)[0]
    moved_t, ok_t = retreat_above_table(T, 0.0, approach_distance=0.1, config=CONFIG)
    assert ok_t[0] and 0 < short_t / c <= CONFIG.max_retreat
    assert np.linalg.norm(moved_t[0][:3, 3] - T[:3, 3]) == pytest.approx(short_t / c)
    assert lowest_point(moved_t[0], 0.1)[0] == pytest.approx(CONFIG.table_clearance)


def test_a_pose_that_needs_more_than_max_retreat_or_cannot_rise_is_dropped():
    deep = top_down((0.6, 0.0, -0.04))  # needs ~8 cm
    side = np.eye(4)  # approach +y_W, horizontal: moving back does not raise it
    side[:3, 3] = [0.6, 0.0, 0.005]
    high = top_down((0.6, 0.0, 0.2))
    X, source = executed_poses(np.stack([deep, side, high]), 0.0, approach_distance=0.1,
                               config=CONFIG, variants=False)
    assert source.tolist() == [2]
    np.testing.assert_array_equal(X[0], high)  # clear already: untouched


def test_a_side_grasp_is_offered_tilted_down_about_its_grasp_point():
    X = np.eye(4)  # approach +y_W: horizontal
    X[:3, 3] = [0.5, 0.0, 0.2]
    variants = approach_variants(X, CONFIG)
    assert len(variants) == 1 + len(CONFIG.approach_tilts)
    for V, tilt in zip(variants[1:], CONFIG.approach_tilts, strict=True):
        np.testing.assert_allclose(grasp_point(V), grasp_point(X), atol=1e-12)
        assert np.degrees(np.arcsin(-V[2, 1])) == pytest.approx(tilt)
    poses, source = executed_poses(X[None], 0.0, approach_distance=0.1, config=CONFIG)
    assert source.tolist() == [0] * len(variants)
    np.testing.assert_allclose(poses, np.array(variants))


def test_a_steep_grasp_far_out_is_also_offered_leaning_back_towards_the_robot():
    X = np.eye(4)
    X[:3, :3] = np.column_stack([[0, 1, 0], [0, 0, -1], [-1, 0, 0]])  # x_G = y_W: across
    X[:3, 3] = np.array([0.85, 0.0, 0.05]) - X[:3, 1] * WSG_GRASP_POINT_G[1]
    variants = approach_variants(X, CONFIG)
    assert len(variants) == 1 + len(CONFIG.top_tilts)
    for V, tilt in zip(variants[1:], CONFIG.top_tilts, strict=True):
        np.testing.assert_allclose(grasp_point(V), grasp_point(X), atol=1e-12)
        np.testing.assert_allclose(V[:3, 0], X[:3, 0], atol=1e-12)  # the same closing axis
        assert -V[0, 1] < 0.0  # the wrist (−y_G) leans back towards the robot
        assert np.degrees(np.arccos(-V[2, 1])) == pytest.approx(tilt)
    # Closing towards the robot, the wrist cannot lean back about the closing axis.
    assert len(approach_variants(top_down((0.85, 0.0, 0.05)), CONFIG)) == 1


def test_bad_expansion_settings_name_the_field():
    with pytest.raises(ScenarioError, match="pipeline.expansion.max_retreat"):
        ExpansionConfig(max_retreat=-0.01).validate("pipeline.expansion")
    with pytest.raises(ScenarioError, match="top_tilts"):
        ExpansionConfig(top_tilts=[95.0]).validate()


def test_training_data_and_inference_make_the_same_poses_of_the_same_hypotheses():
    """The DGI's box grasps (training data) and the scoring stage's candidates (inference) of the
    same part-box hypotheses over the same table: the same poses. Fails if either side moved
    to a rule of its own."""
    sampling = SamplingConfig(perturbed_per_box=0, n_random=0)
    assert sampling.expansion == PipelineConfig().expansion  # one rule, one set of parameters
    obj = get_object("cup_01")
    grasps = scene_grasps(obj, "upright", seed=0, config=sampling)
    assert len(grasps.X_WG) > len(grasps.hypotheses) // 3  # the table rules some out, not most
    n = len(grasps.hypotheses)
    target = ObjectDescription(
        p_W=np.zeros((4, 3)), n_W=np.zeros((4, 3)), labels=np.zeros(4, int),
        visible=np.ones(4, bool), X_WO=grasps.X_WO, extents=np.full(3, 0.1), pose="upright",
        pose_likelihood={"upright": 1.0}, part_probabilities={}, part_boxes={},
        pregrasp_X_WG=grasps.hypotheses, pregrasp_parts=np.zeros(n, int))
    scene = SceneDescription(objects=[target], X_WT=np.eye(4))  # the table top at z_W = 0
    X_WG, _, _ = candidate_poses(scene, 0, expansion=sampling.expansion,
                                 approach=sampling.approach_distance)
    np.testing.assert_allclose(X_WG, grasps.X_WG, atol=1e-12)
    # Some of them are variants or moved: the rule did something.
    assert len(X_WG) != n or not np.allclose(X_WG, grasps.hypotheses)
