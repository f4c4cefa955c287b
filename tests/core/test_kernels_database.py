"""The kernel database shipped with the package (tg_drake/data/kernel_db.npz)."""

from __future__ import annotations

import numpy as np
import pytest

from tg_drake.kernels.database import load_database
from tg_drake.kernels.library import SPACING, library_fingerprint, sample_object
from tg_drake.kernels.propagation import BIN_WIDTH
from tg_drake.objects import load_library
from tg_drake.types import CATEGORIES


@pytest.fixture(scope="module")
def database():
    return load_database()


def test_shipped_database_matches_the_library_and_the_paper_parameters(database):
    library = load_library()
    assert set(database.object_ids.tolist()) == set(library)
    for obj_id, cat in zip(database.object_ids, database.categories):
        assert CATEGORIES[cat] == library[obj_id].category
    assert (database.k, database.projections.w, database.spacing) == (4, BIN_WIDTH, SPACING)
    assert database.t_max == 15 and 0 <= database.t_default <= 15
    assert load_database() is database  # loaded once per process.


def test_shipped_database_is_built_from_the_current_library(database):
    assert database.library_fingerprint == library_fingerprint(), (
        "tg_drake/data/kernel_db.npz was built from another version of the object library; "
        "rebuild it with `python tools/build_kernel_db.py`")


@pytest.mark.parametrize("obj_id", ["cup_02", "hammer_03", "bottle_01"])
def test_fresh_sampling_of_a_library_object_finds_its_own_category(database, obj_id):
    # A new sampling of an object in the database: its own samplings are among the nearest
    # graphs (the nearest may be a sibling of its category), and the argmax is its category.
    category = load_library()[obj_id].category
    cloud = sample_object(load_library()[obj_id], rng=np.random.default_rng(99))
    d = database.prior(cloud.points, cloud.normals, cloud.labels)
    assert obj_id in [n[0] for n in d.neighbours[:5]]
    assert d.neighbours[0][1] == category
    assert CATEGORIES[int(np.argmax(d.probabilities))] == load_library()[obj_id].category
    assert d.probabilities.sum() == pytest.approx(1.0, abs=1e-12)
