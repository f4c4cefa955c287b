"""The local-shape grasp scoring stage as a Drake system (paper section V)."""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem, ValueProducer

from tg_drake.grasping.expansion import ExpansionConfig
from tg_drake.grasping.model import DgiGraspModel, load_default_model
from tg_drake.grasping.scoring import (
    DEFAULT_APPROACH,
    check_selection,
    local_probabilities,
    rank_grasps,
)
from tg_drake.systems.memo import LastResult
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

    Scores the poses that may be executed by part and local shape. For the object that
    ``grasp_semantics`` (a `GraspSemantics`) is about, every pre-grasp hypothesis of
    ``scene_description`` (a `SceneDescription`) is turned into its approach variants, each moved
    back above the table (`tg_drake.grasping.expansion.executed_poses`, the rule of the DGI's
    training data; `expansion`, with the planner's approach distance `approach` [m]); each such
    pose gets P(grasp | local shape) from the DGI features of the object's cloud in the WSG's
    closing volume and the RBF SVM + Platt sigmoid, and the logic's P(part | task) of its part.
    ``ranked_grasps`` (a `GraspCandidates`, `source`: each pose's hypothesis) holds them all with
    score = P(part | task) · P(grasp | local shape), best first: the feasibility stage and the
    planner take these poses as they are.

    P(grasp | local shape) depends on the scene alone: it is a cache entry on
    ``scene_description`` (for the object the logic reasons about, the scene's ``target``),
    so new semantics (a re-query with collision evidence) re-rank without re-scoring shapes.

    The model is the one shipped with the package unless `model` is given. `selection`
    "local_only" ranks by P(grasp | local shape) alone (the paper's Local baseline); "one_part"
    ranks only the hypotheses of `part`, by P(grasp | local shape) (`rank_grasps`); "random_part"
    those of a part drawn with `seed`.
    """

    def __init__(self, model: DgiGraspModel | None = None, *, selection: str = "pipeline",
                 part: str | None = None, expansion: ExpansionConfig | None = None,
                 approach: float = DEFAULT_APPROACH, seed: int = 0):
        super().__init__()
        self._last = LastResult()  # the stage's last answer and its inputs
        check_selection(selection, part)
        self._expansion = expansion or ExpansionConfig()
        self._approach = float(approach)
        self._selection = selection
        self._part = part
        self._seed = seed
        self._model = model if model is not None else load_default_model()
        self._scene_port = self.DeclareAbstractInputPort(
            "scene_description",
            AbstractValue.Make(SceneDescription(objects=[], X_WT=np.eye(4))))
        self._semantics_port = self.DeclareAbstractInputPort(
            "grasp_semantics",
            AbstractValue.Make(GraspSemantics(category={}, task={}, part={}, given_task=None)))
        on_scene = {self.input_port_ticket(self._scene_port.get_index())}
        # (target, its hypotheses' P(grasp | local shape)), or None for a target not in the scene.
        self._p_local = self.DeclareCacheEntry(
            "p_local", ValueProducer(allocate=AbstractValue.Make(None).Clone,
                                     calc=self._calc_p_local),
            prerequisites_of_calc=on_scene)
        empty = np.zeros(0)
        self._ranked_port = self.DeclareAbstractOutputPort(
            "ranked_grasps",
            lambda: AbstractValue.Make(GraspCandidates(np.zeros((0, 4, 4)), np.zeros(0, int),
                                                       empty, empty, empty)),
            self._calc_ranked_grasps,
            prerequisites_of_calc=on_scene | {
                self._p_local.ticket(),
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

    def p_local_cache_entry(self):
        """The cache entry of P(grasp | local shape): (target, one value per candidate pose in the
        order of `scoring.candidate_poses`), or None when the scene's target is not one of its
        objects."""
        return self._p_local

    def _calc_p_local(self, context, value):
        scene: SceneDescription = self._scene_port.Eval(context)
        target = scene.reasoning_target
        value.set_value(None if not 0 <= target < len(scene.objects) else
                        (target, local_probabilities(scene, target, self._model,
                                                     expansion=self._expansion,
                                                     approach=self._approach)))

    def _calc_ranked_grasps(self, context, output):
        semantics: GraspSemantics = self._semantics_port.Eval(context)
        cached = self._p_local.Eval(context)
        p_local = cached[1] if cached is not None and cached[0] == semantics.target else None
        scene = self._scene_port.Eval(context)
        output.set_value(self._last((scene, semantics, cached), lambda: rank_grasps(
            scene, semantics, self._model, selection=self._selection, part=self._part,
            p_local=p_local, expansion=self._expansion, approach=self._approach,
            seed=self._seed)))
