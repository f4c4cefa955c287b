"""Scenario fields the station honours: cameras through ApplyCameraConfig (renderer_class and
renderer_name) and `table_size`."""

import numpy as np
import pytest

from tg_drake.errors import ScenarioError
from tg_drake.scenario import load_scenario
from tg_drake.station import _gl_unavailable, make_station


def _scenario(text: str = ""):
    return load_scenario("scenarios/default.yaml", scenario_text=text)


def _rgb(text: str) -> np.ndarray:
    diagram, _ = make_station(_scenario(text))
    return diagram.GetOutputPort("camera0.rgb_image").Eval(diagram.CreateDefaultContext()).data


def test_renderer_parameters_and_name_are_honoured():
    # A black clear colour in the engine's parameters shows where the camera sees nothing (the
    # top rows look over the table); the default engine draws Drake's light blue there.
    black = _rgb("cameras: {camera0: {renderer_name: mine, renderer_class: "
                 "!RenderEngineVtkParams {default_clear_color: [0, 0, 0]}}}")
    default = _rgb("")
    assert black[0, 0, :3].tolist() == [0, 0, 0]
    assert default[0, 0, :3].tolist() == [204, 229, 255]
    diagram, station = make_station(_scenario("cameras: {camera0: {renderer_name: mine}}"))
    assert station.scene_graph.HasRenderer("mine") and not station.scene_graph.HasRenderer("default")


@pytest.mark.parametrize("renderer_class", ["RenderEngineOgre", "RenderEngineGltfClient"])
def test_unusable_renderer_class_is_a_scenario_error_naming_the_field(renderer_class):
    with pytest.raises(ScenarioError, match="allowed( here)?: RenderEngineVtk") as e:
        make_station(_scenario(f"cameras: {{camera0: {{renderer_class: {renderer_class}}}}}"))
    assert e.value.field == "cameras.camera0.renderer_class"


@pytest.mark.skipif(_gl_unavailable() is None, reason="RenderEngineGl works on this machine")
def test_gl_without_a_display_is_rejected_before_building():
    with pytest.raises(ScenarioError, match="RenderEngineGl cannot render on this machine") as e:
        make_station(_scenario("cameras: {camera0: {renderer_class: RenderEngineGl}}"))
    assert e.value.field == "cameras.camera0.renderer_class"


def test_conflicting_renderers_and_bad_ranges_name_the_camera():
    with pytest.raises(ScenarioError, match="renderer") as e:
        make_station(_scenario(
            "cameras: {camera0: {renderer_class: RenderEngineVtk},"
            " camera1: {depth: true, renderer_class: !RenderEngineVtkParams {cast_shadows: true}}}"))
    assert e.value.field == "cameras.camera1"
    with pytest.raises(ScenarioError, match="clipping") as e:
        make_station(_scenario("cameras: {camera0: {z_near: 0.001}}"))
    assert e.value.field == "cameras.camera0"


def test_the_key_names_the_camera_and_its_ports():
    diagram, station = make_station(_scenario(
        "cameras: {camera0: {}, side: {name: ignored, depth: true}}"))
    assert set(station.cameras) == {"camera0", "side"}
    for port in ("rgb_image", "depth_image", "label_image", "camera_pose"):
        assert diagram.HasOutputPort(f"side.{port}")
    assert station.cameras["side"].sensor.get_name() == "rgbd_sensor_side"
