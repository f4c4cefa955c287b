"""Labelled clouds of the object library for the kernel database (the paper's S_SYN analogue).

Each sampling of an object draws points uniformly on its mesh (three times denser than the
database spacing), turns the object by a random rotation and keeps one point per voxel of
`SPACING` on a randomly shifted grid: a near-uniform cloud with ground-truth part labels and
outward normals, at about the density perception produces (it averages visible points per 4 mm
voxel; the prior resamples its clouds to `SPACING` too). Different samplings of one object differ
in where the points fall, so they are different graphs of the same shape.
"""

from __future__ import annotations

import hashlib

import numpy as np
from scipy.spatial.transform import Rotation

from tg_drake.kernels.graph import LabelledCloud, voxel_resample
from tg_drake.types import CATEGORIES

SPACING = 0.008  # [m] database voxel size: ~160 (small knives) to ~3000 (pans) points per object.
OVERSAMPLING = 3.0  # surface samples are drawn at SPACING / OVERSAMPLING before resampling.


def sample_object(obj, *, spacing: float = SPACING, rng: np.random.Generator) -> LabelledCloud:
    """One resampled labelled cloud of a library object (a `tg_drake.objects.LibraryObject`)."""
    from tg_drake.objects import sample_surface

    p, n, labels = sample_surface(obj, spacing=spacing / OVERSAMPLING, rng=rng)
    R = Rotation.random(rng=rng).as_matrix()
    cloud = LabelledCloud(p @ R.T, n @ R.T, labels)
    return voxel_resample(cloud, spacing, offset=rng.random(3) * spacing)


def library_clouds(*, n_samplings: int, spacing: float = SPACING, rng: np.random.Generator,
                   object_ids=None) -> tuple[list[LabelledCloud], list[str], list[int]]:
    """`n_samplings` clouds of every library object (or of `object_ids`), in library order.

    Returns (clouds, object ids, category indices), one entry per cloud.
    """
    from tg_drake.objects import get_object, load_library

    objects = list(load_library().values()) if object_ids is None else \
        [get_object(i) for i in object_ids]
    clouds, ids, cats = [], [], []
    for obj in objects:
        for _ in range(n_samplings):
            clouds.append(sample_object(obj, spacing=spacing, rng=rng))
            ids.append(obj.id)
            cats.append(CATEGORIES.index(obj.category))
    return clouds, ids, cats


def library_fingerprint() -> str:
    """SHA-256 of what the database depends on: every object's id, category, mesh and part
    labels, in library order. A database whose fingerprint differs is stale."""
    from tg_drake.objects import load_library, mesh

    digest = hashlib.sha256()
    for obj in load_library().values():
        V, F, L = mesh(obj)
        digest.update(f"{obj.id}:{obj.category}:{V.shape}:{F.shape};".encode())
        for a in (V, F, L):
            digest.update(np.ascontiguousarray(a).tobytes())
    return digest.hexdigest()
