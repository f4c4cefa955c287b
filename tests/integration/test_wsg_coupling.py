"""The WSG 50's fingers move as one mechanism: a load along the closing axis does not move a
held object, fingers and all, along that axis."""

import dataclasses
from pathlib import Path

import numpy as np
from pydrake.geometry import Box
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    CoulombFriction,
    MultibodyPlantConfig,
)
from pydrake.multibody.tree import PdControllerGains, SpatialInertia
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from tg_drake.models import make_parser
from tg_drake.robot import WSG_FINGER_JOINTS, WSG_FORCE_LIMIT, WSG_GRASP_POINT_G
from tg_drake.robot_plants import couple_fingers
from tg_drake.scenario import WsgPdDriver, load_scenario
from tg_drake.station import make_station

MASS = 1.5  # [kg] its weight (15 N) pulls along the closing axis, below both fingers' 80 N
# [m] the box, its width along the closing axis: wide enough that the fingers, commanded shut,
# push at the force limit (80 N at 2000 N/m: 40 mm short of where they stop, each)
BOX = (0.104, 0.05, 0.05)


def finger_offset(coupled: bool) -> float:
    """[m] how far the fingers' centre moved along the closing axis after 1 s with a box held
    between the pads and gravity along that axis (the fingers commanded shut: both pushing at the
    drive's force limit)."""
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(MultibodyPlantConfig(
        time_step=0.005, contact_model="hydroelastic_with_fallback",
        discrete_contact_approximation="sap"), builder)
    wsg = make_parser(plant).AddModels(url="package://tg_drake_models/wsg_50/wsg_50.urdf")[0]
    # The closing axis x_G along gravity.
    X_WG = RigidTransform(RollPitchYaw(0.0, np.pi / 2, 0.0), [0.0, 0.0, 0.5])
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("body", wsg), X_WG)
    driver = WsgPdDriver()
    for name in WSG_FINGER_JOINTS:
        actuator = plant.GetJointActuatorByName(name, wsg)
        actuator.set_controller_gains(PdControllerGains(p=driver.kp, d=driver.kd))
        actuator.set_effort_limit(WSG_FORCE_LIMIT)
    if coupled:
        couple_fingers(plant, wsg)
    box = plant.AddRigidBody("box", plant.AddModelInstance("box"),
                             SpatialInertia.SolidBoxWithMass(MASS, *BOX))
    plant.RegisterCollisionGeometry(box, RigidTransform(), Box(*BOX), "box",
                                    CoulombFriction(1.0, 1.0))
    plant.set_gravity_enabled(wsg, False)  # the fingers' own weight: compensated, as on the arm
    plant.Finalize()
    command = builder.AddSystem(ConstantVectorSource(np.zeros(4)))  # both fingers shut, at rest
    builder.Connect(command.get_output_port(), plant.get_desired_state_input_port(wsg))
    diagram = builder.Build()
    simulator = Simulator(diagram)
    context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    plant.SetFreeBodyPose(context, box, X_WG @ RigidTransform(WSG_GRASP_POINT_G))
    for name, q in zip(WSG_FINGER_JOINTS, (-0.055, 0.055), strict=True):
        plant.GetJointByName(name, wsg).set_translation(context, q)
    simulator.AdvanceTo(1.0)
    left, right = (plant.GetJointByName(n, wsg).get_translation(context) for n in WSG_FINGER_JOINTS)
    X_GB = X_WG.inverse() @ plant.GetFreeBodyPose(context, box)
    assert np.abs(X_GB.translation()[1:] - WSG_GRASP_POINT_G[1:]).max() < 0.01  # still held
    return abs(left + right) / 2


def test_a_load_along_the_closing_axis_does_not_slide_the_coupled_fingers():
    assert finger_offset(coupled=True) < 0.0005
    # Each finger on its own PD: the weight moves the pair, object and all (measured 5.8 mm; the
    # lower finger's PD at its force limit gives way).
    assert finger_offset(coupled=False) > 0.003


def test_the_robots_and_the_receivers_fingers_follow_the_scenarios_driver():
    # The default scenario (a pass: the station has a receiver): both grippers coupled, one
    # constraint each; the scenario's driver uncoupled: neither is.
    scenario = load_scenario(Path(__file__).resolve().parents[2] / "scenarios" / "default.yaml")
    _, station = make_station(scenario)
    assert station.plant.num_constraints() == 2
    drivers = dict(scenario.model_drivers)
    drivers["wsg"] = dataclasses.replace(drivers["wsg"], coupled=False)
    _, station = make_station(dataclasses.replace(scenario, model_drivers=drivers))
    assert station.plant.num_constraints() == 0
