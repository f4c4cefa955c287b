"""Every object of set b (models/objects_b/), put on the table in each pose that suits it, stays
put: tests/integration/test_objects_rest.py's table, simulation and bounds (5 mm, 3°, one
hydroelastic contact carrying the weight).

The default run takes the first instance of the most distinct new families (lidded pot, stemmed
glass, squat can, square bottle, flat knife, heavy hammer) in every pose; every other object ×
pose is marked slow. And every SDF loads with its mass properties and a rigid hydroelastic mesh."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig
from pydrake.systems.framework import DiagramBuilder

from tests.integration.test_objects_rest import TIME_STEP, check_rest
from tg_drake.objects import load_library

LIB = load_library(Path(__file__).resolve().parents[2] / "models" / "objects_b")
NEW_FAMILIES = ("pot_b01", "glass_b01", "can_b01", "bottle_b01", "knife_b01", "hammer_b01")
CASES = [(i, pose) for i, o in LIB.items() for pose in o.poses]
DEFAULT = [c for c in CASES if c[0] in NEW_FAMILIES]
SLOW = [c for c in CASES if c not in DEFAULT]


@pytest.mark.parametrize("obj_id,pose", DEFAULT, ids=[f"{i}-{p}" for i, p in DEFAULT])
def test_new_families_rest_on_table(obj_id, pose):
    check_rest(LIB[obj_id], pose)


@pytest.mark.slow
@pytest.mark.parametrize("obj_id,pose", SLOW, ids=[f"{i}-{p}" for i, p in SLOW])
def test_set_b_rests_on_table_all(obj_id, pose):
    check_rest(LIB[obj_id], pose)


def test_every_set_b_sdf_loads_with_its_mass_and_rigid_hydroelastic_mesh():
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(MultibodyPlantConfig(time_step=TIME_STEP), builder)
    for obj in LIB.values():
        Parser(plant).AddModels(str(obj.sdf_path))
    plant.Finalize()
    inspector = scene_graph.model_inspector()
    for obj in LIB.values():
        body = plant.GetBodyByName(obj.id)
        M = body.default_spatial_inertia()
        assert M.get_mass() == pytest.approx(obj.mass, rel=1e-5)
        np.testing.assert_allclose(M.get_com(), obj.com, atol=1e-6)
        I_Bcm = M.CalcRotationalInertia().ShiftToCenterOfMass(M.get_mass(), M.get_com())
        np.testing.assert_allclose(I_Bcm.CopyToFullMatrix3(), obj.inertia,
                                   atol=1e-9 + 1e-5 * np.abs(obj.inertia).max())
        (gid,) = plant.GetCollisionGeometriesForBody(body)
        props = inspector.GetProximityProperties(gid)
        assert props.HasProperty("hydroelastic", "compliance_type")
        assert not props.HasProperty("hydroelastic", "hydroelastic_modulus")
