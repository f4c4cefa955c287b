"""The station alone: arm posture control, gripper position control, camera rendering."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from tg_drake.scenario import Scenario
from tg_drake.station import flange_pose, make_station


@pytest.fixture(scope="module")
def station():
    return make_station(Scenario())


def test_iiwa_holds_a_commanded_posture_within_1mm(station):
    diagram, st = station
    context = diagram.CreateDefaultContext()
    plant = st.plant
    plant_context = plant.GetMyMutableContextFromRoot(context)
    q_cmd = np.array([0.3, 0.5, -0.2, -1.5, 0.4, 0.9, 0.2])
    diagram.GetInputPort("iiwa.desired_state").FixValue(context,
                                                        np.concatenate([q_cmd, np.zeros(7)]))
    diagram.GetInputPort("wsg.position").FixValue(context, [0.05])
    Simulator(diagram, context).AdvanceTo(3.0)
    X_W7 = flange_pose(plant, plant_context)
    # The flange where the commanded joint positions would put it (forward kinematics).
    fk_context = plant.CreateDefaultContext()
    plant.SetPositions(fk_context, st.instances["iiwa"], q_cmd)
    X_W7_cmd = flange_pose(plant, fk_context)
    error = np.linalg.norm(X_W7.translation() - X_W7_cmd.translation())
    assert error < 1e-3  # 1 mm: the posture-hold requirement
    assert np.linalg.norm(plant.GetVelocities(plant_context, st.instances["iiwa"])) < 1e-3


def test_wsg_follows_its_width_command(station):
    diagram, st = station
    context = diagram.CreateDefaultContext()
    plant = st.plant
    plant_context = plant.GetMyMutableContextFromRoot(context)
    q0 = plant.GetPositions(plant_context, st.instances["iiwa"])
    diagram.GetInputPort("iiwa.desired_state").FixValue(context, np.concatenate([q0, np.zeros(7)]))
    diagram.GetInputPort("wsg.position").FixValue(context, [0.04])
    Simulator(diagram, context).AdvanceTo(1.0)
    q = plant.GetPositions(plant_context, st.instances["wsg"])
    # 1 mm: PD tracking of a 0.05 kg finger with no load settles well inside this.
    assert q[1] - q[0] == pytest.approx(0.04, abs=1e-3)
    assert q[0] == pytest.approx(-q[1], abs=1e-3)


def test_camera_sees_the_table_at_the_right_depth(station):
    diagram, st = station
    context = diagram.CreateDefaultContext()
    depth = diagram.GetOutputPort("camera0.depth_image").Eval(context).data[:, :, 0]
    X_WC = diagram.GetOutputPort("camera0.camera_pose").Eval(context)
    info = st.cameras["camera0"].info
    assert depth.shape == (info.height(), info.width())
    # The ray through the image centre hits the table plane z = 0 at the depth along the optical
    # axis.
    v, u = info.height() // 2, info.width() // 2
    ray_C = np.array([(u - info.center_x()) / info.focal_x(),
                      (v - info.center_y()) / info.focal_y(), 1])
    ray_W = X_WC.rotation() @ ray_C
    expected_depth = -X_WC.translation()[2] / ray_W[2]
    assert depth[v, u] == pytest.approx(expected_depth, abs=2e-3)  # 2 mm: depth rendering precision
    assert np.isfinite(depth).mean() > 0.5  # the table fills most of the view


def test_depth_image_shows_an_object_on_the_table():
    from tg_drake.objects import get_object
    from tg_drake.scenario import ObjectPlacement

    empty, _ = make_station(Scenario())
    with_can, st = make_station(Scenario(objects=[ObjectPlacement(id="can_02", pose="upright")]))
    depths = [d.GetOutputPort("camera0.depth_image").Eval(d.CreateDefaultContext()).data[:, :, 0]
              for d in (empty, with_can)]
    closer = depths[1] < depths[0] - 0.01  # 1 cm: well above depth noise (none in the renderer)
    # The can (about 6.8 cm wide, 12.3 cm tall at ~0.85 m) covers roughly 50 × 100 pixels.
    assert 1500 < closer.sum() < 10000
    # The covered pixels are where the can is: around the image column of the table's centre.
    rows, cols = np.nonzero(closer)
    assert abs(cols.mean() - st.cameras["camera0"].info.center_x()) < 20
    # And their depth matches the can's distance from the camera (within its radius).
    X_WC = with_can.GetOutputPort("camera0.camera_pose").Eval(with_can.CreateDefaultContext())
    distance = np.linalg.norm(X_WC.translation() - [0.75, 0.0, 0.06])
    radius = get_object("can_02").dimensions["diameter"] / 2
    assert np.median(depths[1][closer]) == pytest.approx(distance, abs=2 * radius)


def test_an_object_of_a_user_library_loads_through_its_file_url(tmp_path):
    from library_helpers import copy_object

    from tg_drake.objects import forget_registered
    from tg_drake.scenario import ObjectPlacement

    copy_object("can_02", "my_can", tmp_path / "lib")
    try:
        scenario = Scenario(object_libraries=[str(tmp_path / "lib")],
                            objects=[ObjectPlacement(id="my_can", containment="full")])
        diagram, st = make_station(scenario)
        body = st.object_body("my_can")
        context = diagram.CreateDefaultContext()
        plant_context = st.plant.GetMyContextFromRoot(context)
        # the user library's SDF (file://) with its mesh beside it: the can's mass, resting upright
        from tg_drake.objects import get_object
        obj = get_object("my_can")
        assert obj.sdf_url.startswith("file:///")
        assert body.default_mass() == pytest.approx(obj.mass, rel=1e-6)
        X_WO = st.plant.EvalBodyPoseInWorld(plant_context, body)
        assert X_WO.translation()[2] == pytest.approx(
            scenario.X_WT.GetDeterministicValue().translation()[2], abs=1e-6)
        assert len(st.objects) == 1
    finally:
        forget_registered()
