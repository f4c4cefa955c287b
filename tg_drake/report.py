"""What a run writes: result.json (assembled from port values), the one-screen summary and the
pictures (the camera view, the part-coloured perceived cloud, the chosen grasp, and for a task run
its key frames: task.png).

`write` puts result.json down first and the pictures after it: a picture that fails is a warning,
never a lost result.
"""

from __future__ import annotations

import json
import sys
import textwrap
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydrake.common.yaml import yaml_dump_typed, yaml_load
from pydrake.math import RigidTransform, RollPitchYaw

from tg_drake import robot
from tg_drake.errors import TgDrakeError
from tg_drake.grasping.scoring import scored_pose_match
from tg_drake.perception.plot import save_scene_png
from tg_drake.types import PART_COLORS


@dataclass
class Stages:
    """The stages' values at the start of the run (evaluated once after `Simulator.Initialize`),
    and what the pictures need."""

    scene: object = None  # SceneDescription
    prior: object = None  # CategoryDistribution
    semantics: object = None  # GraspSemantics
    ranked: object = None  # GraspCandidates
    scored: object = None  # GraspCandidates: the scoring stage's (the poses the DGI scored)
    rgb: np.ndarray | None = None  # (H, W, 3) camera image, when pictures are wanted
    warnings: list = field(default_factory=list)


def evaluate_stages(pipeline, context, timings: dict, *, rgb: bool = False) -> Stages:
    """Each stage's output once, timed on its own (`timings` gets render, perception,
    kernel_prior, logic, dgi_scoring [s] of wall time). A stage's error stops here: the
    supervisor meets it again and makes it the outcome."""
    stages = Stages()
    station = pipeline.station

    def timed(name, port):
        t0 = time.perf_counter()
        value = port.Eval(port.get_system().GetMyContextFromRoot(context))
        timings[name] = time.perf_counter() - t0
        return value

    # The camera perception looks through (the first camera for ground-truth perception).
    camera = getattr(pipeline.config.perception, "camera", next(iter(station.cameras), ""))
    try:
        if not pipeline.config.ground_truth_perception:
            timed("render", station.outputs[f"{camera}.depth_image"])
        stages.scene = timed("perception", pipeline.ports["scene_description"])
        # Perception ran in the initialization event (latched): its own wall time says what it
        # cost, the port read above only what reading the latched value did.
        status_port = pipeline.perception.GetOutputPort("perception_status")
        timings["perception"] = float(
            status_port.Eval(pipeline.perception.GetMyContextFromRoot(context)).wall_time)
        if rgb and camera in station.cameras:
            port = station.outputs[f"{camera}.rgb_image"]
            stages.rgb = np.array(port.Eval(port.get_system().GetMyContextFromRoot(context))
                                  .data[:, :, :3])
        if stages.scene.target is None:
            return stages
        stages.prior = timed("kernel_prior", pipeline.ports["category_prior"])
        stages.semantics = timed("logic", pipeline.ports["grasp_semantics"])
        if "scored_grasps" in pipeline.ports:
            stages.scored = timed("dgi_scoring", pipeline.ports["scored_grasps"])
            stages.ranked = timed("feasibility", pipeline.ports["ranked_grasps"])
        else:
            stages.ranked = timed("dgi_scoring", pipeline.ports["ranked_grasps"])
            stages.scored = stages.ranked
    except TgDrakeError:
        pass
    return stages


def final_stages(pipeline, context, stages: Stages, outcome) -> Stages:
    """The logic's and the scorer's values the planner used last: after re-queries the ones at
    the end of the run (the collision evidence changed them), else those of the start."""
    # After place-and-regrasp legs, the final leg's stages (perception looked again).
    if not (outcome.requeries or outcome.legs) or stages.semantics is None:
        return stages
    final = Stages(scene=stages.scene, prior=stages.prior, rgb=stages.rgb,
                   warnings=list(stages.warnings))
    ports = {"semantics": "grasp_semantics", "ranked": "ranked_grasps",
             "scored": "scored_grasps" if "scored_grasps" in pipeline.ports else "ranked_grasps"}
    try:
        for name, port_name in ports.items():
            port = pipeline.ports[port_name]
            setattr(final, name, port.Eval(port.get_system().GetMyContextFromRoot(context)))
    except TgDrakeError as e:
        final.semantics, final.ranked = stages.semantics, stages.ranked
        final.scored = stages.scored
        final.warnings.append(f"the stages after the re-queries could not be evaluated ({e}); "
                              "category, task, part and grasp scores are those of the start")
    return final


def result_of(*, scenario, scenario_path: str, stages: Stages, outcome, plan_status,
              timings: dict) -> dict:
    """The result.json dictionary (its keys: docs of `tg_drake.run`)."""
    result: dict = {"scenario": scenario_path, "task_given": scenario.task.task or None,
                    "perception": {"n_objects": 0, "target": None}}
    if stages.scene is not None:
        result["perception"] = _perception_json(stages.scene)
    if stages.prior is not None:
        result["category_prior"] = _distribution(
            stages.prior.distributions[stages.scene.target].as_dict())
    if stages.semantics is not None:
        result.update(_semantics_json(stages.semantics))
        result["collisions"] = list(outcome.unreachable_parts)  # the evidence last given
        result["grasp_probability"] = round(float(stages.semantics.grasp_probability), 6)
    if stages.ranked is not None:
        result["n_hypotheses"] = int(len(stages.ranked.score))
    if plan_status is not None and plan_status.attempt > 0:
        timings["planning"] = plan_status.planning_time
        result["planning"] = {"status": plan_status.status.value, "attempt": plan_status.attempt,
                              "part": plan_status.part,
                              "unreachable_parts": list(outcome.unreachable_parts),
                              "requeries": outcome.requeries, "reason": plan_status.reason,
                              "ik_solves": plan_status.ik_solves}
        if plan_status.plan is not None:
            i = plan_status.candidate
            ranked = stages.ranked
            known = ranked is not None and i is not None and i < len(ranked.score)
            result["grasp"] = {**_xyz_rpy(plan_status.X_WG), "part": plan_status.part,
                               "p_part": float(ranked.p_part[i]) if known else None,
                               "p_local": float(ranked.p_local[i]) if known else None,
                               "p_hold": (float(ranked.p_hold[i]) if known
                                          and ranked.p_hold is not None else None),
                               "score": float(ranked.score[i]) if known else None}
            if known and i < len(ranked.holds):  # the feasibility stage's contact mechanics
                result["grasp"]["hold"] = ranked.holds[i].summary()
            if stages.scored is not None:
                result["grasp"]["scored_pose"] = _scored_pose_json(plan_status.X_WG,
                                                                   stages.scored)
    result["outcome"] = outcome.as_dict()
    if outcome.task_outcome is not None:
        result["task_outcome"] = outcome.task_outcome.as_dict()
    if stages.warnings:
        result["warnings"] = list(stages.warnings)
    result["timings"] = {k: round(v, 4) for k, v in timings.items()}
    result["config"] = yaml_load(data=yaml_dump_typed(scenario))  # the full resolved scenario
    return result


def _scored_pose_json(X_WG, scored) -> dict:
    """Is the executed grasp pose one the DGI scored? (`scoring.scored_pose_match`, in mm and
    degrees; `same` is the check.)"""
    m = scored_pose_match(np.asarray(X_WG, float), scored)
    return {"same": m["same"], "index": m["index"],
            "offset_mm": None if m["offset_m"] is None else round(m["offset_m"] * 1000, 4),
            "angle_deg": None if m["angle_rad"] is None else round(np.degrees(m["angle_rad"]), 4),
            "p_local": m["p_local"]}


@dataclass
class Pictures:
    """What the pictures are drawn from."""

    stages: Stages
    X_WG: np.ndarray | None = None  # the chosen grasp pose, if a plan was made
    task_frames: object = None  # a task run with a plan: () → [(name, t [s], (H, W, 3) RGB)],
    # its key frames rendered from the camera (tg_drake.render.render_key_frames)


def write(folder: Path, result: dict, pictures: Pictures | None) -> list[str]:
    """Writes result.json, then the pictures; returns (and prints to stderr) the warnings of the
    pictures that could not be drawn."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "result.json").write_text(json.dumps(result, indent=2) + "\n")
    if pictures is None:
        return []
    warnings = []
    stages = pictures.stages
    seed = int(result.get("config", {}).get("random_seed", 0))  # which points are drawn
    jobs = []
    if stages.rgb is not None:
        jobs.append(("camera.png", lambda: _save_rgb(stages.rgb, folder / "camera.png")))
    if stages.scene is not None and stages.scene.objects:
        jobs.append(("parts.png", lambda: save_scene_png(stages.scene.objects,
                                                         folder / "parts.png", seed=seed)))
    if pictures.X_WG is not None and stages.scene is not None and "grasp" in result:
        target = stages.scene.objects[stages.scene.target]
        jobs.append(("grasp.png", lambda: save_grasp_png(target, pictures.X_WG,
                                                         folder / "grasp.png",
                                                         title=_grasp_title(result),
                                                         seed=seed)))
    if pictures.task_frames is not None:
        jobs.append(("task.png", lambda: save_task_png(pictures.task_frames(),
                                                       folder / "task.png",
                                                       title=_task_title(result))))
    for name, job in jobs:
        try:
            job()
        except Exception as e:  # a picture is never worth the result
            warnings.append(f"{name} not written: {type(e).__name__}: {e}")
            print(f"warning: {warnings[-1]}", file=sys.stderr)
    if warnings:  # the result is on disk already; now it says which pictures are missing
        result["warnings"] = list(result.get("warnings", [])) + warnings
        (folder / "result.json").write_text(json.dumps(result, indent=2) + "\n")
    return warnings


def save_task_png(frames, path: Path, *, title: str = "") -> Path:
    """The key frames of a task run side by side (grasp, the task's moment, the end), each titled
    with its name and simulated time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if not frames:
        raise ValueError("no key frames to draw")
    fig, axes = plt.subplots(1, len(frames), figsize=(4.2 * len(frames), 3.6), squeeze=False)
    for ax, (name, t, rgb) in zip(axes[0], frames, strict=True):
        ax.imshow(rgb)
        ax.set_title(f"{name}, t = {t:.1f} s", fontsize=10)
        ax.axis("off")
    if title:
        fig.suptitle(textwrap.shorten(title, 60 * len(frames)), fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _task_title(result: dict) -> str:
    """task.png's title: the task and its outcome in physics, with its measure."""
    t = result.get("task_outcome") or {}
    if not t:
        return f"task {result.get('task_given')}: no task check ({result['outcome']['status']})"
    measure = ", ".join(f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}"
                        for k, v in (t.get("measure") or {}).items())
    return (f"{t['task']}: {'success' if t['success'] else 'failed'}"
            + (f" ({measure})" if measure else "") + (f" — {t['detail']}" if t.get("detail")
                                                      else ""))


def _save_rgb(rgb: np.ndarray, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.imsave(path, rgb)


def _distribution(d: dict) -> dict:
    return {k: round(float(v), 6) for k, v in sorted(d.items(), key=lambda kv: -kv[1])}


def _xyz_rpy(X) -> dict:
    X = X if isinstance(X, RigidTransform) else RigidTransform(np.asarray(X))
    return {"xyz": [round(float(v), 5) for v in X.translation()],
            "rpy": [round(float(v), 5) for v in RollPitchYaw(X.rotation()).vector()]}


def _perception_json(scene) -> dict:
    if scene.target is None:
        return {"n_objects": len(scene.objects), "target": None}
    obj = scene.objects[scene.target]
    return {"n_objects": len(scene.objects), "target": scene.target, "pose": obj.pose,
            "pose_likelihood": _distribution(obj.pose_likelihood),
            "parts": _distribution(obj.part_probabilities),
            "extents": [round(float(v), 4) for v in obj.extents],
            "n_points": int(len(obj.p_W))}


def _semantics_json(semantics) -> dict:
    out = {"category": _distribution(semantics.category), "task": _distribution(semantics.task),
           "part": _distribution(semantics.part), "collisions": list(semantics.collisions)}
    out["explanations"] = {
        query: [{"answer": e.answer, "probability": round(float(e.probability), 6),
                 "reasons": [[r, round(float(w), 6)] for r, w in e.reasons[:5]]}
                for e in explanations]
        for query, explanations in semantics.explanations.items()}
    return out


# The open WSG's finger pads in G and its body box, for the grasp picture (tg_drake.robot).
_PADS_G = robot.wsg_pad_boxes()
_BODY_G = (robot.WSG_BODY_CENTRE_G, robot.WSG_BODY_SIZE)


def _box_edges(X_WG: np.ndarray, centre, size) -> list[np.ndarray]:
    """The 12 edges of a box given in G, as (2, 3) world segments."""
    c, h = np.asarray(centre), np.asarray(size) / 2
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h + c
    corners_W = corners @ X_WG[:3, :3].T + X_WG[:3, 3]
    return [corners_W[[i, j]] for i in range(8) for j in range(i + 1, 8)
            if np.sum(np.abs(np.sign(corners[i] - c) - np.sign(corners[j] - c))) == 2]


def save_grasp_png(obj, X_WG: np.ndarray, path: Path, *, title: str = "", seed: int = 0) -> Path:
    """The target's part-coloured cloud in the world with the chosen gripper pose drawn as boxes
    (finger pads black, body grey) and its approach direction."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt


    X_WG = np.asarray(X_WG, float)
    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d")
    idx = np.random.default_rng(seed).permutation(len(obj.p_W))[:5000]
    ax.scatter(*obj.p_W[idx].T, c=np.asarray(PART_COLORS)[obj.labels[idx]], s=2,
               depthshade=False, linewidths=0)
    for centre, size in _PADS_G:
        for e in _box_edges(X_WG, centre, size):
            ax.plot(*e.T, color="black", linewidth=1.2)
    for e in _box_edges(X_WG, *_BODY_G):
        ax.plot(*e.T, color="0.5", linewidth=0.8)
    grasp_point = X_WG[:3, 3] + X_WG[:3, :3] @ robot.WSG_GRASP_POINT_G
    ax.quiver(*(grasp_point - 0.12 * X_WG[:3, 1]), *(0.08 * X_WG[:3, 1]), color="black")
    centre = obj.X_WO[:3, 3]
    half = max(0.5 * float(np.max(obj.extents)), 0.12)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(max(centre[2] - half, -0.01), centre[2] + 2 * half)
    ax.set_box_aspect((1, 1, 1.5))
    ax.set_xlabel("x_W [m]")
    ax.set_ylabel("y_W [m]")
    ax.set_zlabel("z_W [m]")
    ax.set_title(title, fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _grasp_title(result: dict) -> str:
    g = result["grasp"]
    if g["score"] is None:
        return f"grasp on {g['part']}\noutcome: {result['outcome']['status']}"
    return (f"grasp on {g['part']}: score {g['score']:.2f} = P(part|task) {g['p_part']:.2f} × "
            f"P(grasp|shape) {g['p_local']:.2f}{_hold_text(g, result)}\n"
            f"outcome: {result['outcome']['status']}")


def summary(result: dict) -> str:
    """The one-screen summary printed after a run."""
    def top(d, n=4):
        return ", ".join(f"{k} {v:.2f}" for k, v in list(d.items())[:n]) if d else "-"
    o = result["outcome"]
    lines = [f"scenario   {result['scenario']}"]
    if "perception" in result and result["perception"].get("pose"):
        p = result["perception"]
        lines.append(f"perceived  {p['n_objects']} object(s); target pose {p['pose']}, parts "
                     f"{top(p['parts'], 5)}")
    for key in ("category_prior", "category", "task", "part"):
        if key in result:
            lines.append(f"{key:<10} {top(result[key])}")
    if "grasp" in result and result["grasp"]["score"] is not None:
        g = result["grasp"]
        lines.append(f"grasp      part {g['part']}, xyz {g['xyz']}, score {g['score']:.3f} "
                     f"(P(part|task) {g['p_part']:.2f} × P(grasp|shape) {g['p_local']:.2f}"
                     f"{_hold_text(g, result)})")
    status = o["status"] + (f" ({o['reason']})" if o["reason"] else "")
    lines.append(f"outcome    {status}: {o['detail']}")
    if result.get("task_outcome"):
        task = result["task_outcome"]
        lines.append(f"task check {task['task']} {'succeeded' if task['success'] else 'failed'}: "
                     f"{task['detail']}")
    if o.get("legs"):  # place-and-regrasp legs (and retried grasps) before the final one
        lines.append(f"legs       {len(o['legs']) + 1}: " + "; ".join(
            (f"put down {leg['placed_pose']} at ({leg['xy'][0]:.3f}, {leg['xy'][1]:.3f}) m "
             f"by its {leg['part']}" if leg["ended"] == "placed" else
             f"{leg['ended']} by its {leg['part']}")
            + ", looked again" for leg in o["legs"]) + ", then the final leg")
    if o["unreachable_parts"]:
        lines.append(f"closed loop: unreachable parts {o['unreachable_parts']} became "
                     f"collision evidence; {o['requeries']} "
                     f"re-quer{'y' if o['requeries'] == 1 else 'ies'}")
    if o.get("reseats"):
        lines.append(f"release    the object still touched a pad once they opened at the place: "
                     f"re-seated {o['reseats']} time{'s' if o['reseats'] > 1 else ''} (closed on "
                     f"it and opened again) before the retreat")
    t = result["timings"]
    lines.append("timings    " + ", ".join(f"{k} {v:.2f}s" for k, v in t.items()
                                          if k not in ("simulated_time", "contents_asleep")))
    if t.get("contents_asleep"):
        lines.append(f"contents   asleep {t['contents_asleep']:.2f} of {t['simulated_time']:.2f} "
                     "simulated s (resting, nothing moving near them)")
    for w in result.get("warnings", []):
        lines.append(f"warning    {w}")
    return "\n".join(lines)


def _hold_text(g: dict, result: dict) -> str:
    """P(hold)'s place in the summary: a factor of the score when the feasibility stage ranks by
    it, else beside it (reported, not used)."""
    if g.get("p_hold") is None:
        return ""
    feasibility = result.get("config", {}).get("pipeline", {}).get("feasibility", {})
    if feasibility.get("rank_by_hold", False):
        return f" × P(hold) {g['p_hold']:.2f}"
    return f"; P(hold) {g['p_hold']:.2f}, not ranked by"
