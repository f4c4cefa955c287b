"""The part-coloured picture of a perceived object."""

import numpy as np
from matplotlib.image import imread

from tg_drake.perception import synthetic as S
from tg_drake.perception.geometry import make_transform
from tg_drake.perception.pipeline import describe_cloud
from tg_drake.perception.plot import save_object_png, save_scene_png
from tg_drake.types import PART_COLORS, PART_LABELS


def test_png_shows_the_parts_in_the_papers_colours(tmp_path):
    rng = np.random.default_rng(0)
    p, n = S.cylinder_points(0.035, 0.12, 8000, rng)
    eye = np.array([0.5, 0.1, 0.5])
    o = describe_cloud(S.partial_view(p, n, make_transform(np.eye(3), [0, 0, 0]), eye, 0.001, rng),
                       np.eye(4), eye)
    path = save_object_png(o, tmp_path / "cyl.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    image = imread(path)[..., :3]
    for part in ("top", "middle", "bottom"):
        colour = np.array(PART_COLORS[PART_LABELS.index(part)])
        # Observed points are drawn opaque in the part's colour (PNG: 8 bits per channel).
        close = np.all(np.abs(image - colour) < 2 / 255, axis=-1)
        assert close.sum() > 50, part
    handle = np.array(PART_COLORS[PART_LABELS.index("handle")])
    assert not np.all(np.abs(image - handle) < 2 / 255, axis=-1).any()  # no handle on a can
    scene = save_scene_png([o, o], tmp_path / "scene.png")
    assert imread(scene).shape[1] > imread(path).shape[1] * 0.9
