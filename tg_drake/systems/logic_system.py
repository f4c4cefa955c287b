"""The probabilistic logic stage as a Drake system (paper section IV)."""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem

from tg_drake.errors import RuleError
from tg_drake.logic.engine import LogicEngine, LogicQueryConfig
from tg_drake.logic.observations import Observations
from tg_drake.systems.memo import LastResult
from tg_drake.types import CategoryPrior, GraspSemantics, SceneDescription


class LogicQuerySystem(LeafSystem):
    """Category, task and pre-grasp part of the target object from the ProbLog theory.

    .. pydrake_system::

        name: LogicQuerySystem
        input_ports:
        - scene_description
        - category_prior
        - task
        - collisions
        - no_hold
        output_ports:
        - grasp_semantics

    ``scene_description`` (`SceneDescription`): the target is its ``target`` object, else object
    0; its part probabilities, pose likelihood and containment are the observations.
    ``category_prior`` (`CategoryPrior`): the kernel prior of that object, used as an annotated
    disjunction when `config.use_prior`, else a uniform prior is used and the port may be left
    unconnected. ``task`` (str): a TASKS name, or "" to infer the task; unconnected means "".
    ``collisions`` (tuple of part names): collision(Part) evidence from the planner, the parts it
    could not reach; unconnected or () means none. ``no_hold`` (tuple of part names): no_hold(Part)
    evidence, the parts on which the feasibility stage found no grasp that would hold; likewise.

    ``grasp_semantics`` (`GraspSemantics`): the normalised category, task and part distributions
    with explanations. A part distribution of all zeros means the theory rules every grasp out.
    The theory is compiled once, when the system is built.
    """

    def __init__(self, config: LogicQueryConfig | None = None):
        super().__init__()
        self._last = LastResult()  # the stage's last answer and its inputs
        self._config = config if config is not None else LogicQueryConfig()
        self._engine = LogicEngine(self._config.theory())
        self._scene_port = self.DeclareAbstractInputPort(
            "scene_description",
            AbstractValue.Make(SceneDescription(objects=[], X_WT=np.eye(4))))
        self._prior_port = self.DeclareAbstractInputPort(
            "category_prior", AbstractValue.Make(CategoryPrior(distributions=[])))
        self._task_port = self.DeclareAbstractInputPort("task", AbstractValue.Make(""))
        self._collisions_port = self.DeclareAbstractInputPort(
            "collisions", AbstractValue.Make(()))
        self._no_hold_port = self.DeclareAbstractInputPort("no_hold", AbstractValue.Make(()))
        inputs = [self._scene_port, self._task_port, self._collisions_port, self._no_hold_port]
        if self._config.use_prior:
            inputs.append(self._prior_port)
        self._semantics_port = self.DeclareAbstractOutputPort(
            "grasp_semantics",
            lambda: AbstractValue.Make(GraspSemantics(category={}, task={}, part={},
                                                      given_task=None)),
            self._calc_grasp_semantics,
            prerequisites_of_calc={self.input_port_ticket(p.get_index()) for p in inputs})

    @property
    def engine(self) -> LogicEngine:
        return self._engine

    def get_scene_description_input_port(self):
        return self._scene_port

    def get_category_prior_input_port(self):
        return self._prior_port

    def get_task_input_port(self):
        return self._task_port

    def get_collisions_input_port(self):
        return self._collisions_port

    def get_no_hold_input_port(self):
        return self._no_hold_port

    def get_grasp_semantics_output_port(self):
        return self._semantics_port

    def _calc_grasp_semantics(self, context, output):
        scene: SceneDescription = self._scene_port.Eval(context)
        if not scene.objects:
            raise RuleError("the scene description holds no object to reason about",
                            field="scene_description")
        target = scene.reasoning_target
        if not 0 <= target < len(scene.objects):
            raise RuleError(f"target {target} is not an object of the scene description "
                            f"(it has {len(scene.objects)})", field="scene_description.target")
        prior = None
        if self._config.use_prior:
            priors: CategoryPrior = self._prior_port.Eval(context)
            if len(priors.distributions) != len(scene.objects):
                raise RuleError(f"the category prior has {len(priors.distributions)} "
                                f"distributions for {len(scene.objects)} objects",
                                field="category_prior")
            prior = priors.distributions[target]
        task = self._task_port.Eval(context) if self._task_port.HasValue(context) else ""
        collisions = (self._collisions_port.Eval(context)
                      if self._collisions_port.HasValue(context) else ())
        if isinstance(collisions, str) or not isinstance(collisions, tuple | list):
            raise RuleError(f"collisions must be a tuple of part names, got {collisions!r}",
                            field="collisions")
        no_hold = (self._no_hold_port.Eval(context)
                   if self._no_hold_port.HasValue(context) else ())
        if isinstance(no_hold, str) or not isinstance(no_hold, tuple | list):
            raise RuleError(f"no_hold must be a tuple of part names, got {no_hold!r}",
                            field="no_hold")
        collisions, no_hold = tuple(collisions), tuple(no_hold)

        def answer():
            obs = Observations.from_object(scene.objects[target], prior=prior, task=task,
                                           collisions=collisions, no_hold=no_hold,
                                           prior_floor=self._config.prior_floor)
            return self._engine.query(obs, explain=self._config.explain).to_semantics(
                target=target)

        output.set_value(self._last((scene, prior, task, collisions, no_hold), answer))


class TaskSource(LeafSystem):
    """The task, constant, for the logic's ``task`` input.

    .. pydrake_system::

        name: TaskSource
        output_ports:
        - task

    ``task`` (str): a TASKS name, or "" to infer the task. Its output depends on nothing (a
    ConstantValueSource's depends on every source, the time included), so the logic's cache
    stays valid while the simulation runs.
    """

    def __init__(self, task: str):
        super().__init__()
        self._task = str(task)
        self.DeclareAbstractOutputPort("task", lambda: AbstractValue.Make(""), self._calc_task,
                                       prerequisites_of_calc={self.nothing_ticket()})

    def _calc_task(self, context, output):
        output.set_value(self._task)
