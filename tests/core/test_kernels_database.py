"""The kernel database shipped with the package (tg_drake/data/kernel_db.npz)."""

from __future__ import annotations

import numpy as np
import pytest

from tg_drake.evaluation.split import load_split
from tg_drake.kernels.database import load_database
from tg_drake.kernels.library import SPACING, library_fingerprint, sample_object
from tg_drake.kernels.propagation import BIN_WIDTH
from tg_drake.objects import get_object, load_library
from tg_drake.types import CATEGORIES, SCANLIKE_SUFFIX, source_objects


@pytest.fixture(scope="module")
def database():
    load_split().register_libraries()
    return load_database()


def test_shipped_database_holds_the_training_objects_only(database):
    # Fit on training objects (the object-wise split): no held-out object in any graph.
    # Each with its scan-like version (<id>_scan, tools/make_scanlike.py), of the same category.
    split = load_split()
    ids = database.object_ids.tolist()
    assert set(ids) == set(split.train) | {f"{i}{SCANLIKE_SUFFIX}" for i in split.train}
    sources = source_objects(database.object_ids)
    assert not set(sources.tolist()) & set(split.held_out)
    library = {i: get_object(i) for i in split.train}
    for obj_id, cat in zip(sources, database.categories, strict=True):
        assert CATEGORIES[cat] == library[obj_id].category
    assert (database.k, database.spacing) == (4, SPACING)
    # w is cross-validated from the paper's 1e-4 up to 0.1 (tools/build_kernel_db.py).
    assert BIN_WIDTH <= database.projections.w <= 0.1
    assert database.t_max == 15 and 0 <= database.t_default <= 15
    # Every object has ground-truth samplings and perceived views in every resting pose.
    for source in ("ground_truth", "perceived"):
        assert set(database.object_ids[database.sources == source].tolist()) == set(ids)
    perceived = database.sources == "perceived"
    for obj_id, obj in library.items():
        assert set(database.poses[perceived & (database.object_ids == obj_id)].tolist()) == \
            set(obj.poses)
    # The prior's floors, fitted on the database's own graphs (leave-one-object-out).
    assert 0.0 < database.floor("ground_truth") < database.floor("perceived") < 0.5
    assert load_database() is database  # loaded once per process.


def test_shipped_database_is_built_from_the_current_library(database):
    assert database.library_fingerprint == library_fingerprint(
        set(source_objects(database.object_ids).tolist())), (
        "tg_drake/data/kernel_db.npz was built from another version of the object library; "
        "rebuild it with `python tools/build_kernel_db.py`")


@pytest.mark.parametrize("obj_id", ["cup_02", "hammer_03", "bottle_01"])
def test_fresh_sampling_of_a_library_object_finds_its_own_category(database, obj_id):
    # A new sampling of an object in the database, compared as ground-truth samplings are. Among
    # the database's ground-truth samplings its own are among the nearest n = 10 (coarse bins:
    # siblings of a category hash alike, so they can come first).
    category = load_library()[obj_id].category
    cloud = sample_object(load_library()[obj_id], rng=np.random.default_rng(99))
    entries, t = database.choice("ground_truth")
    own = database.prior(cloud.points, cloud.normals, cloud.labels, entries="ground_truth", t=t)
    assert obj_id in [n[0] for n in own.neighbours]
    # With the entries cross-validation chose for such queries (perceived views too, where
    # "all" won), its category is among the three nearest and the two most probable: a scan-like
    # sibling of another category can come first by a hair (bottle_01's sampling meets a scan-like
    # bowl's view at 0.9774 against a scan-like bottle's 0.9766: bowl 0.63, bottle 0.37).
    d = database.prior(cloud.points, cloud.normals, cloud.labels, entries=entries, t=t)
    assert category in [n[1] for n in d.neighbours[:3]]
    assert category in [CATEGORIES[i] for i in np.argsort(-d.probabilities)[:2]]
    assert d.probabilities.sum() == pytest.approx(1.0, abs=1e-12)


def test_perceived_views_find_their_category_among_other_objects_views(database):
    from tg_drake.kernels.evaluation import evaluate_members, perceived_queries

    # The S_REAL analogue's queries, each against the graphs of the other objects only, at the
    # database's T: with the perceived views (its cross-validated entries) against the
    # ground-truth samplings alone (the database before perceived views).
    queries = perceived_queries(database)
    assert queries.size >= 250  # the training objects' 109 resting poses × 3 yaws, less
    # perception failures
    entries, t = database.choice("perceived")
    result = evaluate_members(database, queries, entries=[entries, "ground_truth"],
                              t_values=[t])
    ids = database.object_ids[queries]
    for name in (entries, "ground_truth"):
        correct = result.outcomes[name, t][0]
        assert correct.shape == ids.shape
    perceived_acc = result.outcomes[entries, t][0].mean()
    ground_truth_acc = result.outcomes["ground_truth", t][0].mean()
    # The shipped database (rebuilt with the closed-end pose cue and thin-object segmentation):
    # 0.61 against 0.51 (327 queries: ±0.03 binomial sd).
    assert perceived_acc > 0.55
    assert perceived_acc > ground_truth_acc + 0.05
