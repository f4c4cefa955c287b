"""Labelled clouds of the object library for the kernel database.

Two kinds of entries: ground-truth samplings of the meshes (the paper's S_SYN analogue) and
perceived views (the S_REAL analogue: the object alone on the table, ray cast and put through
our perception stage, with its estimated part labels), so that a perceived query meets perceived
database graphs, as the paper compared real scans with real scans.

Each sampling of an object draws points uniformly on its mesh (three times denser than the
database spacing), turns the object by a random rotation and keeps one point per voxel of
`SPACING` of the object's size on a randomly shifted grid (the cloud scaled to unit size first,
`graph.size_normalised`): a near-uniform cloud with ground-truth part labels and outward normals;
the prior scales and resamples its query clouds the same way. Different samplings of one object
differ in where the points fall, so they are different graphs of the same shape.
"""

from __future__ import annotations

import hashlib
import zlib

import numpy as np
from scipy.spatial.transform import Rotation

from tg_drake.errors import PerceptionError
from tg_drake.kernels.graph import LabelledCloud, size_normalised, voxel_resample
from tg_drake.objects import get_object, load_library, mesh, sample_surface
from tg_drake.perception.render import P_CAMERA, P_TARGET, perceive
from tg_drake.types import CATEGORIES

SPACING = 0.05  # database voxel size as a fraction of the object's size (clouds are scaled to a
# largest principal extent of 1): ~200 (knives) to ~1,300 (pots) points per object.
OVERSAMPLING = 3.0  # surface samples are drawn at SPACING / OVERSAMPLING before resampling.


def sample_object(obj, *, spacing: float = SPACING, rng: np.random.Generator) -> LabelledCloud:
    """One resampled labelled cloud of a library object (a `tg_drake.objects.LibraryObject`),
    scaled to unit size (`graph.size_normalised`); `spacing` is relative to that size."""
    size = float(max(obj.extents))
    p, n, labels = sample_surface(obj, spacing=size * spacing / OVERSAMPLING, rng=rng)
    R = Rotation.random(rng=rng).as_matrix()
    cloud = size_normalised(LabelledCloud(p @ R.T, n @ R.T, labels))
    return voxel_resample(cloud, spacing, offset=rng.random(3) * spacing)


def library_clouds(*, n_samplings: int, spacing: float = SPACING, rng: np.random.Generator,
                   object_ids=None) -> tuple[list[LabelledCloud], list[str], list[int]]:
    """`n_samplings` clouds of every library object (or of `object_ids`), in library order.

    Returns (clouds, object ids, category indices), one entry per cloud.
    """
    objects = list(load_library().values()) if object_ids is None else \
        [get_object(i) for i in object_ids]
    clouds, ids, cats = [], [], []
    for obj in objects:
        for _ in range(n_samplings):
            clouds.append(sample_object(obj, spacing=spacing, rng=rng))
            ids.append(obj.id)
            cats.append(CATEGORIES.index(obj.category))
    return clouds, ids, cats


# Viewpoints of the perceived entries: camera eye [m] from the object's table point, looking at
# `VIEW_TARGET`. The first is the default scenario camera's; the others are lower and closer, and
# higher and farther.
VIEWPOINTS = (P_CAMERA, (0.65, 0.0, 0.40), (0.9, 0.0, 0.80))
VIEW_TARGET = P_TARGET
VIEW_YAWS_DEG = (60.0, 180.0, 300.0)  # [deg] object turns about the table normal: between the
# evaluation suites' yaws 0, 120, 240.


def view_seed(obj_id: str, pose: str, view: int, yaw_deg: float, seed: int = 0) -> int:
    """The depth sensor's seed of one perceived view: a function of the view alone (not of the
    order views are perceived in), so views perceived in any process agree."""
    return zlib.crc32(f"{obj_id}/{pose}/{view}/{yaw_deg:g}".encode()) + 1_000_003 * seed


def perceive_view(job: tuple) -> dict:
    """One perceived view: job = (object id, category, pose, viewpoint index, yaw [deg],
    viewpoints, sensor, seed). A dict with object, category, pose, yaw, view and description
    (the perceived `ObjectDescription`), or a reason instead of the description (perception
    found no object)."""
    obj_id, category, pose, v, yaw, viewpoints, sensor, seed = job
    entry = {"object": obj_id, "category": category, "pose": pose, "yaw": float(yaw), "view": v}
    try:
        return {**entry, "description": perceive(
            obj_id, pose, yaw, p_camera=viewpoints[v], p_target=VIEW_TARGET, sensor=sensor,
            seed=view_seed(obj_id, pose, v, yaw, seed))}
    except PerceptionError as e:
        return {**entry, "reason": str(e)}


def perceived_views(*, object_ids=None, viewpoints=VIEWPOINTS, yaws_deg=VIEW_YAWS_DEG,
                    sensor=None, seed: int = 0, progress=None, map_fn=map
                    ) -> tuple[list[dict], list[dict]]:
    """Perceived clouds of library objects, one per resting pose × viewpoint × yaw
    (`tg_drake.perception.render.perceive`: the depth image ray cast, measured by `sensor` — a
    `perception.sensor_model` model, None: the exact image — seeded per view (`view_seed`),
    then `describe_scene`).

    Returns (views, failures) in the objects' order. A view is a dict with object, category,
    pose, yaw, view (index into `viewpoints`) and description (the perceived
    `ObjectDescription`); a failure has a reason instead (perception found no object).
    `progress(done, total)` is called after each view; `map_fn` maps `perceive_view` over the
    jobs (a process pool's imap to spread them, in order).
    """
    objects = list(load_library().values()) if object_ids is None else \
        [get_object(i) for i in object_ids]
    jobs = [(obj.id, obj.category, pose, v, float(yaw), tuple(viewpoints), sensor, seed)
            for obj in objects for pose in obj.poses
            for v in range(len(viewpoints)) for yaw in yaws_deg]
    views, failures = [], []
    for done, view in enumerate(map_fn(perceive_view, jobs), start=1):
        (views if "description" in view else failures).append(view)
        if progress is not None:
            progress(done, len(jobs))
    return views, failures


def library_fingerprint(object_ids=None) -> str:
    """SHA-256 of what the database depends on: every object's id, category, mesh and part
    labels, in library order (or of `object_ids`, sorted: the database's objects). A database
    whose fingerprint differs is stale."""
    digest = hashlib.sha256()
    objects = load_library().values() if object_ids is None else \
        [get_object(i) for i in sorted(object_ids)]
    for obj in objects:
        V, F, L = mesh(obj)
        digest.update(f"{obj.id}:{obj.category}:{V.shape}:{F.shape};".encode())
        for a in (V, F, L):
            digest.update(np.ascontiguousarray(a).tobytes())
    return digest.hexdigest()
