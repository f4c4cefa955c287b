"""Scan-like meshes (tg_drake.scanlike): the defects a real scan brings, each one checked on the
mesh itself against the library original, not on the record the generator keeps."""

from __future__ import annotations

import json

import numpy as np
import open3d as o3d
import pytest
import trimesh

from tg_drake import scanlike
from tg_drake.errors import ScenarioError
from tg_drake.objects import get_object, mesh

N = 20_000  # triangles: smaller than the default 50,000 to keep the module fast
SIGMA = 0.3e-3  # [m] the default surface noise
CONFIG = scanlike.ScanLikeConfig(n_triangles=N, noise_sigma=SIGMA)


@pytest.fixture(scope="module")
def cup():
    return scanlike.make_scanlike("cup_01", seed=3, config=CONFIG)


def in_O(scan) -> np.ndarray:
    """The scan's vertices mapped back to the object frame O [m]."""
    X_OS = np.linalg.inv(scan.X_SO)
    return scan.mesh.vertices @ X_OS[:3, :3].T + X_OS[:3, 3]


def original_scene(obj_id):
    V, F, _ = mesh(obj_id)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(V.astype(np.float32)),
                        o3d.core.Tensor(F.astype(np.uint32)))
    return scene


def test_refine_is_conforming_and_keeps_the_surface():
    V0, F0, _ = mesh("glass_01")
    V, F = scanlike.refine(V0, F0, 4e-3)  # [m] longest edge after refinement
    m = trimesh.Trimesh(V, F, process=False)
    edges = np.linalg.norm(V[m.edges_unique[:, 0]] - V[m.edges_unique[:, 1]], axis=1)
    assert edges.max() <= 4e-3
    assert len(F) > 4 * len(F0)
    assert m.is_watertight and m.is_winding_consistent  # no T-junction, winding kept
    # midpoints lie on the original faces: the volume is the original's (to rounding)
    assert m.volume == pytest.approx(get_object("glass_01").volume, rel=1e-6)


def test_triangle_count_near_target(cup):
    # within 10 %: the remesh aims at ±5 %, then holes remove and zero-area triangles add a few
    assert abs(len(cup.mesh.faces) / N - 1) < 0.10
    assert cup.record["n_triangles"] == len(cup.mesh.faces)


def test_millimetres_y_up_and_offset(cup):
    o = get_object("cup_01")
    ext = cup.mesh.vertices.max(axis=0) - cup.mesh.vertices.min(axis=0)
    # O's x, z, y become the scan's x, y, z, ×1000; 3 mm: noise at the extremes (a few sigma)
    np.testing.assert_allclose(ext, 1000 * np.array(o.extents)[[0, 2, 1]], atol=3.0)
    # y is up: the cup's opening (O's +z) is at the scan's top in y
    top = in_O(cup)[:, 2] > 0.9 * o.extents[2]
    assert cup.mesh.vertices[top, 1].mean() > cup.mesh.vertices[~top, 1].mean()
    assert cup.record["units"] == "mm" and cup.record["up_axis"] == "y"
    assert cup.record["scale"] == 1000.0
    # placed away from the origin: O's origin is not the scan's
    assert np.linalg.norm(cup.X_SO[:3, 3]) > 1.0  # [mm]


def test_noise_present_but_bounded(cup):
    d = original_scene("cup_01").compute_distance(
        o3d.core.Tensor(in_O(cup).astype(np.float32))).numpy()
    rms = np.sqrt(np.mean(d ** 2))
    # the displacement is Gaussian along the normal, so the distance to the surface is at most
    # |displacement| (max of ~10⁴ draws ≈ 4 sigma; 6 sigma bound) and its RMS about sigma
    assert d.max() < 6 * SIGMA
    assert 0.6 * SIGMA < rms < 1.2 * SIGMA


def test_pieces_holes_degenerate(cup):
    F = cup.mesh.faces
    assert scanlike.n_components(F) == cup.record["n_pieces"] > 1
    # re-joined when coincident vertices merge (the pieces share positions along the cuts)
    merged = trimesh.Trimesh(cup.mesh.vertices, F)  # process=True merges vertices
    merged.update_faces(merged.nondegenerate_faces())
    assert len(merged.split(only_watertight=False)) == 1
    assert not merged.is_watertight  # the holes
    # zero-area triangles: a repeated index, or three collinear vertices
    V = cup.mesh.vertices
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    assert (area < 1e-9).sum() >= cup.record["n_degenerate"] > 0  # [mm²]
    assert ((F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])).any()


def test_some_faces_flipped(cup):
    P, F = in_O(cup), cup.mesh.faces
    cross = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    norm = np.linalg.norm(cross, axis=1)
    ok = norm > 1e-12  # [m²] the zero-area ones have no normal
    closest = original_scene("cup_01").compute_closest_points(
        o3d.core.Tensor(P[F[ok]].mean(axis=1).astype(np.float32)))
    n_orig = closest["primitive_normals"].numpy()
    disagree = ((cross[ok] / norm[ok, None]) * n_orig).sum(axis=1) < 0
    flipped = cup.record["n_flipped"]
    assert flipped == round(CONFIG.flip_fraction * (len(F) - cup.record["n_degenerate"]))
    # the flipped faces, plus a few the noise tilts at creases (rim, handle joint)
    assert flipped <= disagree.sum() <= 1.1 * flipped + 20


def test_labels_carried_over(cup):
    o = get_object("cup_01")
    labels = cup.labels
    assert labels.shape == (len(cup.mesh.vertices),) and labels.dtype == np.uint8
    assert set(np.unique(labels)) == set(np.unique(mesh("cup_01")[2]))
    assert len(o.parts) == len(np.unique(labels))


def test_deterministic_per_seed():
    cfg = scanlike.ScanLikeConfig(n_triangles=5_000)
    a = scanlike.make_scanlike("knife_01", seed=7, config=cfg)
    b = scanlike.make_scanlike("knife_01", seed=7, config=cfg)
    c = scanlike.make_scanlike("knife_01", seed=8, config=cfg)
    np.testing.assert_array_equal(a.mesh.vertices, b.mesh.vertices)
    np.testing.assert_array_equal(a.mesh.faces, b.mesh.faces)
    np.testing.assert_array_equal(a.labels, b.labels)
    assert a.record == b.record
    assert not np.array_equal(a.mesh.vertices[:100], c.mesh.vertices[:100])


def test_write_obj_round_trip(tmp_path):
    cfg = scanlike.ScanLikeConfig(n_triangles=5_000)
    scan = scanlike.write_scanlike("bowl_01", tmp_path / "bowl.obj", seed=1, config=cfg)
    back = trimesh.load(tmp_path / "bowl.obj", process=False)
    np.testing.assert_allclose(back.vertices, scan.mesh.vertices, atol=1e-6)  # [mm]
    np.testing.assert_array_equal(back.faces, scan.mesh.faces)
    assert len(np.load(tmp_path / "bowl_parts.npy")) == len(back.vertices)
    assert json.loads((tmp_path / "bowl_scanlike.json").read_text())["units"] == "mm"
    scanlike.write_scanlike("bowl_01", tmp_path / "bowl_s.stl", seed=1, config=cfg)
    assert not (tmp_path / "bowl_s_parts.npy").exists()  # STL keeps no vertices to label
    assert len(trimesh.load(tmp_path / "bowl_s.stl").faces) > 0.9 * 5_000


def test_bad_input():
    with pytest.raises(ScenarioError, match="unknown scan-like format 'dae'"):
        scanlike.write_scanlike("bowl_01", "/tmp/x.dae")
    with pytest.raises(ScenarioError, match="unknown object 'mugg'"):
        scanlike.make_scanlike("mugg")
    with pytest.raises(ScenarioError, match="flip_fraction"):
        scanlike.ScanLikeConfig(flip_fraction=2.0)
