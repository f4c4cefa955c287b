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
