"""The final grasp score: the logic's P(part | task) times the DGI's P(grasp | local shape).

`selection="local_only"` ranks by P(grasp | local shape) alone, ignoring the logic: the paper's
Local baseline (section VI, Table "pipeline"). `selection="one_part"` scores only the hypotheses of
one part, by P(grasp | local shape) alone (for collecting grasp outcomes per part).
`selection="random_part"` is the random-part baseline: one part drawn uniformly (seeded) among the
parts that have a hypothesis, its hypotheses ranked by P(grasp | local shape), the others 0.
"""

from __future__ import annotations

import numpy as np

from tg_drake.errors import GraspingError, unknown_name
from tg_drake.grasping.model import DgiGraspModel
from tg_drake.types import PART_LABELS, GraspCandidates, GraspSemantics, SceneDescription

# How rank_grasps scores a hypothesis.
SELECTIONS = ("pipeline", "local_only", "one_part", "random_part")


def check_selection(selection: str, part: str | None = None) -> None:
    """Raises GraspingError for an unknown selection, or a "one_part" one without a known part."""
    if selection not in SELECTIONS:
        raise unknown_name("grasp selection", selection, SELECTIONS, error=GraspingError)
    if selection == "one_part" and part not in PART_LABELS:
        raise unknown_name("part", str(part), PART_LABELS, error=GraspingError, field="part")


def rank_grasps(scene: SceneDescription, semantics: GraspSemantics,
                model: DgiGraspModel | None, *, selection: str = "pipeline",
                part: str | None = None, p_local: np.ndarray | None = None,
                seed: int = 0) -> GraspCandidates:
    """Every pre-grasp hypothesis of the target object, scored and sorted best first.

    p_local = P(grasp | local shape) from the DGI model (`local_probabilities`; pass `p_local`
    when it is known already for the target, and `model` may be None), p_part = the logic's
    P(part | task) of the hypothesis' part (0 for a part the logic did not name), score =
    p_part · p_local (`selection="pipeline"`) or p_local alone (`"local_only"`), or p_local for
    the hypotheses of `part` and 0 for the others (`"one_part"`: a part the logic gives 0 is
    still ranked), or p_local for the hypotheses of the part `random_part(parts, seed)` draws
    and 0 for the others (`"random_part"`). Ties keep the hypotheses' order.
    """
    check_selection(selection, part)
    target = semantics.target
    X_WG, parts = _hypotheses(scene, target)
    if len(X_WG) == 0:
        empty = np.zeros(0)
        return GraspCandidates(np.zeros((0, 4, 4)), parts, empty, empty, empty, target)
    if p_local is None:
        p_local = model.p_grasp(scene.objects[target].p_W, X_WG)
    p_local = np.asarray(p_local, dtype=float)
    if p_local.shape != (len(X_WG),):
        raise GraspingError(f"p_local has shape {p_local.shape} for {len(X_WG)} pre-grasp poses "
                            f"of object {target}")
    p_part = np.array([semantics.part.get(PART_LABELS[k], 0.0) for k in parts], dtype=float)
    if selection == "pipeline":
        score = p_part * p_local
    elif selection == "local_only":
        score = p_local
    elif selection == "one_part":
        score = np.where(parts == PART_LABELS.index(part), p_local, 0.0)
    else:
        score = np.where(parts == PART_LABELS.index(random_part(parts, seed)), p_local, 0.0)
    order = np.argsort(-score, kind="stable")
    return GraspCandidates(X_WG[order], parts[order], p_part[order], p_local[order], score[order],
                           target)


def random_part(parts: np.ndarray, seed: int) -> str:
    """The random-part baseline's part: drawn uniformly among the distinct parts of the
    hypotheses (indices into PART_LABELS), by a generator seeded with `seed` alone, so that the
    same hypotheses and seed give the same part (a re-ranking after a re-query too)."""
    present = np.unique(np.asarray(parts, dtype=int))
    if present.size == 0:
        raise GraspingError("random_part: the object has no pre-grasp hypothesis to draw from")
    return PART_LABELS[int(present[np.random.default_rng(seed).integers(present.size)])]


def local_probabilities(scene: SceneDescription, target: int,
                        model: DgiGraspModel) -> np.ndarray:
    """P(grasp | local shape) of each pre-grasp hypothesis of object `target`, in the order of
    its `pregrasp_X_WG` (the part of a ranking that depends on the scene alone)."""
    X_WG, _ = _hypotheses(scene, target)
    if len(X_WG) == 0:
        return np.zeros(0)
    return model.p_grasp(scene.objects[target].p_W, X_WG)


def _hypotheses(scene: SceneDescription, target: int) -> tuple[np.ndarray, np.ndarray]:
    """The pre-grasp poses (M, 4, 4) and part labels (M,) of object `target`, checked."""
    if not 0 <= target < len(scene.objects):
        raise GraspingError(
            f"grasp_semantics names target object {target} but the scene description has "
            f"{len(scene.objects)} object(s)")
    obj = scene.objects[target]
    X_WG = np.asarray(obj.pregrasp_X_WG, dtype=float).reshape(-1, 4, 4)
    parts = np.asarray(obj.pregrasp_parts, dtype=int).reshape(-1)
    if len(parts) != len(X_WG):
        raise GraspingError(
            f"object {target} has {len(X_WG)} pre-grasp poses but {len(parts)} part labels")
    if np.any((parts < 0) | (parts >= len(PART_LABELS))):
        raise GraspingError(
            f"pre-grasp part labels must index PART_LABELS (0..{len(PART_LABELS) - 1}), got "
            f"{sorted(set(parts.tolist()))}")
    return X_WG, parts
