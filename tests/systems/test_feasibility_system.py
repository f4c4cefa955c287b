"""GraspFeasibility alone, and between a fixed scoring output and a planner-facing output in a
small diagram: fixed scene, semantics and scored candidates in, executed poses with P(hold) out."""

import numpy as np
import pytest
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from tg_drake.grasping.feasibility import FeasibilityConfig
from tg_drake.robot import WSG_GRASP_POINT_G
from tg_drake.systems.feasibility_system import GraspFeasibility
from tg_drake.types import (
    GraspCandidates,
    GraspSemantics,
    ObjectDescription,
    SceneDescription,
    part_index,
)


def box_points(size, centre, spacing=0.003):
    size, centre = np.asarray(size, float), np.asarray(centre, float)
    axes = [np.arange(-s / 2, s / 2 + 1e-9, spacing) for s in size]
    g = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return g[np.any(np.isclose(np.abs(g), size / 2, atol=spacing / 2), axis=1)] + centre


def obj(p_W):
    n = len(p_W)
    X_WO = np.eye(4)
    X_WO[:3, 3] = p_W.mean(axis=0)
    return ObjectDescription(p_W=p_W, n_W=np.tile([0.0, 0.0, 1.0], (n, 1)),
                             labels=np.full(n, part_index("middle")), visible=np.ones(n, bool),
                             X_WO=X_WO, extents=np.ptp(p_W, axis=0), pose="upright",
                             pose_likelihood={"upright": 1.0}, part_probabilities={"middle": 1.0},
                             part_boxes={}, pregrasp_X_WG=np.zeros((0, 4, 4)),
                             pregrasp_parts=np.zeros(0, int))


def top_down(p_grasp):
    X = np.eye(4)
    X[:3, :3] = np.column_stack([[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    X[:3, 3] = np.asarray(p_grasp, float) + [0.0, 0.0, WSG_GRASP_POINT_G[1]]
    return X


@pytest.fixture(scope="module")
def scene():
    target = obj(box_points((0.04, 0.04, 0.08), (0.7, 0.0, 0.04)))
    # A neighbour 10 mm beside the target along x: the pads closing along x would land on it.
    neighbour = obj(box_points((0.04, 0.04, 0.08), (0.75, 0.0, 0.04)))
    return SceneDescription(objects=[target, neighbour], X_WT=np.eye(4), target=0)


def candidates():
    across_y = top_down((0.7, 0.0, 0.06))
    across_y[:3, :3] = np.column_stack([[0, 1, 0], [0, 0, -1], [-1, 0, 0]])
    along_x = top_down((0.7, 0.0, 0.06))
    X = np.array([along_x, across_y])
    return GraspCandidates(X, np.full(2, part_index("middle")), np.array([1.0, 1.0]),
                           np.array([0.9, 0.8]), np.array([0.9, 0.8]), target=0)


@pytest.mark.parametrize("rank_by_hold", [False, True])
def test_feasibility_system_rules_out_the_pose_that_would_cut_a_neighbour(scene, rank_by_hold):
    builder = DiagramBuilder()
    config = FeasibilityConfig(rank_by_hold=rank_by_hold, min_p_hold=0.0)
    system = builder.AddSystem(GraspFeasibility(config, approach=0.1))
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    sc = system.GetMyContextFromRoot(context)
    system.GetInputPort("scene_description").FixValue(sc, scene)
    system.GetInputPort("grasp_semantics").FixValue(sc, GraspSemantics(
        category={"can": 1.0}, task={}, part={"middle": 1.0}, given_task=None))
    system.GetInputPort("ranked_grasps").FixValue(sc, candidates())
    out: GraspCandidates = system.get_ranked_grasps_output_port().Eval(sc)
    # The poses as scored, none added or moved (the scoring stage made them).
    assert len(out.score) == 2 and len(out.source) == len(out.score)
    for k, i in enumerate(out.source):
        np.testing.assert_array_equal(out.X_WG[k], candidates().X_WG[i])
    assert out.p_hold is not None and len(out.feasibility_reasons) == len(out.score)
    along = out.source == 0
    assert np.all(out.score[along] == 0.0)
    assert all(r.startswith("collision") for r, a in zip(out.feasibility_reasons, along,
                                                          strict=True) if a)
    # The pose across y clears the neighbour; its score is the product of the factors, P(hold)
    # among them when the stage ranks by it.
    best = int(np.argmax(out.score))
    assert out.source[best] == 1
    p_hold = out.p_hold[best] if rank_by_hold else 1.0
    assert out.score[best] == pytest.approx(1.0 * 0.8 * p_hold)
    assert 0.0 < out.p_hold[best] <= 1.0
    assert np.all(np.diff(out.score) <= 0)  # best first


class Held(LeafSystem):
    """Gives its `values` (name -> Python object) on output ports of those names, as an upstream
    stage gives its cached answer: the same object until it changes. Their prerequisites are the
    defaults (time among them), so every new time makes them, and all below, out of date."""

    def __init__(self, values: dict):
        super().__init__()
        self.values = dict(values)
        for name, value in values.items():
            self.DeclareAbstractOutputPort(
                name, lambda v=value: AbstractValue.Make(v),
                lambda context, output, name=name: output.set_value(self.values[name]))


def test_the_stage_answers_again_without_recomputing_while_its_inputs_are_the_same(scene):
    semantics = GraspSemantics(category={"can": 1.0}, task={}, part={"middle": 1.0},
                               given_task=None)
    builder = DiagramBuilder()
    held = builder.AddSystem(Held({"scene_description": scene, "grasp_semantics": semantics,
                                   "ranked_grasps": candidates()}))
    system = builder.AddSystem(GraspFeasibility(FeasibilityConfig()))
    for name in ("scene_description", "grasp_semantics", "ranked_grasps"):
        builder.Connect(held.GetOutputPort(name), system.GetInputPort(name))
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    port = system.get_ranked_grasps_output_port()
    answers = []
    for t in (0.0, 0.1, 0.2):  # a new time: the port is out of date, its inputs the same objects
        context.SetTime(t)
        answers.append(port.Eval(system.GetMyContextFromRoot(context)))
    first = answers[0]
    assert all(a is first for a in answers) and system._last.computed == 1
    # Other candidates (an equal copy is another object): computed again, the same answer.
    held.values["ranked_grasps"] = candidates()
    context.SetTime(0.3)
    again = port.Eval(system.GetMyContextFromRoot(context))
    assert system._last.computed == 2 and again is not first
    np.testing.assert_array_equal(again.score, first.score)
