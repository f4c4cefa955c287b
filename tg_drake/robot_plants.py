"""Models of the robot alone, taken from a scenario's directives: for planning and for control.

The station's plant holds everything the scenario adds (the arm, the gripper, the table, loose
objects); the planner's collision model and the inverse-dynamics controller's model hold only some
of those models. `add_scenario_models` adds them to a plant from the scenario's own directives,
so the models, their welds and their default positions are those of the station, whatever the
scenario says. The plant is not finalised: the caller may add to it first.
"""

from __future__ import annotations

from pydrake.common.schema import Transform
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import (
    AddModel,
    AddWeld,
    ModelDirective,
    ModelDirectives,
    ModelInstanceInfo,
    ProcessModelDirectives,
)
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex

from tg_drake.errors import ModelError, ScenarioError
from tg_drake.models import make_parser
from tg_drake.robot import (
    IIWA_HOME,
    IIWA_JOINT_NAMES,
    WSG_FINGER_JOINTS,
    WSG_OPEN_POSITIONS,
    X_7G_RPY,
    X_7G_XYZ,
)


def default_directives() -> list[ModelDirective]:
    """The robot: the iiwa on the floor at the world origin, the WSG on its flange. (The table is
    not a directive: the station adds it from `table_size` and `X_WT`, tg_drake.table.)"""
    mount = Transform(RigidTransform(RollPitchYaw(*X_7G_RPY), X_7G_XYZ))
    return [
        ModelDirective(add_model=AddModel(
            name="iiwa", file="package://tg_drake_models/iiwa14/iiwa14.urdf",
            default_joint_positions={n: [q] for n, q in zip(IIWA_JOINT_NAMES, IIWA_HOME,
                                                            strict=True)})),
        ModelDirective(add_weld=AddWeld(parent="world", child="iiwa::iiwa_link_0")),
        ModelDirective(add_model=AddModel(
            name="wsg", file="package://tg_drake_models/wsg_50/wsg_50.urdf",
            default_joint_positions={n: [q] for n, q in zip(WSG_FINGER_JOINTS,
                                                            WSG_OPEN_POSITIONS, strict=True)})),
        ModelDirective(add_weld=AddWeld(parent="iiwa::iiwa_link_7", child="wsg::body",
                                        X_PC=mount)),
    ]


def _model_of(scoped_name: str) -> str:
    return scoped_name.split("::")[0]


def model_directives(scenario,
                     model_instance_names: tuple[str, ...] | list[str]) -> list[ModelDirective]:
    """The directives of `scenario` (default: the station's) that add the named models, and the
    welds whose child is one of their frames. Raises ScenarioError when a named model is not
    among those the directives add."""
    directives = (scenario.directives if scenario is not None else None) or default_directives()
    names = set(model_instance_names)
    added = {d.add_model.name for d in directives if d.add_model}
    missing = sorted(names - added)
    if missing:
        raise ScenarioError(f"the directives add no model named {', '.join(missing)} (needed for "
                            f"the robot's own model); models: {', '.join(sorted(added))}",
                            field="directives")
    return [d for d in directives
            if (d.add_model and d.add_model.name in names)
            or (d.add_weld and _model_of(d.add_weld.child) in names)]


def add_scenario_models(plant: MultibodyPlant, scenario,
                        model_instance_names: tuple[str, ...] | list[str]
                        ) -> list[ModelInstanceInfo]:
    """Adds to `plant` (not finalised) the named models of `scenario` (default: the station's)
    with the welds that attach them, as `model_directives` selects them."""
    directives = model_directives(scenario, model_instance_names)
    try:
        return ProcessModelDirectives(ModelDirectives(directives=directives), make_parser(plant))
    except RuntimeError as e:
        raise ModelError(f"could not load the models {', '.join(model_instance_names)} of the "
                         f"scenario's directives: {e}") from None


def couple_fingers(plant: MultibodyPlant, instance: ModelInstanceIndex) -> None:
    """The WSG 50's two fingers move as one mechanism, symmetric about the gripper's centre (one
    drive for both jaws): a coupler constraint q_left = −q_right between the finger joints
    (before Finalize). Without it each finger's PD pushes on its own, and a load along the
    closing axis moves a held object, fingers and all (a mug held end to end drifted 13 mm during
    its lift, to one finger's stroke limit)."""
    left, right = (plant.GetJointByName(name, instance) for name in WSG_FINGER_JOINTS)
    plant.AddCouplerConstraint(left, right, -1.0)
