"""Pose and part detection of the perception stage on renders of the object library.

The paper's Table (section VI-C-1): pose detection 100 % and part detection 84.56 % (S_GRASP_noisy)
/ 82.14 % (S_ROBOT), over upright and sideways poses only ("we do not consider the upside-down
pose for these tests"). A view is a success for the pose when the discrete pose matches, and for
the parts when the set of detected parts equals the object's ground-truth set ("a success if all
detected object parts match the ground truth").

Every object of the library is placed alone at the table's centre in every pose that suits it, at
four yaws (0°, 90°, 180°, 270°), and seen by three cameras around the table (`CAMERAS`). Depth
comes from the Drake station (`tg_drake.station`, RenderEngineVtk: one station holds all objects,
those not on show are parked out of the cameras' range) or, with ``--renderer open3d``, from Open3D
ray casting of the library meshes on a table plane. `evaluate` takes any iterable of `View`
(depth image, intrinsics, X_WC, ground truth), so other renders plug in the same way.

    .venv/bin/python tools/eval_perception.py                    # station renders → docs/results/
    .venv/bin/python tools/eval_perception.py --renderer open3d --out /tmp/perception
    .venv/bin/python tools/eval_perception.py --only cup_01 --only hammer_02

Writes ``perception.json`` (pose_accuracy, part_accuracy, per_category, n_views, ...) and
``perception.md`` beside it.
"""

from __future__ import annotations

import argparse
import collections
import json
import statistics
import sys
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tg_drake.errors import PerceptionError
from tg_drake.evaluation.paper import PAPER
from tg_drake.evaluation.suite import DATASETS
from tg_drake.perception.config import PerceptionConfig
from tg_drake.perception.geometry import Intrinsics, inverse, make_transform, transform
from tg_drake.perception.pipeline import describe_object
from tg_drake.perception.segmentation import segment_depth

# Cameras around the table: name → (azimuth from the table's +x [deg], elevation [deg], distance
# from the point 5 cm above the table centre [m]). The front camera faces the robot across the
# table, like the station's default camera; the side ones look from 50° left and right.
CAMERAS = {"front": (0.0, 55.0, 0.85), "left": (50.0, 40.0, 0.85), "right": (-50.0, 45.0, 0.85)}
YAWS_DEG = (0.0, 90.0, 180.0, 270.0)
WIDTH, HEIGHT, FOV_Y_DEG = 640, 480, 45.0  # the station's default camera


@dataclass
class Truth:
    object_id: str
    category: str
    pose: str
    parts: tuple[str, ...]
    yaw_deg: float
    camera: str


@dataclass
class View:
    """One evaluation input: a depth frame of one object on the table and the truth about it."""

    depth: np.ndarray  # (H, W) float32 [m]; +inf / 0: no return
    intrinsics: Intrinsics
    X_WC: np.ndarray  # 4×4 camera pose
    truth: Truth


def _rz(yaw_deg: float) -> np.ndarray:
    a = np.radians(yaw_deg)
    return np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0, 0, 1.0]])


def camera_position_T(azimuth: float, elevation: float, distance: float) -> np.ndarray:
    a, e = np.radians(azimuth), np.radians(elevation)
    return np.array([0.0, 0.0, 0.05]) + distance * np.array(
        [np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def _cases(objects) -> Iterator[tuple]:
    for obj in objects:
        for pose, resting in obj.poses.items():
            for yaw in YAWS_DEG:
                yield obj, pose, yaw, make_transform(_rz(yaw), [0.0, 0.0, 0.0]) @ resting.X_TO


def station_views(objects) -> Iterator[View]:
    """Views rendered by the Drake station (one station, every object in it)."""
    from pydrake.common.schema import Transform
    from pydrake.math import RigidTransform
    from pydrake.systems.sensors import CameraConfig

    from tg_drake.scenario import ObjectPlacement, Scenario, look_at
    from tg_drake.station import make_station

    objects = list(objects)
    scenario = Scenario()
    scenario.objects = [ObjectPlacement(id=obj.id, pose=next(iter(obj.poses))) for obj in objects]
    X_WT = scenario.X_WT.GetDeterministicValue().GetAsMatrix4()
    scenario.cameras = {}
    for name, (az, el, d) in CAMERAS.items():
        config = CameraConfig(width=WIDTH, height=HEIGHT, name=name,
                              renderer_class="RenderEngineVtk", rgb=False, depth=True,
                              label=False)
        config.focal = CameraConfig.FovDegrees(y=FOV_Y_DEG)
        config.z_far = config.clipping_far = 3.0
        p_WC = transform(X_WT, camera_position_T(az, el, d)[None])[0]
        config.X_PB = Transform(look_at(p_WC, X_WT[:3, 3] + [0.0, 0.0, 0.05]))
        scenario.cameras[name] = config
    diagram, station = make_station(scenario)
    context = diagram.CreateDefaultContext()
    plant = station.plant
    plant_context = plant.GetMyMutableContextFromRoot(context)
    bodies = {obj.id: station.object_body(obj.id) for obj in objects}
    park = {obj.id: RigidTransform([0.0, 20.0 + 1.0 * i, -20.0]) for i, obj in enumerate(objects)}
    for obj_id, body in bodies.items():
        plant.SetFreeBodyPose(plant_context, body, park[obj_id])
    intrinsics = {n: Intrinsics.from_camera_info(station.cameras[n].info) for n in CAMERAS}
    shown = None
    for obj, pose, yaw, X_TO in _cases(objects):
        if shown is not None and shown != obj.id:
            plant.SetFreeBodyPose(plant_context, bodies[shown], park[shown])
        plant.SetFreeBodyPose(plant_context, bodies[obj.id], RigidTransform(X_WT @ X_TO))
        shown = obj.id
        for name in CAMERAS:
            depth = diagram.GetOutputPort(f"{name}.depth_image").Eval(context).data[:, :, 0]
            X_WC = diagram.GetOutputPort(f"{name}.camera_pose").Eval(context).GetAsMatrix4()
            yield View(np.array(depth), intrinsics[name], X_WC,
                       Truth(obj.id, obj.category, pose, obj.parts, yaw, name))


def open3d_views(objects) -> Iterator[View]:
    """Views ray cast with Open3D from the library meshes on a 0.8 × 1.2 m table top."""
    import open3d as o3d

    from tg_drake.objects import mesh
    from tg_drake.perception import synthetic as S

    K = Intrinsics.from_fov(WIDTH, HEIGHT, np.radians(FOV_Y_DEG))
    table = S.table_mesh((0.8, 1.2))
    for obj, pose, yaw, X_TO in _cases(objects):
        V, F, _ = mesh(obj)
        m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(np.array(V)),
                                      o3d.utility.Vector3iVector(np.array(F, dtype=np.int32)))
        placed = S.placed(m, X_TO)
        for name, (az, el, d) in CAMERAS.items():
            X_WC = S.look_at(camera_position_T(az, el, d), np.array([0.0, 0.0, 0.05]))
            yield View(S.render_depth([table, placed], K, X_WC), K, X_WC,
                       Truth(obj.id, obj.category, pose, obj.parts, yaw, name))


def add_depth_noise(depth: np.ndarray, sigma_1m: float, rng: np.random.Generator) -> np.ndarray:
    """Gaussian depth noise growing with the square of the range, as a structured-light camera's
    (Khoshelham & Elberink 2012: about 1.5 mm at 1 m): σ(z) = sigma_1m · (z / 1 m)²."""
    if sigma_1m <= 0:
        return depth
    valid = np.isfinite(depth) & (depth > 0)
    noisy = depth.astype(np.float64).copy()
    noisy[valid] += rng.normal(0.0, 1.0, int(valid.sum())) * sigma_1m * noisy[valid] ** 2
    return noisy.astype(np.float32)


def _describe(view: View, depth: np.ndarray, cfg: PerceptionConfig, seg_ms: list, obj_ms: list
              ) -> dict:
    t = view.truth
    rec = {"object": t.object_id, "category": t.category, "pose": t.pose,
           "yaw_deg": t.yaw_deg, "camera": t.camera, "parts": sorted(t.parts)}
    try:
        t0 = time.perf_counter()
        seg = segment_depth(depth, view.intrinsics, view.X_WC, cfg.segmentation)
        seg_ms.append(1e3 * (time.perf_counter() - t0))
        if len(seg.objects_T) != 1:
            raise PerceptionError(f"{len(seg.objects_T)} objects found, expected 1")
        p_TC = transform(inverse(seg.X_WT), view.X_WC[:3, 3][None])[0]
        t0 = time.perf_counter()
        o = describe_object(seg.objects_T[0], seg.X_WT, p_TC, cfg)
        obj_ms.append(1e3 * (time.perf_counter() - t0))
        rec.update(found_pose=o.pose, found_parts=sorted(o.part_probabilities),
                   pose_likelihood={k: round(v, 3) for k, v in o.pose_likelihood.items()},
                   part_probabilities={k: round(v, 3) for k, v in o.part_probabilities.items()})
    except PerceptionError as e:
        rec.update(found_pose=None, found_parts=None, error=str(e))
    rec["pose_ok"] = rec["found_pose"] == t.pose
    rec["parts_ok"] = rec["found_parts"] == sorted(t.parts)
    return rec


def evaluate(views: Iterable[View], cfg: PerceptionConfig | None = None,
             noise_levels: tuple[float, ...] = (0.0,), seed: int = 0, progress: bool = True
             ) -> dict[float, tuple[dict, list[dict]]]:
    """Pose and part accuracy over views, for each depth-noise level (σ at 1 m [m]); returns
    level → (summary, one record per view)."""
    cfg = cfg or PerceptionConfig()
    rng = np.random.default_rng(seed)
    runs = {level: ([], [], []) for level in noise_levels}  # records, seg_ms, obj_ms
    for i, view in enumerate(views):
        for level, (records, seg_ms, obj_ms) in runs.items():
            depth = add_depth_noise(view.depth, level, rng)
            records.append(_describe(view, depth, cfg, seg_ms, obj_ms))
        if progress and (i + 1) % 50 == 0:
            print(f"  {i + 1} views", file=sys.stderr, flush=True)
    return {level: (summarise(*run), run[0]) for level, run in runs.items()}


def _rates(recs: list[dict]) -> dict:
    n = len(recs)
    return {"n_views": n,
            "pose_accuracy": sum(r["pose_ok"] for r in recs) / n if n else None,
            "part_accuracy": sum(r["parts_ok"] for r in recs) / n if n else None}


def failures(records: list[dict], n: int = 12) -> list[dict]:
    """The most frequent failures: (object, true pose, found pose, found parts) with counts."""
    counts = collections.Counter(
        (r["object"], r["pose"], r["found_pose"], ", ".join(r["found_parts"] or [])
         if r["found_parts"] is not None else r.get("error", ""))
        for r in records if not (r["pose_ok"] and r["parts_ok"]))
    return [{"object": o, "pose": p, "found_pose": fp, "found_parts": fpa, "views": c}
            for (o, p, fp, fpa), c in counts.most_common(n)]


def summarise(records: list[dict], seg_ms: list[float], obj_ms: list[float]) -> dict:
    by_cat = collections.defaultdict(list)
    by_pose = collections.defaultdict(list)
    for r in records:
        by_cat[r["category"]].append(r)
        by_pose[r["pose"]].append(r)
    paper_like = [r for r in records if r["pose"] in ("upright", "sideways")]
    summary = _rates(records)
    summary.update(
        per_category={c: _rates(rs) for c, rs in sorted(by_cat.items())},
        per_pose={p: _rates(rs) for p, rs in sorted(by_pose.items())},
        upright_and_sideways=_rates(paper_like),
        n_objects=len({r["object"] for r in records}),
        n_errors=sum("error" in r for r in records),
        cameras={n: {"azimuth_deg": a, "elevation_deg": e, "distance_m": d}
                 for n, (a, e, d) in CAMERAS.items()},
        yaws_deg=list(YAWS_DEG),
        failures=failures(records),
        timing_ms={"segmentation_median": statistics.median(seg_ms) if seg_ms else None,
                   "object_median": statistics.median(obj_ms) if obj_ms else None},
        paper={d: PAPER["detection"][d] for d in ("grasp", "robot")})
    return summary


def markdown(summary: dict, command: str, renderer: str) -> str:
    pct = lambda x: "–" if x is None else f"{100 * x:.1f}"  # noqa: E731
    us = summary["upright_and_sideways"]
    lines = [
        "# Perception: pose and part detection",
        "",
        f"Regenerate: `{command}` (renderer: {renderer}).",
        "",
        f"{summary['n_objects']} library objects, every suitable pose, yaws "
        f"{', '.join(f'{y:g}°' for y in summary['yaws_deg'])}, cameras "
        + ", ".join(f"{n} (az {c['azimuth_deg']:g}°, el {c['elevation_deg']:g}°, "
                    f"{c['distance_m']:g} m)" for n, c in summary["cameras"].items())
        + f": {summary['n_views']} views. Parts: a success when the set of detected parts equals "
        "the object's (the paper's measure).",
        "",
        "| setting | views | pose [%] | parts [%] |",
        "|---|---:|---:|---:|",
        *(f"| paper, {DATASETS[d]} (upright, sideways) | – | "
          f"{PAPER['detection'][d]['pose_accuracy']:g} | "
          f"{PAPER['detection'][d]['part_accuracy']:g} |" for d in ("grasp", "robot")),
        f"| ours, upright and sideways | {us['n_views']} | {pct(us['pose_accuracy'])} | "
        f"{pct(us['part_accuracy'])} |",
        f"| ours, all suitable poses (with upside-down) | {summary['n_views']} | "
        f"{pct(summary['pose_accuracy'])} | {pct(summary['part_accuracy'])} |",
    ]
    for level, r in summary.get("depth_noise", {}).items():
        u = r["upright_and_sideways"]
        lines += [
            f"| ours, depth noise σ = {1e3 * float(level):g} mm at 1 m, upright and sideways | "
            f"{u['n_views']} | {pct(u['pose_accuracy'])} | {pct(u['part_accuracy'])} |",
            f"| ours, depth noise σ = {1e3 * float(level):g} mm at 1 m, all poses | "
            f"{r['n_views']} | {pct(r['pose_accuracy'])} | {pct(r['part_accuracy'])} |"]
    lines += [
        "",
        "| category | views | pose [%] | parts [%] |",
        "|---|---:|---:|---:|",
    ]
    for c, r in summary["per_category"].items():
        lines.append(f"| {c} | {r['n_views']} | {pct(r['pose_accuracy'])} | "
                     f"{pct(r['part_accuracy'])} |")
    lines += ["", "| true pose | views | pose [%] | parts [%] |", "|---|---:|---:|---:|"]
    for p, r in summary["per_pose"].items():
        lines.append(f"| {p} | {r['n_views']} | {pct(r['pose_accuracy'])} | "
                     f"{pct(r['part_accuracy'])} |")
    lines += ["", "Most frequent failures (of 12 views per object and pose):", "",
              "| object | true pose | found pose | found parts | views |", "|---|---|---|---|---:|"]
    for f in summary.get("failures", []):
        lines.append(f"| {f['object']} | {f['pose']} | {f['found_pose']} | {f['found_parts']} | "
                     f"{f['views']} |")
    t, ms = summary["timing_ms"], PAPER["detection_ms"]
    lines += ["", "Median time per view during this run: segmentation "
              f"{t['segmentation_median']:.1f} ms (640×480 frame), one object's completion + "
              "pose + parts "
              f"{t['object_median']:.1f} ms (paper: {ms['completion']:g} + {ms['pose']:g} = "
              f"{ms['completion'] + ms['pose']:.2f} ms). The speed figures "
              "proper come from `tg-drake bench --only perception_ms --only segmentation_ms`.", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--renderer", choices=("station", "open3d"), default="station")
    parser.add_argument("--out", type=Path, default=Path("docs/results"))
    parser.add_argument("--only", action="append", help="only this object id (repeatable)")
    parser.add_argument("--records", type=Path, help="also write one JSON line per view here")
    parser.add_argument("--depth-noise", type=float, action="append",
                        help="also evaluate with Gaussian depth noise of this σ at 1 m [m], "
                             "growing with range² (repeatable; e.g. 0.0015, a Kinect's)")
    args = parser.parse_args(argv)
    from tg_drake.objects import get_object, load_library

    objects = ([get_object(i) for i in args.only] if args.only
               else list(load_library().values()))
    views = station_views(objects) if args.renderer == "station" else open3d_views(objects)
    levels = (0.0, *(args.depth_noise or ()))
    runs = evaluate(views, noise_levels=levels)
    summary, records = runs[0.0]
    summary["renderer"] = args.renderer
    summary["depth_noise"] = {f"{level:g}": {k: runs[level][0][k] for k in (
        "n_views", "pose_accuracy", "part_accuracy", "upright_and_sideways", "per_category")}
        for level in levels[1:]}
    command = "python tools/eval_perception.py" + "".join(
        f" {a}" for a in (argv if argv is not None else sys.argv[1:]))
    summary["command"] = command
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "perception.json").write_text(json.dumps(summary, indent=1) + "\n")
    (args.out / "perception.md").write_text(markdown(summary, command, args.renderer))
    if args.records:
        args.records.write_text("".join(json.dumps({"depth_noise": level, **r}) + "\n"
                                        for level in levels for r in runs[level][1]))
    us = summary["upright_and_sideways"]
    print(f"{summary['n_views']} views: pose {summary['pose_accuracy']:.3f}, parts "
          f"{summary['part_accuracy']:.3f}; upright+sideways: pose {us['pose_accuracy']:.3f}, "
          f"parts {us['part_accuracy']:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
