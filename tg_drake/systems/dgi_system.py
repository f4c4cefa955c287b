"""The local-shape grasp scoring stage as a Drake system (paper section V)."""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem

from tg_drake.grasping.model import DgiGraspModel, load_default_model
from tg_drake.grasping.scoring import check_selection, rank_grasps
from tg_drake.types import GraspCandidates, GraspSemantics, SceneDescription


class DgiScoringSystem(LeafSystem):
    """
    .. pydrake_system::

        name: DgiScoringSystem
        input_ports:
        - scene_description
        - grasp_semantics
        output_ports:
        - ranked_grasps

    Scores the target object's pre-grasp hypotheses by part and local shape. For the object that ``grasp_semantics`` (a `GraspSemantics`) is about, every pre-grasp
    hypothesis of ``scene_description`` (a `SceneDescription`) gets P(grasp | local shape) from
    the DGI features of the object's cloud in the WSG's closing volume and the RBF SVM + Platt
    sigmoid, and the logic's P(part | task) of its part. ``ranked_grasps`` (a `GraspCandidates`)
    holds them all with score = P(part | task) · P(grasp | local shape), best first.

    The model is the one shipped with the package unless `model` is given. `selection`
    "local_only" ranks by P(grasp | local shape) alone (the paper's Local baseline); "one_part"
    ranks only the hypotheses of `part`, by P(grasp | local shape) (`rank_grasps`).
    """

    def __init__(self, model: DgiGraspModel | None = None, *, selection: str = "pipeline",
                 part: str | None = None):
        super().__init__()
        check_selection(selection, part)
        self._selection = selection
        self._part = part
        self._model = model if model is not None else load_default_model()
        self._scene_port = self.DeclareAbstractInputPort(
            "scene_description",
            AbstractValue.Make(SceneDescription(objects=[], X_WT=np.eye(4))))
        self._semantics_port = self.DeclareAbstractInputPort(
            "grasp_semantics",
            AbstractValue.Make(GraspSemantics(category={}, task={}, part={}, given_task=None)))
        empty = np.zeros(0)
        self._ranked_port = self.DeclareAbstractOutputPort(
            "ranked_grasps",
            lambda: AbstractValue.Make(GraspCandidates(np.zeros((0, 4, 4)), np.zeros(0, int),
                                                       empty, empty, empty)),
            self._calc_ranked_grasps,
            prerequisites_of_calc={self.input_port_ticket(self._scene_port.get_index()),
                                   self.input_port_ticket(self._semantics_port.get_index())})

    @property
    def model(self) -> DgiGraspModel:
        return self._model

    def get_scene_description_input_port(self):
        return self._scene_port

    def get_grasp_semantics_input_port(self):
        return self._semantics_port

    def get_ranked_grasps_output_port(self):
        return self._ranked_port

    def _calc_ranked_grasps(self, context, output):
        output.set_value(rank_grasps(self._scene_port.Eval(context),
                                     self._semantics_port.Eval(context), self._model,
                                     selection=self._selection, part=self._part))
