"""One grasp in hydroelastic physics: the free-floating WSG 50 closes, lifts and shakes.

The object is the cylinder the simulation settings were measured with (r 0.033 m, h 0.1 m,
0.3 kg; docs/design.md), rigid hydroelastic with friction 1.0, standing upright on the table.
"""

import numpy as np
import pytest

from tg_drake.grasping.dgi import FINGERTIP_Y, PAD_CENTER_Y
from tg_drake.outcome import CLOSED_ON_AIR, MIN_SQUEEZE
from tg_drake.simulation.episode import EpisodeConfig, GraspWorld, run_grasp_batch, scripted_targets

CYLINDER_SDF = """<?xml version="1.0"?>
<sdf version="1.9" xmlns:drake="http://drake.mit.edu">
  <model name="cylinder">
    <link name="cylinder">
      <inertial><mass>0.3</mass>
        <inertia><ixx>3.32e-4</ixx><iyy>3.32e-4</iyy><izz>1.63e-4</izz>
          <ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
      <collision name="collision">
        <geometry><cylinder><radius>0.033</radius><length>0.1</length></cylinder></geometry>
        <drake:proximity_properties><drake:rigid_hydroelastic/>
          <drake:mesh_resolution_hint>0.01</drake:mesh_resolution_hint>
          <drake:mu_dynamic>1.0</drake:mu_dynamic><drake:mu_static>1.0</drake:mu_static>
        </drake:proximity_properties>
      </collision>
    </link>
  </model>
</sdf>
"""

HEIGHT = 0.1
X_WO = np.eye(4)
X_WO[2, 3] = HEIGHT / 2  # standing on the table top (z_W = 0)


def top_down(grasp_point):
    """Approach −z_W, fingers closing along x_W."""
    X = np.eye(4)
    X[:3, :3] = np.column_stack([[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    X[:3, 3] = np.asarray(grasp_point) + [0, 0, PAD_CENTER_Y]
    return X


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    path = tmp_path_factory.mktemp("objects") / "cylinder.sdf"
    path.write_text(CYLINDER_SDF)
    return GraspWorld(str(path), EpisodeConfig())


def test_a_centred_grasp_holds_through_lift_and_shake(world):
    # Pads reach 0.096 − 0.055 = 41 mm below the grasp point: 31 mm below the cylinder's top.
    result = world.run(X_WO, top_down([0, 0, HEIGHT + 0.01]))
    assert result["status"] == "ok" and result["success"]
    # The fingers stop on the 66 mm wide cylinder; pressed with 60 N each, the compliant pads
    # (1e6 Pa, 12 mm thick) overlap it by a few mm each (3 mm here): allow up to 5.5 mm each.
    assert 0.055 < result["finger_gap"] < 0.066
    # 10 mm: the object may slip a little in the pads while it is lifted 0.1 m and shaken.
    assert result["object_rise"] == pytest.approx(0.1, abs=0.01)
    assert result["touches_left_pad"] and result["touches_right_pad"]
    # Each pad pushed apart by about the grip force (the drive's 80 N effort limit).
    assert min(result["squeeze"]) > 0.5 * EpisodeConfig().grip_force
    assert not result["touches_table"]


def test_a_blade_thinner_than_the_pads_sink_is_held(tmp_path):
    # A 1.5 mm × 6 cm × 10 cm blade standing on its edge: the compliant pads sink into it further
    # than half its thickness, so the fingers close to their limit (0 mm apart) and squeeze it.
    # Held by the one rule (it pushes both pads apart), lifted and shaken with the gripper.
    path = tmp_path / "blade.sdf"
    path.write_text(CYLINDER_SDF.replace("<cylinder><radius>0.033</radius><length>0.1</length>"
                                         "</cylinder>", "<box><size>0.0015 0.06 0.1</size></box>"))
    result = GraspWorld(str(path)).run(X_WO, top_down([0, 0, HEIGHT + 0.01]))
    assert result["status"] == "ok" and result["success"], result
    assert abs(result["finger_gap"]) <= CLOSED_ON_AIR
    assert min(result["squeeze"]) >= MIN_SQUEEZE
    assert result["object_rise"] == pytest.approx(0.1, abs=0.01)


def test_a_grasp_beside_the_object_closes_on_nothing(world):
    result = world.run(X_WO, top_down([0.09, 0, HEIGHT + 0.01]))
    assert result["status"] == "ok" and not result["success"]
    # Fully closed on nothing: no push on either pad.
    assert abs(result["finger_gap"]) <= CLOSED_ON_AIR and result["squeeze"] == [0.0, 0.0]
    assert abs(result["object_rise"]) < 0.005  # the cylinder still stands on the table
    assert result["touches_table"] and not result["touches_left_pad"]


def test_fingers_that_land_on_a_wide_face_do_not_grasp(tmp_path):
    # A 15 × 15 × 4 cm slab, wider than the 11 cm opening: the fingertips land on its top face
    # (the gripper stops there, its push limited to 150 N) and close on nothing once lifted.
    path = tmp_path / "slab.sdf"
    path.write_text(CYLINDER_SDF.replace("<cylinder><radius>0.033</radius><length>0.1</length>"
                                         "</cylinder>", "<box><size>0.15 0.15 0.04</size></box>"))
    X = np.eye(4)
    X[2, 3] = 0.02
    result = GraspWorld(str(path)).run(X, top_down([0, 0, 0.04 + 0.03]))
    assert result["status"] == "ok" and not result["success"]
    assert abs(result["finger_gap"]) <= CLOSED_ON_AIR and result["touches_table"]


def test_a_grasp_on_the_rim_with_the_fingertips_slips(world):
    # Only the last 2 mm of the pads reach the cylinder's top edge.
    result = world.run(X_WO, top_down([0, 0, HEIGHT + (FINGERTIP_Y - PAD_CENTER_Y) - 0.002]))
    assert result["status"] == "ok" and not result["success"]


def test_a_physics_failure_is_reported_not_raised(world):
    # The object placed inside the table top: it is pushed out or falls through, never raises.
    X = X_WO.copy()
    X[2, 3] = -0.3
    result = world.run(X, top_down([0, 0, HEIGHT + 0.01]))
    assert result["status"] == "sim_error"
    assert result["reason"] == "object fell through the table during approach"
    # The world is reusable after a failure.
    again = world.run(X_WO, top_down([0, 0, HEIGHT + 0.01]))
    assert again["status"] == "ok" and again["success"]


def test_the_script_approaches_closes_lifts_and_shakes_back_to_rest():
    c = EpisodeConfig()
    R_GW = top_down([0, 0, 0])[:3, :3].T
    at = {t: scripted_targets(t, c, R_GW) for t in (
        0.0, c.approach_time, c.approach_time + c.close_time,
        c.approach_time + c.close_time + c.lift_time, c.duration)}
    t0, t1, t2, t3, t4 = at.values()
    assert t0["carrier_y"] == (-c.approach_distance, 0.0)
    assert t0["right_finger_sliding_joint"][0] == pytest.approx(0.055)
    assert t1["carrier_y"] == (0.0, 0.0)
    # Past the centre by grip_force / kp: 60 N / 2000 N/m = 3 cm.
    assert t2["right_finger_sliding_joint"][0] == pytest.approx(-0.03)
    assert t2["left_finger_sliding_joint"][0] == pytest.approx(0.03)
    # Up 0.1 m along z_W, which is −y_G for a top-down grasp.
    for t in (t3, t4):
        assert t["carrier_y"][0] == pytest.approx(-c.lift_height, abs=1e-12)
        assert t["carrier_x"][0] == pytest.approx(0.0, abs=1e-12)
        assert t["carrier_rz"] == (0.0, 0.0)
        # Desired velocities are zero at rest (1e-12: rounding of the sin² envelope).
        assert all(abs(qv[1]) < 1e-12 for qv in t.values())


def test_object_mass_scales_the_inertia_and_keeps_the_centre_of_mass(tmp_path):
    path = tmp_path / "cylinder.sdf"
    path.write_text(CYLINDER_SDF)
    world = GraspWorld(str(path), EpisodeConfig(object_mass=0.1))
    context = world.plant.GetMyContextFromRoot(world.context)
    M = world.object_body.CalcSpatialInertiaInBodyFrame(context)
    assert M.get_mass() == pytest.approx(0.1)
    np.testing.assert_allclose(M.get_com(), [0, 0, 0], atol=1e-12)
    # A third of the 0.3 kg model's inertia: the same shape, a third of its density.
    np.testing.assert_allclose(M.CalcRotationalInertia().get_moments(),
                               np.array([3.32e-4, 3.32e-4, 1.63e-4]) / 3, rtol=1e-6)
    result = world.run(X_WO, top_down([0, 0, HEIGHT + 0.01]))  # the context's mass persists
    assert result["status"] == "ok" and result["success"]
    assert world.object_body.CalcSpatialInertiaInBodyFrame(context).get_mass() == pytest.approx(0.1)


def test_a_batch_records_the_object_mass_it_ran_with(tmp_path):
    # collect_grasps.py refuses to add grasps of one mass to a file of another: the records say.
    path = tmp_path / "cylinder.sdf"
    path.write_text(CYLINDER_SDF)
    grasp = {"index": 0, "kind": "box", "part": 1,
             "X_WG": top_down([0, 0, HEIGHT + 0.01]).ravel().tolist()}
    payload = {"object_sdf": str(path), "object": "cylinder", "pose": "upright",
               "X_WO": X_WO.ravel().tolist(), "grasps": [grasp]}
    light, = run_grasp_batch({**payload, "config": {"object_mass": 0.1}})
    own, = run_grasp_batch({**payload, "config": {}})
    assert light["object_mass"] == 0.1 and "object_mass" not in own
    assert light["status"] == own["status"] == "ok" and light["index"] == 0


def test_the_episode_fingers_close_as_one_drive(world):
    # 15 mm off the cylinder's axis along the closing axis: one pad meets it 30 mm before the
    # other. Coupled (the WSG 50's one drive, as in the station), the pads stay symmetric about the
    # gripper's centre whatever they touch first.
    result = world.run(X_WO, top_down([0.015, 0, HEIGHT + 0.01]))
    assert result["status"] == "ok"
    plant_context = world.plant.GetMyContextFromRoot(world.context)
    left, right = (f.get_translation(plant_context) for f in world.fingers)
    assert left < -0.02 and right > 0.02  # closed on the 66 mm cylinder, not on air
    assert abs(left + right) < 0.0005
