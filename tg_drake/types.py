"""Vocabulary and port-value dataclasses shared by every stage.

These are the values carried on the diagram's abstract-valued ports:

- `SceneDescription` (``scene_description``): one `ObjectDescription` per perceived object.
- `PerceptionStatus` (``perception_status``): whether the latest perception succeeded, and when.
- `CategoryPrior` (``category_prior``): one `CategoryDistribution` per object.
- `GraspSemantics` (``grasp_semantics``): the logic's category, task and part distributions for
  the target object, with explanations.
- `GraspCandidates` (``ranked_grasps``): gripper poses in the world frame with their scores.

Poses are 4×4 homogeneous transforms as NumPy arrays, named in Drake's monogram notation: ``X_WO``
is the pose of frame O (object) measured in and expressed in W (world); ``p_W`` points in world
coordinates; ``n_W`` normals in world coordinates. Cores never need pydrake to use them.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

# The paper's 11 object categories (section IV-B), in a fixed order used by every distribution.
CATEGORIES: tuple[str, ...] = (
    "pan", "pot", "cup", "glass", "bowl", "bottle", "can",
    "hammer", "knife", "screwdriver", "cooking_tool",
)

# The paper's 7 tasks (section IV-B). Names as in the paper; the ProbLog theory maps them to atoms.
# Variants of the ProbLog theory's category and grasp models (paper IV-C: specific, general;
# "learned": the probabilities fitted to simulated grasps, tg_drake/logic/learning.py and
# tools/learn_theory.py, in rules/category_learned.pl and rules/grasp_learned.pl).
THEORY_VARIANTS: tuple[str, ...] = ("specific", "general", "learned")

TASKS: tuple[str, ...] = (
    "pass", "pourOut", "pourIn", "p&pInUpright", "p&pInUpsidedown", "p&pInSideways", "p&pOn",
)

# Semantic part labels (section III-B). The integer label of a point is its index in this tuple.
PART_LABELS: tuple[str, ...] = ("top", "middle", "bottom", "handle", "usable_area")

# The paper's part colours (Fig. 4): top yellow, middle blue, bottom red, handle green,
# usable area magenta. RGB in [0, 1], indexed like PART_LABELS.
PART_COLORS: tuple[tuple[float, float, float], ...] = (
    (1.0, 0.85, 0.0), (0.1, 0.3, 1.0), (0.9, 0.1, 0.1), (0.1, 0.75, 0.2), (0.9, 0.1, 0.9),
)

# Discrete object poses on the table (section III-A).
POSES: tuple[str, ...] = ("upright", "sideways", "upsidedown")

# Containment of a container.
CONTAINMENTS: tuple[str, ...] = ("empty", "full")


SCANLIKE_SUFFIX = "_scan"  # the id of an object's scan-like version (tools/make_scanlike.py)


def source_objects(ids) -> np.ndarray:
    """(N,) str: each object id with its scan-like suffix dropped, the object it was made from
    (a scan-like version and its original are one object for leave-one-object-out)."""
    return np.array([str(i).removesuffix(SCANLIKE_SUFFIX) for i in np.atleast_1d(ids)], dtype=str)


def part_index(name: str) -> int:
    """The integer label of a part name; ValueError listing the names if unknown."""
    try:
        return PART_LABELS.index(name)
    except ValueError:
        raise ValueError(
            f"unknown part {name!r}; allowed: {', '.join(PART_LABELS)}") from None


def as_distribution(values: dict[str, float], names: tuple[str, ...]) -> np.ndarray:
    """A dict name → probability as a vector in the order of `names` (missing names are 0)."""
    unknown = set(values) - set(names)
    if unknown:
        raise ValueError(
            f"unknown name(s) {sorted(unknown)}; allowed: {', '.join(names)}")
    return np.array([float(values.get(n, 0.0)) for n in names])


@dataclass
class PartBox:
    """An oriented bounding box of one semantic part."""

    X_WB: np.ndarray  # 4×4 pose of the box centre and axes in the world frame.
    half_extents: np.ndarray  # (3,) half side lengths along the box axes [m].


@dataclass
class ObjectDescription:
    """What perception says about one object on the table."""

    p_W: np.ndarray  # (N, 3) completed point cloud in the world frame [m].
    n_W: np.ndarray  # (N, 3) unit normals, oriented outwards from the symmetry axis.
    labels: np.ndarray  # (N,) int part labels, indices into PART_LABELS.
    visible: np.ndarray  # (N,) bool: True for observed points, False for completed ones.
    X_WO: np.ndarray  # 4×4 object frame: origin at the box centroid, z along the symmetry axis.
    extents: np.ndarray  # (3,) full box side lengths along the object frame's x, y, z [m].
    pose: str  # the most likely entry of POSES.
    pose_likelihood: dict[str, float]  # POSES entry → likelihood (sums to 1).
    part_probabilities: dict[str, float]  # detected part name → probability it is there.
    part_boxes: dict[str, PartBox]  # detected part name → its bounding box.
    pregrasp_X_WG: np.ndarray  # (M, 4, 4) pre-grasp gripper poses (WSG body frame G) in world.
    pregrasp_parts: np.ndarray  # (M,) int part label of each pre-grasp hypothesis.
    containment: str | None = None  # "empty", "full", or None when unknown.
    is_tool: bool = False  # True when perception classified the shape as a tool.
    name: str = ""  # ground-truth instance name when known (GroundTruthPerception), else "".
    interior_seen: float = 0.0  # probability that its inside was seen through a wide opening.
    interior_hidden: float = 0.0  # probability that perception looked for its inside and did not
    # see it (1 − interior_seen from perception; 0 when nothing looked, e.g. a hand-made
    # description).
    pose_cue: str = ""  # what decided the pose (perception.pose.PoseEstimate.cue), or "".
    pose_end: tuple | None = None  # the closed end on top, (recess, dome, rise, rise error)
    # [m], its wall's (narrowing, error) [m/m] (NaN: no wall) and 1.0 when the end radii read
    # the top narrower than the base (else 0.0), when the pose reached that cue
    # (perception.pose.closed_end, wall_taper, PoseEstimate.narrower_top), else None.


def moved_rigidly(target: ObjectDescription, T: np.ndarray) -> ObjectDescription:
    """`target` moved rigidly by T (4×4, world): its points, normals, frame, part boxes and
    pre-grasp poses; its pose label and everything else kept as perceived."""
    T = np.asarray(T, float)
    R, t = T[:3, :3], T[:3, 3]
    boxes = {name: PartBox(T @ np.asarray(b.X_WB, float), np.asarray(b.half_extents, float))
             for name, b in target.part_boxes.items()}
    p_W = np.asarray(target.p_W, float).reshape(-1, 3)
    n_W = np.asarray(target.n_W, float).reshape(-1, 3)
    X_WG = np.asarray(target.pregrasp_X_WG, float).reshape(-1, 4, 4)
    return dataclasses.replace(target, p_W=p_W @ R.T + t, n_W=n_W @ R.T,
                               X_WO=T @ np.asarray(target.X_WO, float), part_boxes=boxes,
                               pregrasp_X_WG=np.einsum("ij,njk->nik", T, X_WG))


@dataclass
class SceneDescription:
    """The perceived scene: the table and every object on it."""

    objects: list[ObjectDescription]
    X_WT: np.ndarray  # 4×4 table frame: origin on the table top, z along its normal.
    target: int | None = None  # index into `objects` of the task's target, when known.

    @property
    def reasoning_target(self) -> int:
        """The object the logic and the scoring reason about: `target`, else object 0."""
        return 0 if self.target is None else int(self.target)


@dataclass(frozen=True)
class PerceptionStatus:
    """Port value of ``perception_status``: how the latest perception went, without raising."""

    ok: bool  # the latched scene description is valid (False before the first perception)
    error: str = ""  # the PerceptionError's message when the latest perception failed, else ""
    wall_time: float = 0.0  # [s] wall-clock time the latest perception took
    n_perceptions: int = 0  # how many perceptions have run in this context
    request: int = 0  # the perception_request value the latest perception served
    t_perceived: float | None = None  # [s] simulated time of the latest perception


@dataclass
class CategoryDistribution:
    """The kernel prior for one object: a distribution over CATEGORIES."""

    probabilities: np.ndarray  # (11,) in CATEGORIES order, sums to 1.
    neighbours: list[tuple[str, str, float]] = field(default_factory=list)
    # (database object id, its category, normalised kernel value), most similar first.
    floor: float = 0.0  # the database's fitted floor ε for this kind of query
    # (KernelDatabase.floor): the logic sees (1 − ε)·probabilities + ε/11, unless told otherwise.

    def as_dict(self) -> dict[str, float]:
        return {c: float(p) for c, p in zip(CATEGORIES, self.probabilities, strict=True) if p > 0}


@dataclass
class CategoryPrior:
    """Port value of ``category_prior``: one distribution per object of the scene description."""

    distributions: list[CategoryDistribution]


@dataclass
class Explanation:
    """Why an answer got its probability: the rules and observations that carry most of it."""

    answer: str
    probability: float
    # (rule or observation text, share of probability), largest first.
    reasons: list[tuple[str, float]]


@dataclass
class GraspSemantics:
    """Port value of ``grasp_semantics``: the logic module's answers for the target object."""

    category: dict[str, float]  # CATEGORIES entry → probability (normalised).
    task: dict[str, float]  # TASKS entry → probability (normalised; the given task gets 1).
    part: dict[str, float]  # part name → P(grasp part | task) (normalised over observed parts).
    given_task: str | None
    explanations: dict[str, list[Explanation]] = field(default_factory=dict)
    # "category" / "task" / "part" → explanations of the leading answers.
    collisions: tuple[str, ...] = ()  # parts given as collision(Part) evidence.
    target: int = 0  # index of the object in the scene description these answers are about.
    grasp_probability: float = 1.0  # P(some part is grasped | observations) before `part` was
    # normalised: near 0 when the constraints rule grasping out in almost every world (e.g. an
    # upside-down pan with a small chance of being something else).


@dataclass
class GraspCandidates:
    """Port value of ``ranked_grasps``: hypotheses sorted by `score`, best first."""

    X_WG: np.ndarray  # (M, 4, 4) gripper poses in the world frame.
    parts: np.ndarray  # (M,) int part labels.
    p_part: np.ndarray  # (M,) the logic's P(part | task).
    p_local: np.ndarray  # (M,) the SVM's P(grasp | local shape).
    score: np.ndarray  # (M,) combined score.
    target: int = 0  # index of the object in the scene description.
    p_hold: np.ndarray | None = None  # (M,) GraspFeasibility's P(hold | pose); None: not assessed
    # (scoring's output), taken as 1. Its score is then P(part | task) · P(local) · P(hold).
    feasibility_reasons: tuple = ()  # (M,) why a pose is infeasible ("" if it is not); () when
    # not assessed.
    source: np.ndarray | None = None  # (M,) the scored hypothesis each pose was made from (the
    # approach variants of one hypothesis share it); None: each row is its own.
    unholdable_parts: tuple = ()  # parts that have candidates, none of which would hold
    holds: tuple = ()  # (M,) each pose's contact mechanics (grasping.feasibility.Hold); () when
    # not assessed.
