"""DI and DGI of simple shapes against hand-computed values (paper, section V-A)."""

import xml.etree.ElementTree as ET
from importlib.resources import files

import numpy as np
import pytest

from tg_drake.errors import GraspingError
from tg_drake.grasping.dgi import (
    EMPTY_DEPTH,
    FINGERTIP_Y,
    GRIPPER_BASE_Y,
    MAX_OPENING,
    PAD_CENTER_Y,
    PAD_SIZE,
    DgiConfig,
    depth_gradient_images,
    depth_images,
    dgi_features,
)

CFG = DgiConfig()


def grid(x_range, z_range, step=0.0005):
    """Points of a height field sampled every `step` along x_G and z_G."""
    x = np.arange(*x_range, step)
    z = np.arange(*z_range, step)
    xx, zz = np.meshgrid(x, z, indexing="ij")
    return xx.ravel(), zz.ravel()


def in_gripper(x, depth, z):
    """Points given by x_G, depth (from the gripper base) and z_G, as an (N, 3) cloud in G."""
    return np.stack([x, GRIPPER_BASE_Y + np.asarray(depth), z], axis=1)


def random_pose(rng):
    """A random X_WG."""
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    R = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])
    X = np.eye(4)
    X[:3, :3] = R
    X[:3, 3] = rng.uniform(-0.5, 0.5, size=3)
    return X


def to_world(p_G, X_WG):
    return p_G @ X_WG[:3, :3].T + X_WG[:3, 3]


def test_flat_plate_has_constant_depth_and_zero_gradient():
    x, z = grid((-0.08, 0.08), (-0.03, 0.03))
    p_G = in_gripper(x, np.full_like(x, 0.030), z)
    di = depth_images(p_G, np.eye(4))
    assert di.shape == (1, CFG.n_u, CFG.n_v)
    np.testing.assert_allclose(di, 0.030, atol=1e-12)  # exact: every point has depth 0.030
    np.testing.assert_allclose(depth_gradient_images(di), 0.0, atol=1e-12)


def test_step_gradient_is_the_step_height_next_to_the_edge():
    # Height field: depth 0.03 m for x_G < 0, 0.05 m for x_G ≥ 0. x_G = 0 is the boundary between
    # pixels u = 9 and u = 10 (20 pixels of 7 mm from −0.070 m).
    x, z = grid((-0.08, 0.08), (-0.03, 0.03))
    p_G = in_gripper(x, np.where(x < 0, 0.03, 0.05), z)
    di = depth_images(p_G, np.eye(4))[0]
    expected_di = np.repeat(np.r_[np.full(10, 0.03), np.full(10, 0.05)][:, None], 3, axis=1)
    np.testing.assert_allclose(di, expected_di, atol=1e-12)
    # DGI pixel i is DI pixel u = i + 1: DI(10) − DI(8) = DI(11) − DI(9) = 0.02 at u = 9, 10.
    expected_dgi = np.zeros((18, 1))
    expected_dgi[[8, 9]] = 0.02
    np.testing.assert_allclose(depth_gradient_images(di), expected_dgi, atol=1e-12)


def test_cylinder_depth_follows_its_circle():
    # A cylinder of radius r along z_G, its axis at x_G = 0 and depth c: the front surface is at
    # depth c − sqrt(r² − x²); a pixel's minimum is at the x of its cell closest to the axis.
    r, c = 0.03, 0.05
    theta = np.arange(0.0, 2 * np.pi, 0.00002 / r)  # 0.02 mm arc steps
    z = np.arange(-0.015, 0.015, 0.001)
    tt, zz = np.meshgrid(theta, z, indexing="ij")
    p_G = in_gripper(r * np.sin(tt.ravel()), c - r * np.cos(tt.ravel()), zz.ravel())
    di = depth_images(p_G, np.eye(4))[0]

    edges = -0.070 + 0.007 * np.arange(21)
    lo, hi = edges[:-1], edges[1:]
    x_star = np.where((lo <= 0) & (hi > 0), 0.0, np.minimum(np.abs(lo), np.abs(hi)))
    expected = np.where(x_star < r, c - np.sqrt(np.maximum(r**2 - x_star**2, 0.0)), EMPTY_DEPTH)
    # Pixels u = 5 and 14 reach |x| = 0.028 m: 0.05 − sqrt(0.03² − 0.028²) = 0.039230 m.
    assert expected[5] == pytest.approx(0.0392297, abs=1e-6)
    assert expected[14] == pytest.approx(0.0392297, abs=1e-6)
    assert expected[9] == expected[10] == pytest.approx(0.02)
    assert np.all(expected[:4] == EMPTY_DEPTH) and np.all(expected[16:] == EMPTY_DEPTH)
    # 1e-4 m: with 0.02 mm arc steps the sampled point nearest a cell edge is within 0.02 mm of
    # it in x, and the circle's slope there is below 2.6, so the sampled minimum is within 0.06 mm.
    np.testing.assert_allclose(di, np.repeat(expected[:, None], 3, axis=1), atol=1e-4)
    dgi = depth_gradient_images(di)
    np.testing.assert_allclose(dgi[:, 0], np.abs(expected[2:] - expected[:-2]), atol=2e-4)
    # The edges of the cylinder (empty → surface) dominate the gradient.
    assert dgi[:, 0].max() == pytest.approx(0.0392297 + 1.0, abs=1e-4)


def test_features_scale_depths_and_keep_empty_pixels_apart():
    # The step: DI 0.03 / 0.05 m; features measure from the volume's back face (0.021 m behind the
    # base) at 25 units per metre: 1.275 and 1.775; the DGI is taken of those.
    x, z = grid((-0.08, 0.08), (-0.0105, 0.0105))
    p_G = in_gripper(x, np.where(x < 0, 0.03, 0.05), z)
    f = dgi_features(p_G, np.eye(4))[0]
    n_di = CFG.n_u * CFG.n_v
    expected = np.repeat(np.r_[np.full(10, 1.275), np.full(10, 1.775)][:, None], 3, axis=1)
    np.testing.assert_allclose(f[:n_di].reshape(20, 3), expected, atol=1e-12)
    expected_dgi = np.zeros(18)
    expected_dgi[[8, 9]] = 0.5
    np.testing.assert_allclose(f[n_di:], expected_dgi, atol=1e-12)
    # An object reaching 1 cm into the palm is at 0.275 units; empty stays −1.
    p_G = in_gripper(x[x < 0], np.full(np.sum(x < 0), -0.01), z[x < 0])
    f = dgi_features(p_G, np.eye(4))[0, :n_di].reshape(20, 3)
    np.testing.assert_allclose(f[:10], 0.275, atol=1e-12)
    np.testing.assert_array_equal(f[10:], EMPTY_DEPTH)


def test_empty_volume_gives_minus_one_and_zero_gradient():
    x, z = grid((-0.08, 0.08), (-0.03, 0.03))
    behind_palm = in_gripper(x, np.full_like(x, -0.022), z)  # behind the volume's back face
    past_tips = in_gripper(x, np.full_like(x, FINGERTIP_Y - GRIPPER_BASE_Y + 0.001), z)
    beside = in_gripper(x, np.full_like(x, 0.03), z + 0.05)  # beyond the pads' width
    for cloud in (behind_palm, past_tips, beside):
        f = dgi_features(cloud, np.eye(4))
        n_di = CFG.n_u * CFG.n_v
        np.testing.assert_array_equal(f[0, :n_di], EMPTY_DEPTH)
        np.testing.assert_array_equal(f[0, n_di:], 0.0)


def test_features_do_not_depend_on_the_world_frame_and_are_vectorised():
    rng = np.random.default_rng(7)
    # Offset by 0.37 mm so that no point lies on a cell boundary, where rounding decides the cell.
    x, z = grid((-0.08037, 0.08), (-0.03037, 0.03), step=0.001)
    p_G = in_gripper(x, 0.02 + 0.3 * x**2 + 0.1 * z, z)
    X_WGs = np.stack([random_pose(rng) for _ in range(3)])
    # The same shape seen from three poses: the cloud is placed in W relative to each pose in turn,
    # and every cloud is scored against all three poses at once.
    for k in range(3):
        f_all = dgi_features(to_world(p_G, X_WGs[k]), X_WGs)
        assert f_all.shape == (3, CFG.n_features)
        f_ref = dgi_features(p_G, np.eye(4))[0]
        # 1e-12 m: only the rounding of one rotation and translation separates the two.
        np.testing.assert_allclose(f_all[k], f_ref, atol=1e-12)
        for j in range(3):
            np.testing.assert_allclose(
                f_all[j], dgi_features(to_world(p_G, X_WGs[k]), X_WGs[j])[0], atol=1e-15)


def test_bad_inputs_are_clear_errors():
    cloud = np.zeros((5, 3))
    with pytest.raises(GraspingError, match=r"point cloud must be \(N, 3\)"):
        dgi_features(np.zeros((5, 2)), np.eye(4))
    with pytest.raises(GraspingError, match="NaN"):
        dgi_features(np.full((5, 3), np.nan), np.eye(4))
    with pytest.raises(GraspingError, match=r"must be \(4, 4\) or \(M, 4, 4\)"):
        dgi_features(cloud, np.eye(3))
    bad = np.eye(4)
    bad[0, 0] = 2.0
    with pytest.raises(GraspingError, match=r"X_WG\[0\] has a rotation that is not orthonormal"):
        dgi_features(cloud, bad)
    with pytest.raises(GraspingError, match="must be ≥ 3"):
        DgiConfig(n_v=2)


def test_constants_match_the_wsg_model():
    urdf = ET.fromstring((files("tg_drake_models") / "wsg_50" / "wsg_50.urdf").read_text())
    links = {link.get("name"): link for link in urdf.findall("link")}
    joints = {j.get("name"): j for j in urdf.findall("joint")}  # (not a transmission's)
    for side, sign in (("left", -1.0), ("right", 1.0)):
        pad = links[f"{side}_finger"].find("collision")
        size = np.array(pad.find("geometry/box").get("size").split(), dtype=float)
        pose = np.array(pad.find("origin").get("xyz").split(), dtype=float)
        np.testing.assert_allclose(size, PAD_SIZE)
        assert pose[1] == pytest.approx(PAD_CENTER_Y)
        limit = joints[f"{side}_finger_sliding_joint"].find("limit")
        stroke = float(limit.get("upper" if sign > 0 else "lower"))
        # The pad's inner face at full stroke: its centre offset minus half its thickness.
        inner_face = stroke + pose[0] - sign * PAD_SIZE[0] / 2
        assert abs(inner_face) == pytest.approx(MAX_OPENING / 2)
    # The volume covers both open pads and their width.
    assert CFG.half_extent_x >= MAX_OPENING / 2 + PAD_SIZE[0]
    assert CFG.half_extent_z >= PAD_SIZE[2] / 2
