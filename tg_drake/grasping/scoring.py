"""The final grasp score: the logic's P(part | task) times the DGI's P(grasp | local shape).

The poses scored are the ones that may be executed: each pre-grasp hypothesis of the target
turned into its approach variants, each moved back above the table
(`tg_drake.grasping.expansion.executed_poses`, the rule the DGI's training data uses); the
feasibility stage and the planner take these poses as they are.

`selection="local_only"` ranks by P(grasp | local shape) alone, ignoring the logic: the paper's
Local baseline (section VI, Table "pipeline"). `selection="one_part"` scores only the hypotheses of
one part, by P(grasp | local shape) alone (for collecting grasp outcomes per part).
`selection="random_part"` is the random-part baseline: one part drawn uniformly (seeded) among the
parts that have a hypothesis, its hypotheses ranked by P(grasp | local shape), the others 0.
"""

from __future__ import annotations

import numpy as np

from tg_drake.errors import GraspingError, unknown_name
from tg_drake.grasping.expansion import ExpansionConfig, executed_poses
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


DEFAULT_EXPANSION = ExpansionConfig()
DEFAULT_APPROACH = 0.10  # [m] the planner's pre-grasp distance (PlannerConfig.pregrasp_distance)


def rank_grasps(scene: SceneDescription, semantics: GraspSemantics,
                model: DgiGraspModel | None, *, selection: str = "pipeline",
                part: str | None = None, p_local: np.ndarray | None = None,
                expansion: ExpansionConfig = DEFAULT_EXPANSION,
                approach: float = DEFAULT_APPROACH, seed: int = 0) -> GraspCandidates:
    """Every pose that may be executed for the target object's pre-grasp hypotheses
    (`candidate_poses`), scored and sorted best first; `source` names each pose's hypothesis.

    p_local = P(grasp | local shape) of the pose from the DGI model (`local_probabilities`; pass
    `p_local` when it is known already for the target, and `model` may be None), p_part = the
    logic's
    P(part | task) of the hypothesis' part (0 for a part the logic did not name), score =
    p_part · p_local (`selection="pipeline"`) or p_local alone (`"local_only"`), or p_local for
    the hypotheses of `part` and 0 for the others (`"one_part"`: a part the logic gives 0 is
    still ranked), or p_local for the hypotheses of the part `random_part(parts, seed)` draws
    and 0 for the others (`"random_part"`). Ties keep the hypotheses' order.
    """
    check_selection(selection, part)
    target = semantics.target
    X_WG, parts, source = candidate_poses(scene, target, expansion=expansion, approach=approach)
    if len(X_WG) == 0:
        empty = np.zeros(0)
        return GraspCandidates(np.zeros((0, 4, 4)), parts, empty, empty, empty, target,
                               source=np.zeros(0, int))
    if p_local is None:
        p_local = model.p_grasp(scene.objects[target].p_W, X_WG)
    p_local = np.asarray(p_local, dtype=float)
    if p_local.shape != (len(X_WG),):
        raise GraspingError(f"p_local has shape {p_local.shape} for {len(X_WG)} candidate poses "
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
                           target, source=source[order])


def random_part(parts: np.ndarray, seed: int) -> str:
    """The random-part baseline's part: drawn uniformly among the distinct parts of the
    hypotheses (indices into PART_LABELS), by a generator seeded with `seed` alone, so that the
    same hypotheses and seed give the same part (a re-ranking after a re-query too)."""
    present = np.unique(np.asarray(parts, dtype=int))
    if present.size == 0:
        raise GraspingError("random_part: the object has no pre-grasp hypothesis to draw from")
    return PART_LABELS[int(present[np.random.default_rng(seed).integers(present.size)])]


def candidate_poses(scene: SceneDescription, target: int, *,
                    expansion: ExpansionConfig = DEFAULT_EXPANSION,
                    approach: float = DEFAULT_APPROACH
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The poses that may be executed for object `target`'s pre-grasp hypotheses: (X_WG (K, 4,
    4), part labels (K,), source (K,): the index of each pose's hypothesis in its
    `pregrasp_X_WG`), by `executed_poses` above the scene's table with the planner's approach
    `approach` [m]."""
    X_h, parts = _hypotheses(scene, target)
    X_WG, source = executed_poses(X_h, float(np.asarray(scene.X_WT)[2, 3]),
                                  approach_distance=approach, config=expansion)
    return X_WG, parts[source], source


def local_probabilities(scene: SceneDescription, target: int, model: DgiGraspModel, *,
                        expansion: ExpansionConfig = DEFAULT_EXPANSION,
                        approach: float = DEFAULT_APPROACH) -> np.ndarray:
    """P(grasp | local shape) of each candidate pose of object `target`, in the order of
    `candidate_poses` (the part of a ranking that depends on the scene alone)."""
    X_WG, _, _ = candidate_poses(scene, target, expansion=expansion, approach=approach)
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


SAME_POSE_OFFSET = 1e-4  # [m] an executed pose this close to a scored one (and within
SAME_POSE_ANGLE = 1e-3  # [rad] this angle of it) is that pose: float round-off, nothing more.


def scored_pose_match(X_WG: np.ndarray, scored: GraspCandidates) -> dict:
    """How an executed grasp pose X_WG (4, 4) relates to the poses the DGI scored (`scored`, the
    scoring stage's output): the nearest scored pose's index, its distance [m] and angle [rad]
    from X_WG (distance first), its P(grasp | local shape), and `same` (within
    SAME_POSE_OFFSET and SAME_POSE_ANGLE: the executed pose is one the DGI scored)."""
    X_WG = np.asarray(X_WG, float)
    poses = np.asarray(scored.X_WG, float).reshape(-1, 4, 4)
    if len(poses) == 0:
        return {"index": None, "offset_m": None, "angle_rad": None, "p_local": None,
                "same": False}
    offset = np.linalg.norm(poses[:, :3, 3] - X_WG[:3, 3], axis=1)
    cos = (np.einsum("mij,ij->m", poses[:, :3, :3], X_WG[:3, :3]) - 1.0) / 2.0
    angle = np.arccos(np.clip(cos, -1.0, 1.0))
    i = int(np.lexsort((angle, offset))[0])
    return {"index": i, "offset_m": float(offset[i]), "angle_rad": float(angle[i]),
            "p_local": float(scored.p_local[i]),
            "same": bool(offset[i] <= SAME_POSE_OFFSET and angle[i] <= SAME_POSE_ANGLE)}
