"""DepthNoise alone and before perception in a small diagram; the sensor field of a scenario."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantValueSource
from pydrake.systems.sensors import CameraInfo, ImageDepth32F

from tg_drake.errors import ScenarioError
from tg_drake.perception import synthetic as S
from tg_drake.perception.geometry import Intrinsics, make_transform
from tg_drake.perception.sensor_model import IdealDepth, StructuredLight, apply_sensor
from tg_drake.scenario import load_scenario
from tg_drake.systems.depth_noise import DepthNoise
from tg_drake.systems.perception_system import PerceptionSystem

INFO = CameraInfo(width=640, height=480, fov_y=np.pi / 4)
K = Intrinsics.from_camera_info(INFO)
EYE = np.array([0.8, 0.1, 0.55])


def image_of(depth: np.ndarray) -> ImageDepth32F:
    image = ImageDepth32F(depth.shape[1], depth.shape[0])
    image.mutable_data[:, :, 0] = depth
    return image


@pytest.fixture(scope="module")
def scene():
    X_WC = S.look_at(EYE, np.array([0.0, 0.0, 0.05]))
    meshes = [S.table_mesh(),
              S.placed(S.cup(0.04, 0.09), make_transform(np.eye(3), [0.0, -0.12, 0.0])),
              S.placed(S.bottle(0.035, 0.25, 0.013), make_transform(np.eye(3), [0.0, 0.12, 0.0]))]
    return S.render_depth(meshes, K, X_WC), X_WC


def _output(system, context):
    return np.array(system.get_output_port().Eval(context).data[:, :, 0])


def test_the_output_is_the_cores_image_of_the_capture(scene):
    depth, _ = scene
    system = DepthNoise(INFO, StructuredLight(), seed=4, fps=10.0)
    context = system.CreateDefaultContext()
    system.get_input_port().FixValue(context, image_of(depth))
    context.SetTime(0.25)  # the third frame after the one at t = 0
    first = _output(system, context)
    np.testing.assert_array_equal(first, apply_sensor(depth, K, StructuredLight(), seed=4,
                                                      capture=2))
    context.SetTime(0.29)  # the same frame: the same image
    np.testing.assert_array_equal(_output(system, context), first)
    context.SetTime(0.31)  # the next frame: new noise
    assert np.mean(_output(system, context) != first) > 0.3
    # The sensor lost pixels the render had.
    assert np.sum(first == 0) > np.sum(depth == 0) + 1000


def test_ideal_depth_passes_the_image_through(scene):
    depth, _ = scene
    system = DepthNoise(INFO, IdealDepth())
    context = system.CreateDefaultContext()
    system.get_input_port().FixValue(context, image_of(depth))
    np.testing.assert_array_equal(_output(system, context), depth)


def test_perception_sees_both_objects_through_the_sensor(scene):
    """Rendered depth ─▶ DepthNoise (D415) ─▶ PerceptionSystem, simulated: two objects found,
    each within 1 cm of where it stands."""
    depth, X_WC = scene
    builder = DiagramBuilder()
    source = builder.AddSystem(ConstantValueSource(AbstractValue.Make(image_of(depth))))
    pose = builder.AddSystem(ConstantValueSource(AbstractValue.Make(RigidTransform(X_WC))))
    noise = builder.AddSystem(DepthNoise(INFO, StructuredLight(), seed=1))
    perception = builder.AddSystem(PerceptionSystem(INFO))
    builder.Connect(source.get_output_port(), noise.get_input_port())
    builder.Connect(noise.get_output_port(), perception.get_depth_image_input_port())
    builder.Connect(pose.get_output_port(), perception.get_camera_pose_input_port())
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.Initialize()
    context = perception.GetMyContextFromRoot(simulator.get_context())
    objects = perception.get_scene_description_output_port().Eval(context).objects
    assert len(objects) == 2
    centres = sorted(o.p_W[:, 1].mean() for o in objects)
    np.testing.assert_allclose(centres, [-0.12, 0.12], atol=0.01)


def test_a_bad_frame_rate_is_refused():
    with pytest.raises(Exception, match="frame rate"):
        DepthNoise(INFO, StructuredLight(), fps=0.0)


def _load(tmp_path, text):
    path = tmp_path / "s.yaml"
    path.write_text("objects:\n  - {id: cup_01}\n" + text)
    return load_scenario(path)


def test_the_sensor_is_a_tagged_field_of_depth_perception(tmp_path):
    s = _load(tmp_path, "pipeline:\n  perception: !DepthPerception\n"
              "    sensor: !StructuredLight {baseline: 0.075, subpixel_rms: 0.1}\n")
    sensor = s.pipeline.perception.sensor
    assert isinstance(sensor, StructuredLight)
    assert (sensor.baseline, sensor.subpixel_rms) == (0.075, 0.1)
    assert sensor.max_incidence_deg == StructuredLight().max_incidence_deg  # default kept
    s = _load(tmp_path, "pipeline:\n  perception: !DepthPerception {sensor: !IdealDepth {}}\n")
    assert isinstance(s.pipeline.perception.sensor, IdealDepth)


@pytest.mark.parametrize("text, message", [
    ("sensor: !Kinect {}", "unknown alternative !Kinect"),
    ("sensor: !StructuredLight {baseline: 0.0}", "baseline"),
    ("sensor: !StructuredLight {max_incidence_deg: 120}", "max_incidence_deg"),
    ("sensor: !StructuredLight {baselin: 0.05}", "did you mean 'baseline'"),
])
def test_bad_sensor_settings_are_clear_errors(tmp_path, text, message):
    with pytest.raises(ScenarioError, match=message):
        _load(tmp_path, f"pipeline:\n  perception: !DepthPerception {{{text}}}\n")


def test_the_pipeline_puts_the_sensor_between_camera_and_perception(tmp_path):
    from tg_drake.diagram import add_pipeline

    s = _load(tmp_path, "pipeline:\n  perception: !DepthPerception {sensor: !StructuredLight {}}\n")
    builder = DiagramBuilder()
    pipeline = add_pipeline(builder, scenario=s)
    diagram = builder.Build()
    noise = diagram.GetSubsystemByName("depth_noise")
    assert isinstance(noise.model, StructuredLight)
    sources = {(dst.get_name(), int(i)): (src.get_name(), int(j))
               for (dst, i), (src, j) in diagram.connection_map().items()}
    depth_in = pipeline.perception.get_depth_image_input_port().get_index()
    assert sources[("perception", int(depth_in))][0] == "depth_noise"
    assert sources[("depth_noise", 0)][0] == "rgbd_sensor_camera0"
