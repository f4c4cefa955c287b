"""Unit tests of the kernel-prior core (tg_drake/kernels) on synthetic labelled clouds."""

from __future__ import annotations

import io

import numpy as np
import pytest
import scipy.sparse as sp

from tg_drake.errors import KernelError
from tg_drake.kernels import synthetic
from tg_drake.kernels.database import KernelDatabase, prepare_cloud
from tg_drake.kernels.graph import (
    LabelledCloud,
    cloud_transition,
    knn_graph,
    object_size,
    size_normalised,
    transition_matrix,
    validate_cloud,
    voxel_resample,
)
from tg_drake.kernels.prior import category_priors, is_correct, true_category_rank
from tg_drake.kernels.propagation import (
    LshProjections,
    graph_features,
    lsh,
    normalise,
    one_hot,
    propagation_hashes,
)
from tg_drake.types import CATEGORIES

SPACING = 0.05  # voxel size of the test clouds as a fraction of the object's size: a few
# hundred points per object, fast.


def _shapes(rng):
    """Six labelled clouds of four kinds, as sampled (dense)."""
    return [
        synthetic.cylinder(radius=0.033, height=0.12, n=6000, rng=rng),
        synthetic.cylinder(radius=0.035, height=0.11, n=6000, rng=rng),
        synthetic.mug(radius=0.04, height=0.10, n=6000, rng=rng),
        synthetic.mug(radius=0.042, height=0.095, n=6000, rng=rng),
        synthetic.tool(handle_length=0.2, handle_radius=0.015, head_size=(0.03, 0.1, 0.03),
                       n=6000, rng=rng),
        synthetic.box(size=(0.07, 0.07, 0.2), n=6000, rng=rng),
    ]


@pytest.fixture(scope="module")
def raw_clouds():
    return _shapes(np.random.default_rng(7))


@pytest.fixture(scope="module")
def clouds(raw_clouds):
    """The clouds scaled to unit size and resampled to SPACING, as the database holds them."""
    return [prepare_cloud(c.points, c.normals, c.labels, spacing=SPACING) for c in raw_clouds]


@pytest.fixture(scope="module")
def projections():
    return LshProjections.sample(t_max=15, rng=np.random.default_rng(3))


@pytest.fixture(scope="module")
def features(clouds, projections):
    return graph_features([cloud_transition(c) for c in clouds], [c.labels for c in clouds],
                          projections)


# -- graph ------------------------------------------------------------------------------------

def test_knn_graph_is_symmetric_with_normal_weights(clouds):
    c = clouds[2]
    a = knn_graph(c.points, c.normals).toarray()
    np.testing.assert_array_equal(a, a.T)
    # Brute force: each point's 4 nearest others, and the union of both directions.
    d = np.linalg.norm(c.points[:, None] - c.points[None], axis=2)
    np.fill_diagonal(d, np.inf)
    nearest = np.argsort(d, axis=1)[:, :4]
    joined = np.zeros_like(a, dtype=bool)
    joined[np.repeat(np.arange(len(d)), 4), nearest.ravel()] = True
    joined |= joined.T
    weights = np.abs(c.normals @ c.normals.T)
    # atol 1e-15: the same dot product, possibly summed in another order. Pairs not joined
    # weigh 0, as do joined pairs with perpendicular normals (the rim of a cylinder).
    np.testing.assert_allclose(a, np.where(joined, weights, 0.0), atol=1e-15)
    assert np.count_nonzero(a[joined] == 0.0) > 0


def test_knn_graph_joins_nearest_points():
    # Five points on a line: with k = 1, each is joined to its nearest neighbour only.
    p = np.array([[0.0, 0, 0], [1.0, 0, 0], [3.0, 0, 0], [3.5, 0, 0], [10.0, 0, 0]])
    n = np.tile([0.0, 0.0, 1.0], (5, 1))
    a = knn_graph(p, n, k=1).toarray()
    expected = np.zeros((5, 5))
    for i, j in [(0, 1), (2, 3), (4, 3)]:
        expected[i, j] = expected[j, i] = 1.0
    np.testing.assert_array_equal(a, expected)


def test_transition_rows_sum_to_one_and_isolated_nodes_keep_their_labels():
    a = sp.csr_matrix(np.array([[0, 2.0, 0], [2.0, 0, 0], [0, 0, 0]]))
    t = transition_matrix(a).toarray()
    np.testing.assert_array_equal(t, [[0, 1, 0], [1, 0, 0], [0, 0, 1]])


def test_voxel_resample_keeps_one_real_point_per_cell():
    dense = synthetic.cylinder(radius=0.03, height=0.1, n=20000, rng=np.random.default_rng(0))
    out = voxel_resample(dense, 0.01)
    cells = np.floor((out.points - dense.points.min(axis=0)) / 0.01).astype(int)
    assert len(np.unique(cells, axis=0)) == len(out.points)
    # The kept points are input points, with their own normals and labels.
    idx = np.array([np.flatnonzero(np.all(dense.points == q, axis=1))[0] for q in out.points[:50]])
    np.testing.assert_array_equal(dense.labels[idx], out.labels[:50])
    np.testing.assert_array_equal(dense.normals[idx], out.normals[:50])


# -- bad input --------------------------------------------------------------------------------

def test_too_few_points_is_a_kernel_error():
    p = np.random.default_rng(0).random((4, 3))
    with pytest.raises(KernelError, match="cloud of 4 point.* k = 4 needs at least 5"):
        validate_cloud(p, np.tile([0, 0, 1.0], (4, 1)), np.zeros(4, int))


def test_missing_normals_is_a_kernel_error():
    p = np.random.default_rng(0).random((10, 3))
    with pytest.raises(KernelError, match="missing normals"):
        validate_cloud(p, None, np.zeros(10, int))
    n = np.tile([0, 0, 1.0], (10, 1))
    n[3] = 0.0
    with pytest.raises(KernelError, match="missing normals: 1 of 10 .* point 3"):
        validate_cloud(p, n, np.zeros(10, int))


def test_unknown_labels_is_a_kernel_error():
    p = np.random.default_rng(0).random((10, 3))
    labels = np.array([0, 1, 2, 3, 4, 7, 7, -1, 0, 0])
    with pytest.raises(KernelError, match=r"unknown part label\(s\) \[-1, 7\]; allowed: 0 \(top\)"):
        validate_cloud(p, np.tile([0, 0, 1.0], (10, 1)), labels)


def test_database_rejects_bad_queries(clouds, projections):
    db = KernelDatabase.build(clouds, list("abcdef"), [0, 1, 2, 3, 4, 5],
                              projections=projections, spacing=SPACING)
    c = clouds[0]
    with pytest.raises(KernelError, match="iterations T = 16 out of range; allowed: 0..15"):
        db.similarities(c.points, c.normals, c.labels, t=16)
    # Leaving out an object the database never saw (an imported one) leaves nothing out.
    assert db.prior(c.points, c.normals, c.labels, exclude_object="zz").neighbours == \
        db.prior(c.points, c.normals, c.labels).neighbours
    assert db.prior(c.points, c.normals, c.labels, exclude_object="a").neighbours != \
        db.prior(c.points, c.normals, c.labels).neighbours
    # Four of six points at one place: three voxels are left, the graph needs five points.
    few = np.array([[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0], [1e-2, 0, 0], [0, 1e-2, 0]])
    with pytest.raises(KernelError, match="after resampling at 0.050 of its size is too small"):
        db.prior(few, np.tile([0, 0, 1.0], (6, 1)), np.zeros(6, int))


# -- LSH and propagation ----------------------------------------------------------------------

def _collision_probability(c: float) -> float:
    """Datar et al. (2004): P(same bin) for a 1-stable (Cauchy) projection, c = w / l1 distance."""
    return 2 * np.arctan(c) / np.pi - np.log1p(c ** 2) / (np.pi * c)


def test_lsh_keeps_near_distributions_together_and_separates_far_ones():
    w = 1e-4
    proj = LshProjections.sample(t_max=19999, w=w, rng=np.random.default_rng(11))
    x = np.array([0.4, 0.3, 0.2, 0.1, 0.0])

    def same_bin_rate(y):
        hx = np.floor((proj.v @ x + proj.b) / w)
        hy = np.floor((proj.v @ y + proj.b) / w)
        return np.mean(hx == hy)

    near = x + np.array([1e-9, -1e-9, 0, 0, 0])  # l1 distance 2e-9 = w / 5e4.
    far = np.array([0.0, 0.3, 0.2, 0.1, 0.4])  # total variation 0.4.
    between = x + np.array([w / 2, -w / 2, 0, 0, 0])  # l1 distance w.
    # Expected rates 1 − 1.3e-5 and 1.6e-4 (formula above); 20000 draws, so these bounds
    # are more than 5 standard deviations away.
    assert same_bin_rate(near) > 0.999
    assert same_bin_rate(far) < 0.002
    # At l1 distance w the rate is the 1-stable one (0.279), which shows that the hash
    # preserves the l1 (= 2 × total variation) distance; 0.016 = 5 standard deviations.
    assert abs(same_bin_rate(between) - _collision_probability(1.0)) < 0.016


def test_t0_is_the_linear_kernel_on_label_counts(clouds, features):
    counts = np.stack([np.bincount(c.labels, minlength=5) for c in clouds]).astype(float)
    np.testing.assert_array_equal(features.kernel(t_max=0)[0], counts @ counts.T)


def test_normalised_self_kernel_is_maximal(features):
    k_hat = normalise(features.kernel())
    np.testing.assert_allclose(np.diagonal(k_hat, axis1=1, axis2=2), 1.0, rtol=1e-12)
    off = k_hat + np.where(np.eye(k_hat.shape[1], dtype=bool), -np.inf, 0.0)
    # Cauchy–Schwarz; 1e-12 allows rounding of the square roots.
    assert np.all(off.max(axis=2) <= 1.0 + 1e-12)
    # And the graphs are not all alike: different shapes score clearly below 1 at T = 15.
    assert k_hat[15, 0, 4] < 0.95


def test_isomorphic_relabelled_graphs_have_equal_features(clouds, projections):
    c = clouds[2]
    perm = np.random.default_rng(5).permutation(len(c.labels))
    # Permuted nodes, and flipped normals too (the weights |n_i · n_j| ignore orientation).
    shuffled = LabelledCloud(c.points[perm], -c.normals[perm], c.labels[perm])
    h = propagation_hashes(cloud_transition(c), c.labels, projections)
    h_perm = propagation_hashes(cloud_transition(shuffled), shuffled.labels, projections)
    # Same multiset of bins at every t (1e-16 rounding could move a node across a bin edge with
    # probability ~1e-12, so exact equality is expected).
    np.testing.assert_array_equal(np.sort(h, axis=1), np.sort(h_perm, axis=1))


def test_diffusion_is_row_normalised_adjacency():
    # A path 0 - 1 - 2 with weights 1 and 3: node 1 takes 1/4 of node 0's and 3/4 of node 2's.
    a = sp.csr_matrix(np.array([[0, 1.0, 0], [1.0, 0, 3.0], [0, 3.0, 0]]))
    t = transition_matrix(a)
    l1 = t @ one_hot(np.array([0, 1, 2]), 3)
    np.testing.assert_allclose(l1, [[0, 1, 0], [0.25, 0, 0.75], [0, 1, 0]], atol=1e-15)
    proj = LshProjections(v=np.array([[1.0, 2.0, 3.0], [1.0, 2.0, 3.0]]), b=np.zeros(2), w=0.1)
    h = propagation_hashes(t, np.array([0, 1, 2]), proj)
    # t=0: 1/0.1, 2/0.1, 3/0.1; t=1: 2/0.1, (0.25 + 2.25)/0.1, 2/0.1 (floor; 1e-9 guards rounding).
    np.testing.assert_array_equal(h, [[10, 20, 30], [20, 25, 20]])
    np.testing.assert_array_equal(lsh(l1, np.array([1.0, 2, 3]), 1e-9, 0.1), [20, 25, 20])


def test_features_of_a_batch_equal_features_one_by_one(clouds, projections, features):
    single = graph_features([cloud_transition(clouds[3])], [clouds[3].labels], projections)
    for t in range(16):
        row = features.counts[t][3].toarray().ravel()
        present = row > 0
        np.testing.assert_array_equal(features.vocabularies[t][present],
                                      single.vocabularies[t])
        np.testing.assert_array_equal(row[present], single.counts[t].toarray().ravel())


# -- prior ------------------------------------------------------------------------------------

def test_prior_weights_by_exp_minus_rank_and_sums_to_one():
    sims = np.array([[0.9, 0.1, 0.8, 0.7]])
    cats = np.array([2, 5, 6, 2])
    prior, nbrs = category_priors(sims, cats, n_neighbours=3)
    np.testing.assert_array_equal(nbrs, [[0, 2, 3]])
    expected = np.zeros(11)
    expected[2] = np.exp(-1) + np.exp(-3)
    expected[6] = np.exp(-2)
    np.testing.assert_allclose(prior[0], expected / expected.sum(), rtol=1e-14)
    assert prior.sum() == pytest.approx(1.0, abs=1e-15)


def test_prior_leaves_out_excluded_graphs():
    sims = np.array([[0.9, -np.inf, 0.8]])
    prior, nbrs = category_priors(sims, np.array([0, 1, 2]), n_neighbours=10)
    assert prior[0, 1] == 0.0
    np.testing.assert_allclose(prior[0, [0, 2]], np.array([np.exp(-1), np.exp(-2)])
                               / (np.exp(-1) + np.exp(-2)), rtol=1e-14)


def test_rank_and_accuracy_measures():
    p = np.array([[0.5, 0.3, 0.2, 0, 0], [0.4, 0.4, 0.2, 0, 0], [0.6, 0.4, 0, 0, 0]])
    truth = np.array([1, 0, 3])
    # Row 2: three zeros tie for ranks 3..5, mean 4.
    np.testing.assert_array_equal(true_category_rank(p, truth), [2.0, 1.5, 4.0])
    np.testing.assert_array_equal(is_correct(p, np.array([0, 0, 0])), [True, False, True])


# -- database ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def database(clouds, projections):
    cats = [CATEGORIES.index(c) for c in ("can", "can", "cup", "cup", "hammer", "bottle")]
    return KernelDatabase.build(clouds, ["can1", "can2", "cup1", "cup2", "hammer1", "bottle1"],
                                cats, projections=projections, spacing=SPACING, t_default=4)


def test_query_row_equals_kernel_matrix_row(database, features, raw_clouds):
    k_hat = normalise(features.kernel())
    c = raw_clouds[3]
    for t in (0, 4, 15):
        # The query resamples the raw cloud as the database did, so it is graph 3;
        # rtol 1e-12: the same sums in another order.
        np.testing.assert_allclose(database.similarities(c.points, c.normals, c.labels, t=t),
                                   k_hat[t, 3], rtol=1e-12)
    np.testing.assert_allclose(database.similarity_profile(c.points, c.normals, c.labels),
                               k_hat[:, 3], rtol=1e-12)


def test_prior_of_a_database_member_names_itself_first(database, raw_clouds):
    c = raw_clouds[2]
    d = database.prior(c.points, c.normals, c.labels)
    assert d.neighbours[0][:2] == ("cup1", "cup")
    assert d.neighbours[0][2] == pytest.approx(1.0, rel=1e-12)
    assert d.probabilities.sum() == pytest.approx(1.0, abs=1e-12)
    # Left out, the other cup is the nearest.
    d = database.prior(c.points, c.normals, c.labels, exclude_object="cup1")
    assert d.neighbours[0][:2] == ("cup2", "cup")
    assert all(n[0] != "cup1" for n in d.neighbours)
    assert max(d.as_dict(), key=d.as_dict().get) == "cup"


def test_database_round_trip(database, raw_clouds):
    buf = io.BytesIO()
    database.save(buf)
    buf.seek(0)
    loaded = KernelDatabase.load(buf)
    np.testing.assert_array_equal(loaded.object_ids, database.object_ids)
    np.testing.assert_array_equal(loaded.projections.v, database.projections.v)
    assert (loaded.spacing, loaded.k, loaded.t_default) == (SPACING, 4, 4)
    c = raw_clouds[5]
    np.testing.assert_array_equal(loaded.similarities(c.points, c.normals, c.labels, t=9),
                                  database.similarities(c.points, c.normals, c.labels, t=9))


def test_loading_garbage_is_a_kernel_error(tmp_path):
    bad = tmp_path / "kernel_db.npz"
    bad.write_bytes(b"not a zip file")
    with pytest.raises(KernelError, match="cannot read the kernel database"):
        KernelDatabase.load(bad)


def test_resampling_follows_a_moved_cloud(raw_clouds):
    c = raw_clouds[2]
    moved = LabelledCloud(c.points + np.array([0.5037, -0.2011, 0.7993]), c.normals, c.labels)
    a, b = voxel_resample(c, SPACING), voxel_resample(moved, SPACING)
    np.testing.assert_array_equal(a.labels, b.labels)
    shift = np.broadcast_to([0.5037, -0.2011, 0.7993], a.points.shape)
    # 1e-15 m: float rounding of the shifted coordinates.
    np.testing.assert_allclose(b.points - a.points, shift, rtol=0, atol=1e-15)


def test_object_size_is_the_largest_principal_extent_whatever_the_turn():
    rng = np.random.default_rng(5)
    box = synthetic.box(size=(0.07, 0.03, 0.2), n=4000, rng=rng)
    from scipy.spatial.transform import Rotation
    R = Rotation.random(random_state=1).as_matrix()
    # 2e-3 relative: the principal axes of a sampled box tilt a little off its edges.
    assert object_size(box.points) == pytest.approx(0.2, rel=2e-3)
    assert object_size(box.points @ R.T + 0.3) == pytest.approx(object_size(box.points), rel=1e-12)
    assert object_size(size_normalised(box).points) == pytest.approx(1.0, rel=1e-12)
    with pytest.raises(KernelError, match="no extent"):
        size_normalised(LabelledCloud(np.zeros((6, 3)), box.normals[:6], box.labels[:6]))


def test_a_scaled_copy_of_a_cloud_has_the_same_prior(database, raw_clouds):
    # The paper's normalised kernel is meant to be independent of the object's scale: a cup
    # 1.7 times as large is the same graph after size normalisation and resampling.
    c = raw_clouds[3]
    big = database.similarities(1.7 * c.points, c.normals, c.labels, t=9)
    # 1e-9: the scaled coordinates round differently, not enough to move a point to another voxel.
    np.testing.assert_allclose(big, database.similarities(c.points, c.normals, c.labels, t=9),
                               rtol=1e-9)


def test_leave_one_object_out_drops_all_samplings_of_the_held_out_object():
    from tg_drake.kernels.evaluation import best, leave_one_object_out, random_score

    # Graphs 0, 1 are two samplings of object "a" (category 0); "b" is category 1, "c" 0.
    k = np.array([[1.0, 0.99, 0.9, 0.5],
                  [0.99, 1.0, 0.4, 0.8],
                  [0.9, 0.4, 1.0, 0.3],
                  [0.5, 0.8, 0.3, 1.0]])
    scores = leave_one_object_out(np.stack([k, k[[0, 1, 3, 2]][:, [0, 1, 3, 2]]]),
                                  ["a", "a", "b", "c"], [0, 0, 1, 0], n_neighbours=10)
    # T = 0: graph 0 sees b (0.9) before c (0.5): wrong, rank 2; graph 1 sees c first: right,
    # rank 1; b sees only category 0: wrong, and its category ties with the nine others at 0
    # for ranks 2..11, mean 6.5; c sees a first: right, rank 1.
    assert scores[0].accuracy == 0.5
    assert scores[0].mean_rank == (2 + 1 + 6.5 + 1) / 4
    # T = 1 swaps the kernel entries of b and c: graph 0 now sees c (0.9) first: right, rank 1;
    # graph 1 sees b (0.8) first: wrong, rank 2; b sees only category 0: rank 6.5; c right.
    assert (scores[1].accuracy, scores[1].mean_rank) == (0.5, (1 + 2 + 6.5 + 1) / 4)
    # Equal scores: the smaller T wins.
    assert best(scores).T == 0 and best(scores, by="mean_rank").T == 0
    assert random_score().accuracy == pytest.approx(1 / 11)
    assert random_score().mean_rank == 6.0


# -- perceived entries and their leave-one-object-out evaluation ------------------------------

@pytest.fixture(scope="module")
def mixed_database(clouds, raw_clouds, projections):
    """Each shape twice: once as a ground-truth sampling, once (another grid) as a "perceived"
    view of the same object; only "can" has two objects."""
    rng = np.random.default_rng(11)
    views = [voxel_resample(size_normalised(c), SPACING, offset=rng.random(3) * SPACING)
             for c in raw_clouds]
    ids = ["can1", "can2", "cup1", "cup2", "hammer1", "bottle1"]
    cats = [CATEGORIES.index(c) for c in ("can", "can", "cup", "cup", "hammer", "bottle")]
    return KernelDatabase.build(
        clouds + views, ids + ids, cats + cats, projections=projections, spacing=SPACING,
        t_default=3, sources=["ground_truth"] * 6 + ["perceived"] * 6,
        poses=[""] * 6 + ["upright"] * 6, yaws=[np.nan] * 6 + [0.0, 120.0] * 3,
        viewpoints=[-1] * 6 + [0] * 6, entries_default="perceived")


def test_prior_compares_with_the_chosen_entries_only(mixed_database, raw_clouds):
    c = raw_clouds[4]
    assert mixed_database.prior(c.points, c.normals, c.labels).neighbours[0][0] == "hammer1"
    for entries, n in (("perceived", 6), ("ground_truth", 6), ("all", 10)):
        d = mixed_database.prior(c.points, c.normals, c.labels, entries=entries)
        assert len(d.neighbours) == n
    with pytest.raises(KernelError, match="unknown database entries 'scans'"):
        mixed_database.prior(c.points, c.normals, c.labels, entries="scans")


def test_mixed_database_round_trip(mixed_database):
    buf = io.BytesIO()
    mixed_database.save(buf)
    buf.seek(0)
    loaded = KernelDatabase.load(buf)
    for name in ("sources", "poses", "viewpoints"):
        np.testing.assert_array_equal(getattr(loaded, name), getattr(mixed_database, name))
    np.testing.assert_array_equal(loaded.yaws, mixed_database.yaws)
    assert (loaded.entries_default, loaded.t_default) == ("perceived", 3)


def test_member_profile_equals_the_query_of_the_same_cloud(mixed_database, raw_clouds):
    # Database graph 1 is raw_clouds[1] as a query prepares it (scaled, resampled).
    c = raw_clouds[1]
    np.testing.assert_allclose(mixed_database.member_profile([1])[:, 0],
                               mixed_database.similarity_profile(c.points, c.normals, c.labels),
                               rtol=1e-12)


def test_perceived_evaluation_never_sees_the_query_object(mixed_database):
    from tg_drake.kernels.evaluation import evaluate_members

    queries = np.flatnonzero(mixed_database.sources == "perceived")
    result = evaluate_members(mixed_database, queries)
    # Its own object's graphs are each perceived view's most similar graphs (K̂ = 1 with itself),
    # and for cup, hammer and bottle the only graphs of their category (cup1 and cup2 are
    # different mugs but one category: they may find each other). If any own graph leaked in,
    # hammer1 and bottle1 would be right; without it they cannot be.
    for name, (correct, rank) in result.outcomes.items():
        ids = mixed_database.object_ids[queries]
        assert not correct[np.isin(ids, ["hammer1", "bottle1"])].any(), name
        assert np.all(rank[np.isin(ids, ["hammer1", "bottle1"])] > 1), name
    # Not vacuous: the cans and cups do find their category among the other objects.
    can_or_cup = np.isin(mixed_database.object_ids[queries], ["can1", "can2", "cup1", "cup2"])
    assert result.outcomes["all", 3][0][can_or_cup].any()
    assert result.score.accuracy <= 4 / 6


def test_nested_choice_is_made_without_the_held_out_object():
    from tg_drake.kernels.evaluation import nested_leave_one_object_out

    # Two queries (objects a and b, category 0) against graphs of objects a, b, c (category 0)
    # and d (category 1). At T = 0 both queries prefer d (wrong) over c; at T = 1 they prefer c.
    # A held-out object's own choice may use only the other query: each sees T = 1 win.
    ids_db, cats_db = np.array(["a", "b", "c", "d"]), np.array([0, 0, 0, 1])
    rows = np.array([[[1.0, 0.0, 0.2, 0.9], [0.0, 1.0, 0.2, 0.9]],
                     [[1.0, 0.0, 0.9, 0.2], [0.0, 1.0, 0.9, 0.2]]])
    result = nested_leave_one_object_out(rows, ["a", "b"], [0, 0], ids_db, cats_db,
                                         {"all": np.ones(4, bool)}, n_neighbours=1)
    assert result.choices == {"a": {"T": 1, "entries": "all"}, "b": {"T": 1, "entries": "all"}}
    assert result.score.accuracy == 1.0 and result.score.T == 1
    # Query a's own graph (K̂ = 1) never counts: at T = 0 its only neighbour is d.
    assert not result.outcomes["all", 0][0].any()
