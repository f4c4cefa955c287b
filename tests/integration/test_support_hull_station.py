"""The station's support hulls: an object touches the table only through its support hull, and
everything else only through its mesh; at rest it stands and lies where its mesh would."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from tg_drake.outcome import contact_pairs
from tg_drake.scenario import load_scenario
from tg_drake.station import SUPPORT_HULL, make_station


def _station(objects: str):
    # A placing task: a pass would add the receiver and its driver, which needs the pipeline.
    scenario = load_scenario("scenarios/default.yaml", scenario_text=(
        f"objects: [{objects}]\ntask: {{target: cup_01, task: p&pInUpright}}"))
    return make_station(scenario)


def _geometries(st, instance_name):
    plant, inspector = st.plant, st.scene_graph.model_inspector()
    body = plant.get_body(plant.GetBodyIndices(st.instances[instance_name])[0])
    ids = plant.GetCollisionGeometriesForBody(body)
    hull = [g for g in ids if inspector.GetName(g).endswith(SUPPORT_HULL)]
    return hull, [g for g in ids if g not in hull]


def _of(st, instance):
    plant = st.plant
    return [g for b in plant.GetBodyIndices(st.instances[instance])
            for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))]


def test_the_support_hull_meets_only_the_table_and_the_mesh_everything_else():
    diagram, st = _station("{id: cup_01, pose: upright, xy: [0.0, 0.05]}, "
                           "{id: can_01, pose: upright, xy: [0.0, -0.15]}")
    inspector = st.scene_graph.model_inspector()
    (hull,), meshes = _geometries(st, "cup_01")
    (other_hull,), other_meshes = _geometries(st, "can_01")
    table, fingers = _of(st, "table"), _of(st, "wsg")
    assert meshes and table and fingers
    assert all(not inspector.CollisionFiltered(hull, t) for t in table)
    assert all(inspector.CollisionFiltered(m, t) for m in meshes for t in table)
    for g in fingers + other_meshes + [other_hull]:
        assert inspector.CollisionFiltered(hull, g)
    # The mesh still meets the fingers and the other object.
    assert all(not inspector.CollisionFiltered(m, g) for m in meshes
               for g in fingers + other_meshes)


@pytest.mark.parametrize("pose", ["upright", "sideways"])
def test_an_object_rests_on_the_table_through_its_support_hull(pose):
    diagram, st = _station(f"{{id: cup_01, pose: {pose}, xy: [0.0, 0.05]}}")
    context = diagram.CreateDefaultContext()
    plant_context = st.plant.GetMyContextFromRoot(context)
    q0 = st.plant.GetPositions(plant_context, st.instances["iiwa"])
    diagram.GetInputPort("iiwa.desired_state").FixValue(context, np.concatenate([q0, np.zeros(7)]))
    diagram.GetInputPort("wsg.position").FixValue(context, [0.1])
    body = st.plant.get_body(st.plant.GetBodyIndices(st.instances["cup_01"])[0])
    X0 = body.EvalPoseInWorld(plant_context)
    Simulator(diagram, context).AdvanceTo(1.0)
    X = body.EvalPoseInWorld(plant_context)
    (hull,), meshes = _geometries(st, "cup_01")
    table = set(_of(st, "table"))
    pairs = contact_pairs(diagram.GetOutputPort("contact_results").Eval(context))
    touching = {a if b in table else b for a, b in pairs if a in table or b in table}
    assert touching == {hull}
    # It rests where the library's resting pose put it: within the hull's tolerance (2 mm) and
    # tilted less than a degree.
    assert np.linalg.norm(X.translation() - X0.translation()) < 0.002 + 1e-3
    tilt = np.arccos(np.clip(X.rotation().col(2) @ X0.rotation().col(2), -1.0, 1.0))
    assert np.degrees(tilt) < 1.0
