"""`tg-drake run SCENARIO [--out DIR] [--meshcat]`: the whole pipeline in simulation.

perception → kernel prior → logic → DGI scoring → planning → execution, in one diagram
(`tg_drake.diagram.add_pipeline`). Prints a one-screen summary; writes `result.json` (keys in
DESIGN.md) and pictures: the camera view, the part-coloured perceived cloud, the chosen grasp.

A run never ends in a traceback for a failure of the task itself: an object out of reach, nothing
perceived at the target, every grasp ruled out by the logic, a diverging simulation — each is an
outcome with status "failed" and its reason.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from tg_drake.logic.theory import VARIANTS as THEORY_VARIANTS
from tg_drake.errors import (GraspingError, KernelError, PerceptionError, PlanningError,
                             RuleError, SimulationError, TgDrakeError)

HELP = "run the whole pipeline on a scenario: perceive, reason, score, plan, grasp, place"

OUTCOME_STATUSES = ("placed", "lifted", "grasped", "failed")
FAILURE_REASONS = ("unreachable", "perception", "logic", "slipped", "missed", "collision",
                   "simulation", "timeout")


# The failure reason a stage's error stands for.
REASON_OF_ERROR = ((PerceptionError, "perception"), (KernelError, "perception"),
                   (RuleError, "logic"), (GraspingError, "logic"),
                   (PlanningError, "unreachable"), (SimulationError, "simulation"))


def reason_of(error: TgDrakeError) -> str:
    return next((r for cls, r in REASON_OF_ERROR if isinstance(error, cls)), "simulation")


@dataclass
class Outcome:
    status: str  # one of OUTCOME_STATUSES
    reason: str = ""  # for "failed" (one of FAILURE_REASONS) or partial success; "" when placed
    detail: str = ""  # a human-readable explanation
    reachable_parts: list = field(default_factory=list)
    unreachable_parts: list = field(default_factory=list)
    requeries: int = 0


def add_arguments(parser) -> None:
    parser.add_argument("scenario", type=Path, help="scenario YAML file")
    parser.add_argument("--name", help="a named entry of a multi-scenario file")
    parser.add_argument("--out", type=Path, default=None,
                        help="output folder (default: out/<scenario name>)")
    parser.add_argument("--meshcat", action="store_true",
                        help="serve Drake's Meshcat viewer on localhost and replay the run there")
    parser.add_argument("--no-images", action="store_true", help="skip the PNG pictures")
    parser.add_argument("--theory", choices=THEORY_VARIANTS, default=None,
                        help="both models of this theory variant, overriding the scenario's "
                        "pipeline.logic.category and pipeline.logic.grasp")


def default_out(args) -> Path:
    """The output folder when --out is not given: out/<scenario name>."""
    return Path("out") / (args.name or args.scenario.stem)


def _distribution(d: dict) -> dict:
    return {k: round(float(v), 6) for k, v in sorted(d.items(), key=lambda kv: -kv[1])}


def _xyz_rpy(X) -> dict:
    from pydrake.math import RigidTransform, RollPitchYaw
    X = X if isinstance(X, RigidTransform) else RigidTransform(np.asarray(X))
    return {"xyz": [round(float(v), 5) for v in X.translation()],
            "rpy": [round(float(v), 5) for v in RollPitchYaw(X.rotation()).vector()]}


def run_scenario(scenario, *, scenario_path: str = "", meshcat=None, images_dir: Path | None = None
                 ) -> dict:
    """Runs one scenario end to end and returns the result dictionary (result.json)."""
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder

    from tg_drake.diagram import add_pipeline

    timings: dict[str, float] = {}
    t_start = time.perf_counter()
    builder = DiagramBuilder()
    pipeline = add_pipeline(builder, scenario=scenario)
    station = pipeline.station
    visualizer = None
    if meshcat is not None:
        from pydrake.geometry import MeshcatVisualizer
        visualizer = MeshcatVisualizer.AddToBuilder(builder, station.scene_graph, meshcat)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    timings["build"] = time.perf_counter() - t_start

    result: dict = {"scenario": scenario_path, "task_given": scenario.task.task or None,
                    "perception": {"n_objects": 0, "target": None}}

    # The stages at t = 0, each timed on its own (their values stay cached for the planner).
    def timed(name, port):
        t0 = time.perf_counter()
        value = port.Eval(port.get_system().GetMyContextFromRoot(context))
        timings[name] = time.perf_counter() - t0
        return value

    # The camera perception looks through (the first camera for ground-truth perception).
    camera = getattr(pipeline.config.perception, "camera", next(iter(station.cameras), ""))
    outcome = None
    try:
        if not pipeline.config.ground_truth_perception:
            timed("render", station.outputs[f"{camera}.depth_image"])
        scene = timed("perception", pipeline.ports["scene_description"])
        result["perception"] = _perception_json(scene)
        if not scene.objects:
            outcome = Outcome("failed", "perception", "perception found no object on the table")
        elif scene.target is None:
            outcome = Outcome("failed", "perception",
                              "perception found no object at the target's position")
        if outcome is None:
            prior = timed("kernel_prior", pipeline.ports["category_prior"])
            result["category_prior"] = _distribution(prior.distributions[scene.target].as_dict())
            semantics = timed("logic", pipeline.ports["grasp_semantics"])
            result.update(_semantics_json(semantics))
            result["grasp_probability"] = round(float(semantics.grasp_probability), 6)
            if not semantics.part or max(semantics.part.values()) <= 0:
                outcome = Outcome("failed", "logic", "the logic ruled every grasp out "
                                  f"(task {scenario.task.task or 'inferred'})")
            elif semantics.grasp_probability < pipeline.config.min_grasp_probability:
                outcome = Outcome(
                    "failed", "logic", "the logic rules grasping out: P(some part is grasped) = "
                    f"{semantics.grasp_probability:.3f} < {pipeline.config.min_grasp_probability}"
                    f" (task {scenario.task.task or 'inferred'})")
        if outcome is None:
            ranked = timed("dgi_scoring", pipeline.ports["ranked_grasps"])
            result["n_hypotheses"] = int(len(ranked.score))
            if len(ranked.score) == 0 or not np.any(ranked.score > 0):
                outcome = Outcome("failed", "logic", "no pre-grasp hypothesis with a non-zero score")
    except TgDrakeError as e:
        outcome = Outcome("failed", reason_of(e), str(e))

    if images_dir is not None and "perception" in result:
        _write_images(images_dir, station, context, pipeline, camera)

    if outcome is None:
        outcome = _execute(simulator, pipeline, scenario, result, timings, visualizer)
    result["outcome"] = asdict(outcome)
    X_WG = result.pop("grasp_X_WG", None)
    if images_dir is not None and X_WG is not None:
        save_grasp_png(scene.objects[scene.target], X_WG, images_dir / "grasp.png",
                       title=_grasp_title(result))
    timings["total"] = time.perf_counter() - t_start
    result["timings"] = {k: round(v, 4) for k, v in timings.items()}
    return result


def _execute(simulator, pipeline, scenario, result, timings, visualizer) -> Outcome:
    """Simulates planning and execution; reads off what physically happened."""
    from tg_drake.objects import box_centre
    from tg_drake.outcome import hand_contact, placed, touches_table

    context = simulator.get_mutable_context()
    station = pipeline.station
    plant = station.plant
    plant_context = plant.GetMyMutableContextFromRoot(context)
    status_port = pipeline.ports["plan_status"]
    planner_context = pipeline.planner.GetMyContextFromRoot(context)
    target_name = scenario.target_placement().instance_name
    body = station.object_body(target_name)
    wsg = station.instances["wsg"]
    if visualizer is not None:
        visualizer.StartRecording()
    t_sim = time.perf_counter()
    try:
        simulator.Initialize()
        # Planning: events every period until the planner executes or gives up.
        deadline = pipeline.config.planning_start + 2.0
        status = status_port.Eval(planner_context)
        while status.status == "planning" and context.get_time() < deadline:
            simulator.AdvanceTo(context.get_time() + 0.05)
            status = status_port.Eval(planner_context)
        timings["planning"] = status.planning_time
        result["planning"] = {"status": status.status, "part": status.part,
                              "unreachable_parts": list(status.unreachable_parts),
                              "requeries": status.requeries, "reason": status.reason}
        if status.status != "executing":
            reason = "unreachable" if status.status == "unreachable" else "timeout"
            return Outcome("failed", reason, status.reason or "planning did not finish",
                           unreachable_parts=list(status.unreachable_parts),
                           requeries=status.requeries)
        ranked = pipeline.ports["ranked_grasps"].Eval(
            pipeline.scoring.GetMyContextFromRoot(context))
        i = status.candidate
        result["grasp_X_WG"] = np.asarray(status.X_WG, float)  # for the picture; not in JSON
        result["grasp"] = {**_xyz_rpy(status.X_WG), "part": status.part,
                           "p_part": float(ranked.p_part[i]) if i is not None else None,
                           "p_local": float(ranked.p_local[i]) if i is not None else None,
                           "score": float(ranked.score[i]) if i is not None else None}
        plan = status.plan
        t0 = status.t_plan
        X_WO_picked = body.EvalPoseInWorld(plant_context)
        common = dict(unreachable_parts=list(status.unreachable_parts),
                      requeries=status.requeries)

        simulator.AdvanceTo(t0 + plan.t_grasp_closed)
        grasp = hand_contact(plant, plant_context, object_body=body, wsg_instance=wsg)
        if not grasp.held:
            return Outcome("failed", "missed", f"fingers closed to {grasp.opening * 1000:.0f} mm "
                           f"without holding the object (left pad {grasp.left}, right pad "
                           f"{grasp.right})", **common)
        G = plant.GetFrameByName("body", wsg)
        z_G_grasped = G.CalcPoseInWorld(plant_context).translation()[2]
        z_O_grasped = body.EvalPoseInWorld(plant_context).translation()[2]
        simulator.AdvanceTo(t0 + plan.t_lift_done)
        lift = hand_contact(plant, plant_context, object_body=body, wsg_instance=wsg)
        rise = body.EvalPoseInWorld(plant_context).translation()[2] - z_O_grasped
        gripper_rise = G.CalcPoseInWorld(plant_context).translation()[2] - z_G_grasped
        if not lift.held or rise < 0.5 * gripper_rise:
            return Outcome("grasped", "slipped", f"the object rose {rise * 100:.1f} cm while the "
                           f"gripper rose {gripper_rise * 100:.1f} cm", **common)
        simulator.AdvanceTo(t0 + plan.duration)
        X_WO_now = body.EvalPoseInWorld(plant_context)
        if not np.all(np.isfinite(X_WO_now.GetAsMatrix4())):
            return Outcome("failed", "simulation", "the simulation diverged", **common)
        # Let go: the gripper has opened and the table carries the object (a pad may still
        # brush it after opening).
        release = hand_contact(plant, plant_context, object_body=body, wsg_instance=wsg)
        on_table = touches_table(plant, plant_context, object_body=body,
                                 table_instance=station.instances["table"])
        ok, detail = placed(X_WO_picked, X_WO_now, plan.X_WO_place[:2, 3],
                            released=on_table and not release.held,
                            p_OC=box_centre(scenario.target_placement().id))
        if ok:
            return Outcome("placed", "", detail, **common)
        return Outcome("lifted", "slipped", detail, **common)
    except TgDrakeError as e:  # a stage failed while the planner re-queried it
        return Outcome("failed", reason_of(e), str(e))
    except RuntimeError as e:
        return Outcome("failed", "simulation", f"the simulation failed: {e}")
    finally:
        timings["simulation"] = time.perf_counter() - t_sim
        timings["simulated_time"] = context.get_time()
        if visualizer is not None:
            visualizer.StopRecording()
            visualizer.PublishRecording()


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


def _write_images(folder: Path, station, context, pipeline, camera) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    if camera in station.cameras:
        rgb = station.outputs[f"{camera}.rgb_image"].Eval(
            station.cameras[camera].sensor.GetMyContextFromRoot(context))
        plt.imsave(folder / "camera.png", np.array(rgb.data[:, :, :3]))
    scene = pipeline.ports["scene_description"].Eval(
        pipeline.target.GetMyContextFromRoot(context))
    from tg_drake.perception.plot import save_scene_png
    save_scene_png(scene.objects, folder / "parts.png")


# The open WSG's finger pads in G (models/wsg_50: 0.012 × 0.082 × 0.02 m boxes centred 0.055 m
# along +y_G, inner faces at x = ±0.055) and its body box, for the grasp picture.
_PADS_G = [((-0.061, 0.055, 0.0), (0.012, 0.082, 0.02)), ((0.061, 0.055, 0.0), (0.012, 0.082, 0.02))]
_BODY_G = ((0.0, -0.0213, 0.0), (0.146, 0.0725, 0.05))


def _box_edges(X_WG: np.ndarray, centre, size) -> list[np.ndarray]:
    """The 12 edges of a box given in G, as (2, 3) world segments."""
    c, h = np.asarray(centre), np.asarray(size) / 2
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h + c
    corners_W = corners @ X_WG[:3, :3].T + X_WG[:3, 3]
    return [corners_W[[i, j]] for i in range(8) for j in range(i + 1, 8)
            if np.sum(np.abs(np.sign(corners[i] - c) - np.sign(corners[j] - c))) == 2]


def save_grasp_png(obj, X_WG: np.ndarray, path: Path, *, title: str = "") -> Path:
    """The target's part-coloured cloud in the world with the chosen gripper pose drawn as boxes
    (finger pads black, body grey) and its approach direction."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from tg_drake.types import PART_COLORS

    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d")
    idx = np.random.default_rng(0).permutation(len(obj.p_W))[:5000]
    ax.scatter(*obj.p_W[idx].T, c=np.asarray(PART_COLORS)[obj.labels[idx]], s=2,
               depthshade=False, linewidths=0)
    for centre, size in _PADS_G:
        for e in _box_edges(X_WG, centre, size):
            ax.plot(*e.T, color="black", linewidth=1.2)
    for e in _box_edges(X_WG, *_BODY_G):
        ax.plot(*e.T, color="0.5", linewidth=0.8)
    grasp_point = X_WG[:3, 3] + 0.055 * X_WG[:3, 1]
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
    return (f"grasp on {g['part']}: score {g['score']:.2f} = P(part|task) {g['p_part']:.2f} × "
            f"P(grasp|shape) {g['p_local']:.2f}\noutcome: {result['outcome']['status']}")


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
    if "grasp" in result:
        g = result["grasp"]
        lines.append(f"grasp      part {g['part']}, xyz {g['xyz']}, score {g['score']:.3f} "
                     f"(P(part|task) {g['p_part']:.2f} × P(grasp|shape) {g['p_local']:.2f})")
    status = o["status"] + (f" ({o['reason']})" if o["reason"] else "")
    lines.append(f"outcome    {status}: {o['detail']}")
    if o["unreachable_parts"]:
        lines.append(f"closed loop: unreachable parts {o['unreachable_parts']} became "
                     f"collision evidence; {o['requeries']} re-quer{'y' if o['requeries'] == 1 else 'ies'}")
    t = result["timings"]
    lines.append("timings    " + ", ".join(f"{k} {v:.2f}s" for k, v in t.items()
                                          if k != "simulated_time"))
    return "\n".join(lines)


def main(args) -> int:
    from tg_drake.scenario import load_scenario

    scenario = load_scenario(args.scenario, scenario_name=args.name)
    if getattr(args, "theory", None):
        scenario.pipeline.logic.category = scenario.pipeline.logic.grasp = args.theory
    out = args.out or default_out(args)
    out.mkdir(parents=True, exist_ok=True)
    meshcat = None
    if args.meshcat:
        from pydrake.geometry import StartMeshcat
        meshcat = StartMeshcat()
        print(f"Meshcat: {meshcat.web_url()}")
    result = run_scenario(scenario, scenario_path=str(args.scenario), meshcat=meshcat,
                          images_dir=None if args.no_images else out)
    (out / "result.json").write_text(json.dumps(result, indent=2) + "\n")
    print(summary(result))
    print(f"wrote {out}/result.json")
    if meshcat is not None:
        print("the run is replayed in Meshcat; press Ctrl-C to stop serving")
        try:
            while True:
                time.sleep(1.0)
        except KeyboardInterrupt:
            pass
    return 0 if result["outcome"]["status"] != "failed" else 1


def bench_pipeline_rtf():
    """`pipeline_rtf`: simulated seconds per wall second of the default scenario's whole
    pick-and-place (render, perception, prior, logic, scoring, planning and the simulated execution;
    the one-off diagram build is not counted), median of 3 runs. The reference is the same run with
    Drake's explicit inverse-dynamics arm controller at a 2 ms step (one run); `speedup` = ours /
    reference (a rate: higher is better)."""
    from tg_drake.bench import Figure
    from tg_drake.scenario import InverseDynamicsDriver, ObjectPlacement, Scenario, TaskConfig

    def rate(explicit: bool) -> float:
        # scenarios/default.yaml: the paper's Fig. 1 cup, upright and empty, to be passed.
        scenario = Scenario(objects=[ObjectPlacement(id="cup_01", pose="upright")],
                            task=TaskConfig(task="pass", place_xy=[0.0, -0.3]))
        if explicit:
            scenario.model_drivers["iiwa"] = InverseDynamicsDriver()
            scenario.plant_config.time_step = 0.002
        t = run_scenario(scenario, scenario_path="default")["timings"]
        return t["simulated_time"] / (t["total"] - t["build"])

    ours = sorted(rate(False) for _ in range(3))[1]
    reference = rate(True)
    return Figure(median=ours, unit="simulated s / wall s",
                  reference="explicit InverseDynamicsController, 2 ms step, same scenario",
                  reference_median=reference, speedup=ours / reference)
