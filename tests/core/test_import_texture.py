"""A textured file keeps its texture: a second visual for the illustration (Meshcat), the repaired
grey mesh for the cameras; both in the object frame O."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from PIL import Image
from pydrake.geometry import Role, SceneGraph
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from tests.import_helpers import read_obj
from tg_drake.importing import ImportOptions, import_object


def _textured_gso_folder(d):
    """A Google Scanned Objects-like folder: a textured cylinder in mm, y up (meshes/model.obj,
    its .mtl and image), the texture a 16×16 random image."""
    m = trimesh.creation.cylinder(radius=40.0, height=100.0, sections=32)  # [mm]
    m.vertices = m.vertices[:, [0, 2, 1]] * [1, 1, -1]  # z up → y up (a turn about x)
    m.fix_normals()
    uv = np.c_[(np.arctan2(m.vertices[:, 2], m.vertices[:, 0]) / (2 * np.pi)) % 1,
               m.vertices[:, 1] / 100.0 + 0.5]
    image = Image.fromarray(
        (np.random.default_rng(0).random((16, 16, 3)) * 255).astype(np.uint8))
    m.visual = trimesh.visual.TextureVisuals(uv=uv, image=image)
    text, files = trimesh.exchange.obj.export_obj(m, return_texture=True, mtl_name="model.mtl")
    (d / "meshes").mkdir(parents=True)
    (d / "meshes" / "model.obj").write_text(text)
    for name, data in files.items():
        (d / "meshes" / name).write_bytes(data)
    return d


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    d = _textured_gso_folder(tmp_path_factory.mktemp("gso") / "Tin")
    result = import_object(d, ImportOptions(category="can", up_axis="y", obj_id="tin"),
                           d.parent / "lib", pictures=False)
    return d.parent / "lib" / "tin", result


def test_the_texture_is_kept_in_the_object_frame(imported):
    obj_dir, _ = imported
    names = {p.name for p in obj_dir.iterdir()}
    assert {"tin_textured.obj", "tin_textured.mtl"} <= names
    assert any(n.endswith(".png") for n in names)
    assert "map_Kd" in (obj_dir / "tin_textured.mtl").read_text()
    textured = trimesh.load(obj_dir / "tin_textured.obj", process=False)
    assert isinstance(textured.visual, trimesh.visual.TextureVisuals)
    assert textured.visual.material.image.size == (16, 16)
    V, _ = read_obj(obj_dir / "tin.obj")  # the repaired mesh, in O [m]
    # the same solid: mm → m and y up → z up, the same place in O (the 80 × 80 × 100 mm tin)
    assert textured.bounds == pytest.approx(np.array([V.min(0), V.max(0)]), abs=1e-4)
    assert np.ptp(V, axis=0) == pytest.approx([0.08, 0.08, 0.10], abs=1e-3)


def test_cameras_see_the_repaired_mesh_and_the_illustration_the_textured_one(imported):
    obj_dir, _ = imported
    plant = MultibodyPlant(0.0)
    scene_graph = SceneGraph()
    plant.RegisterAsSourceForSceneGraph(scene_graph)
    Parser(plant).AddModels(str(obj_dir / "tin.sdf"))
    plant.Finalize()
    inspector = scene_graph.model_inspector()
    frame = plant.GetBodyFrameIdOrThrow(plant.GetBodyByName("tin").index())

    def names(role):
        return sorted(inspector.GetName(g).split("::")[-1]
                      for g in inspector.GetGeometries(frame, role))
    assert names(Role.kPerception) == ["visual"]
    assert names(Role.kIllustration) == ["visual_textured"]


def test_an_untextured_file_has_one_visual_for_both(tmp_path):
    m = trimesh.creation.cylinder(radius=0.04, height=0.1, sections=32)
    m.export(tmp_path / "plain.obj")
    import_object(tmp_path / "plain.obj", ImportOptions(category="can", obj_id="plain"),
                  tmp_path / "lib", pictures=False)
    sdf = (tmp_path / "lib" / "plain" / "plain.sdf").read_text()
    assert "visual_textured" not in sdf and "illustration_properties" not in sdf
    assert not list((tmp_path / "lib" / "plain").glob("*_textured*"))
