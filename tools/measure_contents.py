"""Measures the sphere contents' settings: wall time per simulated second and spill/tunnelling.

For each setting (radius, count bound, hydroelastic modulus and resolution hint, plant time step,
mutual contact), two runs:

- standing: the station with a full cup (contents: spheres) and the robot holding its posture,
  simulated `--standing` s; wall seconds per simulated second, and where the spheres are at the
  end (all in the cup, or some spilled or through a wall);
- pour: the tilt rig (tg_drake.simulation.pour.tilt_rig) turns the cup upside down over `--turn`
  s above the table, simulated 2.5 s; wall seconds per simulated second and the counts (all on
  the table, or some still in the cup, on the floor or elsewhere).

The reference is the same standing run with contents: mass. Times are wall and CPU seconds of
this process per simulated second (on a shared machine the CPU time is the steadier). One JSON
object per line.

    python tools/measure_contents.py > /tmp/contents.jsonl
"""

import argparse
import dataclasses
import json
import time

import numpy as np
from pydrake.systems.analysis import Simulator

from tg_drake.objects import get_object
from tg_drake.scenario import ObjectPlacement, Scenario, default_plant_config
from tg_drake.simulation.pour import tilt_rig
from tg_drake.station import make_station
from tg_drake.tasks.contents import ContentsConfig, count_contents

SETTINGS = [
    {},
    {"max_count": 10}, {"max_count": 36},
    {"radius": 0.006}, {"radius": 0.010},
    {"modulus": 1e6}, {"modulus": 1e8},
    {"resolution_hint": 0.004},
    {"time_step": 0.0025}, {"time_step": 0.01},
    {"mutual": False},
]


def _config(setting: dict) -> tuple[ContentsConfig, object]:
    plant = default_plant_config()
    if "time_step" in setting:
        plant.time_step = setting["time_step"]
    fields = {k: v for k, v in setting.items() if k != "time_step"}
    return dataclasses.replace(ContentsConfig(model="spheres"), **fields), plant


def standing(obj_id: str, contents: ContentsConfig, plant_config, seconds: float) -> dict:
    scenario = Scenario(objects=[ObjectPlacement(id=obj_id, containment="full")],
                        contents=contents, plant_config=plant_config, cameras={})
    diagram, station = make_station(scenario)
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    plant = station.plant
    plant_context = plant.GetMyContextFromRoot(context)
    q = plant.GetPositions(plant_context, station.instances["iiwa"])
    diagram.GetInputPort("iiwa.desired_state").FixValue(context, np.concatenate([q, 0 * q]))
    diagram.GetInputPort("wsg.position").FixValue(context, [0.1])
    simulator.Initialize()
    t0, c0 = time.perf_counter(), time.process_time()
    simulator.AdvanceTo(seconds)
    out = {"wall_per_sim_s": (time.perf_counter() - t0) / seconds,
           "cpu_per_sim_s": (time.process_time() - c0) / seconds}
    poses = diagram.GetOutputPort("body_poses").Eval(context)
    X_WO = plant.EvalBodyPoseInWorld(plant_context, station.object_body(obj_id))
    for model in station.contents:
        out["n"] = len(model.bodies)
        out["counts"] = count_contents(model, poses, table_z=0.0,
                                       containers={obj_id: (X_WO, get_object(obj_id))})
    return out


def pour(obj_id: str, contents: ContentsConfig, plant_config, turn_s: float) -> dict:
    rig = tilt_rig(obj_id, contents, duration=turn_s, plant_config=plant_config)
    simulator = Simulator(rig.diagram)
    simulator.Initialize()
    t0, c0 = time.perf_counter(), time.process_time()
    simulator.AdvanceTo(2.5)
    return {"wall_per_sim_s": (time.perf_counter() - t0) / 2.5,
            "cpu_per_sim_s": (time.process_time() - c0) / 2.5,
            "counts": rig.counts(simulator.get_mutable_context())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--object", default="cup_01")
    parser.add_argument("--standing", type=float, default=0.5, help="[s] simulated")
    parser.add_argument("--turn", type=float, default=1.0, help="[s] of the rig's half turn")
    parser.add_argument("--only", type=int, action="append", help="indices into SETTINGS")
    args = parser.parse_args()
    reference = standing(args.object, ContentsConfig(), default_plant_config(), args.standing)
    print(json.dumps({"setting": "mass (reference)", **reference}), flush=True)
    for k, setting in enumerate(SETTINGS):
        if args.only and k not in args.only:
            continue
        contents, plant_config = _config(setting)
        row = {"setting": setting or "defaults",
               "standing": standing(args.object, contents, plant_config, args.standing),
               "pour": pour(args.object, contents, plant_config, args.turn)}
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
