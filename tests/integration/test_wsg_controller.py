"""Our WSG 50 model works with pydrake's SchunkWsgPositionController (explicit force control)."""

import numpy as np
import pytest
from pydrake.manipulation import SchunkWsgPositionController
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from tg_drake.models import make_parser


def test_schunk_wsg_position_controller_drives_our_model_to_a_width():
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.001)
    wsg = make_parser(plant).AddModels(url="package://tg_drake_models/wsg_50/wsg_50.urdf")[0]
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("body", wsg))
    plant.Finalize()
    assert plant.num_actuated_dofs(wsg) == 2  # the controller's requirement
    controller = builder.AddSystem(SchunkWsgPositionController())
    builder.Connect(plant.get_state_output_port(wsg), controller.get_state_input_port())
    builder.Connect(controller.get_generalized_force_output_port(),
                    plant.get_actuation_input_port(wsg))
    width = builder.AddSystem(ConstantVectorSource([0.06]))
    builder.Connect(width.get_output_port(), controller.get_desired_position_input_port())
    force = builder.AddSystem(ConstantVectorSource([40.0]))
    builder.Connect(force.get_output_port(), controller.get_force_limit_input_port())
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(1.5)
    q = plant.GetPositions(plant.GetMyContextFromRoot(simulator.get_context()), wsg)
    # 2 mm: the controller's PD on the finger separation settles within this in 1.5 s.
    assert q[1] - q[0] == pytest.approx(0.06, abs=2e-3)
    assert np.abs(q[0] + q[1]) < 2e-3  # the fingers stay centred
