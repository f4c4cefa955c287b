"""PerceptionSystem and GroundTruthPerception alone: fixed inputs in, scene description out.

Perception runs in events and latches its result: the tests initialize the context (or simulate)
before they read the outputs, and change the inputs to check that only a request re-perceives."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.systems.analysis import Simulator
from pydrake.systems.sensors import CameraInfo, ImageDepth32F

from tg_drake.errors import PerceptionError
from tg_drake.objects import box_centre, get_object
from tg_drake.perception import synthetic as S
from tg_drake.perception.geometry import Intrinsics, make_transform
from tg_drake.systems.perception_system import GroundTruthPerception, PerceptionSystem
from tg_drake.types import PerceptionStatus, SceneDescription

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


@pytest.fixture(scope="module")
def cup_alone(two_objects):
    """The same view with the bottle taken away."""
    _, X_WC = two_objects
    meshes = [S.table_mesh(),
              S.placed(S.cup(0.04, 0.09), make_transform(np.eye(3), [0.0, -0.12, 0.0]))]
    return S.render_depth(meshes, Intrinsics.from_camera_info(INFO), X_WC)


def initialized(system, depth, X_WC):
    """A context of `system` with the given frame, after its initialization event."""
    context = system.CreateDefaultContext()
    system.get_depth_image_input_port().FixValue(context, image_of(depth))
    system.get_camera_pose_input_port().FixValue(context, RigidTransform(X_WC))
    system.ExecuteInitializationEvents(context)
    return context


def test_perception_system_describes_each_object(two_objects):
    depth, X_WC = two_objects
    system = PerceptionSystem(INFO)
    context = initialized(system, depth, X_WC)
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
    status = system.get_perception_status_output_port().Eval(context)
    assert status.ok and status.error == "" and status.n_perceptions == 1
    assert status.request == 0 and status.t_perceived == 0.0 and status.wall_time > 0


def test_a_fresh_context_is_perceived_on_demand(two_objects):
    # Before any initialization event the output perceives the current frame, latching nothing.
    depth, X_WC = two_objects
    system = PerceptionSystem(INFO)
    context = system.CreateDefaultContext()
    system.get_depth_image_input_port().FixValue(context, image_of(depth))
    system.get_camera_pose_input_port().FixValue(context, RigidTransform(X_WC))
    assert len(system.get_scene_description_output_port().Eval(context).objects) == 2
    assert system.get_perception_status_output_port().Eval(context) == PerceptionStatus(ok=False)


def test_the_scene_is_latched_until_a_request(two_objects, cup_alone):
    depth, X_WC = two_objects
    system = PerceptionSystem(INFO)
    context = system.CreateDefaultContext()
    system.get_depth_image_input_port().FixValue(context, image_of(depth))
    system.get_camera_pose_input_port().FixValue(context, RigidTransform(X_WC))
    simulator = Simulator(system, context)
    simulator.Initialize()
    scene_port = system.get_scene_description_output_port()
    status_port = system.get_perception_status_output_port()
    before = scene_port.Eval(context)
    assert len(before.objects) == 2
    # The bottle leaves the view; with no request the latched scene stays, even stepping.
    system.get_depth_image_input_port().FixValue(context, image_of(cup_alone))
    simulator.AdvanceTo(0.1)
    assert simulator.get_num_steps_taken() > 0
    assert scene_port.Eval(context) is before
    assert status_port.Eval(context).n_perceptions == 1
    assert not scene_port.cache_entry().is_out_of_date(context)  # a look that found no request
    # A connected request with the value already served changes nothing either.
    system.get_perception_request_input_port().FixValue(context, 0)
    simulator.AdvanceTo(0.2)
    assert scene_port.Eval(context) is before
    # A new request value: perceived again at the next look, and served once.
    system.get_perception_request_input_port().FixValue(context, 1)
    simulator.AdvanceTo(0.3)
    after = scene_port.Eval(context)
    assert len(after.objects) == 1
    np.testing.assert_allclose(after.objects[0].X_WO[:2, 3], [0.0, -0.12], atol=0.01)
    status = status_port.Eval(context)
    assert status.ok and status.request == 1 and status.n_perceptions == 2
    assert 0.2 <= status.t_perceived <= 0.3
    simulator.AdvanceTo(0.4)
    assert status_port.Eval(context).n_perceptions == 2
    assert scene_port.Eval(context) is after


def test_a_failure_is_latched_and_reported(two_objects):
    depth, X_WC = two_objects
    system = PerceptionSystem(INFO)
    context = system.CreateDefaultContext()
    system.get_depth_image_input_port().FixValue(
        context, image_of(np.full((480, 640), np.inf, np.float32)))
    system.get_camera_pose_input_port().FixValue(context, RigidTransform(X_WC))
    system.get_perception_request_input_port().FixValue(context, 0)
    simulator = Simulator(system, context)
    simulator.Initialize()  # the failure stays in the state: nothing escapes the simulator
    status = system.get_perception_status_output_port().Eval(context)
    assert not status.ok and "empty cloud" in status.error and status.n_perceptions == 1
    with pytest.raises(PerceptionError, match="empty cloud") as raised:
        system.get_scene_description_output_port().Eval(context)
    assert str(raised.value) == status.error
    # A frame of the wrong size is a failure too, latched on the next request.
    system.get_depth_image_input_port().FixValue(context, ImageDepth32F(320, 240))
    system.get_perception_request_input_port().FixValue(context, 1)
    simulator.AdvanceTo(0.1)
    status = system.get_perception_status_output_port().Eval(context)
    assert not status.ok and status.request == 1 and status.n_perceptions == 2
    assert status.error == "depth_image is 320×240 but the camera info says 640×480"
    with pytest.raises(PerceptionError, match="320×240 but the camera info says 640×480"):
        system.get_scene_description_output_port().Eval(context)
    # A good frame on the next request clears it.
    system.get_depth_image_input_port().FixValue(context, image_of(depth))
    system.get_perception_request_input_port().FixValue(context, 2)
    simulator.AdvanceTo(0.2)
    assert system.get_perception_status_output_port().Eval(context).ok
    assert len(system.get_scene_description_output_port().Eval(context).objects) == 2


def test_a_request_must_be_an_int(two_objects):
    depth, X_WC = two_objects
    system = PerceptionSystem(INFO)
    context = system.CreateDefaultContext()
    system.get_depth_image_input_port().FixValue(context, image_of(depth))
    system.get_camera_pose_input_port().FixValue(context, RigidTransform(X_WC))
    system.get_perception_request_input_port().FixValue(context, "again")
    with pytest.raises(TypeError, match="perception_request must be an int counter"):
        system.ExecuteInitializationEvents(context)


def test_ground_truth_perception_from_library_labels():
    cup = get_object("cup_01")
    X_WO = make_transform(np.eye(3), [0.1, 0.2, 0.0]) @ cup.resting_pose("upright").X_TO
    hammer = get_object("hammer_01")
    X_WH = make_transform(np.eye(3), [0.3, 0.0, 0.0]) @ hammer.resting_pose("sideways").X_TO
    system = GroundTruthPerception(["cup_01", "hammer_01"], [RigidTransform(X_WO), X_WH])
    context = system.CreateDefaultContext()
    system.ExecuteInitializationEvents(context)
    scene = system.get_scene_description_output_port().Eval(context)
    status = system.get_perception_status_output_port().Eval(context)
    assert status.ok and status.n_perceptions == 1
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


def test_ground_truth_looks_again_where_the_bodies_are_now():
    """A request after the first, with body_poses connected, describes the object at its body's
    pose now (a place-and-regrasp moved it), its pose label derived from it."""
    X_up = RigidTransform([0.8, 0.0, 0.0])
    system = GroundTruthPerception(["bottle_01"], [X_up], poses=["upright"], body_indices=[1])
    context = system.CreateDefaultContext()
    X_lying = RigidTransform(RotationMatrix.MakeYRotation(np.pi / 2), [0.7, -0.1, 0.036])
    system.GetInputPort("body_poses").FixValue(context, [RigidTransform(), X_lying])
    system.get_perception_request_input_port().FixValue(context, 0)
    simulator = Simulator(system, context)
    simulator.Initialize()
    first = system.get_scene_description_output_port().Eval(context).objects[0]
    assert first.pose == "upright" and np.allclose(first.X_WO[:2, 3], [0.8, 0.0], atol=0.02)
    system.get_perception_request_input_port().FixValue(context, 1)
    simulator.AdvanceTo(0.1)
    again = system.get_scene_description_output_port().Eval(context).objects[0]
    assert system.get_perception_status_output_port().Eval(context).request == 1
    assert again.pose == "sideways"
    assert np.allclose(again.X_WO[:3, 3], X_lying.multiply(box_centre("bottle_01")), atol=0.01)
