"""Back-projection, transforms, voxel averaging and normals of the perception core."""

import numpy as np
import pytest

from tg_drake.errors import PerceptionError
from tg_drake.perception.geometry import (
    Intrinsics,
    check_transform,
    depth_to_points,
    estimate_normals,
    inverse,
    make_transform,
    transform,
    voxel_average,
)
from tg_drake.perception.synthetic import look_at

K = Intrinsics(width=64, height=48, fx=50.0, fy=55.0, cx=31.5, cy=23.5)


def test_back_projection_follows_drakes_pinhole_model():
    # Camera 1 m above the floor looking straight down: every pixel sees the plane z = 0.
    X_WC = look_at(np.array([0.2, -0.1, 1.0]), np.array([0.2, -0.1, 0.0]))
    depth = np.ones((K.height, K.width), np.float32)
    p_W, pixels = depth_to_points(depth, K, X_WC)
    assert p_W.shape == (K.width * K.height, 3)
    np.testing.assert_allclose(p_W[:, 2], 0.0, atol=1e-9)  # float64 arithmetic on depth 1.0
    # Pixel (row 10, column 40) sees ((u − cx)/fx, (v − cy)/fy, 1) in C (X right, Y down).
    i = np.flatnonzero((pixels[:, 0] == 10) & (pixels[:, 1] == 40))[0]
    p_C = np.array([(40 - K.cx) / K.fx, (10 - K.cy) / K.fy, 1.0])
    np.testing.assert_allclose(p_W[i], transform(X_WC, p_C[None])[0], atol=1e-12)
    # Image right (+X_C) and image down (+Y_C) are orthogonal directions on the floor.
    right = p_W[np.flatnonzero((pixels[:, 0] == 10) & (pixels[:, 1] == 41))[0]] - p_W[i]
    down = p_W[np.flatnonzero((pixels[:, 0] == 11) & (pixels[:, 1] == 40))[0]] - p_W[i]
    assert right @ down == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(np.linalg.norm(right), 1 / K.fx)
    np.testing.assert_allclose(np.linalg.norm(down), 1 / K.fy)


def test_back_projection_skips_no_return_pixels_and_checks_sizes():
    X_WC = look_at(np.array([0.0, 0.0, 1.0]), np.zeros(3))
    depth = np.full((K.height, K.width, 1), 0.8, np.float32)  # Drake's (H, W, 1) layout
    depth[0, 0] = np.inf  # too far
    depth[1, 1] = 0.0  # too close
    depth[2, 2] = np.nan
    p_W, pixels = depth_to_points(depth, K, X_WC)
    assert len(p_W) == K.width * K.height - 3
    assert not ((pixels[:, 0] == 1) & (pixels[:, 1] == 1)).any()
    with pytest.raises(PerceptionError, match=r"depth image is \(48, 64\).*\(64, 48\)"):
        depth_to_points(np.ones((64, 48)), K, X_WC)
    with pytest.raises(PerceptionError, match="X_WC has a rotation block"):
        depth_to_points(depth, K, np.diag([1.0, 1.0, -1.0, 1.0]))
    with pytest.raises(PerceptionError, match="X_WC must be a finite 4×4"):
        depth_to_points(depth, K, np.eye(3))


def test_intrinsics_from_fov_matches_drakes_camera_info():
    from pydrake.systems.sensors import CameraInfo

    info = CameraInfo(width=640, height=480, fov_y=np.pi / 4)
    a = Intrinsics.from_camera_info(info)
    b = Intrinsics.from_fov(640, 480, np.pi / 4)
    for f in ("width", "height", "fx", "fy", "cx", "cy"):
        assert getattr(a, f) == pytest.approx(getattr(b, f), rel=1e-12), f  # same formula


def test_transforms_round_trip():
    rng = np.random.default_rng(1)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))
    X = make_transform(q, [0.1, 0.2, 0.3])
    p = rng.normal(size=(10, 3))
    np.testing.assert_allclose(transform(inverse(X), transform(X, p)), p, atol=1e-12)
    check_transform(X, "X")


def test_voxel_average_means_points_per_voxel():
    p = np.array([[0.001, 0.001, 0.001], [0.003, 0.003, 0.003], [0.011, 0.0, 0.0]])
    q, index = voxel_average(p, 0.005)
    assert len(q) == 2
    np.testing.assert_allclose(q[index[0]], [0.002, 0.002, 0.002])
    assert index[0] == index[1] != index[2]


def test_normals_point_to_the_viewpoint():
    rng = np.random.default_rng(0)
    p = np.column_stack([rng.uniform(-0.05, 0.05, (400, 2)), np.zeros(400)])
    n = estimate_normals(p, np.array([0.3, 0.0, 0.5]), 12)
    np.testing.assert_allclose(n, np.tile([0.0, 0.0, 1.0], (400, 1)), atol=1e-9)  # exact plane
