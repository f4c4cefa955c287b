"""The DGI training set: which grasps to try on the object library, and their features.

A *scene* is one library object resting on the table (top at z_W = 0, table frame = world) in
one of its poses. For each scene:

- `scene_cloud`: the object's surface sampled at the perception's voxel size (4 mm) with 1 mm
  Gaussian noise, in the world — what the DGI sees (perception delivers clouds of that density);
- `scene_grasps`: the grasps to execute — the paper's pre-grasp hypotheses on the ground-truth part
  boxes (two per face) and perturbed copies of them, each turned into the poses that may be
  executed by the rule inference uses (`tg_drake.grasping.expansion.executed_poses`: its approach
  variants, each moved back above the table or left out — the DGI of the object alone cannot see
  the table), plus random grasps at surface points (moved back above the table by the same rule,
  without variants); optionally `max_grasps` of them drawn at random;
- `training_set`: features and labels from the executed grasps (JSON Lines from
  tools/collect_grasps.py), the clouds regenerated from the same seeds.

Randomness comes from `seed` and the scene's name, so every run makes the same grasps and clouds.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from tg_drake.grasping.dgi import PAD_CENTER_Y, DgiConfig, dgi_features
from tg_drake.grasping.expansion import ExpansionConfig, executed_poses
from tg_drake.grasping.hypotheses import box_grasps, perturb_grasps, surface_grasps
from tg_drake.objects import LibraryObject, get_object, sample_surface

KINDS = ("box", "perturbed", "random")
DEFAULT_DGI = DgiConfig()  # the default features (frozen: one shared default is safe)


@dataclass(frozen=True)
class SamplingConfig:
    """How many grasps of which kind each scene gets, and how its cloud is made."""

    perturbed_per_box: int = 2  # perturbed copies of each part-box hypothesis.
    n_random: int = 24  # random grasps at surface points that clear the table.
    position_std: float = 0.01  # perturbation of the grasp point, per axis [m].
    angle_std: float = 0.2  # perturbation of the orientation, per axis-angle component [rad].
    cloud_spacing: float = 0.004  # surface sample spacing [m] (perception's voxel size).
    cloud_noise: float = 0.001  # Gaussian noise on each point, per axis [m].
    approach_distance: float = 0.05  # the episode's approach [m], for the table check
    # (simulation.episode.EpisodeConfig.approach_distance).
    expansion: ExpansionConfig = field(default_factory=ExpansionConfig)  # hypothesis → the poses
    # that may be executed: inference's rule (PipelineConfig.expansion's default).
    max_grasps: int | None = None  # a scene's grasps drawn at random down to this many (None:
    # all of them): a collection within a time budget.


def scene_rng(seed: int, object_id: str, pose: str, purpose: str) -> np.random.Generator:
    """A generator that depends only on the seed, the scene and what it is for."""
    digest = hashlib.sha256(f"{seed}/{object_id}/{pose}/{purpose}".encode()).digest()
    return np.random.default_rng(int.from_bytes(digest[:8], "little"))


def scene_cloud(obj: LibraryObject, pose: str, *, seed: int,
                config: SamplingConfig = SamplingConfig()):
    """(p_W, n_W, labels): the object's noisy surface cloud at its resting pose."""
    rng = scene_rng(seed, obj.id, pose, "cloud")
    p_O, n_O, labels = sample_surface(obj, spacing=config.cloud_spacing, rng=rng)
    X_WO = obj.resting_pose(pose).X_TO
    p_W = p_O @ X_WO[:3, :3].T + X_WO[:3, 3] + rng.normal(scale=config.cloud_noise,
                                                          size=p_O.shape)
    return p_W, n_O @ X_WO[:3, :3].T, labels


def part_boxes(p_O: np.ndarray, labels: np.ndarray) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Part label → (X_OB, half extents): each part's bounding box along the object axes."""
    boxes = {}
    for label in np.unique(labels):
        q = p_O[labels == label]
        lo, hi = q.min(axis=0), q.max(axis=0)
        X_OB = np.eye(4)
        X_OB[:3, 3] = (lo + hi) / 2
        boxes[int(label)] = (X_OB, (hi - lo) / 2)
    return boxes


@dataclass
class SceneGrasps:
    """The grasps to execute in one scene."""

    object_id: str
    pose: str
    X_WO: np.ndarray  # 4×4 resting pose of the object.
    X_WG: np.ndarray  # (M, 4, 4) grasps.
    kinds: np.ndarray  # (M,) str, entries of KINDS.
    parts: np.ndarray  # (M,) int part label of the surface point nearest to the grasp point.
    n_through_table: int  # box and perturbed hypotheses left out: the gripper would pass through
    # the table.
    hypotheses: np.ndarray | None = None  # (H, 4, 4) the part-box hypotheses before the rule
    # (`executed_poses`) made the box grasps of them.


def scene_grasps(obj: LibraryObject, pose: str, *, seed: int,
                 config: SamplingConfig = SamplingConfig()) -> SceneGrasps:
    """The grasps of one scene (see the module docstring)."""
    rng = scene_rng(seed, obj.id, pose, "grasps")
    X_WO = obj.resting_pose(pose).X_TO
    # Part boxes from a dense, noiseless sample of the ground-truth parts.
    p_O, n_O, labels = sample_surface(obj, spacing=0.003, rng=rng)
    boxes = [X_WO @ X_OB for X_OB, _ in part_boxes(p_O, labels).values()]
    halves = [h for _, h in part_boxes(p_O, labels).values()]
    box = np.concatenate([box_grasps(X, h) for X, h in zip(boxes, halves, strict=True)])
    perturbed = perturb_grasps(np.repeat(box, config.perturbed_per_box, axis=0), rng,
                               position_std=config.position_std, angle_std=config.angle_std)
    p_W = p_O @ X_WO[:3, :3].T + X_WO[:3, 3]
    n_W = n_O @ X_WO[:3, :3].T
    # The table top is z_W = 0 (the resting pose's frame T is the world's).
    hypotheses = np.concatenate([box, perturbed])
    X_h, source = executed_poses(hypotheses, 0.0, approach_distance=config.approach_distance,
                                 config=config.expansion)
    n_through_table = len(hypotheses) - len(np.unique(source))
    # Random grasps: drawn 32 times over, the first n_random that can clear the table are kept.
    X_r, _ = executed_poses(surface_grasps(p_W, n_W, 32 * config.n_random, rng), 0.0,
                            approach_distance=config.approach_distance, config=config.expansion,
                            variants=False)
    X_r = X_r[:config.n_random]
    X_WG = np.concatenate([X_h, X_r])
    kinds = np.array(["box" if j < len(box) else "perturbed" for j in source]
                     + ["random"] * len(X_r))
    if config.max_grasps is not None and len(X_WG) > config.max_grasps:
        keep = np.sort(rng.choice(len(X_WG), size=config.max_grasps, replace=False))
        X_WG, kinds = X_WG[keep], kinds[keep]
    grasp_points = X_WG[:, :3, 3] + PAD_CENTER_Y * X_WG[:, :3, 1]
    parts = labels[cKDTree(p_W).query(grasp_points)[1]]
    return SceneGrasps(obj.id, pose, X_WO, X_WG, kinds, parts, n_through_table, box)


def library_scenes(objects: Iterable[LibraryObject]) -> list[tuple[LibraryObject, str]]:
    """Every (object, pose) of the given objects, in library and pose order."""
    return [(obj, pose) for obj in objects for pose in obj.poses]


@dataclass
class TrainingSet:
    X: np.ndarray  # (n, n_features) DGI features.
    y: np.ndarray  # (n,) 1 = the object stayed in the hand.
    object_ids: np.ndarray  # (n,) str
    scenes: np.ndarray  # (n,) str "object/pose"
    kinds: np.ndarray  # (n,) str
    parts: np.ndarray  # (n,) int
    X_WG: np.ndarray | None = None  # (n, 4, 4) the grasps' gripper poses.
    centroids: np.ndarray | None = None  # (n, 3) centroid of the scene's cloud in the world [m].


def _by_scene(records: list[dict]) -> list[tuple[tuple[str, str], list[dict]]]:
    by_scene: dict[tuple[str, str], list[dict]] = {}
    for r in records:
        if r.get("status") == "ok":
            by_scene.setdefault((r["object"], r["pose"]), []).append(r)
    return sorted(by_scene.items())


def training_order(records: list[dict]) -> list[dict]:
    """The records with status "ok" in the order of `training_set`'s rows: scenes (object, pose)
    sorted, and within a scene as in `records` — to line other data of the same grasps up with
    the features (the same jobs executed with another object mass, say)."""
    return [r for _, rows in _by_scene(records) for r in rows]


def training_set(records: list[dict], *, seed: int, config: DgiConfig = DEFAULT_DGI,
                 sampling: SamplingConfig = SamplingConfig()) -> TrainingSet:
    """Features and labels of the executed grasps with status "ok" (see collect_grasps.py), in
    the order of `training_order`."""
    X, y, objs, scenes, kinds, parts, poses, centroids = [], [], [], [], [], [], [], []
    for (object_id, pose), rows in _by_scene(records):
        p_W, _, _ = scene_cloud(get_object(object_id), pose, seed=seed, config=sampling)
        X_WG = np.array([r["X_WG"] for r in rows], dtype=float).reshape(-1, 4, 4)
        X.append(dgi_features(p_W, X_WG, config))
        poses.append(X_WG)
        centroids.append(np.repeat(p_W.mean(axis=0)[None], len(rows), axis=0))
        y.extend(int(r["success"]) for r in rows)
        objs.extend(object_id for _ in rows)
        scenes.extend(f"{object_id}/{pose}" for _ in rows)
        kinds.extend(r["kind"] for r in rows)
        parts.extend(int(r["part"]) for r in rows)
    if not X:
        return TrainingSet(np.zeros((0, config.n_features)), np.zeros(0, int), np.zeros(0, str),
                           np.zeros(0, str), np.zeros(0, str), np.zeros(0, int),
                           np.zeros((0, 4, 4)), np.zeros((0, 3)))
    return TrainingSet(np.concatenate(X), np.array(y), np.array(objs), np.array(scenes),
                       np.array(kinds), np.array(parts), np.concatenate(poses),
                       np.concatenate(centroids))
