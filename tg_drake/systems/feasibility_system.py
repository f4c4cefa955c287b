"""The grasp feasibility stage as a Drake system (tg_drake.grasping.feasibility)."""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem

from tg_drake.grasping.feasibility import FeasibilityConfig, assess_candidates, load_hold_model
from tg_drake.systems.memo import LastResult
from tg_drake.types import GraspCandidates, GraspSemantics, SceneDescription


def _no_candidates() -> GraspCandidates:
    empty = np.zeros(0)
    return GraspCandidates(np.zeros((0, 4, 4)), np.zeros(0, int), empty, empty, empty)


class GraspFeasibility(LeafSystem):
    """
    .. pydrake_system::

        name: GraspFeasibility
        input_ports:
        - scene_description
        - grasp_semantics
        - ranked_grasps
        output_ports:
        - ranked_grasps

    Between scoring and the planner: every hypothesis of the input ``ranked_grasps`` (a
    `GraspCandidates`, scored P(part | task) · P(grasp | local shape)) with its approach variants,
    each pose as it will be executed with P(hold) (`GraspCandidates.p_hold`) and the score
    P(part | task) · P(grasp | local shape) · P(hold); a pose whose gripper would cut another
    perceived object or the table, or that would not hold, gets score 0 and a reason
    (`feasibility_reasons`). The object's mass weighs the density priors by the logic's category
    distribution (``grasp_semantics``). Output ``ranked_grasps`` best first
    (`tg_drake.grasping.feasibility.assess_candidates`).

    `approach` [m]: how far the gripper comes along its approach (the planner's pre-grasp
    distance).
    """

    def __init__(self, config: FeasibilityConfig | None = None, *, approach: float = 0.10):
        super().__init__()
        self._last = LastResult()  # the stage's last answer and its inputs
        self._config = config or FeasibilityConfig()
        self._model = load_hold_model(self._config.model or None)
        self._approach = float(approach)
        self._scene_port = self.DeclareAbstractInputPort(
            "scene_description", AbstractValue.Make(SceneDescription(objects=[], X_WT=np.eye(4))))
        self._semantics_port = self.DeclareAbstractInputPort(
            "grasp_semantics",
            AbstractValue.Make(GraspSemantics(category={}, task={}, part={}, given_task=None)))
        self._grasps_port = self.DeclareAbstractInputPort(
            "ranked_grasps", AbstractValue.Make(_no_candidates()))
        self._ranked_port = self.DeclareAbstractOutputPort(
            "ranked_grasps", lambda: AbstractValue.Make(_no_candidates()), self._calc,
            prerequisites_of_calc={self.input_port_ticket(p.get_index()) for p in (
                self._scene_port, self._semantics_port, self._grasps_port)})

    def get_ranked_grasps_output_port(self):
        return self._ranked_port

    def _calc(self, context, output):
        semantics: GraspSemantics = self._semantics_port.Eval(context)
        scene, grasps = self._scene_port.Eval(context), self._grasps_port.Eval(context)
        output.set_value(self._last((scene, semantics, grasps), lambda: assess_candidates(
            scene, grasps, category=semantics.category or None, approach=self._approach,
            config=self._config, model=self._model)))
