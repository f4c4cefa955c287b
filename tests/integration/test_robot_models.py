"""tg_drake.robot against the models: the iiwa and WSG files, parsed by Drake, carry its figures,
and the scenario's robot-only plants (planning, control) hold the models they name."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from pydrake.geometry import Box
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from tg_drake import robot
from tg_drake.errors import ScenarioError
from tg_drake.robot_plants import add_scenario_models, default_directives, model_directives
from tg_drake.scenario import X_7G, Scenario

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def station_robot():
    """The scenario's iiwa and WSG, as the station adds them, with their geometry."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    add_scenario_models(plant, Scenario(), ("iiwa", "wsg"))
    plant.Finalize()
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    return plant, scene_graph, plant.GetMyMutableContextFromRoot(context)


def test_the_generator_writes_the_committed_models_from_robot_py():
    done = subprocess.run([sys.executable, "-m", "tools.make_robot_models", "--check"], cwd=ROOT,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_iiwa_kinematics_and_limits(station_robot):
    plant, _, context = station_robot
    iiwa = plant.GetModelInstanceByName("iiwa")
    for fact in robot.IIWA_JOINTS:
        joint = plant.GetJointByName(fact.name, iiwa)
        assert (joint.parent_body().name(), joint.child_body().name()) == (fact.parent, fact.child)
        X_PF = joint.frame_on_parent().GetFixedPoseInBodyFrame()
        # The URDF writes its figures to 6 significant digits: π as 3.14159, 2.7 µrad short.
        assert X_PF.IsNearlyEqualTo(RigidTransform(RollPitchYaw(fact.rpy), fact.xyz), 1e-5)
        np.testing.assert_allclose(joint.position_lower_limits(), [-fact.limit], rtol=1e-12)
        np.testing.assert_allclose(joint.position_upper_limits(), [fact.limit], rtol=1e-12)
        np.testing.assert_allclose(joint.velocity_upper_limits(), [fact.velocity], rtol=1e-12)
        assert plant.GetJointActuatorByName(f"{fact.name}_actuator", iiwa).effort_limit() \
            == pytest.approx(fact.effort)
    assert robot.IIWA_JOINT_NAMES == tuple(f"iiwa_joint_{k}" for k in range(1, 8))
    np.testing.assert_array_equal(robot.IIWA_POSITION_LIMITS,
                                  [j.limit for j in robot.IIWA_JOINTS])
    X_7E = plant.CalcRelativeTransform(context, plant.GetFrameByName("iiwa_link_7", iiwa),
                                       plant.GetFrameByName("iiwa_link_ee", iiwa))
    np.testing.assert_allclose(X_7E.translation(), [0, 0, robot.IIWA_FLANGE_Z], atol=1e-12)
    # The home posture is the scenario's default and lies inside the limits.
    q = plant.GetPositions(context, iiwa)
    np.testing.assert_allclose(q, robot.IIWA_HOME, atol=1e-12)
    assert np.all(np.abs(q) < robot.IIWA_POSITION_LIMITS)


def test_wsg_mount_fingers_and_force(station_robot):
    plant, _, context = station_robot
    iiwa, wsg = plant.GetModelInstanceByName("iiwa"), plant.GetModelInstanceByName("wsg")
    G = plant.GetFrameByName(robot.WSG_BODY, wsg)
    X_7G_plant = plant.CalcRelativeTransform(context, plant.GetFrameByName("iiwa_link_7", iiwa), G)
    np.testing.assert_allclose(X_7G_plant.GetAsMatrix4(), robot.X_7G, atol=1e-12)
    np.testing.assert_allclose(X_7G.GetAsMatrix4(), robot.X_7G, atol=1e-12)
    # Approach +y_G along link 7's z axis, G's origin 0.114 m out.
    np.testing.assert_allclose(robot.X_7G[:3, 1], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(robot.X_7G[:3, 3], [0, 0, 0.114])
    actuated = [plant.get_joint_actuator(i).joint().name()
                for i in plant.GetJointActuatorIndices(wsg)]
    assert tuple(actuated) == robot.WSG_FINGER_JOINTS
    lower = [plant.GetJointByName(n, wsg).position_lower_limits()[0]
             for n in robot.WSG_FINGER_JOINTS]
    upper = [plant.GetJointByName(n, wsg).position_upper_limits()[0]
             for n in robot.WSG_FINGER_JOINTS]
    assert lower == pytest.approx([-robot.WSG_STROKE, 0.0])
    assert upper == pytest.approx([0.0, robot.WSG_STROKE])
    for i in plant.GetJointActuatorIndices(wsg):
        assert plant.get_joint_actuator(i).effort_limit() == pytest.approx(robot.WSG_FORCE_LIMIT)
    # The scenario's default: fully open.
    assert tuple(plant.GetPositions(context, wsg)) == pytest.approx(robot.WSG_OPEN_POSITIONS)
    assert plant.GetBodyByName(robot.WSG_BODY, wsg).default_mass() \
        == pytest.approx(robot.WSG_BODY_MASS)
    for name in robot.WSG_FINGERS:
        assert plant.GetBodyByName(name, wsg).default_mass() \
            == pytest.approx(robot.WSG_FINGER_MASS)


def _boxes_in_G(plant, scene_graph, context, body_name):
    """(centre in G, size) of the collision boxes of a WSG body at the context's positions."""
    wsg = plant.GetModelInstanceByName("wsg")
    body = plant.GetBodyByName(body_name, wsg)
    X_GB = plant.CalcRelativeTransform(context, plant.GetFrameByName(robot.WSG_BODY, wsg),
                                       body.body_frame())
    inspector = scene_graph.model_inspector()
    out = []
    for g in plant.GetCollisionGeometriesForBody(body):
        shape = inspector.GetShape(g)
        assert isinstance(shape, Box)
        X_BS = inspector.GetPoseInFrame(g)
        out.append(((X_GB @ X_BS).translation(), np.array([shape.width(), shape.depth(),
                                                           shape.height()])))
    return out


@pytest.mark.parametrize("opening", [robot.WSG_MAX_OPENING, 0.04])
def test_wsg_pads_and_body(station_robot, opening):
    plant, scene_graph, context = station_robot
    wsg = plant.GetModelInstanceByName("wsg")
    plant.SetPositions(context, wsg, [-opening / 2, opening / 2])
    expected = robot.wsg_pad_boxes(opening)
    for name, (centre, size) in zip(robot.WSG_FINGERS, expected, strict=False):
        ((c, s),) = _boxes_in_G(plant, scene_graph, context, name)
        np.testing.assert_allclose(c, centre, atol=1e-12)
        np.testing.assert_allclose(s, size, atol=1e-12)
    left, right = expected
    # Inner faces: the opening; pads from the palm to the fingertips; the grasp point between them.
    assert (right[0][0] - right[1][0] / 2) - (left[0][0] + left[1][0] / 2) \
        == pytest.approx(opening)
    assert right[0][1] - right[1][1] / 2 == pytest.approx(robot.WSG_PALM_Y)
    assert right[0][1] + right[1][1] / 2 == pytest.approx(robot.WSG_FINGERTIP_Y)
    np.testing.assert_allclose((left[0] + right[0]) / 2, robot.WSG_GRASP_POINT_G, atol=1e-12)
    ((c, s),) = _boxes_in_G(plant, scene_graph, context, robot.WSG_BODY)
    np.testing.assert_allclose(c, robot.WSG_BODY_CENTRE_G, atol=1e-12)
    np.testing.assert_allclose(s, robot.WSG_BODY_SIZE, atol=1e-12)
    plant.SetPositions(context, wsg, list(robot.WSG_OPEN_POSITIONS))


def test_robot_plants_hold_only_the_named_models():
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    added = add_scenario_models(plant, None, ("iiwa", "wsg"))
    assert sorted(plant.GetModelInstanceName(i.model_instance) for i in added) == ["iiwa", "wsg"]
    # A weld whose child belongs to a model left out is left out too.
    kept = model_directives(None, ("iiwa", "wsg"))
    assert {d.add_model.name for d in kept if d.add_model} == {"iiwa", "wsg"}
    assert [d.add_weld.child for d in kept if d.add_weld] == ["iiwa::iiwa_link_0", "wsg::body"]
    assert len(default_directives()) == 4  # the table is added from table_size, not a directive


def test_a_robot_plant_names_a_model_the_scenario_lacks():
    scenario = Scenario(directives=[d for d in default_directives()
                                    if not (d.add_model and d.add_model.name == "wsg")
                                    and not (d.add_weld and d.add_weld.child.startswith("wsg"))])
    with pytest.raises(ScenarioError, match="no model named wsg"):
        model_directives(scenario, ("iiwa", "wsg"))


def test_the_inverse_dynamics_controller_models_the_arm_with_the_gripper_as_payload():
    from tg_drake.scenario import InverseDynamicsDriver
    from tg_drake.station import add_station

    scenario = Scenario()
    scenario.cameras = {}
    scenario.model_drivers["iiwa"] = InverseDynamicsDriver()
    builder = DiagramBuilder()
    add_station(builder, scenario=scenario)
    control = builder.GetSubsystemByName("iiwa_inverse_dynamics").get_multibody_plant_for_control()
    assert control.HasModelInstanceNamed("iiwa") and control.HasModelInstanceNamed("wsg")
    assert not control.HasModelInstanceNamed("table")
    assert control.num_positions() == 7  # the finger joints welded: they ride as payload
    wsg = control.GetModelInstanceByName("wsg")
    assert control.GetBodyByName(robot.WSG_BODY, wsg).default_mass() \
        == pytest.approx(robot.WSG_BODY_MASS)
