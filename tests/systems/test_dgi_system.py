"""DgiScoringSystem alone: fixed scene description and grasp semantics in, ranked grasps out."""

import numpy as np
import pytest
from pydrake.systems.framework import DiagramBuilder

from tg_drake.errors import GraspingError
from tg_drake.grasping.dataset import part_boxes, scene_cloud
from tg_drake.grasping.dgi import GRIPPER_BASE_Y, PAD_CENTER_Y, dgi_features
from tg_drake.grasping.hypotheses import box_grasps
from tg_drake.grasping.model import DgiGraspModel, load_model
from tg_drake.grasping.svm import PlattSvmClassifier
from tg_drake.objects import get_object, sample_surface
from tg_drake.systems.dgi_system import DgiScoringSystem
from tg_drake.types import (
    GraspCandidates,
    GraspSemantics,
    ObjectDescription,
    SceneDescription,
    part_index,
)


def synthetic_training_set(rng, n=300):
    """Cylinders that fit between the fingers (1) against empty volumes and plates wider than the
    opening (0), seen from the gripper frame."""
    x = np.arange(-0.07, 0.07, 0.001)
    z = np.arange(-0.012, 0.012, 0.002)
    xx, zz = (a.ravel() for a in np.meshgrid(x, z, indexing="ij"))
    features, labels = [], []
    for i in range(n):
        depth = rng.uniform(0.005, 0.04)
        if i % 3 == 0:
            r = rng.uniform(0.015, 0.045)
            keep = np.abs(xx) < r
            d, xs, zs = depth + r - np.sqrt(r**2 - xx[keep] ** 2), xx[keep], zz[keep]
        elif i % 3 == 1:
            d, xs, zs = np.full(xx.shape, depth), xx, zz
        else:
            d, xs, zs = np.full(1, depth), np.full(1, 1.0), np.zeros(1)  # nothing in the volume
        p_G = np.stack([xs, GRIPPER_BASE_Y + d, zs], axis=1)
        features.append(dgi_features(p_G, np.eye(4))[0])
        labels.append(int(i % 3 == 0))
    return np.array(features), np.array(labels)


@pytest.fixture(scope="module")
def model():
    X, y = synthetic_training_set(np.random.default_rng(0))
    return DgiGraspModel(PlattSvmClassifier(gamma=1.0, random_state=0).fit(X, y))


def top_down(grasp_point):
    X = np.eye(4)
    X[:3, :3] = np.column_stack([[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    X[:3, 3] = np.asarray(grasp_point) + [0, 0, PAD_CENTER_Y]
    return X


def cylinder_object(pregrasps, parts):
    """An upright cylinder (r 0.03 m, h 0.1 m) on the table at x = 0.5 m."""
    t = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    h = np.linspace(0, 0.1, 51)
    tt, hh = (a.ravel() for a in np.meshgrid(t, h))
    p = np.stack([0.5 + 0.03 * np.cos(tt), 0.03 * np.sin(tt), hh], axis=1)
    n = np.stack([np.cos(tt), np.sin(tt), np.zeros_like(tt)], axis=1)
    X_WO = np.eye(4)
    X_WO[:3, 3] = [0.5, 0, 0.05]
    return ObjectDescription(
        p_W=p, n_W=n, labels=np.zeros(len(p), int), visible=np.ones(len(p), bool), X_WO=X_WO,
        extents=np.array([0.06, 0.06, 0.1]), pose="upright", pose_likelihood={"upright": 1.0},
        part_probabilities={"top": 1.0, "middle": 1.0}, part_boxes={},
        pregrasp_X_WG=np.asarray(pregrasps), pregrasp_parts=np.asarray(parts))


@pytest.fixture
def setup(model):
    builder = DiagramBuilder()
    system = builder.AddSystem(DgiScoringSystem(model))
    diagram = builder.Build()
    return system, diagram


def evaluate(system, diagram, scene, semantics) -> GraspCandidates:
    context = diagram.CreateDefaultContext()
    sub = system.GetMyMutableContextFromRoot(context)
    system.get_scene_description_input_port().FixValue(sub, scene)
    system.get_grasp_semantics_input_port().FixValue(sub, semantics)
    return system.get_ranked_grasps_output_port().Eval(sub)


def test_ranks_the_targets_hypotheses_by_part_and_local_shape(setup, model):
    system, diagram = setup
    poses = np.stack([
        top_down([0.5, 0, 0.09]),  # on the cylinder's top: graspable
        top_down([0.62, 0, 0.09]),  # beside it: nothing between the fingers
        top_down([0.5, 0, 0.07]),  # on the cylinder, a part the logic gives 0.3
        top_down([0.5, 0, 0.09]),  # graspable, but a part the logic does not name
    ])
    parts = [part_index("top"), part_index("top"), part_index("middle"), part_index("handle")]
    target = cylinder_object(poses, parts)
    other = cylinder_object(poses[:1], parts[:1])
    scene = SceneDescription(objects=[other, target], X_WT=np.eye(4), target=1)
    semantics = GraspSemantics(category={"cup": 1.0}, task={"pass": 1.0},
                               part={"top": 0.7, "middle": 0.3}, given_task="pass", target=1)

    ranked = evaluate(system, diagram, scene, semantics)
    p_local = model.p_grasp(target.p_W, poses)
    assert p_local[0] > 0.5 > p_local[1]  # the model separates the two shapes
    order = np.argsort(-(np.array([0.7, 0.7, 0.3, 0.0]) * p_local), kind="stable")
    assert ranked.target == 1
    np.testing.assert_array_equal(ranked.parts, np.asarray(parts)[order])
    # 1e-12: the same arithmetic as the system's.
    np.testing.assert_allclose(ranked.p_local, p_local[order], atol=1e-12)
    np.testing.assert_allclose(ranked.p_part, np.array([0.7, 0.7, 0.3, 0.0])[order])
    np.testing.assert_allclose(ranked.score, ranked.p_part * ranked.p_local, atol=1e-15)
    np.testing.assert_array_equal(ranked.X_WG, poses[order])
    assert np.all(np.diff(ranked.score) <= 0)
    assert ranked.parts[0] == part_index("top") and ranked.score[-1] == 0.0


def test_a_target_outside_the_scene_is_a_clear_error(setup):
    system, diagram = setup
    scene = SceneDescription(objects=[cylinder_object(np.zeros((0, 4, 4)), [])], X_WT=np.eye(4))
    semantics = GraspSemantics(category={}, task={}, part={}, given_task=None, target=2)
    with pytest.raises(GraspingError, match="target object 2 but the scene description has 1"):
        evaluate(system, diagram, scene, semantics)
    semantics.target = 0
    assert len(evaluate(system, diagram, scene, semantics).score) == 0


def test_model_file_round_trip(model, tmp_path):
    path = tmp_path / "m.joblib"
    model.save(path)
    loaded = load_model(path)
    X, _ = synthetic_training_set(np.random.default_rng(1), 30)
    np.testing.assert_array_equal(loaded.classifier.predict_proba(X),
                                  model.classifier.predict_proba(X))
    with pytest.raises(GraspingError, match="no DGI model file"):
        load_model(tmp_path / "missing.joblib")


def test_the_shipped_model_scores_side_grasps_of_a_glass_above_an_empty_volume():
    system = DgiScoringSystem()  # loads tg_drake/data/dgi_svm.joblib
    model = system.model
    assert model.info["n_grasps"] >= 5000
    glass = get_object("glass_01")  # 6.8 cm across: fits the 11 cm opening
    p_W, _, _ = scene_cloud(glass, "upright", seed=0)
    p_O, _, labels = sample_surface(glass, spacing=0.003, rng=np.random.default_rng(0))
    X_OB, half = part_boxes(p_O, labels)[part_index("middle")]
    X_WG = box_grasps(glass.resting_pose("upright").X_TO @ X_OB, half)
    # From the four sides, closing horizontally across the glass (faces ±x, ±y; closing along the
    # other horizontal axis): the grasps that held in the training scenes.
    side = X_WG[[0, 2, 5, 7]]
    assert np.all(np.abs(side[:, 2, 0]) < 1e-9)  # closing axis horizontal
    far = np.eye(4)
    far[:3, 3] = [1.0, 1.0, 1.0]  # nothing in the volume
    p = model.p_grasp(p_W, np.concatenate([side, far[None]]))
    assert np.all(p[:4] > 0.5) and p[4] < 0.5


def test_local_only_ranks_by_local_shape_alone_and_names_bad_selections(model):
    builder = DiagramBuilder()
    system = builder.AddSystem(DgiScoringSystem(model, selection="local_only"))
    diagram = builder.Build()
    poses = np.stack([top_down([0.62, 0, 0.09]), top_down([0.5, 0, 0.09])])
    parts = [part_index("top"), part_index("handle")]  # the logic gives the graspable one 0
    scene = SceneDescription(objects=[cylinder_object(poses, parts)], X_WT=np.eye(4), target=0)
    semantics = GraspSemantics(category={"cup": 1.0}, task={"pass": 1.0}, part={"top": 1.0},
                               given_task="pass")
    ranked = evaluate(system, diagram, scene, semantics)
    p_local = model.p_grasp(scene.objects[0].p_W, poses)
    assert p_local[1] > 0.5 > p_local[0]
    np.testing.assert_array_equal(ranked.parts, [part_index("handle"), part_index("top")])
    np.testing.assert_allclose(ranked.score, p_local[[1, 0]], atol=1e-12)
    np.testing.assert_allclose(ranked.p_part, [0.0, 1.0])  # kept for the record
    with pytest.raises(GraspingError, match="unknown grasp selection 'logic'; allowed: pipeline"):
        DgiScoringSystem(model, selection="logic")


def test_new_semantics_rerank_without_rescoring_the_shapes(model):
    # P(grasp | local shape) depends on the scene alone: a cache entry on scene_description.
    calls = []

    class CountingModel:
        def p_grasp(self, p_W, X_WG):
            calls.append(len(X_WG))
            return model.p_grasp(p_W, X_WG)

    builder = DiagramBuilder()
    system = builder.AddSystem(DgiScoringSystem(CountingModel()))
    diagram = builder.Build()
    context = system.GetMyMutableContextFromRoot(diagram.CreateDefaultContext())
    poses = np.stack([top_down([0.5, 0, 0.09]), top_down([0.5, 0, 0.07])])
    parts = [part_index("top"), part_index("middle")]
    scene = SceneDescription(objects=[cylinder_object(poses, parts)], X_WT=np.eye(4), target=0)
    system.get_scene_description_input_port().FixValue(context, scene)
    port = system.get_ranked_grasps_output_port()
    rankings = []
    for part in ({"top": 0.9, "middle": 0.1}, {"top": 0.1, "middle": 0.9}):
        system.get_grasp_semantics_input_port().FixValue(context, GraspSemantics(
            category={"cup": 1.0}, task={"pass": 1.0}, part=part, given_task="pass"))
        rankings.append(port.Eval(context))
    assert calls == [2]
    p_local = model.p_grasp(scene.objects[0].p_W, poses)
    for ranked, first in zip(rankings, ("top", "middle"), strict=False):
        assert ranked.parts[0] == part_index(first)
        np.testing.assert_allclose(np.sort(ranked.p_local), np.sort(p_local), atol=1e-12)
    # A new scene scores its shapes again.
    system.get_scene_description_input_port().FixValue(
        context, SceneDescription(objects=[cylinder_object(poses[:1], parts[:1])],
                                  X_WT=np.eye(4), target=0))
    assert len(port.Eval(context).score) == 1 and calls == [2, 1]


def test_scores_the_poses_that_will_be_executed_and_feasibility_passes_them_on(model):
    """scoring → feasibility in a small diagram: the scorer turns each hypothesis into the poses
    that may be executed (`executed_poses`: variants, moved back above the table), scores each of
    them by its own DGI, and feasibility hands exactly those poses on."""
    from tg_drake.grasping.expansion import ExpansionConfig, executed_poses
    from tg_drake.grasping.feasibility import FeasibilityConfig
    from tg_drake.systems.feasibility_system import GraspFeasibility

    side = np.eye(4)  # from −y_W towards the cylinder's middle, closing along x_W: 4 variants
    side[:3, 3] = np.array([0.5, 0.0, 0.06]) - [0.0, PAD_CENTER_Y, 0.0]
    low = top_down([0.5, 0, 0.03])  # its pad tips 11 mm under the table top: moved back
    hypotheses = np.stack([side, low])
    target = cylinder_object(hypotheses, [part_index("middle"), part_index("top")])
    scene = SceneDescription(objects=[target], X_WT=np.eye(4), target=0)
    semantics = GraspSemantics(category={"cup": 1.0}, task={"pass": 1.0},
                               part={"top": 0.5, "middle": 0.5}, given_task="pass")
    expansion = ExpansionConfig()
    builder = DiagramBuilder()
    scoring = builder.AddSystem(DgiScoringSystem(model, expansion=expansion, approach=0.1))
    feasibility = builder.AddSystem(GraspFeasibility(FeasibilityConfig(), approach=0.1))
    builder.Connect(scoring.get_ranked_grasps_output_port(),
                    feasibility.GetInputPort("ranked_grasps"))
    builder.ExportInput(scoring.get_scene_description_input_port(), "scene")
    builder.ExportInput(feasibility.GetInputPort("scene_description"), "scene_f")
    builder.ExportInput(scoring.get_grasp_semantics_input_port(), "semantics")
    builder.ExportInput(feasibility.GetInputPort("grasp_semantics"), "semantics_f")
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    for name, value in (("scene", scene), ("scene_f", scene), ("semantics", semantics),
                        ("semantics_f", semantics)):
        diagram.GetInputPort(name).FixValue(context, value)
    scored = scoring.get_ranked_grasps_output_port().Eval(
        scoring.GetMyContextFromRoot(context))

    poses, source = executed_poses(hypotheses, 0.0, approach_distance=0.1, config=expansion)
    assert np.bincount(source).tolist() == [1 + len(expansion.approach_tilts), 1]
    assert poses[-1][2, 3] > low[2, 3]  # the low one moved up its approach
    assert len(scored.score) == len(poses)
    for k in range(len(poses)):
        i = int(np.flatnonzero(np.all(np.isclose(poses, scored.X_WG[k]), axis=(1, 2)))[0])
        assert scored.source[k] == source[i]
        # Each pose's P(grasp | local shape) is its own DGI's, not its hypothesis'.
        assert scored.p_local[k] == pytest.approx(model.p_grasp(target.p_W, poses[i:i + 1])[0])
    assert len(set(np.round(scored.p_local, 9))) > 1  # the variants look different to the DGI
    assert np.all(np.diff(scored.score) <= 0)  # best first
    out = feasibility.get_ranked_grasps_output_port().Eval(
        feasibility.GetMyContextFromRoot(context))
    assert len(out.score) == len(scored.score)
    for X in out.X_WG:  # every pose the planner may take is one the DGI scored
        assert np.any(np.all(np.isclose(scored.X_WG, X, atol=0), axis=(1, 2)))
