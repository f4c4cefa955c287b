"""Calibrates perception's pose likelihood on perceived views of the training objects.

Every training object (the object-wise split's `train`: `tg_drake.evaluation.split`, or, until
that exists, the library without its `*_04` objects) is perceived alone on the table in each of
its resting poses at yaws the evaluation suites do not use, its depth image ray cast from the
default camera's viewpoint and measured by the scenario default's depth sensor
(`tg_drake.perception.render.perceive`). Per (decision, cue) — the pose perception decided and
the cue that decided it — the true poses are counted; `tg_drake.perception.pose.PoseCalibration`
turns the counts into P(true pose | decision, cue).

    .venv/bin/python tools/calibrate_pose.py  # → tg_drake/data/pose_likelihood.json
    .venv/bin/python tools/calibrate_pose.py --sensor ideal --out /tmp/pose.json
"""

from __future__ import annotations

import argparse
import collections
import json
import sys
from pathlib import Path

from tg_drake.errors import TgDrakeError
from tg_drake.objects import load_library
from tg_drake.perception.pose import CALIBRATION_FILE, PoseCalibration
from tg_drake.perception.render import perceive
from tg_drake.perception.sensor_model import IdealDepth, StructuredLight
from tg_drake.scenario import DepthPerception

# Yaws of the calibration views [deg]: between the S_REAL suite's 0, 120, 240.
YAWS_DEG = (60.0, 180.0, 300.0)
PRIOR_VIEWS = 2.0  # [views] the smoothing prior's weight (PoseCalibration.prior_views)


def training_ids() -> list[str]:
    try:
        from tg_drake.evaluation.split import load_split  # the object set's split, once it exists
        return sorted(load_split().train)
    except ImportError:
        return sorted(i for i in load_library() if not i.endswith("_04"))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sensor", choices=("default", "ideal", "d415"), default="default")
    parser.add_argument("--out", type=Path, default=CALIBRATION_FILE)
    args = parser.parse_args(argv)
    sensor = {"default": DepthPerception().sensor, "ideal": IdealDepth(),
              "d415": StructuredLight()}[args.sensor]
    library = load_library()
    counts: dict = collections.defaultdict(lambda: collections.Counter())
    ids = training_ids()
    n = failed = 0
    for obj_id in ids:
        for pose in library[obj_id].poses:
            for yaw in YAWS_DEG:
                try:
                    d = perceive(obj_id, pose, yaw, sensor=sensor, seed=n)
                except TgDrakeError:
                    failed += 1
                    continue
                finally:
                    n += 1
                counts[f"{d.pose}/{d.pose_cue}"][pose] += 1
    name = getattr(sensor, "name", type(sensor).__name__)
    out = {"source": f"tools/calibrate_pose.py --sensor {args.sensor} ({name}): {len(ids)} "
                     f"training objects, their resting poses at yaws {list(YAWS_DEG)}; {n} views, "
                     f"{failed} not perceived",
           "prior_views": PRIOR_VIEWS,
           "counts": {k: dict(sorted(v.items())) for k, v in sorted(counts.items())}}
    args.out.write_text(json.dumps(out, indent=1) + "\n")
    calibration = PoseCalibration(counts=out["counts"], prior_views=PRIOR_VIEWS)
    for key in out["counts"]:
        decision, cue = key.split("/")
        p = calibration.likelihood(decision, cue)
        print(f"{key:22s} {dict(out['counts'][key])}  →  " + ", ".join(
            f"{k} {v:.2f}" for k, v in p.items()))
    print(f"wrote {args.out} ({n} views, {failed} not perceived)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
