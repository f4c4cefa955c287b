"""LogicQuerySystem alone: fixed inputs, evaluated grasp_semantics."""

from __future__ import annotations

import numpy as np
import pytest

from tg_drake.errors import RuleError
from tg_drake.logic.engine import LogicQueryConfig
from tg_drake.systems.logic_system import LogicQuerySystem, TaskSource
from tg_drake.types import (
    CATEGORIES,
    CategoryDistribution,
    CategoryPrior,
    GraspSemantics,
    ObjectDescription,
    SceneDescription,
    part_index,
)

# The compiled path and the hand derivation agree to float rounding (~1e-15); 1e-9 is the
# module's promised agreement with ProbLog.
EXACT = 1e-9


def _object(parts, pose_likelihood, containment="empty"):
    labels = np.array([part_index(p) for p in parts], dtype=int)
    n = len(labels)
    return ObjectDescription(
        p_W=np.zeros((n, 3)), n_W=np.zeros((n, 3)), labels=labels, visible=np.ones(n, bool),
        X_WO=np.eye(4), extents=np.ones(3), pose=max(pose_likelihood, key=pose_likelihood.get),
        pose_likelihood=pose_likelihood, part_probabilities=parts, part_boxes={},
        pregrasp_X_WG=np.zeros((0, 4, 4)), pregrasp_parts=np.zeros(0, int),
        containment=containment)


def _prior(values):
    return CategoryDistribution(probabilities=np.array([values.get(c, 0.0) for c in CATEGORIES]))


CUP = _object({"top": 0.8, "middle": 1.0, "bottom": 1.0, "handle": 1.0}, {"upright": 0.5})
HAMMER = _object({"handle": 1.0, "usable_area": 1.0}, {"sideways": 1.0}, containment=None)
CUP_PRIOR = _prior({"cup": 0.56, "can": 0.36, "pot": 0.05, "pan": 0.02})
HAMMER_PRIOR = _prior({"hammer": 0.7, "knife": 0.3})


@pytest.fixture(scope="module")
def system():
    return LogicQuerySystem()


def _evaluate(system, *, target=1, task=None, collisions=None, prior=True):
    context = system.CreateDefaultContext()
    scene = SceneDescription(objects=[HAMMER, CUP], X_WT=np.eye(4), target=target)
    system.get_scene_description_input_port().FixValue(context, scene)
    if prior:
        system.get_category_prior_input_port().FixValue(
            context, CategoryPrior(distributions=[HAMMER_PRIOR, CUP_PRIOR]))
    if task is not None:
        system.get_task_input_port().FixValue(context, task)
    if collisions is not None:
        system.get_collisions_input_port().FixValue(context, collisions)
    return system.get_grasp_semantics_output_port().Eval(context)


def test_target_object_gets_the_fig1_answers(system):
    semantics: GraspSemantics = _evaluate(system)  # task and collisions unconnected.
    assert semantics.target == 1 and semantics.given_task is None
    assert semantics.category["cup"] == pytest.approx(0.507 / 0.522, abs=EXACT)  # hand value.
    assert semantics.category["can"] == 0.0
    assert sum(semantics.task.values()) == pytest.approx(1.0, abs=EXACT)
    assert semantics.task["pass"] == pytest.approx(semantics.task["p&pOn"], abs=EXACT)
    assert set(semantics.part) == {"top", "middle", "bottom", "handle"}
    assert semantics.explanations["category"][0].answer == "cup"


def test_task_and_collisions_ports_requery(system):
    free = _evaluate(system, task="pass", collisions=())
    assert free.task == {"pass": 1.0} and free.given_task == "pass"
    assert max(free.part, key=free.part.get) == "middle"
    blocked = _evaluate(system, task="pass", collisions=("middle",))
    assert blocked.part["middle"] == 0.0 and blocked.collisions == ("middle",)
    assert sum(blocked.part.values()) == pytest.approx(1.0, abs=EXACT)
    assert max(blocked.part, key=blocked.part.get) == "top"


def test_default_target_is_object_0_and_tools_are_passed_by_the_usable_area(system):
    semantics = _evaluate(system, target=None, task="pass")
    assert semantics.target == 0
    assert semantics.category["hammer"] > semantics.category["knife"] > 0
    assert max(semantics.part, key=semantics.part.get) == "usable_area"


def test_uniform_prior_leaves_the_prior_port_unconnected():
    system = LogicQuerySystem(LogicQueryConfig(category="general", grasp="general",
                                               use_prior=False, explain=False))
    semantics = _evaluate(system, prior=False)
    # General theory, uniform prior, one handle: cup by rule and prior; pan and pot via
    # kitchen_container; can, bottle ruled out (a canister has no handle).
    assert max(semantics.category, key=semantics.category.get) == "cup"
    assert semantics.category["bottle"] == 0.0 and semantics.category["pot"] > 0
    assert semantics.explanations == {}


def test_bad_inputs_raise_rule_error(system):
    with pytest.raises(RuleError, match="unknown task 'fly'; allowed: pass"):
        _evaluate(system, task="fly")
    with pytest.raises(RuleError, match="unknown part 'rim'"):
        _evaluate(system, collisions=("rim",))
    with pytest.raises(RuleError, match="target 5 is not an object"):
        _evaluate(system, target=5)
    context = system.CreateDefaultContext()
    system.get_scene_description_input_port().FixValue(
        context, SceneDescription(objects=[], X_WT=np.eye(4)))
    with pytest.raises(RuleError, match="no object"):
        system.get_grasp_semantics_output_port().Eval(context)


def test_the_task_source_depends_on_nothing():
    # Its value stays cached as time passes, so the logic downstream is not asked again.
    source = TaskSource("pass")
    context = source.CreateDefaultContext()
    port = source.GetOutputPort("task")
    assert port.Eval(context) == "pass"
    context.SetTime(1.0)
    assert not port.cache_entry().is_out_of_date(context)
    assert port.Eval(context) == "pass"
    infer = TaskSource("")
    assert infer.get_output_port().Eval(infer.CreateDefaultContext()) == ""
