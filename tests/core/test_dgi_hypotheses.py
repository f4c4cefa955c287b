"""Grasp hypotheses for DGI data collection: part-box pre-grasps, perturbations, random ones."""

import xml.etree.ElementTree as ET
from importlib.resources import files

import numpy as np
import pytest

from tg_drake.errors import GraspingError
from tg_drake.grasping.dgi import FINGERTIP_Y, GRIPPER_BASE_Y, PAD_CENTER_Y, depth_images
from tg_drake.grasping.expansion import ExpansionConfig, lowest_point, retreat_above_table
from tg_drake.grasping.hypotheses import GRASP_INSET, box_grasps, perturb_grasps, surface_grasps
from tg_drake.robot import WSG_BODY_CENTRE_G, WSG_BODY_SIZE

BODY_BOX = (np.array(WSG_BODY_CENTRE_G), np.array(WSG_BODY_SIZE))


def clears_plane(X, plane_z, *, approach_distance, clearance=0.003):
    return lowest_point(X, approach_distance) >= plane_z + clearance


def retreat_above_plane(X, plane_z, *, approach_distance, clearance, max_retreat):
    return retreat_above_table(X, plane_z, approach_distance=approach_distance,
                               config=ExpansionConfig(table_clearance=clearance,
                                                      max_retreat=max_retreat))


def assert_rigid(X):
    R = X[:, :3, :3]
    # 1e-12: products of unit vectors, rounding only.
    np.testing.assert_allclose(R.transpose(0, 2, 1) @ R, np.broadcast_to(np.eye(3), R.shape),
                               atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)


def test_two_grasps_per_face_approach_the_box_centre():
    X_WB = np.eye(4)
    X_WB[:3, 3] = [0.1, 0.2, 0.3]
    h = np.array([0.01, 0.05, 0.02])
    X = box_grasps(X_WB, h)
    assert X.shape == (12, 4, 4)
    assert_rigid(X)
    y = X[:, :3, 1]
    grasp_point = X[:, :3, 3] + PAD_CENTER_Y * y
    # Face +x of a 1 cm thin box: the grasp point is the box centre; approach along −x.
    np.testing.assert_allclose(y[0], [-1, 0, 0])
    np.testing.assert_allclose(grasp_point[0], X_WB[:3, 3], atol=1e-12)
    # Closing along y then z of the box for that face.
    np.testing.assert_allclose(X[0, :3, 0], [0, 1, 0])
    np.testing.assert_allclose(X[1, :3, 0], [0, 0, 1])
    # Face −y of a 10 cm deep box: the grasp point is GRASP_INSET behind the face.
    np.testing.assert_allclose(y[6], [0, 1, 0])
    np.testing.assert_allclose(grasp_point[6], X_WB[:3, 3] + [0, -0.05 + GRASP_INSET, 0],
                               atol=1e-12)
    # A thin plate grasped through its thin side puts the plate across the middle of the pads.
    p = np.stack(np.meshgrid(np.linspace(-0.04, 0.04, 81), np.linspace(-0.04, 0.04, 81),
                             [0.0]), -1).reshape(-1, 3) * [1, 1, 0] + [0.1, 0.2, 0.3]
    di = depth_images(p, box_grasps(X_WB, np.array([0.04, 0.04, 0.0]))[8:9])  # face +z
    # Approaching along −z, closing along x: the pixels over the plate (|x| ≤ 0.04 m: columns
    # 4..15 of 7 mm from −0.070 m) see it at depth PAD_CENTER_Y − base = 0.041 m, the rest is
    # empty. 1e-12 m: the plate lies exactly in the grasp point's plane.
    expected = np.full((20, 3), -1.0)
    expected[4:16] = PAD_CENTER_Y - GRIPPER_BASE_Y
    np.testing.assert_allclose(di[0], expected, atol=1e-12)
    with pytest.raises(GraspingError, match="3 half extents"):
        box_grasps(X_WB, np.array([0.1, 0.1]))


def test_perturbations_are_rigid_and_of_the_asked_size():
    rng = np.random.default_rng(3)
    X0 = np.repeat(box_grasps(np.eye(4), np.array([0.02, 0.02, 0.05]))[4:5], 4000, axis=0)
    X = perturb_grasps(X0, rng, position_std=0.01, angle_std=0.2)
    assert_rigid(X)
    gp0 = X0[:, :3, 3] + PAD_CENTER_Y * X0[:, :3, 1]
    gp = X[:, :3, 3] + PAD_CENTER_Y * X[:, :3, 1]
    # Standard deviation of 4000 normal draws: within 5 % of σ (about 4.5 standard errors).
    assert np.std(gp - gp0, axis=0) == pytest.approx([0.01] * 3, rel=0.05)
    angle = np.arccos(np.clip(np.sum(X[:, :3, 1] * X0[:, :3, 1], axis=1), -1, 1))
    # The approach axis turns by a Rayleigh(σ = 0.2)-distributed angle about the other two axes:
    # mean σ·sqrt(π/2) = 0.2507 rad; 5 % as above.
    assert angle.mean() == pytest.approx(0.2 * np.sqrt(np.pi / 2), rel=0.05)


def test_surface_grasps_approach_against_the_normal():
    rng = np.random.default_rng(4)
    # One surface point, so that every hypothesis is about it.
    p = np.array([[0.1, -0.2, 0.3]])
    n = np.array([[0.0, 0.6, 0.8]])
    X = surface_grasps(p, n, 2000, rng, max_tilt=0.5, max_depth=0.04)
    assert X.shape == (2000, 4, 4)
    assert_rigid(X)
    y = X[:, :3, 1]
    # The approach is within max_tilt of the inward normal, and uses the whole range.
    angle = np.arccos(np.clip(-y @ n[0], -1, 1))
    assert angle.max() <= 0.5 + 1e-9 and angle.max() > 0.45
    # The grasp point lies on the approach ray through the point, 0 to max_depth behind it.
    gp = X[:, :3, 3] + PAD_CENTER_Y * y
    depth = np.einsum("mj,mj->m", gp - p, y)
    # 1e-12 m: the grasp point is built on that ray, rounding only.
    np.testing.assert_allclose(gp, p + depth[:, None] * y, atol=1e-12)
    assert depth.min() >= 0 and depth.max() <= 0.04
    with pytest.raises(GraspingError, match=r"need \(N, 3\) points and normals"):
        surface_grasps(p, n[:, :2], 3, rng)


def test_clears_plane_against_the_wsg_boxes():
    urdf = ET.fromstring((files("tg_drake_models") / "wsg_50" / "wsg_50.urdf").read_text())
    body = next(c for c in urdf.iter("collision") if c.get("name") == "body_collision")
    np.testing.assert_allclose(np.array(body.find("geometry/box").get("size").split(), float),
                               BODY_BOX[1])
    np.testing.assert_allclose(np.array(body.find("origin").get("xyz").split(), float),
                               BODY_BOX[0])
    # Top-down grasp (approach −z_W): the lowest point is the open pads' tips at 0.096 m along y_G.
    X = np.eye(4)
    X[:3, :3] = np.column_stack([[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    X[2, 3] = FINGERTIP_Y + 0.003 + 1e-6
    assert clears_plane(X, 0.0, approach_distance=0.05)[0]
    X[2, 3] -= 2e-6
    assert not clears_plane(X, 0.0, approach_distance=0.05)[0]
    # From below, through the table.
    X[:3, :3] = np.column_stack([[1, 0, 0], [0, 0, 1], [0, -1, 0]])
    X[2, 3] = 0.05
    assert not clears_plane(X, 0.0, approach_distance=0.05)[0]
    # Sideways at mid height: the body's 0.05 m side is vertical, its bottom 0.025 below centre,
    # and the pads reach ±0.01 in z.
    X[:3, :3] = np.column_stack([[0, 1, 0], [1, 0, 0], [0, 0, -1]])
    X[2, 3] = 0.025 + 0.003 + 1e-6
    assert clears_plane(X, 0.0, approach_distance=0.05)[0]


def test_retreat_lifts_grasps_on_flat_objects_just_above_the_table():
    top = np.eye(4)
    top[:3, :3] = np.column_stack([[1, 0, 0], [0, 0, -1], [0, 1, 0]])  # approach −z_W
    top[2, 3] = FINGERTIP_Y - 0.02  # fingertips 2 cm under the table top
    side = np.eye(4)
    side[:3, :3] = np.column_stack([[0, 1, 0], [1, 0, 0], [0, 0, -1]])  # approach +x_W
    side[2, 3] = 0.01  # body bottom under the table: moving back along x does not help
    tilted = top.copy()
    tilted[2, 3] = FINGERTIP_Y - 0.06  # 6 cm under: more than max_retreat
    X, ok = retreat_above_plane(np.stack([top, side, tilted]), 0.0, approach_distance=0.05,
                                clearance=0.003, max_retreat=0.05)
    np.testing.assert_array_equal(ok, [True, False, False])
    # Moved back 2.3 cm along −y_G = +z_W: fingertips 3 mm above the table.
    np.testing.assert_allclose(X[0, :3, 3], top[:3, 3] + [0, 0, 0.023], atol=1e-12)
    np.testing.assert_array_equal(X[1:], np.stack([side, tilted]))  # the others unchanged
    assert clears_plane(X[0], 0.0, approach_distance=0.05, clearance=0.003 - 1e-9)[0]
