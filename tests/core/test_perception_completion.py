"""Symmetry completion and the circle test on synthetic clouds with known answers.

Partial views as a camera sees them: numpy-sampled surfaces keep only the points facing the eye
(back-face culling, exact for these convex shapes) plus 1 mm of Gaussian noise; shapes with
self-occlusion (a mug) are ray cast.
"""

import numpy as np
import pytest

from tg_drake.errors import PerceptionError
from tg_drake.evaluation.split import load_split
from tg_drake.objects import forget_registered
from tg_drake.perception import synthetic as S
from tg_drake.perception.completion import circle_test, complete
from tg_drake.perception.config import CompletionConfig
from tg_drake.perception.geometry import (
    Intrinsics,
    estimate_normals,
    inverse,
    make_transform,
    transform,
)
from tg_drake.perception.pipeline import describe_cloud, describe_object
from tg_drake.perception.pose import load_pose_calibration
from tg_drake.perception.render import perceive
from tg_drake.perception.segmentation import segment_depth
from tg_drake.perception.sensor_model import StructuredLight

NOISE = 0.001  # 1 mm depth noise
EYE = np.array([0.55, 0.15, 0.5])  # camera 45° above the table, 0.75 m away


# A vertical solid with a flat closed top shows nothing of which end is up: its pose is the one
# the training views with a flat end on top rested in more often (`PoseCalibration.flat_sign`).
FLAT_POSE = "upright" if load_pose_calibration().flat_sign > 0 else "upsidedown"


def rz(yaw):
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def view(p, n, X_WO, seed=0):
    return S.partial_view(p, n, X_WO, EYE, NOISE, np.random.default_rng(seed))


def test_upright_cylinder_centroid_from_a_partial_view():
    p, n = S.cylinder_points(0.035, 0.12, 20000, np.random.default_rng(0))
    centre = np.array([0.04, -0.03])
    p_W = view(p, n, make_transform(np.eye(3), [*centre, 0.0]))
    # The visible half's centroid is far off: that is what the completion must fix.
    assert np.linalg.norm(p_W[:, :2].mean(axis=0) - centre) > 0.015
    o = describe_cloud(p_W, np.eye(4), EYE)
    # 1 cm: the bound (measured: 3 mm, from the noise at the rim of the top face).
    np.testing.assert_allclose(o.X_WO[:2, 3], centre, atol=0.01)
    assert o.X_WO[2, 3] == pytest.approx(0.06, abs=0.005)  # half the height; 3σ noise on d_z
    np.testing.assert_allclose(np.abs(o.X_WO[:3, 2]), [0, 0, 1], atol=1e-9)  # axis = normal
    # 7 mm per side: 4 mm voxels and 1 mm noise widen the box.
    np.testing.assert_allclose(np.sort(o.extents[:2]), [0.07, 0.07], atol=0.007)
    # A plain cylinder's ends are alike (a flat closed top on a straight wall): which is up is
    # the flat end's calibrated sign.
    assert o.pose == FLAT_POSE
    # The completion fills the far side wall (below the top face, away from the camera).
    away = (o.p_W[:, :2] - centre) @ (centre - EYE[:2]) / np.linalg.norm(centre - EYE[:2])
    far_wall = (away > 0.02) & (o.p_W[:, 2] < 0.1)
    assert far_wall[~o.visible].sum() > 100
    assert far_wall[o.visible].sum() == 0  # it was not seen


def test_sideways_cylinder_axis_and_centroid():
    p, n = S.cylinder_points(0.035, 0.14, 20000, np.random.default_rng(1))
    yaw = 0.5
    R = rz(yaw) @ np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # z → x
    X_WO = make_transform(R, [0.0, 0.05, 0.035])
    o = describe_cloud(view(p - [0.0, 0.0, 0.07], n, X_WO), np.eye(4), EYE)
    assert o.pose == "sideways"
    axis = np.array([np.cos(yaw), np.sin(yaw), 0.0])
    # 6°: W's PCA is tilted by the visible end face.
    assert abs(o.X_WO[:3, 2] @ axis) > np.cos(np.radians(6))
    np.testing.assert_allclose(o.X_WO[:3, 3], [0.0, 0.05, 0.035], atol=0.01)
    assert o.extents[2] == pytest.approx(0.14, abs=0.01)


@pytest.mark.parametrize("size, pose", [((0.1, 0.06, 0.2), FLAT_POSE),
                                        ((0.2, 0.06, 0.05), "sideways")])
def test_box_axis_is_the_direction_left_by_the_closest_pair(size, pose):
    p, n = S.box_points(size, 20000, np.random.default_rng(2))
    o = describe_cloud(view(p, n, make_transform(rz(0.3), [0.0, 0.0, 0.0])), np.eye(4), EYE)
    assert o.pose == pose
    long_axis = (rz(0.3) @ np.eye(3))[:, int(np.argmax(size))]
    assert abs(o.X_WO[:3, 2] @ long_axis) > np.cos(np.radians(6))


def test_normals_point_outwards_after_completion():
    p, n = S.cylinder_points(0.035, 0.12, 20000, np.random.default_rng(3))
    o = describe_cloud(view(p, n, np.eye(4)), np.eye(4), EYE)
    out = np.einsum("ij,ij->i", o.n_W, o.p_W - o.X_WO[:3, 3])
    assert (out >= 0).all()
    np.testing.assert_allclose(np.linalg.norm(o.n_W, axis=1), 1.0, atol=1e-9)
    # Side-wall normals (away from the caps) are radial within 15° (noise on k-nn normals).
    side = (o.p_W[:, 2] > 0.02) & (o.p_W[:, 2] < 0.1)
    radial = o.p_W[side, :2] / np.linalg.norm(o.p_W[side, :2], axis=1, keepdims=True)
    cos = np.einsum("ij,ij->i", o.n_W[side, :2], radial)
    assert np.median(cos) > np.cos(np.radians(15))


def circle(n, radius, rng):
    phi = rng.uniform(0, 2 * np.pi, n)
    return radius * np.column_stack([np.cos(phi), np.sin(phi)]) * rng.uniform(0.3, 1.0, (n, 1))


def test_circle_test_finds_a_handle():
    rng = np.random.default_rng(4)
    disk = circle(3000, 0.04, rng)
    fit = circle_test(disk, CompletionConfig())
    assert fit.ok and not fit.handle.any()
    assert fit.radius == pytest.approx(0.04, rel=0.02)  # outline of 3000 points: < 2 % short
    # A handle: a 1.2 cm wide strip from the wall out to 7 cm along −y.
    handle = np.column_stack([rng.uniform(-0.006, 0.006, 300), rng.uniform(-0.07, -0.045, 300)])
    fit = circle_test(np.vstack([disk, handle]), CompletionConfig())
    assert fit.ok
    assert fit.handle[len(disk):].all() and not fit.handle[:len(disk)].any()
    np.testing.assert_allclose(fit.handle_direction, [0.0, -1.0], atol=0.05)


def test_circle_test_rejects_squares_and_rectangles():
    rng = np.random.default_rng(5)
    square = rng.uniform(-0.04, 0.04, (3000, 2))
    assert not circle_test(square, CompletionConfig()).ok
    rectangle = rng.uniform(-1, 1, (3000, 2)) * [0.1, 0.035]
    assert not circle_test(rectangle, CompletionConfig()).ok


@pytest.fixture(scope="module")
def mug_view():
    K = Intrinsics.from_fov(640, 480, np.pi / 4)
    X_WC = S.look_at(np.array([0.6, 0.3, 0.55]), np.array([0.0, 0.0, 0.05]))
    yaw = 2.5  # handle towards −x, +y: seen from the side
    mesh = S.placed(S.mug(0.04, 0.095), make_transform(rz(yaw), [0.0, 0.0, 0.0]))
    depth = S.render_depth([S.table_mesh(), mesh], K, X_WC)
    seg = segment_depth(depth, K, X_WC)
    return seg, X_WC, np.array([np.cos(yaw), np.sin(yaw), 0.0])


def test_mug_handle_is_kept_not_mirrored(mug_view):
    seg, X_WC, handle_dir = mug_view
    q = seg.objects_T[0]
    p_TC = np.linalg.solve(seg.X_WT, np.append(X_WC[:3, 3], 1.0))[:3]
    c = complete(q, estimate_normals(q, p_TC, 12))
    assert c.vertical and c.circle is not None and c.circle.ok
    assert c.circle.radius == pytest.approx(0.04, abs=0.004)  # one 4 mm voxel
    R_WT = seg.X_WT[:3, :3]
    assert (R_WT @ c.handle_direction_T) @ handle_dir > np.cos(np.radians(15))
    # Handle points stick out beyond the body, on the handle's side only.
    radial = c.p_T[:, :2] - c.p_TA[:2]
    beyond = np.linalg.norm(radial, axis=1) > 0.05
    assert c.handle.sum() > 20
    assert (radial[beyond] @ (R_WT.T @ handle_dir)[:2] > 0).all()  # no phantom handle


def test_completion_rejects_bad_input():
    with pytest.raises(PerceptionError, match="at least 10 visible points, got 3"):
        complete(np.ones((3, 3)), np.ones((3, 3)))
    with pytest.raises(PerceptionError, match="non-finite"):
        complete(np.full((20, 3), np.nan), np.ones((20, 3)))
    with pytest.raises(PerceptionError, match=r"\(N, 3\) points and normals"):
        complete(np.ones((20, 2)), np.ones((20, 2)))
    with pytest.raises(PerceptionError, match="not above the table"):
        complete(np.column_stack([np.ones((20, 2)), -np.ones(20)]), np.ones((20, 3)))


def _lying_library_object(obj_id, yaw_deg, camera):
    """A library object lying on its side, yawed, seen from one of eval_perception's cameras."""
    import open3d as o3d

    from tg_drake.objects import get_object, mesh

    obj = get_object(obj_id)
    V, F, _ = mesh(obj)
    m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(np.array(V)),
                                  o3d.utility.Vector3iVector(np.array(F, dtype=np.int32)))
    X_TO = make_transform(rz(np.radians(yaw_deg)), [0.0, 0.0, 0.0]) @ obj.poses["sideways"].X_TO
    az, el, d = {"left": (50.0, 40.0, 0.85), "right": (-50.0, 45.0, 0.85)}[camera]
    a, e = np.radians(az), np.radians(el)
    eye = d * np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)]) + [0, 0, 0.05]
    K = Intrinsics.from_fov(640, 480, np.radians(45.0))
    X_WC = S.look_at(eye, np.array([0.0, 0.0, 0.05]))
    depth = S.render_depth([S.table_mesh((0.8, 1.2)), S.placed(m, X_TO)], K, X_WC)
    scene = segment_depth(depth, K, X_WC)
    assert len(scene.objects_T) == 1
    p_TC = transform(inverse(scene.X_WT), eye[None])[0]
    return X_TO, describe_object(scene.objects_T[0], scene.X_WT, p_TC)


@pytest.mark.parametrize("obj_id, yaw_deg, camera", [("pot_01", 0.0, "left"),
                                                     ("pot_02", 270.0, "right"),
                                                     ("pot_03", 270.0, "left")])
def test_a_squat_pot_lying_down_gets_its_axis_from_the_normals(obj_id, yaw_deg, camera):
    # Seen from the side, a pot lying down shows a nearly square footprint with its handles: W's
    # box directions were 60-70° off its axis, and the circle test also passed about them. The
    # axis the normals give is a candidate, and among lying axes that pass alike the one whose
    # normals meet it (a surface of revolution) is kept.
    X_TO, o = _lying_library_object(obj_id, yaw_deg, camera)
    assert o.pose == "sideways"
    assert abs(o.X_WO[:3, 2] @ X_TO[:3, 2]) > np.cos(np.radians(10))


# Perceived views (the D415 model, seeded) of training objects where no circle test passes.
NARROW_MISSES = [("cup_b01", "upsidedown", 120.0, 1142), ("glass_b02", "upsidedown", 0.0, 1159),
                 ("can_b01", "upright", 120.0, 1181)]
LONG_BOXES = [("knife_03", "sideways", 240.0, 1062), ("cooking_tool_02", "sideways", 240.0, 1077)]


@pytest.mark.parametrize("object_id, pose, yaw, seed", NARROW_MISSES + LONG_BOXES)
def test_when_no_circle_test_passes_the_clearly_surest_axis_whose_circle_explains_the_box_wins(
        object_id, pose, yaw, seed):
    """Vertical containers whose vertical circle test misses the pass mark by a bin or two (a
    handle, noise at the far rim) are far rounder about it than about any lying axis: their
    vertical test is the surest and its circle explains the box, so they stand (the paper's
    closest-dimensions rule alone laid them down). Lying tools whose vertical test happens to
    be the surest keep their lying axis: their box is several times longer than that circle."""
    forget_registered()
    try:
        load_split().register_libraries()
        d = perceive(object_id, pose, yaw, sensor=StructuredLight(), seed=seed)
    finally:
        forget_registered()
    assert (d.pose == "sideways") == (pose == "sideways")
