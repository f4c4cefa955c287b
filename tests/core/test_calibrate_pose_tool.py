"""tools/calibrate_pose.py keeps the better closed-end model on the training views."""

import importlib.util
from pathlib import Path

from tg_drake.perception.pose import ClosedEnd, ClosedEndModel

REPO = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("calibrate_pose",
                                              REPO / "tools" / "calibrate_pose.py")
tool = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tool)

# Upside down when the closed end's ring stands more (RIGHT) or less (WRONG) than 2 mm above
# its centre (features in mm: recess, dome, recess²).
RIGHT = ClosedEndModel(weights=(1.0, 0.0, 0.0), bias=-2.0)
WRONG = ClosedEndModel(weights=(-1.0, 0.0, 0.0), bias=2.0)
ENDS = [("upsidedown", ClosedEnd(recess=0.005, dome=0.0)),  # a base's rim: 5 mm
        ("upright", ClosedEnd(recess=0.0, dome=0.0)),  # a flat lid
        ("upright", ClosedEnd(recess=0.001, dome=0.0))]


def test_training_accuracy_counts_the_views_a_model_gets_right():
    assert tool.training_accuracy(RIGHT, ENDS) == 1.0
    assert tool.training_accuracy(WRONG, ENDS) == 0.0
    assert tool.training_accuracy(RIGHT, []) == 0.0


def test_the_current_model_is_kept_only_when_it_does_better_on_the_training_views():
    assert tool.better_closed_end(WRONG, RIGHT, ENDS) == (RIGHT, "current")
    assert tool.better_closed_end(RIGHT, WRONG, ENDS) == (RIGHT, "fitted")
    assert tool.better_closed_end(RIGHT, RIGHT, ENDS)[1] == "fitted"  # a tie keeps the fit
    assert tool.better_closed_end(RIGHT, None, ENDS) == (RIGHT, "fitted")
    assert tool.better_closed_end(None, WRONG, ENDS) == (WRONG, "current")


def test_the_shipped_calibration_has_a_closed_end_model_to_compare_with():
    model, contents = tool.load_closed_end(REPO / "tg_drake" / "data" / "pose_likelihood.json")
    assert len(model.weights) == 3 and "counts" in contents
