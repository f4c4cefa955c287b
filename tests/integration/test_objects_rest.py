"""Every library object, put on a table in each pose that suits it, stays put.

Each case builds a MultibodyPlant with the table top of tg_drake/table.py (a box, compliant
hydroelastic: modulus 1e7 Pa, resolution hint 0.1 m, Hunt–Crossley dissipation 3 s/m, friction 0.5)
and the object's SDF (rigid hydroelastic mesh, friction 1.0), places the object at
X_WO = X_WT · X_TO from library.yaml and simulates 2 s with SAP. The object must not drift or
tip, and its contact with
the table must be a hydroelastic contact surface (not point-pair fallback).

The default run takes one object per category and pose (the first instance); the full sweep of
all objects × poses is marked slow.
"""

from __future__ import annotations

import importlib.resources
import time
from pathlib import Path

import numpy as np
import pytest
from pydrake.geometry import (
    AddCompliantHydroelasticProperties,
    AddContactMaterial,
    Box,
    ClippingRange,
    ColorRenderCamera,
    DepthRange,
    DepthRenderCamera,
    MakeRenderEngineVtk,
    ProximityProperties,
    RenderCameraCore,
    RenderEngineVtkParams,
)
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlant, CoulombFriction, MultibodyPlantConfig
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.sensors import CameraInfo, RgbdSensor

from tg_drake.objects import load_library

TIME_STEP = 0.005  # [s] SAP is implicit: 5 ms holds light cans (10 g) and 2.5 kg pans alike.
DURATION = 2.0  # [s] of simulated time at rest.
MAX_DRIFT = 0.005  # [m] displacement of the centre of mass allowed over the 2 s.
# [rad] 3°: tipping or rolling turns an object by tens of degrees (a mug on its side rolling onto
# its handle: 31°); settling into the compliant table turns it by less (the long knives, whose COM
# lies near the front edge of the handle's flat, pitch 1.3–1.6° as that edge sinks in).
MAX_TILT = np.radians(3.0)
X_WT = RigidTransform([0.0, 0.0, 0.75])  # the table top 0.75 m above the floor.

CASES = [(o.id, pose) for o in load_library().values() for pose in o.poses]
FIRST_OF_CATEGORY = {}
for _id, _pose in CASES:
    FIRST_OF_CATEGORY.setdefault((load_library()[_id].category, _pose), (_id, _pose))
DEFAULT = list(FIRST_OF_CATEGORY.values())
SLOW = [c for c in CASES if c not in DEFAULT]


def plant_with_rest_table(builder: DiagramBuilder):
    """A SAP plant (TIME_STEP) in `builder` with the rest table: a 1 m × 1 m × 0.1 m compliant
    hydroelastic slab whose top face is the table-top frame T. Returns the plant, not finalized."""
    plant, _ = AddMultibodyPlant(
        MultibodyPlantConfig(time_step=TIME_STEP, contact_model="hydroelastic_with_fallback",
                             discrete_contact_approximation="sap"), builder)
    table = ProximityProperties()
    AddCompliantHydroelasticProperties(resolution_hint=0.1, hydroelastic_modulus=1e7,
                                       properties=table)
    AddContactMaterial(dissipation=3.0, point_stiffness=None,
                       friction=CoulombFriction(0.5, 0.5), properties=table)
    plant.RegisterCollisionGeometry(plant.world_body(),
                                    X_WT @ RigidTransform([0.0, 0.0, -0.05]),
                                    Box(1.0, 1.0, 0.1), "table", table)
    return plant


def rest_on_table(obj_id, pose: str) -> dict:
    """Simulates the object (a shipped id, or a LibraryObject of any library) resting on the
    table; returns what happened."""
    obj = load_library()[obj_id] if isinstance(obj_id, str) else obj_id
    obj_id = obj.id
    t0 = time.perf_counter()
    builder = DiagramBuilder()
    plant = plant_with_rest_table(builder)
    Parser(plant).AddModels(str(obj.sdf_path))
    plant.Finalize()
    diagram = builder.Build()
    simulator = Simulator(diagram)
    context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    body = plant.GetBodyByName(obj_id)
    X_WO0 = X_WT @ RigidTransform(obj.resting_pose(pose).X_TO)
    plant.SetFreeBodyPose(context, body, X_WO0)
    p_OC = np.array(obj.com)
    t1 = time.perf_counter()
    simulator.AdvanceTo(DURATION)
    t2 = time.perf_counter()
    X_WO = plant.EvalBodyPoseInWorld(context, body)
    contacts = plant.get_contact_results_output_port().Eval(context)
    hydro = [contacts.hydroelastic_contact_info(i) for i in
             range(contacts.num_hydroelastic_contacts())]
    return {
        "drift": float(np.linalg.norm(X_WO.multiply(p_OC) - X_WO0.multiply(p_OC))),
        "tilt": float(X_WO0.rotation().inverse().multiply(X_WO.rotation()).ToAngleAxis().angle()),
        "n_hydro": len(hydro),
        "hydro_area": sum(h.contact_surface().total_area() for h in hydro),
        "hydro_force_z": sum(h.F_Ac_W().translational()[2] for h in hydro),
        "n_point": contacts.num_point_pair_contacts(),
        "weight": obj.mass * 9.81,
        "build_s": t1 - t0,
        "sim_s": t2 - t1,
    }


def check_rest(obj_id, pose):
    r = rest_on_table(obj_id, pose)
    where = f"{getattr(obj_id, 'id', obj_id)} {pose}: {r}"
    assert r["drift"] < MAX_DRIFT, where
    assert r["tilt"] < MAX_TILT, where
    assert r["n_hydro"] == 1 and r["n_point"] == 0, where
    assert r["hydro_area"] > 0, where
    # At rest the hydroelastic surface carries the weight (sign: the force on the first geometry
    # of the pair, which may be the table or the object): 5 % for the residual rocking.
    assert abs(abs(r["hydro_force_z"]) - r["weight"]) < 0.05 * r["weight"], where


@pytest.mark.parametrize("obj_id,pose", DEFAULT, ids=[f"{i}-{p}" for i, p in DEFAULT])
def test_rests_on_table(obj_id, pose):
    check_rest(obj_id, pose)


@pytest.mark.slow
@pytest.mark.parametrize("obj_id,pose", SLOW, ids=[f"{i}-{p}" for i, p in SLOW])
def test_rests_on_table_all(obj_id, pose):
    check_rest(obj_id, pose)


def test_resting_transforms_use_drakes_roll_pitch_yaw():
    for obj in load_library().values():
        for rest in obj.poses.values():
            X = RigidTransform(RollPitchYaw(rest.rpy), rest.xyz).GetAsMatrix4()
            np.testing.assert_allclose(rest.X_TO, X, atol=1e-12)


def test_every_sdf_loads_by_package_url_with_its_mass_and_rigid_hydroelastic_mesh():
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(MultibodyPlantConfig(time_step=TIME_STEP), builder)
    parser = Parser(plant)
    parser.package_map().AddPackageXml(
        str(Path(str(importlib.resources.files("tg_drake_models"))) / "package.xml"))
    for obj in load_library().values():
        parser.AddModelsFromUrl(obj.sdf_url)
    plant.Finalize()
    inspector = scene_graph.model_inspector()
    for obj in load_library().values():
        body = plant.GetBodyByName(obj.id)
        assert body.default_mass() == pytest.approx(obj.mass, rel=1e-5)
        M = body.default_spatial_inertia()
        np.testing.assert_allclose(M.get_com(), obj.com, atol=1e-6)  # 1 µm: SDF text precision
        I_Bcm = M.CalcRotationalInertia().ShiftToCenterOfMass(M.get_mass(), M.get_com())
        np.testing.assert_allclose(I_Bcm.CopyToFullMatrix3(), obj.inertia,
                                   atol=1e-9 + 1e-5 * np.abs(obj.inertia).max())
        (gid,) = plant.GetCollisionGeometriesForBody(body)
        props = inspector.GetProximityProperties(gid)
        # rigid hydroelastic: a compliance type without a modulus (HydroelasticType is unbound)
        assert props.HasProperty("hydroelastic", "compliance_type")
        assert not props.HasProperty("hydroelastic", "hydroelastic_modulus")
        friction = props.GetProperty("material", "coulomb_friction")
        assert (friction.static_friction(), friction.dynamic_friction()) == (1.0, 1.0)


def test_objects_render_in_colour_depth_and_labels():
    """All objects on a grid, seen from above by one RgbdSensor (RenderEngineVtk): each object
    shows up in the label image and at the right depth."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(MultibodyPlantConfig(time_step=0.0), builder)
    scene_graph.AddRenderer("vtk", MakeRenderEngineVtk(RenderEngineVtkParams()))
    objs = list(load_library().values())
    cols = 8
    for k, obj in enumerate(objs):
        Parser(plant).AddModels(str(obj.sdf_path))
        xy = [0.45 * (k % cols - (cols - 1) / 2), 0.45 * (k // cols - 2.5)]
        rest = obj.resting_pose(next(iter(obj.poses)))
        plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(obj.id),
                         RigidTransform([*xy, 0.0]) @ RigidTransform(rest.X_TO))
    plant.Finalize()
    core = RenderCameraCore("vtk", CameraInfo(800, 600, np.radians(70)), ClippingRange(0.1, 10.0),
                            RigidTransform())
    X_WC = RigidTransform(RotationMatrix.MakeXRotation(np.pi), [0.0, 0.0, 3.0])  # looking down
    camera = builder.AddSystem(RgbdSensor(plant.GetBodyFrameIdOrThrow(plant.world_body().index()),
                                          X_WC, ColorRenderCamera(core),
                                          DepthRenderCamera(core, DepthRange(0.1, 10.0))))
    builder.Connect(scene_graph.get_query_output_port(), camera.query_object_input_port())
    diagram = builder.Build()
    context = camera.GetMyContextFromRoot(diagram.CreateDefaultContext())
    labels = camera.label_image_output_port().Eval(context).data[..., 0]
    depth = camera.depth_image_32F_output_port().Eval(context).data[..., 0]
    for obj in objs:
        mask = labels == int(plant.GetBodyByName(obj.id).index())
        assert mask.sum() > 20, obj.id  # a few tens of pixels at least, even for a knife
        # the top of the object is at most its height above the floor plane z = 0: 3 m away
        top = max(rest.X_TO[2, 3] + np.abs(rest.X_TO[2, :3]) @ np.array(obj.extents)
                  for rest in obj.poses.values())
        assert 3.0 - top - 1e-3 <= depth[mask].min() <= 3.0 + 1e-3, obj.id


# The timings for the report: python tests/integration/test_objects_rest.py
if __name__ == "__main__":
    total = 0.0
    for obj_id, pose in CASES:
        r = rest_on_table(obj_id, pose)
        total += r["build_s"] + r["sim_s"]
        print(f"{obj_id:16s} {pose:10s} drift {1000 * r['drift']:6.2f} mm  tilt "
              f"{np.degrees(r['tilt']):5.2f}°  hydro {r['n_hydro']} point {r['n_point']}  "
              f"Fz/mg {abs(r['hydro_force_z']) / r['weight']:.3f}  "
              f"build {r['build_s']:.2f} s  sim {r['sim_s']:.2f} s")
    print(f"{len(CASES)} cases, {total:.1f} s; default subset {len(DEFAULT)} cases")
