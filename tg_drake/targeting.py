"""Which perceived object is the task's target.

A scenario names its target (an instance on the table); perception sees unnamed clusters. The user's
pointing is the target's position on the table: the target is the perceived object whose centroid is
nearest to it in the table plane. This is the only place where the scenario's placement informs
perception's output, and it only picks among what perception found.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from tg_drake.types import SceneDescription

# A perceived object farther than this from the pointed-at position is not the target [m].
MAX_POINTING_ERROR = 0.10


def select_target(scene: SceneDescription, p_W_hint) -> SceneDescription:
    """A copy of `scene` whose `target` is the object nearest `p_W_hint` (xy), or None when no
    object lies within MAX_POINTING_ERROR of it."""
    if not scene.objects:
        return dataclasses.replace(scene, target=None)
    centres = np.array([obj.X_WO[:2, 3] for obj in scene.objects])
    distances = np.linalg.norm(centres - np.asarray(p_W_hint, float)[:2], axis=1)
    best = int(np.argmin(distances))
    target = best if distances[best] <= MAX_POINTING_ERROR else None
    return dataclasses.replace(scene, target=target)
