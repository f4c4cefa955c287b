"""Speed figures of the perception stage for `tg-drake bench`.

- ``object_times_ms``: completion + pose + parts (with normals, part boxes and pre-grasps) of each
  object of a synthetic scene (`tg_drake.evaluation.bench.perception_ms` is the figure: their
  median beside the paper's published times).
- ``segmentation_ms``: table plane and object clusters of a full 640×480 depth frame.

The scene is ray cast with Open3D (`tg_drake.perception.synthetic`): a can, a mug, a bottle, a
pan and a hammer on a table, seen 1 m away from 50° above the table.
"""

from __future__ import annotations

import functools

import numpy as np

from tg_drake.bench import Figure, figure, median_time
from tg_drake.perception import synthetic as S
from tg_drake.perception.config import PerceptionConfig
from tg_drake.perception.geometry import Intrinsics, inverse, make_transform, transform
from tg_drake.perception.pipeline import describe_object
from tg_drake.perception.segmentation import segment_depth


def _rz(yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@functools.cache
def _scene():
    K = Intrinsics.from_fov(640, 480, np.pi / 4)
    eye = 1.0 * np.array([np.cos(np.radians(50)), 0.0, np.sin(np.radians(50))])
    X_WC = S.look_at(eye, np.array([0.0, 0.0, 0.05]))
    placed = [(S.cylinder(0.033, 0.12), (0.15, 0.17, 0.0)), (S.mug(0.04, 0.095), (0.15, -0.1, 2.0)),
              (S.bottle(0.035, 0.25, 0.013), (-0.1, 0.22, 0.0)), (S.pan(), (-0.1, -0.12, 3.0)),
              (S.hammer(), (0.3, -0.15, 1.57))]
    meshes = [S.table_mesh()] + [S.placed(m, make_transform(_rz(yaw), [x, y, 0.0]))
                                 for m, (x, y, yaw) in placed]
    return S.render_depth(meshes, K, X_WC), K, X_WC


def object_times_ms() -> list[float]:
    """Median time to describe each object of the scene (completion + pose + parts) [ms]."""
    depth, K, X_WC = _scene()
    cfg = PerceptionConfig()
    seg = segment_depth(depth, K, X_WC, cfg.segmentation)
    p_TC = transform(inverse(seg.X_WT), X_WC[:3, 3][None])[0]
    return [1e3 * median_time(lambda q=q: describe_object(q, seg.X_WT, p_TC, cfg), repeats=15)
            for q in seg.objects_T]


def segmentation_ms() -> Figure:
    """Median time to segment a full 640×480 depth frame (table plane + clusters) [ms]."""
    depth, K, X_WC = _scene()
    cfg = PerceptionConfig()
    return figure(1e3 * median_time(lambda: segment_depth(depth, K, X_WC, cfg.segmentation),
                                    repeats=7), "ms")
