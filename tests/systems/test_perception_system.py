"""PerceptionSystem and GroundTruthPerception alone: fixed inputs in, scene description out."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.math import RigidTransform
from pydrake.systems.sensors import CameraInfo, ImageDepth32F

from tg_drake.errors import PerceptionError
from tg_drake.perception import synthetic as S
from tg_drake.perception.geometry import Intrinsics, make_transform
from tg_drake.systems.perception_system import GroundTruthPerception, PerceptionSystem
from tg_drake.types import SceneDescription

INFO = CameraInfo(width=640, height=480, fov_y=np.pi / 4)
EYE = np.array([0.7, 0.1, 0.65])


def image_of(depth: np.ndarray) -> ImageDepth32F:
    image = ImageDepth32F(depth.shape[1], depth.shape[0])
    image.mutable_data[:, :, 0] = depth
    return image


@pytest.fixture(scope="module")
def two_objects():
    X_WC = S.look_at(EYE, np.array([0.0, 0.0, 0.05]))
    meshes = [S.table_mesh(),
              S.placed(S.cup(0.04, 0.09), make_transform(np.eye(3), [0.0, -0.12, 0.0])),
              S.placed(S.bottle(0.035, 0.25, 0.013), make_transform(np.eye(3), [0.0, 0.12, 0.0]))]
    depth = S.render_depth(meshes, Intrinsics.from_camera_info(INFO), X_WC)
    return depth, X_WC


def test_perception_system_describes_each_object(two_objects):
    depth, X_WC = two_objects
    system = PerceptionSystem(INFO)
    context = system.CreateDefaultContext()
    system.get_depth_image_input_port().FixValue(context, image_of(depth))
    system.get_camera_pose_input_port().FixValue(context, RigidTransform(X_WC))
    scene = system.get_scene_description_output_port().Eval(context)
    assert isinstance(scene, SceneDescription) and len(scene.objects) == 2
    cup, bottle = sorted(scene.objects, key=lambda o: o.X_WO[1, 3])
    # The completed centroids within 1 cm of the truth (the paper's box centroid).
    np.testing.assert_allclose(cup.X_WO[:2, 3], [0.0, -0.12], atol=0.01)
    np.testing.assert_allclose(bottle.X_WO[:2, 3], [0.0, 0.12], atol=0.01)
    assert cup.pose == bottle.pose == "upright"
    # The table frame: z up, on the table top (the plane z = 0; 1 mm: float32 depth).
    np.testing.assert_allclose(scene.X_WT[:3, 2], [0, 0, 1], atol=1e-3)
    assert abs(scene.X_WT[2, 3]) < 1e-3
    assert system.GetInputPort("depth_image") is system.get_depth_image_input_port()
    assert system.GetOutputPort("scene_description") is (
        system.get_scene_description_output_port())


def test_perception_system_reports_bad_frames():
    system = PerceptionSystem(INFO)
    context = system.CreateDefaultContext()
    system.get_depth_image_input_port().FixValue(
        context, image_of(np.full((480, 640), np.inf, np.float32)))
    system.get_camera_pose_input_port().FixValue(context, RigidTransform([0.0, 0.0, 1.0]))
    with pytest.raises(PerceptionError, match="empty cloud"):
        system.get_scene_description_output_port().Eval(context)
    system.get_depth_image_input_port().FixValue(context, ImageDepth32F(320, 240))
    with pytest.raises(PerceptionError, match="320×240 but the camera info says 640×480"):
        system.get_scene_description_output_port().Eval(context)


def test_ground_truth_perception_from_library_labels():
    pytest.importorskip("tg_drake.objects")
    from tg_drake.objects import get_object

    cup = get_object("cup_01")
    X_WO = make_transform(np.eye(3), [0.1, 0.2, 0.0]) @ cup.resting_pose("upright").X_TO
    hammer = get_object("hammer_01")
    X_WH = make_transform(np.eye(3), [0.3, 0.0, 0.0]) @ hammer.resting_pose("sideways").X_TO
    system = GroundTruthPerception(["cup_01", "hammer_01"], [RigidTransform(X_WO), X_WH])
    context = system.CreateDefaultContext()
    scene = system.get_scene_description_output_port().Eval(context)
    a, b = scene.objects
    assert a.name == "cup_01" and a.pose == "upright" and not a.is_tool
    assert set(a.part_probabilities) == set(cup.parts)
    assert b.name == "hammer_01" and b.pose == "sideways" and b.is_tool
    assert set(b.part_probabilities) == {"handle", "usable_area"}
    # The cup's surface lies within its library extents around its placement (1e-4: the
    # library rounds extents to 0.1 mm).
    half = 0.5 * np.array(cup.extents)
    local = (a.p_W - a.X_WO[:3, 3]) @ a.X_WO[:3, :3]
    assert (np.abs(local) <= half + 1e-4).all()
    np.testing.assert_allclose(np.abs(local).max(axis=0), half, atol=0.004)  # one spacing
    # Perception's object frame for a tool: z from the handle to the usable area.
    usable = b.labels == 4
    assert ((b.p_W[usable] - b.X_WO[:3, 3]) @ b.X_WO[:3, 2]).mean() > 0
    np.testing.assert_allclose(np.linalg.norm(a.n_W, axis=1), 1.0, atol=1e-9)
    assert len(a.pregrasp_X_WG) == 12 * len(a.part_boxes)
    with pytest.raises(PerceptionError, match="2 object ids but 1 poses"):
        GroundTruthPerception(["cup_01", "hammer_01"], [X_WO])
