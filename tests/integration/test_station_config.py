"""Scenario fields the station honours: cameras through ApplyCameraConfig (renderer_class and
renderer_name) and `table_size`."""

from pathlib import Path

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
    assert station.scene_graph.HasRenderer("mine")
    assert not station.scene_graph.HasRenderer("default")


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
            "cameras: {camera0: {renderer_class: RenderEngineVtk}, camera1: {depth: true,"
            " renderer_class: !RenderEngineVtkParams {cast_shadows: true}}}"))
    assert e.value.field == "cameras.camera1"
    with pytest.raises(ScenarioError, match="clipping") as e:
        make_station(_scenario("cameras: {camera0: {z_near: 0.001}}"))
    assert e.value.field == "cameras.camera0"


def test_a_camera_parent_frame_that_does_not_exist_names_the_file_and_the_camera(tmp_path):
    from tg_drake.run import run_scenario
    path = tmp_path / "camera_on_nothing.yaml"
    path.write_text(Path("scenarios/default.yaml").read_text() + "\ncameras: {camera0: {X_PB: "
                    "{base_frame: no_such_frame, translation: [1.5, 0.0, 0.5]}}}\n")
    with pytest.raises(ScenarioError) as e:
        run_scenario(load_scenario(path), scenario_path=str(path))
    assert e.value.file == str(path)
    assert e.value.field == "cameras.camera0"
    assert "no_such_frame" in str(e.value)


def test_the_key_names_the_camera_and_its_ports():
    diagram, station = make_station(_scenario(
        "cameras: {camera0: {}, side: {name: ignored, depth: true}}"))
    assert set(station.cameras) == {"camera0", "side"}
    for port in ("rgb_image", "depth_image", "label_image", "camera_pose"):
        assert diagram.HasOutputPort(f"side.{port}")
    assert station.cameras["side"].sensor.get_name() == "rgbd_sensor_side"


def _table_geometry(plant, scene_graph, role):
    """{name: (Box size, pose in the table_top frame)} of the table's geometries of `role`."""
    inspector = scene_graph.model_inspector()
    body = plant.GetBodyByName("table_top", plant.GetModelInstanceByName("table"))
    frame = plant.GetBodyFrameIdOrThrow(body.index())
    return {inspector.GetName(g): (inspector.GetShape(g), inspector.GetPoseInFrame(g))
            for g in inspector.GetGeometries(frame, role)}


def _box(shape):
    return np.array([shape.width(), shape.depth(), shape.height()])


def test_table_size_sizes_the_table_top_and_keeps_its_legs_under_it():
    from pydrake.geometry import Role

    _, station = make_station(_scenario("table_size: [0.6, 0.9]"))
    for role in (Role.kProximity, Role.kIllustration):
        geometry = _table_geometry(station.plant, station.scene_graph, role)
        (top,) = [v for k, v in geometry.items() if k.endswith("top_collision")
                  or k.endswith("top_visual")]
        np.testing.assert_allclose(_box(top[0]), [0.6, 0.9, 0.04])
        assert top[1].translation()[2] == pytest.approx(-0.02)  # the surface at the frame's z = 0
    legs = [v for k, v in _table_geometry(station.plant, station.scene_graph,
                                          Role.kIllustration).items() if "leg" in k]
    assert len(legs) == 4
    for shape, X in legs:
        p = np.abs(X.translation())
        assert p[0] + shape.width() / 2 < 0.3 and p[1] + shape.depth() / 2 < 0.45  # under the top
        # Each leg reaches from under the top down to the floor, 0.4 m below the surface.
        assert X.translation()[2] - shape.height() / 2 == pytest.approx(-0.4)
    # The table top frame is welded where X_WT says.
    plant = station.plant
    X_WT = plant.GetFrameByName("table_top").CalcPoseInWorld(plant.CreateDefaultContext())
    np.testing.assert_allclose(X_WT.translation(), [0.75, 0.0, 0.0])


def test_an_object_beyond_a_smaller_table_is_rejected():
    obj = "objects: [{id: can_01, pose: upright, xy: [0.35, 0.0]}]"
    _scenario(obj)  # on the default 0.8 m deep table
    with pytest.raises(ScenarioError, match="off the table") as e:
        _scenario(obj + "\ntable_size: [0.6, 0.9]")
    assert e.value.field == "objects[0].xy"
    for bad in ("[0.6]", "[0.1, 0.9]", "[.nan, 0.9]"):
        with pytest.raises(ScenarioError) as e:
            _scenario(f"table_size: {bad}")
        assert e.value.field == "table_size"


def test_default_table_is_the_model_file():
    """The default size gives the table of models/table/table.sdf: same geometry, same contact
    properties."""
    from pydrake.geometry import Role
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.framework import DiagramBuilder

    from tg_drake.models import models_root

    _, station = make_station(_scenario())
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    Parser(plant).AddModels(f"{models_root()}/table/table.sdf")
    plant.Finalize()
    for role in (Role.kProximity, Role.kIllustration):
        ours = _table_geometry(station.plant, station.scene_graph, role)
        theirs = _table_geometry(plant, scene_graph, role)
        assert sorted(ours) == sorted(theirs)
        for name, (shape, X) in ours.items():
            np.testing.assert_allclose(_box(shape), _box(theirs[name][0]))
            np.testing.assert_allclose(X.GetAsMatrix4(), theirs[name][1].GetAsMatrix4())

    def properties(sg, plant_):
        inspector = sg.model_inspector()
        body = plant_.GetBodyByName("table_top")
        (g,) = inspector.GetGeometries(plant_.GetBodyFrameIdOrThrow(body.index()), Role.kProximity)
        props = inspector.GetProximityProperties(g)
        out = {"names and types": str(props)}  # (the compliance type has no Python binding)
        for group, name in [("material", "coulomb_friction"),
                            ("material", "hunt_crossley_dissipation"),
                            ("hydroelastic", "hydroelastic_modulus"),
                            ("hydroelastic", "resolution_hint")]:
            value = props.GetProperty(group, name)
            out[name] = ((value.static_friction(), value.dynamic_friction())
                         if name == "coulomb_friction" else value)
        return out

    ours, theirs = properties(station.scene_graph, station.plant), properties(scene_graph, plant)
    assert "compliance_type" in ours["names and types"] and ours["hydroelastic_modulus"] == 1e7
    assert ours == theirs


def test_the_planning_plant_has_the_scenario_table():
    from pydrake.geometry import Role

    from tg_drake.planning.ik import make_arm_plant

    arm = make_arm_plant(_scenario("table_size: [0.6, 0.9]"))
    geometry = _table_geometry(arm.plant, arm.scene_graph, Role.kProximity)
    (top,) = geometry.values()
    np.testing.assert_allclose(_box(top[0]), [0.6, 0.9, 0.04])


def test_a_table_directive_is_a_clear_error():
    text = ("directives:\n"
            "  - add_model: {name: table, file: package://tg_drake_models/table/table.sdf}\n")
    with pytest.raises(ScenarioError, match="the station adds the table itself") as e:
        make_station(_scenario(text))
    assert e.value.field == "directives"
