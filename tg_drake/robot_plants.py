"""Models of the robot alone, taken from a scenario's directives: for planning and for control.

The station's plant holds everything the scenario adds (the arm, the gripper, the table, loose
objects); the planner's collision model and the inverse-dynamics controller's model hold only some
of those models. `add_scenario_models` adds them to a plant from the scenario's own directives,
so the models, their welds and their default positions are those of the station, whatever the
scenario says. The plant is not finalised: the caller may add to it first.
"""

from __future__ import annotations

import functools
import importlib.resources

from pydrake.multibody.parsing import (ModelDirective, ModelDirectives, ModelInstanceInfo, Parser,
                                       ProcessModelDirectives)
from pydrake.multibody.plant import MultibodyPlant

from tg_drake.errors import ModelError, ScenarioError
from tg_drake.scenario import Scenario, default_directives


@functools.cache
def models_root() -> str:
    """The folder of the tg_drake_models package (models/ in the source tree)."""
    return str(importlib.resources.files("tg_drake_models"))


def make_parser(plant: MultibodyPlant) -> Parser:
    """A parser that resolves package://tg_drake_models/... (and nothing from the internet)."""
    parser = Parser(plant)
    parser.package_map().AddPackageXml(f"{models_root()}/package.xml")
    return parser


def _model_of(scoped_name: str) -> str:
    return scoped_name.split("::")[0]


def model_directives(scenario: Scenario | None,
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


def add_scenario_models(plant: MultibodyPlant, scenario: Scenario | None,
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
