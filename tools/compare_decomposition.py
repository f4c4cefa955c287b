"""Measures convex decompositions (CoACD, V-HACD) on scan-like meshes of library objects, for the
import's collision geometry (issue 18, point 3), and prints a table.

    python tools/compare_decomposition.py                       # the default objects, no Drake
    python tools/compare_decomposition.py --drake               # + the resting check in Drake
    python tools/compare_decomposition.py cup_01 --backends vhacd_r1e5_h32 --drake

For each object: its scan-like mesh (tg_drake.scanlike, default settings, seed 0) gets the basic
repair an import does (trimesh: merge vertices, drop degenerate and duplicate faces, fix normals)
and is mapped back to metres, z up, in the object frame O (the scan's X_SO inverted), so that it
lies on the library original. Each backend of BACKENDS then decomposes it, in a child process
stopped after TIMEOUT (the object is skipped for that backend and the table says so). Measured:

- time: wall time of the decomposition [s] (the machine is shared: compare within a run);
- pieces, vertices: number of convex pieces and their total vertex count;
- vol: volume of the union of the pieces / the original's volume (Monte Carlo, N_SAMPLES points
  in the original's bounding box grown by PAD; a point is in a piece when it is inside all the
  planes of the piece's hull);
- cover: fraction of the original's material inside the union; excess: union outside the
  original, relative to the original's volume (what contact would touch that is not there);
- cavity: open containers only, the fraction of the cavity axis (O's z axis from CAVITY_AXIS's
  lower to upper fraction of the height) outside every piece — 1.0 when the inside stays free,
  and "mid" whether the point at mid-height is free;
- with --drake: the object as one body (the library's mass, centre of mass and inertia) resting
  upright (tools: lying) on a compliant box (tg_drake/table.py's TABLE_HYDRO) for DURATION at
  TIME_STEP with SAP, the collision geometry either the pieces (each a rigid-hydroelastic
  <drake:declare_convex/> mesh), the shipped mesh (rigid hydroelastic, as the library does) or the
  repaired full scan mesh: final drift of the centre of mass [mm], tilt [°] and the simulation's
  wall time [s].
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import open3d as o3d
import trimesh
from scipy.spatial import ConvexHull

from tg_drake.objects import get_object, mesh
from tg_drake.scanlike import make_scanlike

# ------------------------------------------------------------------------------------------------
# Parameters (one place)

OBJECTS = ("cup_01", "glass_01", "pan_01", "bowl_01", "bottle_01", "hammer_01")
SEED = 0  # of the scan-like meshes
# name → (backend, keyword arguments of its Python call)
BACKENDS = {
    # CoACD (coacd.run_coacd): threshold = concavity allowed per piece, relative to the bounding
    # box diagonal (0.05 default; larger: fewer pieces, faster); preprocess "on" remeshes the
    # input to a manifold at preprocess_resolution voxels along the longest side (a scan with
    # holes is not manifold); max_convex_hull −1: no cap; resolution: surface samples for the
    # concavity metric. On the 50k-triangle scan-like cup (2 shared cores) no setting finished:
    # "auto" > 300 s, "on" > 150 s, threshold 0.1 with 30 MCTS iterations, 10 nodes, 16 hulls
    # > 100 s, and the same after a quadric decimation to 3,000 triangles > 100 s.
    "coacd_t0.05": ("coacd", dict(threshold=0.05, preprocess_mode="on", preprocess_resolution=50,
                                  max_convex_hull=-1, resolution=2000, seed=0)),
    "coacd_t0.1": ("coacd", dict(threshold=0.1, preprocess_mode="on", preprocess_resolution=50,
                                 max_convex_hull=-1, resolution=2000, seed=0)),
    # V-HACD 4 (vhacdx via trimesh.decomposition.convex_decomposition): resolution = voxels in
    # the bounding box (400,000 default); maxConvexHulls = cap on pieces (64 default);
    # maxNumVerticesPerCH = cap on a piece's vertices (64 default).
    "vhacd_r1e5_h32": ("vhacd", dict(resolution=100_000, maxConvexHulls=32,
                                     maxNumVerticesPerCH=64)),
    "vhacd_r4e5_h64": ("vhacd", dict(resolution=400_000, maxConvexHulls=64,
                                     maxNumVerticesPerCH=64)),
    # fillMode: how V-HACD decides the voxels inside. "flood" (default) floods from outside and
    # leaks through a scan's holes once the voxels are finer than the holes (a bottle's pieces
    # then cover only its shell); "raycast" decides by rays and does not leak.
    "vhacd_r1e5_h32_ray": ("vhacd", dict(resolution=100_000, maxConvexHulls=32,
                                         maxNumVerticesPerCH=64, fillMode="raycast")),
    "vhacd_r4e5_h64_ray": ("vhacd", dict(resolution=400_000, maxConvexHulls=64,
                                         maxNumVerticesPerCH=64, fillMode="raycast")),
}
TIMEOUT = 120.0  # [s] a decomposition taking longer is stopped; the object is skipped for it
N_SAMPLES = 400_000  # Monte Carlo points for the volumes (±~0.5 % of the box)
PAD = 0.01  # [m] the sampling box grows by this on each side (pieces may stick out)
HULL_TOL = 1e-9  # [m] a point within this of a piece's plane counts as inside
CAVITY_AXIS = (0.35, 0.85, 21)  # fractions of the height (from, to, points) on O's z axis
OPEN_CONTAINERS = ("cup", "glass", "pan", "pot", "bowl")
# Drake resting check (as tests/integration/test_objects_rest.py)
TIME_STEP = 0.005  # [s] SAP
DURATION = 2.0  # [s] simulated at rest
OBJECT_MU = 1.0  # friction of the object's collision geometry (the library's)
MAX_PIECE_OBJS = 256  # refuse to write more piece files than this


# ------------------------------------------------------------------------------------------------
# mesh and decomposition


def repaired_scan(obj_id: str) -> trimesh.Trimesh:
    """The scan-like mesh after the basic repair, in metres, z up, in O."""
    scan = make_scanlike(obj_id, seed=SEED)
    X_OS = np.linalg.inv(scan.X_SO)
    m = trimesh.Trimesh(scan.mesh.vertices @ X_OS[:3, :3].T + X_OS[:3, 3], scan.mesh.faces,
                        process=False)
    m.merge_vertices()
    m.update_faces(m.nondegenerate_faces())
    m.update_faces(m.unique_faces())
    m.remove_unreferenced_vertices()
    trimesh.repair.fix_normals(m)
    return m


def _decompose(backend: str, kwargs: dict, V: np.ndarray, F: np.ndarray, queue) -> None:
    t0 = time.perf_counter()
    if backend == "coacd":
        import coacd

        coacd.set_log_level("error")
        parts = coacd.run_coacd(coacd.Mesh(V, F), **kwargs)
        pieces = [np.asarray(v, float) for v, _ in parts]
    else:
        parts = trimesh.decomposition.convex_decomposition(trimesh.Trimesh(V, F, process=False),
                                                           **kwargs)
        pieces = [np.asarray(p["vertices"], float) for p in parts]
    queue.put((time.perf_counter() - t0, pieces))


def decompose(backend: str, kwargs: dict, m: trimesh.Trimesh):
    """(seconds, [piece vertices (k, 3)]) or None after TIMEOUT (the child is stopped)."""
    queue = mp.get_context("fork").Queue()
    child = mp.get_context("fork").Process(
        target=_decompose, args=(backend, kwargs, np.asarray(m.vertices), np.asarray(m.faces),
                                 queue))
    child.start()
    try:
        return queue.get(timeout=TIMEOUT)
    except Exception:  # queue.Empty: too slow (or the child died)
        return None
    finally:
        child.terminate()
        child.join()


# ------------------------------------------------------------------------------------------------
# measures


def inside_pieces(pieces, P: np.ndarray) -> np.ndarray:
    """(n,) whether each point is inside at least one convex piece."""
    inside = np.zeros(len(P), bool)
    for v in pieces:
        eq = ConvexHull(v).equations  # (m, 4): n·p + d ≤ 0 inside
        inside |= np.all(P @ eq[:, :3].T + eq[:, 3] <= HULL_TOL, axis=1)
    return inside


def volume_measures(obj_id: str, pieces, rng) -> dict:
    V0, F0, _ = mesh(obj_id)
    lo, hi = V0.min(axis=0) - PAD, V0.max(axis=0) + PAD
    P = rng.uniform(lo, hi, (N_SAMPLES, 3))
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(V0.astype(np.float32)),
                        o3d.core.Tensor(F0.astype(np.uint32)))
    in_mesh = scene.compute_occupancy(o3d.core.Tensor(P.astype(np.float32))).numpy() > 0.5
    in_union = inside_pieces(pieces, P)
    n_mesh = max(1, in_mesh.sum())
    return {"vol": in_union.sum() / n_mesh, "cover": (in_union & in_mesh).sum() / n_mesh,
            "excess": (in_union & ~in_mesh).sum() / n_mesh}


def cavity_measures(obj_id: str, pieces) -> dict:
    o = get_object(obj_id)
    if o.category not in OPEN_CONTAINERS:
        return {"cavity": None, "mid": None}
    h = o.extents[2]
    z = np.linspace(CAVITY_AXIS[0] * h, CAVITY_AXIS[1] * h, CAVITY_AXIS[2])
    P = np.stack([np.zeros_like(z), np.zeros_like(z), z], axis=1)
    free = ~inside_pieces(pieces, np.vstack([P, [[0.0, 0.0, 0.5 * h]]]))
    return {"cavity": free[:-1].mean(), "mid": bool(free[-1])}


# ------------------------------------------------------------------------------------------------
# Drake


def _sdf(obj_id: str, collisions: list[tuple[str, bool]]) -> str:
    """One body with the library's inertia and the given collision meshes (uri, convex)."""
    o = get_object(obj_id)
    inertia = o.inertia
    cols = "".join(
        f'<collision name="c{k}"><geometry><mesh><uri>{uri}</uri>'
        f"{'<drake:declare_convex/>' if convex else ''}</mesh></geometry>"
        "<drake:proximity_properties><drake:rigid_hydroelastic/>"
        f"<drake:mu_dynamic>{OBJECT_MU}</drake:mu_dynamic>"
        f"<drake:mu_static>{OBJECT_MU}</drake:mu_static>"
        "</drake:proximity_properties></collision>"
        for k, (uri, convex) in enumerate(collisions))
    c = o.com
    return (f'<?xml version="1.0"?><sdf version="1.9" xmlns:drake="http://drake.mit.edu">'
            f'<model name="{obj_id}"><link name="{obj_id}"><inertial>'
            f"<pose>{c[0]} {c[1]} {c[2]} 0 0 0</pose><mass>{o.mass}</mass><inertia>"
            f"<ixx>{inertia[0, 0]}</ixx><ixy>{inertia[0, 1]}</ixy><ixz>{inertia[0, 2]}</ixz>"
            f"<iyy>{inertia[1, 1]}</iyy><iyz>{inertia[1, 2]}</iyz><izz>{inertia[2, 2]}</izz>"
            f"</inertia></inertial>{cols}</link></model></sdf>")


def rest_in_drake(obj_id: str, collision, folder: Path) -> dict:
    """Rests the object on a compliant box; collision: "shipped", a Trimesh (one rigid mesh) or a
    list of piece vertex arrays (convex pieces)."""
    from pydrake.geometry import (
        AddCompliantHydroelasticProperties,
        AddContactMaterial,
        Box,
        ProximityProperties,
    )
    from pydrake.math import RigidTransform, RollPitchYaw
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import (
        AddMultibodyPlant,
        CoulombFriction,
        MultibodyPlantConfig,
    )
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder

    from tg_drake.table import TABLE_HYDRO

    o = get_object(obj_id)
    folder.mkdir(parents=True, exist_ok=True)
    if isinstance(collision, str):
        collisions = [(str(o.mesh_path), False)]
    elif isinstance(collision, trimesh.Trimesh):
        path = folder / "scan.obj"
        collision.export(path, file_type="obj", include_normals=False)
        collisions = [(str(path), False)]
    else:
        if len(collision) > MAX_PIECE_OBJS:
            raise ValueError(f"{len(collision)} pieces")
        collisions = []
        for k, v in enumerate(collision):
            path = folder / f"piece_{k}.obj"
            trimesh.convex.convex_hull(v).export(path, file_type="obj", include_normals=False)
            collisions.append((str(path), True))
    sdf = folder / "object.sdf"
    sdf.write_text(_sdf(obj_id, collisions))

    t0 = time.perf_counter()
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(
        MultibodyPlantConfig(time_step=TIME_STEP, contact_model="hydroelastic_with_fallback",
                             discrete_contact_approximation="sap"), builder)
    table = ProximityProperties()
    AddCompliantHydroelasticProperties(resolution_hint=TABLE_HYDRO["resolution"],
                                       hydroelastic_modulus=TABLE_HYDRO["modulus"],
                                       properties=table)
    AddContactMaterial(dissipation=TABLE_HYDRO["dissipation"], point_stiffness=None,
                       friction=CoulombFriction(TABLE_HYDRO["mu"], TABLE_HYDRO["mu"]),
                       properties=table)
    plant.RegisterCollisionGeometry(plant.world_body(), RigidTransform([0.0, 0.0, -0.05]),
                                    Box(1.0, 1.0, 0.1), "table", table)
    Parser(plant).AddModels(str(sdf))
    plant.Finalize()
    diagram = builder.Build()
    t_build = time.perf_counter() - t0
    pose = o.resting_pose("upright" if "upright" in o.poses else "sideways")
    X_WO = RigidTransform(RollPitchYaw(pose.rpy), pose.xyz)
    context = diagram.CreateDefaultContext()
    body = plant.GetBodyByName(obj_id)
    plant.SetFreeBodyPose(plant.GetMyMutableContextFromRoot(context), body, X_WO)
    simulator = Simulator(diagram, context)
    t0 = time.perf_counter()
    simulator.AdvanceTo(DURATION)
    t_sim = time.perf_counter() - t0
    X_WO_end = plant.EvalBodyPoseInWorld(plant.GetMyContextFromRoot(context), body)
    com = np.asarray(o.com)
    drift = np.linalg.norm(X_WO_end.multiply(com) - X_WO.multiply(com))
    R = X_WO.rotation().inverse().multiply(X_WO_end.rotation())
    tilt = np.degrees(R.ToAngleAxis().angle())
    return {"drift_mm": 1000 * drift, "tilt_deg": tilt, "sim_s": t_sim, "build_s": t_build}


# ------------------------------------------------------------------------------------------------


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("objects", nargs="*", default=list(OBJECTS))
    p.add_argument("--backends", nargs="+", choices=list(BACKENDS), default=list(BACKENDS))
    p.add_argument("--drake", action="store_true", help="also rest each object in Drake")
    p.add_argument("--scan-mesh", action="store_true",
                   help="with --drake, also rest the full repaired scan mesh (slow: ~1 min each)")
    args = p.parse_args(argv)
    from tqdm import tqdm  # a progress bar for one output

    rng = np.random.default_rng(0)
    rows = []
    jobs = [(o, b) for o in args.objects for b in [None, *args.backends]]
    scans = {}
    with tempfile.TemporaryDirectory() as tmp:
        for obj_id, name in tqdm(jobs, desc="decompositions", unit="job"):
            if obj_id not in scans:
                scans[obj_id] = repaired_scan(obj_id)
            m = scans[obj_id]
            row = {"object": obj_id, "backend": name or "(mesh)"}
            if name is None:  # the reference rows: shipped mesh and the repaired full scan
                row.update(pieces=1, vertices=len(m.vertices))
                if args.drake:
                    refs = [("shipped", "shipped")] + [("scan mesh", m)] * args.scan_mesh
                    for label, col in refs:
                        r = dict(row, backend=label)
                        if label == "shipped":
                            r["vertices"] = len(mesh(obj_id)[0])
                        r.update(rest_in_drake(obj_id, col, Path(tmp) / obj_id / label))
                        rows.append(r)
                continue
            backend, kwargs = BACKENDS[name]
            out = decompose(backend, kwargs, m)
            if out is None:
                row["skipped"] = f"> {TIMEOUT:.0f} s"
                rows.append(row)
                continue
            seconds, pieces = out
            row.update(time_s=seconds, pieces=len(pieces),
                       vertices=int(sum(len(v) for v in pieces)))
            row.update(volume_measures(obj_id, pieces, rng))
            row.update(cavity_measures(obj_id, pieces))
            if args.drake:
                row.update(rest_in_drake(obj_id, pieces, Path(tmp) / obj_id / name))
            rows.append(row)
    print_table(rows)
    return 0


def print_table(rows) -> None:
    cols = [("object", "{}", 10), ("backend", "{}", 15), ("time_s", "{:.1f}", 7),
            ("pieces", "{}", 6), ("vertices", "{}", 8), ("vol", "{:.3f}", 6),
            ("cover", "{:.3f}", 6), ("excess", "{:.3f}", 6), ("cavity", "{:.2f}", 6),
            ("mid", "{}", 5), ("drift_mm", "{:.2f}", 8), ("tilt_deg", "{:.2f}", 8),
            ("sim_s", "{:.2f}", 6), ("skipped", "{}", 8)]
    print(" ".join(f"{c:>{w}s}" for c, _, w in cols))
    for r in rows:
        cells = []
        for c, fmt, w in cols:
            v = r.get(c)
            cells.append(f"{'-' if v is None else fmt.format(v):>{w}s}")
        print(" ".join(cells))


if __name__ == "__main__":
    sys.exit(main())
