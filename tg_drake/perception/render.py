"""A library object alone on a table, seen by the default scene camera and perceived.

`perceive` ray casts the object's depth image (`synthetic.render_depth`) and puts it through the
perception stage (`pipeline.describe_scene`). The evaluation's perceived suites and the kernel
database's perceived entries both see the library this way.
"""

from __future__ import annotations

import numpy as np
import open3d as o3d

from tg_drake.errors import PerceptionError
from tg_drake.objects import get_object, mesh
from tg_drake.perception.geometry import Intrinsics
from tg_drake.perception.pipeline import describe_scene
from tg_drake.perception.sensor_model import IdealDepth, SensorModel, apply_sensor
from tg_drake.perception.synthetic import look_at, render_depth, table_mesh
from tg_drake.types import ObjectDescription

# The default scenario camera relative to the object.
P_CAMERA = (0.8, 0.0, 0.55)  # [m] eye, from the object's table point
P_TARGET = (0.0, 0.0, 0.05)  # [m] looked-at point


def perceive(object_id: str, pose: str, yaw_deg: float, *, p_camera=None,
             p_target=None, sensor: SensorModel | None = None, seed: int = 0
             ) -> ObjectDescription:
    """The perception stage's description of a library object alone on a table, from its depth
    image ray cast (640×480, 45° vertical field of view) from the default camera's viewpoint
    (or from `p_camera` looking at `p_target` [m], both from the object's table point), as
    `sensor` would measure it (`sensor_model.apply_sensor`, seeded by `seed`; default: the
    exact image)."""
    obj = get_object(object_id)
    intrinsics = Intrinsics.from_fov(640, 480, np.deg2rad(45.0))
    X_WC = look_at(np.array(P_CAMERA if p_camera is None else p_camera, dtype=float),
                   np.array(P_TARGET if p_target is None else p_target, dtype=float))
    c, s = np.cos(np.deg2rad(yaw_deg)), np.sin(np.deg2rad(yaw_deg))
    X_WO = np.eye(4)
    X_WO[:2, :2] = [[c, -s], [s, c]]
    X_WO = X_WO @ obj.resting_pose(pose).X_TO
    V, F, _ = mesh(obj)
    m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(np.array(V, float)),
                                  o3d.utility.Vector3iVector(np.array(F, np.int32)))
    m.transform(X_WO)
    depth = apply_sensor(render_depth([table_mesh(), m], intrinsics, X_WC), intrinsics,
                         IdealDepth() if sensor is None else sensor, seed=seed)
    scene = describe_scene(depth, intrinsics, X_WC)
    if not scene.objects:
        raise PerceptionError("no object found on the table")
    p_com = (X_WO @ np.r_[obj.com, 1.0])[:2]  # the cluster nearest to the object's centre
    return min(scene.objects, key=lambda o: np.linalg.norm(o.p_W[:, :2].mean(axis=0) - p_com))
