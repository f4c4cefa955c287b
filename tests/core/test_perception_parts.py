"""Pose, parts, part boxes and pre-grasp hypotheses on ray-cast views of known shapes."""

import numpy as np
import pytest

from tg_drake.errors import PerceptionError
from tg_drake.perception import synthetic as S
from tg_drake.perception.geometry import Intrinsics, make_transform
from tg_drake.perception.pipeline import describe_cloud, describe_scene
from tg_drake.perception.pregrasp import WSG_GRASP_POINT_G, box_pregrasps
from tg_drake.types import PART_LABELS

K = Intrinsics.from_fov(640, 480, np.pi / 4)
# Three viewpoints around the table, 35° to 60° above it.
EYES = [np.array([0.7, 0.0, 0.7]), np.array([0.45, 0.45, 0.85]), np.array([-0.3, 0.6, 0.5])]


def rz(yaw):
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def describe(mesh, eye, yaw=0.3):
    X_WC = S.look_at(eye, np.array([0.0, 0.0, 0.05]))
    depth = S.render_depth([S.table_mesh(), S.placed(mesh, make_transform(rz(yaw), [0, 0, 0]))],
                           K, X_WC)
    scene = describe_scene(depth, K, X_WC)
    assert len(scene.objects) == 1
    return scene.objects[0]


SHAPES = {
    # name: (mesh, pose, parts)
    "cup": (S.cup(0.04, 0.09), "upright", {"top", "middle", "bottom"}),
    "mug": (S.mug(0.04, 0.095), "upright", {"top", "middle", "bottom", "handle"}),
    "bottle": (S.bottle(0.035, 0.25, 0.013), "upright", {"top", "middle", "bottom"}),
    "pan": (S.pan(), "upright", {"top", "middle", "bottom", "handle"}),
    "glass_upside_down": (S.upside_down(S.glass(0.028, 0.038, 0.12), 0.12), "upsidedown",
                          {"top", "middle", "bottom"}),
    "bowl_upside_down": (S.upside_down(S.glass(0.04, 0.08, 0.06), 0.06), "upsidedown",
                         {"top", "middle", "bottom"}),
    "bottle_lying": (S.lying(S.bottle(0.035, 0.25, 0.013), 0.035), "sideways",
                     {"top", "middle", "bottom"}),
    "mug_lying_handle_up": (S.lying(S.mug(0.04, 0.095), 0.04), "sideways",
                            {"top", "middle", "bottom", "handle"}),
    "hammer": (S.hammer(), "sideways", {"handle", "usable_area"}),
}


@pytest.mark.parametrize("name", sorted(SHAPES))
@pytest.mark.parametrize("view", range(len(EYES)))
def test_pose_and_part_set(name, view):
    mesh, pose, parts = SHAPES[name]
    o = describe(mesh, EYES[view])
    assert o.pose == pose
    assert max(o.pose_likelihood, key=o.pose_likelihood.get) == pose
    assert set(o.part_probabilities) == parts
    assert all(0.5 <= p <= 1.0 for p in o.part_probabilities.values())
    assert o.is_tool == (name == "hammer")
    assert set(np.unique(o.labels)) == {PART_LABELS.index(p) for p in parts}


def test_cavity_makes_an_open_cup_surely_upright():
    o = describe(SHAPES["cup"][0], EYES[0])
    assert o.pose_likelihood["upright"] > 0.9


@pytest.mark.parametrize("view", range(len(EYES)))
def test_the_inside_is_seen_through_an_open_top_only(view):
    # Open containers standing up show their inside; a closed can, a bottle's narrow neck, an
    # upside-down glass and a tool do not.
    seen = {name: describe(mesh, EYES[view]).interior_seen for name, mesh in (
        ("cup", SHAPES["cup"][0]), ("glass", S.glass(0.028, 0.038, 0.12)),
        ("can", S.cylinder(0.033, 0.12)), ("bottle", SHAPES["bottle"][0]),
        ("glass_upside_down", SHAPES["glass_upside_down"][0]), ("hammer", SHAPES["hammer"][0]))}
    assert seen["cup"] > 0.9 and seen["glass"] > 0.9
    assert seen["can"] == seen["bottle"] == seen["glass_upside_down"] == seen["hammer"] == 0.0


def test_top_middle_bottom_follow_the_axis_and_the_handle_is_outside():
    o = describe(SHAPES["mug"][0], EYES[1], yaw=1.0)
    z = o.p_W[:, 2]
    top, middle, bottom, handle = (o.labels == PART_LABELS.index(p)
                                   for p in ("top", "middle", "bottom", "handle"))
    assert z[bottom].max() < z[middle].min() + 0.005 < z[top].min() + 0.01
    # Handle points lie beyond the body's 4 cm radius, towards the handle's side (+x_O).
    r = o.p_W[handle, :2] - o.X_WO[:2, 3]
    x_O = o.X_WO[:2, 0]
    assert (r @ x_O > 0).all()
    handle_dir = rz(1.0)[:2, 0]
    assert x_O @ handle_dir > np.cos(np.radians(15))
    # The part boxes are aligned with O and stacked along its z.
    zs = [o.part_boxes[p].X_WB[2, 3] for p in ("bottom", "middle", "top")]
    assert zs == sorted(zs)


def test_hammer_usable_area_is_the_head():
    yaw = 0.3
    o = describe(SHAPES["hammer"][0], EYES[2], yaw=yaw)
    head_W = rz(yaw) @ np.array([0.265, 0.0, 0.015])  # the head's centre (see S.hammer)
    usable = o.labels == PART_LABELS.index("usable_area")
    assert np.linalg.norm(o.p_W[usable].mean(axis=0)[:2] - head_W[:2]) < 0.03
    # O's z runs from the handle to the usable area, along the hammer's handle.
    assert o.X_WO[:3, 2] @ rz(yaw)[:, 0] > np.cos(np.radians(5))
    box = o.part_boxes["usable_area"]
    assert 2 * box.half_extents.max() == pytest.approx(0.1, abs=0.01)  # the head's length


def test_pregrasps_two_per_face_of_each_part_box():
    o = describe(SHAPES["bottle"][0], EYES[0])
    assert o.pregrasp_X_WG.shape == (12 * len(o.part_boxes), 4, 4)
    for name, box in o.part_boxes.items():
        X = o.pregrasp_X_WG[o.pregrasp_parts == PART_LABELS.index(name)]
        assert len(X) == 12
        R = X[:, :3, :3]
        np.testing.assert_allclose(np.einsum("nji,njk->nik", R, R), np.tile(np.eye(3), (12, 1, 1)),
                                   atol=1e-9)
        np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-9)
        # The grasp point is inside the box (1e-9: round-off), the approach (+y_G) points into
        # it and the fingers close (±x_G) along a box axis.
        p_grasp = X[:, :3, 3] + R @ WSG_GRASP_POINT_G
        local = (p_grasp - box.X_WB[:3, 3]) @ box.X_WB[:3, :3]
        assert (np.abs(local) <= box.half_extents + 1e-9).all()
        to_centre = box.X_WB[:3, 3] - p_grasp
        assert (np.einsum("ni,ni->n", R[:, :, 1], to_centre) >= -1e-9).all()
        assert np.allclose(np.abs(R[:, :, 0] @ box.X_WB[:3, :3]).max(axis=1), 1.0)
        # Two per face: the 6 faces' approach directions, each twice, fingers crossed.
        approach = np.round(R[:, :, 1] @ box.X_WB[:3, :3]).astype(int)
        assert len({tuple(a) for a in approach}) == 6
        assert all((approach == a).all(axis=1).sum() == 2 for a in approach)


def test_box_pregrasp_geometry():
    X_WB = make_transform(np.eye(3), [0.0, 0.0, 0.5])
    X = box_pregrasps(X_WB, np.array([0.05, 0.02, 0.01]))
    # Face +x: approach along −x, grasp point 2 cm inside the face (grasp_depth), G 5.5 cm back.
    top = X[0]
    np.testing.assert_allclose(top[:3, 1], [-1, 0, 0])
    np.testing.assert_allclose(top[:3, 3] + top[:3, :3] @ WSG_GRASP_POINT_G, [0.03, 0, 0.5])
    np.testing.assert_allclose(top[:3, 3], [0.03 + 0.055, 0, 0.5])
    # Face +z: the box is 2 cm deep, so the grasp point is at its centre (half the depth).
    face_z = X[8]
    np.testing.assert_allclose(face_z[:3, 3] + face_z[:3, :3] @ WSG_GRASP_POINT_G, [0, 0, 0.5])


def test_describe_cloud_rejects_bad_input():
    with pytest.raises(PerceptionError, match="non-empty"):
        describe_cloud(np.zeros((0, 3)), np.eye(4), np.ones(3))
    with pytest.raises(PerceptionError, match="at least 20 visible points, got 1"):
        describe_cloud(np.array([[0.0, 0.0, 0.05]]), np.eye(4), np.ones(3))
    with pytest.raises(PerceptionError, match="NaN or inf"):
        describe_cloud(np.full((50, 3), np.nan), np.eye(4), np.ones(3))
    rng = np.random.default_rng(0)
    below = rng.uniform(-0.05, 0.05, (500, 3)) - [0.0, 0.0, 0.1]
    with pytest.raises(PerceptionError, match="below the table plane"):
        describe_cloud(below, np.eye(4), np.ones(3))
    with pytest.raises(PerceptionError, match="X_WT"):
        describe_cloud(below, np.eye(3), np.ones(3))


def test_rim_pregrasps_on_a_wide_upright_top_only():
    from tg_drake.perception.config import PregraspConfig
    from tg_drake.perception.pregrasp import rim_pregrasps

    cfg = PregraspConfig()
    X_WB = make_transform(np.eye(3), [0.7, 0.1, 0.05])  # a bowl's top: 16 cm across, 2 cm high
    X = rim_pregrasps(X_WB, np.array([0.08, 0.08, 0.01]), cfg)
    assert X.shape == (cfg.rim_azimuths, 4, 4)
    R = X[:, :3, :3]
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-9)
    np.testing.assert_allclose(R[:, :, 1], np.tile([0.0, 0.0, -1.0], (len(X), 1)), atol=1e-12)
    p_grasp = X[:, :3, 3] + R @ WSG_GRASP_POINT_G
    radial = p_grasp[:, :2] - [0.7, 0.1]
    # On the wall (rim_wall inside the outer radius), rim_depth below the rim, fingers closing
    # radially, spread evenly around the axis.
    np.testing.assert_allclose(np.linalg.norm(radial, axis=1), 0.08 - cfg.rim_wall, atol=1e-12)
    np.testing.assert_allclose(p_grasp[:, 2], 0.06 - cfg.rim_depth, atol=1e-12)
    np.testing.assert_allclose(np.abs(np.einsum("ni,ni->n", R[:, :2, 0], radial)),
                               0.08 - cfg.rim_wall, atol=1e-12)
    assert len({round(float(np.arctan2(*r[::-1])), 6) for r in radial}) == cfg.rim_azimuths
    # A top the gripper spans gets none; nor does a top that does not face up (lying sideways).
    assert rim_pregrasps(X_WB, np.array([0.04, 0.04, 0.01]), cfg).shape == (0, 4, 4)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # 90° about x
    sideways = make_transform(rx, [0.7, 0.1, 0.08])
    assert rim_pregrasps(sideways, np.array([0.08, 0.08, 0.01]), cfg).shape == (0, 4, 4)


def test_a_closed_top_gets_no_rim_grasps():
    # A rim grasp puts a finger inside: where perception saw no inside (a lid), none is made.
    from tg_drake.perception.pregrasp import part_pregrasps

    X_WB = np.eye(4)
    X_WB[:3, 3] = [0.7, 0.1, 0.06]
    boxes = {"top": (X_WB, np.array([0.08, 0.08, 0.01]))}
    X_open, _ = part_pregrasps(boxes, PART_LABELS.index)
    X_closed, parts = part_pregrasps(boxes, PART_LABELS.index, open_top=False)
    assert len(X_closed) == 12 and len(X_open) > 12  # the box faces only
    assert set(parts.tolist()) == {PART_LABELS.index("top")}


def test_a_long_part_also_gets_grasps_along_it_closing_across_it():
    from tg_drake.perception.config import PregraspConfig
    from tg_drake.perception.pregrasp import along_pregrasps

    cfg = PregraspConfig()
    X_WB = np.eye(4)
    X_WB[:3, 3] = [0.6, 0.1, 0.015]
    handle = np.array([0.12, 0.015, 0.015])  # half extents: 24 cm along x
    X = along_pregrasps(X_WB, handle, cfg)
    # The four long faces, each with its pose closing across x, shifted both ways.
    assert X.shape == (8, 4, 4)
    assert np.all(np.abs(X[:, :3, 0] @ [1.0, 0.0, 0.0]) < 1e-12)
    p_grasp = X[:, :3, 3] + np.einsum("nij,j->ni", X[:, :3, :3], WSG_GRASP_POINT_G)
    shift = cfg.along_fraction * handle[0]
    np.testing.assert_allclose(np.sort(np.unique(np.round(p_grasp[:, 0], 9))),
                               [0.6 - shift, 0.6 + shift], atol=1e-12)
    # A short box, or one not twice as long as it is wide, gets none.
    assert along_pregrasps(X_WB, np.array([0.03, 0.015, 0.015]), cfg).shape == (0, 4, 4)
    assert along_pregrasps(X_WB, np.array([0.06, 0.04, 0.015]), cfg).shape == (0, 4, 4)
