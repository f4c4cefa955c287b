"""`tg-drake render SCENARIO --out DIR`: the station alone, one frame from each camera.

Writes, per camera, `rgb.png`, `depth.png` (metres mapped to grey, no return in black) and
`labels.png` (one colour per body: the render label image). With one camera the files sit directly
in DIR; with several, each camera gets a sub-folder.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

HELP = "render one frame of a scenario's cameras: rgb.png, depth.png, labels.png"


def add_arguments(parser) -> None:
    parser.add_argument("scenario", type=Path, help="scenario YAML file")
    parser.add_argument("--name", help="a named entry of a multi-scenario file")
    parser.add_argument("--out", type=Path, required=True, help="output folder")


def render_frames(scenario) -> dict[str, dict[str, np.ndarray]]:
    """camera name → {"rgb": (H, W, 3) uint8, "depth": (H, W) float32 [m], "label": (H, W) int}."""
    from tg_drake.station import make_station  # start-up: --help imports this module; pydrake

    diagram, station = make_station(scenario)
    context = diagram.CreateDefaultContext()
    frames = {}
    for name in station.cameras:
        rgb = diagram.GetOutputPort(f"{name}.rgb_image").Eval(context)
        depth = diagram.GetOutputPort(f"{name}.depth_image").Eval(context)
        label = diagram.GetOutputPort(f"{name}.label_image").Eval(context)
        frames[name] = {"rgb": np.array(rgb.data[:, :, :3]),
                        "depth": np.array(depth.data[:, :, 0]),
                        "label": np.array(label.data[:, :, 0]).astype(np.int32)}
    return frames


def depth_to_grey(depth: np.ndarray) -> np.ndarray:
    """Near is bright; no return (inf, 0, NaN) is black. (H, W) uint8."""
    valid = np.isfinite(depth) & (depth > 0)
    out = np.zeros(depth.shape, np.uint8)
    if valid.any():
        lo, hi = np.percentile(depth[valid], [0.5, 99.5])
        scaled = 1.0 - np.clip((depth - lo) / max(hi - lo, 1e-6), 0.0, 1.0)
        out[valid] = (30 + 225 * scaled[valid]).astype(np.uint8)
    return out


def labels_to_rgb(label: np.ndarray) -> np.ndarray:
    """A distinct colour per label value; Drake's reserved labels (empty, unspecified) are black."""
    import matplotlib  # start-up: --help imports this module

    palette = (np.array(matplotlib.colormaps["tab20"].colors) * 255).astype(np.uint8)
    out = palette[np.mod(label, len(palette))]
    out[(label < 0) | (label >= 32765)] = 0  # Drake's reserved render labels
    return out


def main(args) -> int:
    # Start-up: `tg-drake --help` imports this module; matplotlib and pydrake are slow to import.
    import matplotlib.pyplot as plt

    from tg_drake.scenario import load_scenario

    scenario = load_scenario(args.scenario, scenario_name=args.name)
    frames = render_frames(scenario)
    for name, frame in frames.items():
        folder = args.out if len(frames) == 1 else args.out / name
        folder.mkdir(parents=True, exist_ok=True)
        plt.imsave(folder / "rgb.png", frame["rgb"])
        plt.imsave(folder / "depth.png", depth_to_grey(frame["depth"]), cmap="gray", vmin=0,
                   vmax=255)
        plt.imsave(folder / "labels.png", labels_to_rgb(frame["label"]))
        print(f"{name}: wrote {folder}/rgb.png, depth.png, labels.png")
    return 0


# -- A run's key frames (task.png, tg_drake.report) --------------------------------------------

RECORD_PERIOD = 0.05  # [s] simulated time between the plant positions a run keeps for its pictures


class PositionRecorder:
    """The plant's positions at most every RECORD_PERIOD of simulated time, for the pictures of
    a run (`record` is called from the simulator's monitor; it reads the state, changes nothing)."""

    def __init__(self, plant):
        self._plant = plant
        self.times: list[float] = []
        self.q: list[np.ndarray] = []

    def record(self, root_context) -> None:
        t = root_context.get_time()
        if self.times and t < self.times[-1] + RECORD_PERIOD:
            return
        self.times.append(t)
        self.q.append(np.array(self._plant.GetPositions(
            self._plant.GetMyContextFromRoot(root_context))))

    def at(self, t: float) -> np.ndarray:
        """The positions recorded last at or before `t` (the first ones before the record)."""
        if not self.times:
            raise ValueError("no plant positions were recorded")
        i = int(np.searchsorted(np.asarray(self.times), t, side="right")) - 1
        return self.q[max(i, 0)]


def key_times(plan, t_plan: float, t_end: float, task: str) -> list[tuple[str, float]]:
    """The key frames of a task run [s of simulated time]: the grasp (the fingers closed), the
    task's moment — the middle of the pour or the fill, the hand-over, else the placed pose —
    and the end (`t_end`); `plan`'s times are offset by `t_plan`, none after `t_end`."""
    keys = [("grasp", t_plan + plan.t_grasp_closed)]
    handover = getattr(plan, "t_handover", None)  # the pass's (receiver closes, robot lets go)
    if plan.t_pour is not None:
        keys.append(("pour" if task == "pourOut" else "fill",
                     t_plan + 0.5 * (plan.t_pour[0] + plan.t_pour[1])))
    elif handover is not None:
        keys.append(("hand-over", t_plan + handover[0]))
    else:
        keys.append(("placed", t_plan + plan.t_place_done))
    keys.append(("end", t_end))
    return [(name, min(t, t_end)) for name, t in keys]


def render_key_frames(scenario, recorder: PositionRecorder, keys, camera: str
                      ) -> list[tuple[str, float, np.ndarray]]:
    """(name, t, (H, W, 3) RGB) per key frame, seen through `camera` in a station of its own in
    which the contents' spheres and the dispenser are visible (the run's cameras, perception's,
    never see them), its plant set to the run's recorded positions."""
    from tg_drake.station import make_station  # start-up: --help imports this module; pydrake

    diagram, station = make_station(scenario, contents_visible=True)
    context = diagram.CreateDefaultContext()
    plant_context = station.plant.GetMyContextFromRoot(context)
    port = diagram.GetOutputPort(f"{camera}.rgb_image")
    frames = []
    for name, t in keys:
        q = recorder.at(t)
        if q.shape != (station.plant.num_positions(),):
            raise ValueError(f"the pictures' station has {station.plant.num_positions()} "
                             f"positions, the run recorded {q.shape[0]}")
        station.plant.SetPositions(plant_context, q)
        frames.append((name, t, np.array(port.Eval(context).data[:, :, :3])))
    return frames
