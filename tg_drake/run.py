"""`tg-drake run SCENARIO [--out DIR] [--meshcat]`: the whole pipeline in simulation.

A straight builder script in the shape of Drake's hardware_sim: load the scenario → `add_pipeline`
(station, every stage and the `Supervisor`) → build → `ApplySimulatorConfig` → randomise the context
from `random_seed` → advance until the supervisor's outcome is final or `simulation_duration` has
passed (outcome failed, "timeout") → write `result.json`, then the pictures (`tg_drake.report`).

result.json holds: `scenario`, `task_given`, `perception` (`pose`, `parts`, ...), `category_prior`,
`category`, `task`, `part` (each a distribution: name → probability), `collisions` (the parts given
to the logic as collision evidence), `explanations`, `grasp_probability`, `n_hypotheses`,
`planning`, `grasp` (`xyz`, `rpy`, `part`, `p_part`, `p_local`, `score`, `scored_pose`: is the
executed pose one the DGI scored — `same`, `offset_mm`, `angle_deg`), `outcome` (`status`: one
of `OUTCOME_STATUSES`; `reason`: one of `FAILURE_REASONS` or ""; `detail`; the closed loop's
parts and re-queries), `timings` (seconds) and `config` (the full resolved scenario).

A run never ends in a traceback for a failure of the task itself: an object out of reach, nothing
perceived at the target, every grasp ruled out by the logic, a diverging simulation — each is an
outcome with status "failed" and its reason.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from pathlib import Path

import numpy as np

from tg_drake.errors import TgDrakeError
from tg_drake.types import THEORY_VARIANTS

# Start-up: `tg-drake --help` imports this module, so pydrake, the diagram, the report and the
# supervisor (all importing pydrake) are imported inside the functions that use them.

__all__ = ["run", "run_scenario"]

HELP = "run the whole pipeline on a scenario: perceive, reason, score, plan, grasp, place"


def add_arguments(parser) -> None:
    parser.add_argument("scenario", type=Path, help="scenario YAML file")
    parser.add_argument("--name", help="a named entry of a multi-scenario file")
    parser.add_argument("--out", type=Path, default=None,
                        help="output folder (default: out/<scenario name>)")
    parser.add_argument("--meshcat", action="store_true",
                        help="serve Drake's Meshcat viewer and replay the run there (on "
                        "--meshcat-host, localhost unless given)")
    parser.add_argument("--meshcat-host", default="localhost", metavar="HOST",
                        help="the interface Meshcat listens on (default: localhost, this machine "
                        "only; 0.0.0.0 or * for every interface, to view it from elsewhere)")
    parser.add_argument("--meshcat-port", type=int, default=None, metavar="PORT",
                        help="Meshcat's port (default: the first free one from 7000)")
    parser.add_argument("--no-images", action="store_true", help="skip the PNG pictures")
    parser.add_argument("--theory", choices=THEORY_VARIANTS, default=None,
                        help="both models of this theory variant, overriding the scenario's "
                        "pipeline.logic.category and pipeline.logic.grasp")


def default_out(args) -> Path:
    """The output folder when --out is not given: out/<scenario name>."""
    return Path("out") / (args.name or args.scenario.stem)


def run(scenario, *, scenario_path: str = "", meshcat=None, images: bool = False
        ) -> tuple[dict, object]:
    """Runs one scenario end to end: the result dictionary (result.json) and what the pictures
    are drawn from."""
    from pydrake.common import RandomGenerator
    from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
    from pydrake.systems.framework import DiagramBuilder, EventStatus

    from tg_drake.diagram import add_pipeline
    from tg_drake.render import PositionRecorder, key_times, render_key_frames
    from tg_drake.report import Pictures, Stages, evaluate_stages, final_stages, result_of
    from tg_drake.simulation.sleep import ContentsSleep, advance
    from tg_drake.systems.supervisor import Outcome, Reason, Status, outcome_of_error

    timings: dict[str, float] = {}
    t_start = time.perf_counter()
    # The station and every stage, the supervisor included; Meshcat if asked for.
    builder = DiagramBuilder()
    try:
        pipeline = add_pipeline(builder, scenario=scenario)
    except TgDrakeError as e:  # a field the build rejects (a camera's parent frame): the file too
        raise _in_file(e, scenario_path) from None
    visualizer = None
    if meshcat is not None:
        from pydrake.geometry import MeshcatVisualizer
        visualizer = MeshcatVisualizer.AddToBuilder(builder, pipeline.station.scene_graph,
                                                    meshcat)
    diagram = builder.Build()

    # The simulator as the scenario configures it; the context drawn from its seed.
    simulator = Simulator(diagram)
    ApplySimulatorConfig(scenario.simulator_config, simulator)
    context = simulator.get_mutable_context()
    diagram.SetRandomContext(context, RandomGenerator(scenario.random_seed))
    timings["build"] = time.perf_counter() - t_start

    # Stop as soon as the supervisor's outcome is final.
    outcome_port = pipeline.ports["outcome"]
    supervisor = pipeline.supervisor

    def outcome_now(root_context) -> Outcome:
        return outcome_port.Eval(supervisor.GetMyContextFromRoot(root_context))

    # With pictures, the plant's positions are kept for the task's key frames (task.png).
    recorder = PositionRecorder(pipeline.station.plant) if images else None

    def monitor(root):
        if recorder is not None:
            recorder.record(root)
        return (EventStatus.ReachedTermination(supervisor, "outcome final")
                if outcome_now(root).final else EventStatus.DidNothing())

    simulator.set_monitor(monitor)
    # Resting contents leave the physics while nothing near them moves (tg_drake.simulation.sleep).
    sleeper = ContentsSleep.for_station(pipeline.station, scenario.contents)

    if visualizer is not None:
        visualizer.StartRecording()
    stages = None
    error = None
    t_sim = time.perf_counter()
    try:
        simulator.Initialize()
        stages = evaluate_stages(pipeline, context, timings, rgb=images)
        t_sim = time.perf_counter()
        advance(simulator, scenario.simulation_duration, sleeper)
    except (TgDrakeError, RuntimeError) as e:  # a stage failed, or the simulation did
        error = e
    finally:
        timings["simulation"] = time.perf_counter() - t_sim
        timings["simulated_time"] = context.get_time()
        if sleeper is not None:
            timings["contents_asleep"] = round(sleeper.asleep_time(context.get_time()), 3)
        if visualizer is not None:
            visualizer.StopRecording()
            visualizer.PublishRecording()

    # The outcome: the supervisor's, or the error's, or a timeout.
    outcome = outcome_now(context)
    if error is not None:
        outcome = outcome_of_error(error, pending=outcome)
    elif not outcome.final:
        outcome = dataclasses.replace(
            outcome, status=Status.failed, reason=Reason.timeout,
            detail=f"not finished within simulation_duration = {scenario.simulation_duration} s "
            f"({outcome.detail})")
    plan_status = pipeline.ports["plan_status"].Eval(
        pipeline.planner.GetMyContextFromRoot(context))
    stages = final_stages(pipeline, context, stages, outcome) if stages else Stages()
    timings["total"] = time.perf_counter() - t_start
    result = result_of(scenario=scenario, scenario_path=scenario_path, stages=stages,
                       outcome=outcome, plan_status=plan_status, timings=timings)
    pictures = Pictures(stages, X_WG=plan_status.X_WG)
    if recorder is not None and recorder.times and scenario.task.task and \
            plan_status.plan is not None and plan_status.t_plan is not None:
        keys = key_times(plan_status.plan, plan_status.t_plan, context.get_time(),
                         scenario.task.task)
        camera = getattr(scenario.pipeline.perception, "camera", next(iter(scenario.cameras), ""))
        pictures.task_frames = functools.partial(render_key_frames, scenario, recorder, keys,
                                                 camera)
    return result, pictures


def _in_file(error: TgDrakeError, scenario_path: str) -> TgDrakeError:
    """`error` with the scenario file as its location, unless it names a file already."""
    if error.file is not None or not scenario_path:
        return error
    return type(error)(error.message, file=scenario_path, line=error.line, field=error.field)


def run_scenario(scenario, *, scenario_path: str = "", meshcat=None) -> dict:
    """Runs one scenario end to end and returns the result dictionary (result.json)."""
    return run(scenario, scenario_path=scenario_path, meshcat=meshcat)[0]


def start_meshcat(host: str = "localhost", port: int | None = None):
    """Drake's Meshcat listening on `host` (localhost: this machine only; Drake's own default
    serves every interface) and `port` (None: the first free one from 7000); TgDrakeError naming
    the option when the port is out of range or cannot be opened."""
    from pydrake.geometry import Meshcat, MeshcatParams

    if port is not None and not 1 <= port <= 65535:
        raise TgDrakeError(f"--meshcat-port must be a port number 1..65535, got {port}")
    params = MeshcatParams()
    params.host = host
    if port is not None:
        params.port = port
    try:
        return Meshcat(params)
    except RuntimeError as e:
        raise TgDrakeError(f"Meshcat cannot listen on --meshcat-host {host!r} --meshcat-port "
                           f"{port if port is not None else 'auto'}: {e}") from None


def look_at_the_table(meshcat, scenario) -> None:
    """Meshcat's camera 1.7 m from the scene, from the front right, looking between the robot's
    base and the table's centre (Meshcat's own default view shows the robot at a sixth of the
    window)."""
    p_WT = scenario.X_WT.GetDeterministicValue().translation()
    target = np.array([0.6 * p_WT[0], p_WT[1], p_WT[2] + 0.15])
    meshcat.SetCameraPose(camera_in_world=target + np.array([0.85, -1.25, 0.75]),
                          target_in_world=target)


def main(args) -> int:
    from tg_drake.report import summary, write
    from tg_drake.scenario import load_scenario

    scenario = load_scenario(args.scenario, scenario_name=args.name)
    if getattr(args, "theory", None):
        scenario.pipeline.logic.category = scenario.pipeline.logic.grasp = args.theory
    out = args.out or default_out(args)
    meshcat = None
    if args.meshcat:
        meshcat = start_meshcat(args.meshcat_host, args.meshcat_port)
        look_at_the_table(meshcat, scenario)
        print(f"Meshcat: {meshcat.web_url()}")
    result, pictures = run(scenario, scenario_path=str(args.scenario), meshcat=meshcat,
                           images=not args.no_images)
    write(out, result, None if args.no_images else pictures)
    print(summary(result))
    print(f"wrote {out}/result.json")
    if meshcat is not None:
        print("the run is replayed in Meshcat; press Ctrl-C to stop serving")
        try:
            while True:
                time.sleep(1.0)
        except KeyboardInterrupt:
            pass
    return exit_status(result)


def exit_status(result: dict) -> int:
    """The command's exit status for a run: 0 done — the outcome is not `failed` and, where the
    task has a physical check (result.json's `task_outcome`), the check passed —, 1 otherwise.
    (2, bad input or usage, is tg_drake.cli's.)"""
    if result["outcome"]["status"] == "failed":
        return 1
    task = result.get("task_outcome")
    return 0 if task is None or task.get("success") else 1


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


def bench_scan_run_ratio():
    """`scan_run_ratio`: wall seconds of one whole run (build included, as `tg-drake run`) of the
    default scenario with its cup replaced by the scan-like cup (a `mesh:` entry, already imported:
    the cache's second run), over the same run with the library's cup, median of 3 each. Issue 18's
    goal: ≤ 1.3. `median` is the ratio; the reference is the library cup's run [s]."""
    import os
    import statistics
    import tempfile

    from tg_drake.bench import Figure
    from tg_drake.importing.bench import write_scan_cup
    from tg_drake.scenario import ObjectPlacement, Scenario, TaskConfig, resolve_objects

    def seconds(placement: ObjectPlacement) -> float:
        # scenarios/default.yaml: the paper's Fig. 1 cup, upright and empty, to be passed.
        scenario = Scenario(objects=[placement], task=TaskConfig(task="pass", place_xy=[0.0, -0.3]))
        resolve_objects(scenario)
        t0 = time.perf_counter()
        run_scenario(scenario, scenario_path="bench")
        return time.perf_counter() - t0

    with tempfile.TemporaryDirectory(prefix="tg_drake_bench_scan_") as tmp:
        old = os.environ.get("TG_DRAKE_CACHE")
        os.environ["TG_DRAKE_CACHE"] = str(Path(tmp) / "cache")
        try:
            mesh = str(write_scan_cup(Path(tmp)))
            scan = ObjectPlacement(mesh=mesh, category="cup", up_axis="y", pose="upright",
                                   name="cup")
            resolve_objects(Scenario(objects=[dataclasses.replace(scan)]))  # the import, untimed
            scan_s = statistics.median(seconds(dataclasses.replace(scan)) for _ in range(3))
            library_s = statistics.median(
                seconds(ObjectPlacement(id="cup_01", pose="upright")) for _ in range(3))
        finally:
            if old is None:
                os.environ.pop("TG_DRAKE_CACHE", None)
            else:
                os.environ["TG_DRAKE_CACHE"] = old
    return Figure(median=scan_s / library_s, unit="ratio (scan-like run s / library run s)",
                  reference="the same run with the library's cup_01 [s]",
                  reference_median=library_s, speedup=library_s / scan_s)
