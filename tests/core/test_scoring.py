"""The final grasp score (tg_drake.grasping.scoring.rank_grasps) for each selection."""

import numpy as np
import pytest

from tg_drake.errors import GraspingError
from tg_drake.grasping.scoring import rank_grasps
from tg_drake.types import PART_LABELS, GraspSemantics, ObjectDescription, SceneDescription

P_LOCAL = np.array([0.5, 0.8, 0.7, 0.9])  # per hypothesis, in the object's order
PARTS = np.array([1, 3, 1, 0])  # middle, handle, middle, top


# Straight down over the robot's base: no approach variant (it cannot lean back towards it).
TOP_DOWN = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0.5], [0, 0, 0, 1]])


class FixedModel:
    """A stand-in for the DGI model: P(grasp | local shape) given per hypothesis."""

    def p_grasp(self, p_W, X_WG):
        assert len(X_WG) == len(P_LOCAL)
        return P_LOCAL


def scene():
    obj = ObjectDescription(
        p_W=np.zeros((10, 3)), n_W=np.zeros((10, 3)), labels=np.zeros(10, int),
        visible=np.ones(10, bool), X_WO=np.eye(4), extents=np.full(3, 0.1), pose="upright",
        pose_likelihood={"upright": 1.0}, part_probabilities={}, part_boxes={},
        pregrasp_X_WG=np.tile(TOP_DOWN, (4, 1, 1)), pregrasp_parts=PARTS)
    X_WT = np.eye(4)
    X_WT[2, 3] = -1.0  # the table far below: no pose moves back, none is dropped
    return SceneDescription(objects=[obj], X_WT=X_WT)


SEMANTICS = GraspSemantics(category={}, task={}, part={"middle": 0.9, "top": 0.1},
                           given_task=None)


def test_pipeline_multiplies_part_and_local_shape():
    ranked = rank_grasps(scene(), SEMANTICS, FixedModel())
    assert np.allclose(ranked.score, [0.63, 0.45, 0.09, 0.0])  # handle: the logic gave it 0
    assert ranked.parts.tolist() == [1, 1, 0, 3]


def test_local_only_ignores_the_logic():
    ranked = rank_grasps(scene(), SEMANTICS, FixedModel(), selection="local_only")
    assert np.allclose(ranked.score, [0.9, 0.8, 0.7, 0.5])


def test_one_part_scores_only_that_part_even_where_the_logic_gives_it_zero():
    ranked = rank_grasps(scene(), SEMANTICS, FixedModel(), selection="one_part", part="handle")
    assert np.allclose(ranked.score, [0.8, 0.0, 0.0, 0.0])
    assert ranked.parts[0] == PART_LABELS.index("handle")
    ranked = rank_grasps(scene(), SEMANTICS, FixedModel(), selection="one_part", part="middle")
    assert np.allclose(ranked.score, [0.7, 0.5, 0.0, 0.0])


def test_unknown_selection_or_part_is_refused():
    with pytest.raises(GraspingError, match="unknown grasp selection 'best'; allowed: pipeline"):
        rank_grasps(scene(), SEMANTICS, FixedModel(), selection="best")
    with pytest.raises(GraspingError, match="unknown part 'lid'"):
        rank_grasps(scene(), SEMANTICS, FixedModel(), selection="one_part", part="lid")


def test_an_executed_pose_is_matched_to_the_scored_pose_it_is():
    from tg_drake.grasping.expansion import tilted
    from tg_drake.grasping.scoring import scored_pose_match

    ranked = rank_grasps(scene(), SEMANTICS, FixedModel())
    same = scored_pose_match(ranked.X_WG[2].copy(), ranked)
    assert same["same"] and same["offset_m"] == 0.0 and same["p_local"] == ranked.p_local[0]
    # The same hypothesis tilted by 10° about its grasp point (what the feasibility stage used to
    # execute): not a pose the DGI scored.
    other = scored_pose_match(tilted(ranked.X_WG[0], np.deg2rad(10.0)), ranked)
    assert not other["same"] and np.degrees(other["angle_rad"]) == pytest.approx(10.0)


def test_random_part_draws_one_part_among_the_hypotheses_and_ranks_it_by_local_shape():
    from tg_drake.grasping.scoring import random_part

    drawn = [random_part(PARTS, seed) for seed in range(300)]
    counts = {p: drawn.count(p) for p in set(drawn)}
    assert set(counts) == {"middle", "handle", "top"}  # the parts with a hypothesis, no other
    assert min(counts.values()) > 60  # uniform over the 3 parts (100 each expected), not by count
    assert [random_part(PARTS, 7) for _ in range(3)] == [random_part(PARTS, 7)] * 3  # repeats
    for seed in (0, 1, 2, 5):
        ranked = rank_grasps(scene(), SEMANTICS, FixedModel(), selection="random_part",
                             seed=seed)
        chosen = PART_LABELS.index(random_part(PARTS, seed))
        expected = np.sort(np.where(PARTS == chosen, P_LOCAL, 0.0))[::-1]
        assert np.allclose(ranked.score, expected)  # the logic's handle = 0 does not matter
        assert set(ranked.parts[ranked.score > 0].tolist()) == {chosen}
    with pytest.raises(GraspingError, match="no pre-grasp hypothesis"):
        random_part(np.zeros(0, int), 0)
