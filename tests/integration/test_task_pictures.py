"""A task run's key frames (task.png): drawn from the camera in a pictures-only station where the
contents' spheres and the dispenser are visible, while the cameras perception looks through do not
see them; Meshcat's replay (the illustration role) shows them."""

from pathlib import Path

import numpy as np
import pytest
from pydrake.geometry import Role
from pydrake.multibody.tree import BodyIndex

from tg_drake.render import PositionRecorder, render_key_frames
from tg_drake.scenario import load_scenario
from tg_drake.station import make_station

TASKS = Path(__file__).resolve().parents[2] / "scenarios" / "tasks"


def test_the_pictures_see_the_contents_that_perception_does_not():
    scenario = load_scenario(TASKS / "glass_pour_in.yaml")  # the dispenser's spheres in view
    diagram, station = make_station(scenario)
    context = diagram.CreateDefaultContext()
    seen = np.array(diagram.GetOutputPort("camera0.rgb_image").Eval(context).data[:, :, :3])
    # The replay (Meshcat draws the illustration role) has every sphere.
    inspector = station.scene_graph.model_inspector()
    plant = station.plant
    spheres = [b for m in station.contents for b in m.bodies]
    assert len(spheres) > 0
    for b in spheres:
        frame = plant.GetBodyFrameIdOrThrow(BodyIndex(b))
        assert len(inspector.GetGeometries(frame, Role.kIllustration)) == 1
    recorder = PositionRecorder(plant)
    recorder.record(context)
    frames = render_key_frames(scenario, recorder, [("start", 0.0), ("end", 9.0)], "camera0")
    assert [(name, t) for name, t, _ in frames] == [("start", 0.0), ("end", 9.0)]
    picture = frames[0][2].astype(int)
    assert picture.shape == seen.shape
    # The pictures show the hopper and its spheres (blue, station.SPHERE_COLOR, seen through the
    # hopper's translucent walls) where perception's camera sees the sky and the table.
    changed = np.any(np.abs(picture - seen) > 20, axis=2)
    assert changed.sum() > 300
    assert np.mean(picture[changed][:, 2] - picture[changed][:, 0]) > 20
    assert np.array_equal(render_key_frames(scenario, recorder, [("again", 0.0)], "camera0")[0][2],
                          frames[0][2])  # the same state renders the same picture


@pytest.mark.slow
def test_a_task_run_writes_its_key_frames(tmp_path):
    from tg_drake.report import write
    from tg_drake.run import run

    result, pictures = run(load_scenario(TASKS / "can_on_shelf.yaml"),
                           scenario_path="can_on_shelf", images=True)
    assert pictures.task_frames is not None
    write(tmp_path, result, pictures)
    assert "warnings" not in result, result.get("warnings")
    assert (tmp_path / "task.png").stat().st_size > 10_000
    import matplotlib.image

    image = matplotlib.image.imread(tmp_path / "task.png")
    assert image.shape[1] > 2.5 * image.shape[0]  # three frames side by side
