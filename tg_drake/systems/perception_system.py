"""The perception stage as Drake systems (paper section III-A/B).

`PerceptionSystem` describes the objects on the table from a rendered depth image;
`GroundTruthPerception` gives the same output from the object library's labels, for the
synthetic (perfect-perception) evaluation.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.systems.framework import LeafSystem
from pydrake.systems.sensors import CameraInfo, ImageDepth32F

from tg_drake.errors import PerceptionError
from tg_drake.perception.config import PerceptionConfig
from tg_drake.perception.geometry import Intrinsics
from tg_drake.perception.ground_truth import describe_library_object
from tg_drake.perception.pipeline import describe_scene
from tg_drake.types import SceneDescription


def _empty_scene() -> SceneDescription:
    return SceneDescription(objects=[], X_WT=np.eye(4))


class PerceptionSystem(LeafSystem):
    """Scene description from a depth image: table, objects, completion, pose, parts, pre-grasps.

    .. pydrake_system::

        name: PerceptionSystem
        input_ports:
        - depth_image
        - camera_pose
        output_ports:
        - scene_description

    ``depth_image`` is an ImageDepth32F (metres; +inf / 0 where there is no return) of the size
    given by `camera_info`; ``camera_pose`` is the RigidTransform X_WC of the depth camera
    (Drake's camera frame: X right, Y down, Z forward). ``scene_description`` is a
    `SceneDescription` with one `ObjectDescription` per object on the table, ordered along the
    table frame's x. A frame without a table, or whose objects are all cut by the image border,
    raises PerceptionError when the output is evaluated.
    """

    def __init__(self, camera_info: CameraInfo, config: PerceptionConfig | None = None):
        super().__init__()
        self._intrinsics = Intrinsics.from_camera_info(camera_info)
        self._config = config if config is not None else PerceptionConfig()
        self._depth_port = self.DeclareAbstractInputPort(
            "depth_image", AbstractValue.Make(ImageDepth32F(camera_info.width(),
                                                            camera_info.height())))
        self._pose_port = self.DeclareAbstractInputPort(
            "camera_pose", AbstractValue.Make(RigidTransform()))
        self._scene_port = self.DeclareAbstractOutputPort(
            "scene_description", lambda: AbstractValue.Make(_empty_scene()), self._calc_scene,
            prerequisites_of_calc={self.input_port_ticket(self._depth_port.get_index()),
                                   self.input_port_ticket(self._pose_port.get_index())})

    @property
    def intrinsics(self) -> Intrinsics:
        return self._intrinsics

    def get_depth_image_input_port(self):
        return self._depth_port

    def get_camera_pose_input_port(self):
        return self._pose_port

    def get_scene_description_output_port(self):
        return self._scene_port

    def _calc_scene(self, context, output):
        image: ImageDepth32F = self._depth_port.Eval(context)
        X_WC: RigidTransform = self._pose_port.Eval(context)
        if image.width() != self._intrinsics.width or image.height() != self._intrinsics.height:
            raise PerceptionError(
                f"depth_image is {image.width()}×{image.height()} but the camera info says "
                f"{self._intrinsics.width}×{self._intrinsics.height}")
        output.set_value(describe_scene(image.data, self._intrinsics, X_WC.GetAsMatrix4(),
                                        self._config))


class GroundTruthPerception(LeafSystem):
    """The scene description of library objects at known poses, from their labelled meshes.

    .. pydrake_system::

        name: GroundTruthPerception
        output_ports:
        - scene_description

    Each object's surface is sampled uniformly (``spacing`` apart) with its ground-truth part
    labels and outward normals, at its world pose X_WO (the library object frame); its pose
    label is given or derived from X_WO, its parts have probability 1. For the synthetic
    evaluation only: the pipeline's `PerceptionSystem` never reads ground truth.
    """

    def __init__(self, object_ids: list[str], X_WO: list, *, X_WT=None, poses=None,
                 containments=None, spacing: float = 0.004, seed: int = 0):
        super().__init__()
        if len(object_ids) != len(X_WO):
            raise PerceptionError(
                f"GroundTruthPerception got {len(object_ids)} object ids but {len(X_WO)} poses")
        X_WT = np.eye(4) if X_WT is None else _matrix(X_WT)
        poses = poses if poses is not None else [None] * len(object_ids)
        containments = containments if containments is not None else [None] * len(object_ids)
        rng = np.random.default_rng(seed)
        self._scene = SceneDescription(objects=[
            describe_library_object(i, _matrix(X), X_WT, spacing=spacing, rng=rng, pose=p,
                                    containment=c)
            for i, X, p, c in zip(object_ids, X_WO, poses, containments)], X_WT=X_WT)
        self._scene_port = self.DeclareAbstractOutputPort(
            "scene_description", lambda: AbstractValue.Make(_empty_scene()), self._calc_scene,
            prerequisites_of_calc={self.nothing_ticket()})

    def get_scene_description_output_port(self):
        return self._scene_port

    def _calc_scene(self, context, output):
        output.set_value(self._scene)


def _matrix(X) -> np.ndarray:
    return X.GetAsMatrix4() if isinstance(X, RigidTransform) else np.asarray(X, float)
