"""The compiled-once path equals plain ProbLog (re-grounded per query) within 1e-9."""

from __future__ import annotations

import numpy as np
import pytest

from tg_drake.logic.engine import LogicEngine, reference_query
from tg_drake.logic.observations import Observations
from tg_drake.logic.theory import TheoryConfig
from tg_drake.types import CATEGORIES, PART_LABELS, POSES, TASKS

# The promise of the compiled path: the same numbers as ProbLog up to float rounding (~1e-15 on
# sums of a few hundred products); 1e-9 leaves room and still catches any semantic difference.
EXACT = 1e-9

SCENES = {
    "fig1_cup_inferred_task": Observations(
        parts={"top": 0.8, "middle": 1.0, "bottom": 1.0, "handle": 1.0}, pose={"upright": 0.5},
        containment={"empty": 1.0},
        category_prior={"cup": 0.56, "can": 0.36, "pot": 0.05, "pan": 0.02}),
    "noisy_bottle_pour_out": Observations(
        parts={"top": 0.9, "middle": 1.0, "bottom": 0.7, "handle": 0.2},
        pose={"upright": 0.6, "sideways": 0.3, "upsidedown": 0.1}, containment={"full": 0.8},
        category_prior={"bottle": 0.5, "can": 0.2, "glass": 0.2, "cup": 0.1}, task="pourOut",
        interior_seen=0.7),
    "pot_two_handles_uniform_prior_collision": Observations(
        parts={"top": 1.0, "middle": 1.0, "bottom": 1.0, "handle": 0.9}, pose={"upright": 1.0},
        handles=2, task="p&pOn", collisions=("handle",)),
    "hammer_task_prior": Observations(
        parts={"handle": 1.0, "usable_area": 0.9, "middle": 0.1}, pose={"sideways": 0.9},
        task_prior={"pass": 0.5, "p&pInSideways": 0.3, "pourIn": 0.2}),
}


def _check(obs: Observations, config: TheoryConfig):
    compiled = LogicEngine(config).query(obs)
    plain = reference_query(obs, config)
    for q in ("category", "task", "part"):
        np.testing.assert_allclose(getattr(compiled, q), getattr(plain, q), atol=EXACT,
                                   err_msg=f"{q} differs")


@pytest.mark.parametrize("name", sorted(SCENES))
@pytest.mark.parametrize("theory", ["specific", "general"])
def test_compiled_equals_plain_problog(name, theory):
    _check(SCENES[name], TheoryConfig.named(theory))


@pytest.mark.parametrize("name", ["fig1_cup_inferred_task", "noisy_bottle_pour_out"])
def test_compiled_equals_plain_problog_non_exclusive(name):
    _check(SCENES[name], TheoryConfig(exclusive=False))


@pytest.mark.slow
def test_compiled_equals_plain_problog_on_random_scenes():
    rng = np.random.default_rng(3)
    for i in range(24):
        parts = {p: float(rng.choice([0.0, 1.0, rng.uniform(0.2, 1.0)])) for p in PART_LABELS}
        parts["usable_area"] = 0.0 if i % 3 else 1.0
        obs = Observations(
            parts=parts, pose=dict(zip(POSES, rng.dirichlet(np.ones(3)), strict=False)),
            containment={"empty": float(rng.uniform())},
            category_prior=dict(zip(CATEGORIES, rng.dirichlet(np.ones(len(CATEGORIES))),
                                    strict=False)),
            task=None if i % 2 else str(rng.choice(TASKS)))
        config = TheoryConfig(category=("specific", "general")[i % 2],
                              grasp=("specific", "general")[(i // 2) % 2],
                              exclusive=bool(i % 4))
        _check(obs, config)
