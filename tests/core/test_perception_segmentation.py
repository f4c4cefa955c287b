"""Table plane and object clusters from ray-cast depth images of primitives on a table, end to end
through `describe_scene`, and the segmentation's bad inputs."""

import numpy as np
import pytest

from tg_drake.errors import PerceptionError
from tg_drake.perception import synthetic as S
from tg_drake.perception.config import PerceptionConfig, SegmentationConfig
from tg_drake.perception.geometry import Intrinsics, make_transform, transform
from tg_drake.perception.pipeline import describe_scene
from tg_drake.perception.pose import load_pose_calibration
from tg_drake.perception.segmentation import segment_depth

K = Intrinsics.from_fov(640, 480, np.pi / 4)
TABLE_Z = 0.74  # table top height in the world [m]
EYE = np.array([0.75, -0.2, TABLE_Z + 0.65])
X_WC = S.look_at(EYE, np.array([0.0, 0.0, TABLE_Z + 0.05]))


def on_table(mesh, x, y, yaw=0.0):
    c, s = np.cos(yaw), np.sin(yaw)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return S.placed(mesh, make_transform(R, [x, y, TABLE_Z]))


def table():
    return S.placed(S.table_mesh(), make_transform(np.eye(3), [0.0, 0.0, TABLE_Z]))


# Three objects with their true (x, y) in the world.
OBJECTS = {
    "can": (S.cylinder(0.033, 0.12), (-0.15, -0.12)),
    "mug": (S.mug(0.04, 0.095), (0.05, 0.15)),
    "box": (S.box((0.1, 0.06, 0.2)), (0.12, -0.1)),
}


@pytest.fixture(scope="module")
def three_objects():
    meshes = [table()] + [on_table(m, *xy, yaw=0.4) for m, xy in OBJECTS.values()]
    return S.render_depth(meshes, K, X_WC)


def test_table_plane_and_three_clusters(three_objects):
    seg = segment_depth(three_objects, K, X_WC)
    # Table frame: z up, origin on the table top (exact plane in the render: 1 mm covers
    # float32 depth rounding at 1 m).
    np.testing.assert_allclose(seg.X_WT[:3, 2], [0, 0, 1], atol=1e-3)
    assert seg.X_WT[2, 3] == pytest.approx(TABLE_Z, abs=1e-3)
    assert len(seg.objects_T) == 3 and seg.cut == [False] * 3 and seg.n_dropped_cut == 0
    centroids = [transform(seg.X_WT, q).mean(axis=0)[:2] for q in seg.objects_T]
    for _, xy in OBJECTS.values():
        # The visible points' centroid is biased towards the camera by at most the radius.
        assert min(np.linalg.norm(c - xy) for c in centroids) < 0.05


def test_scene_description_one_object_each(three_objects):
    scene = describe_scene(three_objects, K, X_WC)
    assert len(scene.objects) == 3
    by_name = {}
    for name, (_, xy) in OBJECTS.items():
        by_name[name] = min(scene.objects, key=lambda o: np.linalg.norm(o.X_WO[:2, 3] - xy))
    # The can's completed centroid is within 1 cm of the truth. The mug's box centroid is pulled
    # towards its handle by half the handle's reach (1.5 cm); the box's top region (σ = 0.9)
    # holds the top 2 cm of its visible side faces, which pull it towards the camera (≤ 2 cm).
    for name, (_, xy) in OBJECTS.items():
        tol = 0.01 if name == "can" else 0.02
        assert np.linalg.norm(by_name[name].X_WO[:2, 3] - xy) < tol, name
    # The can is a plain cylinder: a flat closed top on a straight wall, its ends alike; which
    # is up is the flat end's calibrated sign (`PoseCalibration.flat_sign`).
    flat = "upright" if load_pose_calibration().flat_sign > 0 else "upsidedown"
    assert by_name["can"].pose == flat
    assert by_name["mug"].pose == "upright"
    assert set(by_name["mug"].part_probabilities) == {"top", "middle", "bottom", "handle"}
    assert set(by_name["can"].part_probabilities) == {"top", "middle", "bottom"}
    for o in scene.objects:
        n = len(o.p_W)
        assert o.n_W.shape == (n, 3) and o.labels.shape == (n,) and o.visible.shape == (n,)
        np.testing.assert_allclose(np.linalg.norm(o.n_W, axis=1), 1.0, atol=1e-9)
        assert sum(o.pose_likelihood.values()) == pytest.approx(1.0)
        assert len(o.pregrasp_X_WG) == 12 * len(o.part_boxes)
        assert o.p_W[:, 2].min() > TABLE_Z - 0.005  # the completion stays above the table


def test_empty_depth_image_is_a_clear_error():
    depth = np.full((K.height, K.width), np.inf, np.float32)
    with pytest.raises(PerceptionError, match="empty cloud: the depth image has 0 valid pixels"):
        segment_depth(depth, K, X_WC)


def test_no_table_plane_is_a_clear_error():
    # The camera looks at a wall (a vertical plane) and nothing else.
    wall = S.placed(S.table_mesh((2.0, 2.0), 0.02),
                    make_transform(np.array([[0, 0, 1.0], [0, 1.0, 0], [-1.0, 0, 0]]),
                                   [-0.5, 0.0, TABLE_Z]))
    depth = S.render_depth([wall], K, S.look_at(np.array([0.8, 0.0, TABLE_Z]),
                                                np.array([-0.5, 0.0, TABLE_Z])))
    with pytest.raises(PerceptionError, match="no table plane.*tilt: 90°"):
        segment_depth(depth, K, S.look_at(np.array([0.8, 0.0, TABLE_Z]),
                                          np.array([-0.5, 0.0, TABLE_Z])))


def test_object_cut_by_the_image_border():
    # A bottle at the image's left edge and a can in view.
    X = S.look_at(np.array([0.6, 0.0, TABLE_Z + 0.5]), np.array([0.0, 0.0, TABLE_Z]))
    # Where the ray of the image's left edge (column 0, middle row) meets the height 10 cm above
    # the table: a bottle standing there is cut in half by the border.
    d_W = X[:3, :3] @ np.array([-K.cx / K.fx, 0.0, 1.0])
    cut_xy = X[:3, 3] + d_W * (TABLE_Z + 0.1 - X[2, 3]) / d_W[2]
    meshes = [table(), on_table(S.bottle(0.035, 0.25, 0.013), cut_xy[0], cut_xy[1]),
              on_table(S.cylinder(0.033, 0.12), 0.0, 0.0)]
    depth = S.render_depth(meshes, K, X)
    seg = segment_depth(depth, K, X)
    assert len(seg.objects_T) == 1 and seg.n_dropped_cut == 1
    kept = segment_depth(depth, K, X, SegmentationConfig(drop_border_objects=False))
    assert len(kept.objects_T) == 2 and sorted(kept.cut) == [False, True]
    # Only the cut object in view: nothing whole to describe.
    depth = S.render_depth(meshes[:2], K, X)
    with pytest.raises(PerceptionError, match="every object on the table \\(1\\) is cut"):
        describe_scene(depth, K, X)


def test_two_touching_objects_are_one_described_object():
    # Two cans side by side, touching: depth alone cannot part them. The result is one object
    # spanning both (a clear result, not a crash), described as a lying shape.
    meshes = [table(), on_table(S.cylinder(0.033, 0.12), 0.0, -0.033),
              on_table(S.cylinder(0.033, 0.12), 0.0, 0.033)]
    scene = describe_scene(S.render_depth(meshes, K, X_WC), K, X_WC)
    assert len(scene.objects) == 1
    o = scene.objects[0]
    assert np.linalg.norm(o.X_WO[:2, 3] - [0.0, 0.0]) < 0.02  # its box is centred on the pair
    assert max(o.extents) > 0.12  # and spans both cans


def test_config_is_used():
    # A minimum cluster size above every object's size leaves an empty table (a clear result).
    X = S.look_at(np.array([0.6, 0.0, TABLE_Z + 0.5]), np.array([0.0, 0.0, TABLE_Z]))
    depth = S.render_depth([table(), on_table(S.cylinder(0.033, 0.12), 0.0, 0.0)], K, X)
    cfg = PerceptionConfig(segmentation=SegmentationConfig(min_cluster_points=100000))
    assert describe_scene(depth, K, X, cfg).objects == []
    assert len(describe_scene(depth, K, X).objects) == 1


def test_ransac_plane_finds_the_largest_plane_and_repeats_itself():
    from tg_drake.perception.segmentation import ransac_plane
    rng = np.random.default_rng(0)
    table = np.column_stack([rng.uniform(-0.5, 0.5, (4000, 2)), rng.normal(0.0, 0.002, 4000)])
    wall = np.column_stack([rng.uniform(-0.5, 0.5, 1000), np.full(1000, 0.3),
                            rng.uniform(0.0, 0.4, 1000)])
    p = np.vstack([table, wall])
    n, d = ransac_plane(p, 0.005, 300, np.random.default_rng(7))
    assert abs(n[2]) > 0.999 and abs(d) < 0.002  # the table, not the wall
    again = ransac_plane(p, 0.005, 300, np.random.default_rng(7))
    np.testing.assert_array_equal(n, again[0])
    assert d == again[1]


@pytest.mark.parametrize("thickness", [0.002, 0.003])
def test_a_thin_slab_on_the_table_is_found_through_the_d415_and_the_table_alone_gives_nothing(
        thickness):
    """A 2–3 mm slab (a blade lying flat) is within the table's noise point by point (σ ≈ 2 mm
    at 1 m through the D415): its points are found by the raised cells of the table
    (`segmentation.raised_cells`); the bare table, under the same noise, gives no object."""
    from tg_drake.perception.sensor_model import StructuredLight, apply_sensor

    K415 = Intrinsics.from_fov(640, 480, np.deg2rad(45.0))
    X = S.look_at(np.array([0.8, 0.0, 0.55]), np.array([0.0, 0.0, 0.05]))  # ~0.95 m away
    slab = S.placed(S.box((0.2, 0.025, thickness)), make_transform(np.eye(3), [0.0, 0.0, 0.0]))
    for seed in range(3):
        bare = apply_sensor(S.render_depth([S.table_mesh()], K415, X), K415, StructuredLight(),
                            seed=seed)
        assert segment_depth(bare, K415, X).objects_T == []
        depth = apply_sensor(S.render_depth([S.table_mesh(), slab], K415, X), K415,
                             StructuredLight(), seed=seed)
        seg = segment_depth(depth, K415, X)
        assert len(seg.objects_T) == 1
        p_W = transform(seg.X_WT, seg.objects_T[0])
        # The slab's footprint, 200 × 25 mm (2 % to 98 % of its points, within 1 cm); the table
        # points beside it are few (5 %: the table's noise above the 4 mm threshold that the
        # clustering joins, as beside any object).
        lo, hi = np.percentile(p_W[:, :2], [2, 98], axis=0)
        assert 0.18 < hi[0] - lo[0] < 0.21 and 0.02 < hi[1] - lo[1] < 0.035
        off = (np.abs(p_W[:, 0]) > 0.104) | (np.abs(p_W[:, 1]) > 0.0165)  # 4 mm off its edge
        assert off.mean() < 0.05
        np.testing.assert_allclose((lo + hi) / 2, [0.0, 0.0], atol=0.01)
        assert np.median(p_W[:, 2]) == pytest.approx(thickness, abs=0.001)


def _wall(rng, centre, radius, angles, z_top, n=1500):
    """Points on a vertical wall: the arc of a circle (centre, radius [m]) over `angles` [rad],
    from 4 mm to z_top [m] above the table (voxel-sized spacing)."""
    a = rng.uniform(*angles, n)
    z = rng.uniform(0.004, z_top, n)
    return np.column_stack([centre[0] + radius * np.cos(a), centre[1] + radius * np.sin(a), z])


def test_the_near_and_far_walls_of_an_open_container_are_one_object():
    from tg_drake.perception.segmentation import _merge_shared_rims, fit_circle

    rng = np.random.default_rng(4)
    cfg = SegmentationConfig()
    # A wide pot seen from the front: its near wall and its far wall, the rim's sides lost.
    near = _wall(rng, (0.0, 0.0), 0.11, (-2.2, -0.9), 0.15)
    far = _wall(rng, (0.0, 0.0), 0.11, (0.9, 2.2), 0.15)
    q = np.concatenate([near, far])
    labels = np.r_[np.zeros(len(near), int), np.ones(len(far), int)]
    assert list(_merge_shared_rims(q, labels, 2, cfg)) == [0, 0]
    _, radius, rms = fit_circle(q[q[:, 2] > 0.14][:, :2])
    assert radius == pytest.approx(0.11, abs=0.002) and rms < 0.001
    # Two cups of one height side by side: their rims are two circles, not one.
    a = _wall(rng, (0.0, 0.0), 0.04, (-np.pi, np.pi), 0.1)
    b = _wall(rng, (0.12, 0.0), 0.04, (-np.pi, np.pi), 0.1)
    q = np.concatenate([a, b])
    labels = np.r_[np.zeros(len(a), int), np.ones(len(b), int)]
    assert list(_merge_shared_rims(q, labels, 2, cfg)) == [0, 1]
    # The far wall of a lower object behind: tops at other heights stay apart.
    low = _wall(rng, (0.0, 0.0), 0.11, (0.9, 2.2), 0.08)
    q = np.concatenate([near, low])
    labels = np.r_[np.zeros(len(near), int), np.ones(len(low), int)]
    assert list(_merge_shared_rims(q, labels, 2, cfg)) == [0, 1]


def _rims_one_pair_at_a_time(q, labels, n, cfg):
    """The rule of _merge_shared_rims written out pair by pair, every pair fitted."""
    from tg_drake.perception.segmentation import fit_circle

    tops = []
    for k in range(n):
        p = q[labels == k]
        tops.append(p[p[:, 2] >= p[:, 2].max() - cfg.rim_band] if len(p) else p)
    parent = np.arange(n)
    for i in range(n):
        for j in range(i + 1, n):
            ti, tj = tops[i], tops[j]
            if len(ti) < 3 or len(tj) < 3 or abs(ti[:, 2].max() - tj[:, 2].max()) > cfg.rim_band:
                continue
            _, radius, rms = fit_circle(np.concatenate([ti[:, :2], tj[:, :2]]))
            if rms <= cfg.rim_fit_rms and radius > 0 and min(
                    np.ptp(t[:, :2], axis=0).max() for t in (ti, tj)) >= radius:
                a, b = parent[i], parent[j]
                parent[parent == max(a, b)] = min(a, b)
    return parent


@pytest.mark.parametrize("seed", range(3))
def test_shared_rims_among_many_clusters_are_those_every_pair_fitted_finds(seed):
    """The pairs are screened by the circle's radius from the summed normal equations before
    the point-by-point fit: the screen must drop no pair the fit would join (D415 noise leaves
    a hundred small clusters on a table, and three containers' walls here are split in two)."""
    from tg_drake.perception.segmentation import _merge_shared_rims

    rng = np.random.default_rng(seed)
    cfg = SegmentationConfig()
    parts = []
    for centre, radius, height in (((0.0, 0.0), 0.11, 0.15), ((0.4, 0.1), 0.06, 0.15),
                                   ((-0.3, 0.3), 0.08, 0.09)):
        parts += [_wall(rng, centre, radius, (-2.3, -0.8), height),
                  _wall(rng, centre, radius, (0.8, 2.3), height)]
    for _ in range(90):  # blobs of table noise, 3-20 voxels, a few mm high
        c = rng.uniform(-0.5, 0.5, 2)
        m = rng.integers(1, 20)
        parts.append(np.column_stack([c + rng.normal(0, 0.006, (m, 2)),
                                      rng.uniform(0.004, 0.01, m)]))
    q = np.concatenate(parts)
    labels = np.concatenate([np.full(len(p), k) for k, p in enumerate(parts)])
    labels[rng.random(len(q)) < 0.02] = -1  # DBSCAN's noise
    n = len(parts)
    expected = _rims_one_pair_at_a_time(q, labels, n, cfg)
    got = _merge_shared_rims(q, labels, n, cfg)
    assert list(got) == list(expected)
    assert list(got[:6]) == [0, 0, 2, 2, 4, 4]  # each container's two walls, one object


def _d415_objects(meshes, seed, cfg=None):
    from tg_drake.perception.sensor_model import StructuredLight, apply_sensor

    K415 = Intrinsics.from_fov(640, 480, np.deg2rad(45.0))
    X = S.look_at(np.array([0.8, 0.0, 0.55]), np.array([0.0, 0.0, 0.05]))  # ~0.95 m away
    depth = apply_sensor(S.render_depth([S.table_mesh(), *meshes], K415, X), K415,
                         StructuredLight(), seed=seed)
    seg = segment_depth(depth, K415, X, cfg)
    return [transform(seg.X_WT, q) for q in seg.objects_T]


@pytest.mark.parametrize("seed", range(3))
def test_the_tables_noise_at_an_objects_foot_is_not_the_object(seed):
    """An upright can (r 30 mm) through the D415 model: the table's noise that crosses the
    height threshold beside its foot is not joined to it (`segmentation.foot_noise`): every
    point lies within 9 mm of the wall (with the filter off, voxels up to 17 mm out), and its
    foot stays (its lowest points within 6 mm of the table)."""
    can = S.cylinder(0.03, 0.1)
    (p,) = _d415_objects([can], seed)
    assert np.hypot(p[:, 0], p[:, 1]).max() < 0.03 + 0.009
    assert p[:, 2].min() < 0.006
    (q,) = _d415_objects([can], seed, SegmentationConfig(foot_noise_sigmas=0.0))
    assert len(q) > len(p)


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("blade_mm", [5, 6])
def test_a_flat_blade_beside_a_raised_handle_keeps_its_blade(seed, blade_mm):
    """A knife lying flat: a 5–6 mm blade (above the height threshold, inside the table's noise
    band) beyond a 20 mm handle's end. Out from the handle's footprint, but the table there is
    raised all along: the blade stays, its full length, and only the noise beside it goes (the
    blade is 30 mm wide: with the filter off, points 12–27 mm beyond its sides)."""
    handle = S.placed(S.box((0.02, 0.1, 0.02)), make_transform(np.eye(3), [0.0, -0.06, 0.0]))
    blade = S.placed(S.box((0.03, 0.12, blade_mm / 1000)),
                     make_transform(np.eye(3), [0.0, 0.05, 0.0]))
    (p,) = _d415_objects([handle, blade], seed)
    assert p[:, 1].min() < -0.105 and p[:, 1].max() > 0.105  # handle end to blade tip
    assert np.abs(p[:, 0]).max() < 0.015 + 0.008


def _rod_cut(band_m: float, fill: str):
    """A 2.5 × 30 × 2.5 cm rod lying on the table along y (across the camera's view), with the
    pixels of its middle `band_m` [m] either lost (depth 0, as a sensor's dropout) or showing
    the table under it."""
    rod = on_table(S.box((0.025, 0.3, 0.025)), 0.0, 0.0)
    bare = S.render_depth([table()], K, X_WC)
    depth = S.render_depth([table(), rod], K, X_WC)
    from tg_drake.perception.geometry import depth_to_points
    p_W, px = depth_to_points(depth, K, X_WC)
    on_rod = p_W[:, 2] > TABLE_Z + 0.002
    cut = px[on_rod & (np.abs(p_W[:, 1]) < band_m / 2)]
    depth = depth.copy()
    depth[cut[:, 0], cut[:, 1]] = 0.0 if fill == "lost" else bare[cut[:, 0], cut[:, 1]]
    return depth


def _count(depth, bridge_px):
    cfg = SegmentationConfig(lost_bridge_px=bridge_px)
    return len(segment_depth(depth, K, X_WC, cfg).objects_T)


def test_a_part_cut_off_by_lost_pixels_joins_its_object():
    # 2 cm of the rod lost (11 px here): two pieces apart in the image by lost pixels only.
    depth = _rod_cut(0.02, "lost")
    assert _count(depth, 0) == 2
    assert _count(depth, 8) == 1  # each piece grown 8 px into the lost pixels: they meet


def test_table_seen_between_two_pieces_keeps_them_apart():
    # The same cut, but the camera sees the table through it: two objects whatever the bridge.
    depth = _rod_cut(0.02, "table")
    assert _count(depth, 8) == 2
    assert _count(depth, 40) == 2


def test_pieces_farther_apart_than_the_bridge_stay_apart():
    # 12 cm lost (about 67 px): more lost pixels than an 8 px bridge spans; with one that spans
    # them (40 px from each side), the pieces are still farther apart in space than
    # merge_max_gap (0.10 m).
    depth = _rod_cut(0.12, "lost")
    assert _count(depth, 8) == 2
    assert _count(depth, 40) == 2
