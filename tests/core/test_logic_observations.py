"""Observations: validation with clear errors, files, and the translation from perception."""

from __future__ import annotations

import numpy as np
import pytest

from tg_drake.errors import RuleError
from tg_drake.logic.engine import LogicEngine
from tg_drake.logic.observations import (
    HANDLE_PAIR_PRIOR,
    SCHEMA_PARAMETERS,
    Observations,
    count_handles,
    handle_pair_probability,
    opposite_unseen,
    pair_probability_of,
)
from tg_drake.logic.theory import TheoryConfig, load_theory, rules_dir
from tg_drake.types import CATEGORIES, CategoryDistribution, ObjectDescription, part_index

CUP = {"parts": {"top": 0.8, "middle": 1.0, "bottom": 1.0, "handle": 1.0},
       "pose": {"upright": 0.5}, "containment": "empty",
       "category_prior": {"cup": 0.56, "can": 0.36, "pot": 0.05, "pan": 0.02}}


@pytest.mark.parametrize("change, message", [
    ({"category_prior": {"mugg": 0.5}}, "unknown category 'mugg'; allowed: pan, pot, cup"),
    ({"task": "pour"}, "unknown task 'pour'; allowed: pass, pourOut, pourIn"),
    ({"parts": {"lid": 1.0}}, "unknown part 'lid'; allowed: top, middle, bottom, handle"),
    ({"pose": {"lying": 1.0}}, "unknown pose 'lying'; allowed: upright, sideways, upsidedown"),
    ({"parts": {"top": 1.2}}, "field 'parts.top'.*must be a number in \\[0, 1\\], got 1.2"),
    ({"pose": {"upright": -0.1}}, "field 'pose.upright'.*in \\[0, 1\\]"),
    ({"category_prior": {"cup": 0.7, "can": 0.5}}, "field 'category_prior'.*sum to at most 1"),
    ({"category_prior": {"cup": 0.0}}, "field 'category_prior'.*evidence of probability 0"),
    ({"task_prior": {"pass": 0.0}}, "field 'task_prior'.*evidence of probability 0"),
    ({"task": "pass", "task_prior": {"pass": 1.0}}, "either a task or a task prior"),
    ({"containment": "half"}, "unknown containment 'half'; allowed: empty, full"),
    ({"collisions": ["rim"]}, "field 'collisions'.*unknown part 'rim'"),
    ({"handles": 3}, "handles must be 1 or 2"),
    ({"interior_seen": 2}, "field 'interior_seen'.*probability in \\[0, 1\\], got 2"),
    ({"handle_pair": 1.5}, "field 'handle_pair'.*probability in \\[0, 1\\], got 1.5"),
    ({"colour": "red"}, "unknown field 'colour'; allowed: parts, pose"),
    ({"parts": None}, "field 'parts'"),
])
def test_bad_observations_raise_rule_error_naming_the_field(change, message):
    with pytest.raises(RuleError, match=message):
        Observations.from_dict({**CUP, **change}, source="obs.yaml")


def test_malformed_file_names_the_file_and_field(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("parts: {top: 1.0}\ncategory_prior: {cup: 2}\n")
    with pytest.raises(RuleError, match=r"bad.yaml, field 'category_prior.cup'") as e:
        Observations.from_file(bad)
    assert e.value.file == str(bad) and e.value.field == "category_prior.cup"
    broken = tmp_path / "broken.yaml"
    broken.write_text("parts: {top: 1.0\n")
    with pytest.raises(RuleError, match="broken.yaml.*not valid YAML"):
        Observations.from_file(broken)
    with pytest.raises(RuleError, match="missing.yaml.*cannot read"):
        Observations.from_file(tmp_path / "missing.yaml")


def test_parameters_follow_the_schema():
    obs = Observations.from_dict(CUP)
    params = obs.parameters()
    assert params.shape == (len(SCHEMA_PARAMETERS),)
    rows = {key: i for i, key in enumerate(SCHEMA_PARAMETERS)}
    assert params[rows[("part", "top")]] == 0.8
    assert params[rows[("part", "usable_area")]] == 0.0
    assert params[rows[("pose", "upright")]] == 0.5
    assert params[rows[("prior", "pan")]] == 0.02  # first category: q = p.
    assert params[rows[("prior", "pot")]] == pytest.approx(0.05 / 0.98, abs=1e-15)
    # Uniform task prior when no task is given: q_i = 1 / (7 - i + 1).
    assert params[rows[("task", "pass")]] == pytest.approx(1 / 7, abs=1e-15)
    assert params[rows[("task", "p&pOn")]] == pytest.approx(1.0, abs=1e-12)


def _object(labels, p_W, **extra):
    n = len(labels)
    return ObjectDescription(
        p_W=p_W, n_W=np.zeros((n, 3)), labels=np.asarray(labels), visible=np.ones(n, bool),
        X_WO=np.eye(4), extents=np.ones(3), pose="upright", pose_likelihood={"upright": 1.0},
        part_probabilities={"top": 1.0, "middle": 1.0, "bottom": 1.0, "handle": 1.0},
        part_boxes={}, pregrasp_X_WG=np.zeros((0, 4, 4)), pregrasp_parts=np.zeros(0, int),
        **extra)


def test_count_handles_from_the_handle_points():
    rng = np.random.default_rng(0)
    h, m = part_index("handle"), part_index("middle")
    one = np.column_stack([0.06 + rng.normal(0, 0.005, 50), rng.normal(0, 0.01, 50),
                           rng.uniform(-0.02, 0.02, 50)])
    two = np.concatenate([one, one * [-1, 1, 1]])
    body = rng.normal(0, 0.03, (100, 3))
    assert count_handles(_object([m] * 100 + [h] * 50, np.concatenate([body, one]))) == 1
    assert count_handles(_object([m] * 100 + [h] * 100, np.concatenate([body, two]))) == 2
    assert count_handles(_object([m] * 100, body)) == 1


def _mug(rng, seen_opposite: float):
    """A cylinder of radius 4 cm (z its axis) with a handle on +x; `seen_opposite` of the wall
    within 45° of −x is observed, the rest of the points completed."""
    h, m = part_index("handle"), part_index("middle")
    theta = rng.uniform(-np.pi, np.pi, 2000)
    wall = np.column_stack([0.04 * np.cos(theta), 0.04 * np.sin(theta),
                            rng.uniform(-0.05, 0.05, 2000)])
    handle = np.column_stack([0.06 + rng.normal(0, 0.003, 100), rng.normal(0, 0.005, 100),
                              rng.uniform(-0.03, 0.03, 100)])
    opposite = (np.cos(theta) <= -np.cos(np.pi / 4)) & (np.abs(wall[:, 2]) <= 0.03)
    visible = ~opposite | (rng.uniform(size=2000) < seen_opposite)
    labels = np.array([m] * 2000 + [h] * 100)
    return (np.concatenate([wall, handle]), labels,
            np.concatenate([visible, np.ones(100, bool)]))


@pytest.mark.parametrize("seen", [0.0, 0.5, 1.0])
def test_opposite_unseen_is_the_completed_share_of_the_side_away_from_the_handle(seen):
    p, labels, visible = _mug(np.random.default_rng(1), seen)
    assert opposite_unseen(p, labels, visible) == pytest.approx(1.0 - seen, abs=0.06)
    # Nothing of the body at the handle's height: nothing seen there at all.
    low = p[:, 2] < -0.035
    keep = low | (labels == part_index("handle"))
    assert opposite_unseen(p[keep], labels[keep], visible[keep]) == 1.0
    # No handle points: no second handle to miss.
    body = labels != part_index("handle")
    assert opposite_unseen(p[body], labels[body], visible[body]) == 0.0


def test_handle_pair_probability_weighs_what_the_view_could_miss():
    assert handle_pair_probability(2, 0.0) == 1.0
    assert handle_pair_probability(1, 0.0) == 0.0
    assert handle_pair_probability(1, 1.0) == pytest.approx(HANDLE_PAIR_PRIOR)
    p = [handle_pair_probability(1, u) for u in np.linspace(0, 1, 11)]
    assert np.all(np.diff(p) > 0)
    rng = np.random.default_rng(2)
    pts, labels, visible = _mug(rng, 0.0)
    obj = _object(labels, pts)
    obj.visible = visible
    assert pair_probability_of(obj) == pytest.approx(HANDLE_PAIR_PRIOR, abs=0.01)
    obj.visible = np.ones(len(pts), bool)
    assert pair_probability_of(obj) == 0.0


def test_the_pair_probability_moves_pot_against_cup_and_pan():
    engine = LogicEngine(TheoryConfig())
    prior = {"pot": 0.5, "cup": 0.3, "pan": 0.2}

    def p_pot(pair):
        obs = Observations(parts={"top": 1, "middle": 1, "bottom": 1, "handle": 1},
                           pose={"upright": 1.0}, category_prior=prior, handle_pair=pair)
        return engine.query(obs).category[CATEGORIES.index("pot")]

    # One handle for sure rules a pot out; a pair seen makes it one; in between, the more of
    # the far side the view missed, the more likely a pot.
    assert p_pot(0.0) == 0.0 and p_pot(1.0) == pytest.approx(1.0)
    p = [p_pot(x) for x in (0.05, 0.15, 0.25, 1 / 3)]
    assert 0.0 < p[0] and np.all(np.diff(p) > 0) and p[-1] < 1.0
    # handle_pair not given: two handles seen count as a pair, one as no pair.
    assert Observations(parts={"handle": 1}, handles=2).pair_probability == 1.0
    assert Observations(parts={"handle": 1}, handles=1).pair_probability == 0.0


def test_from_object_uses_perception_the_prior_and_the_task():
    obj = _object([part_index("middle")] * 3, np.zeros((3, 3)), containment="full")
    prior = CategoryDistribution(probabilities=np.eye(len(CATEGORIES))[CATEGORIES.index("cup")])
    obs = Observations.from_object(obj, prior=prior, task="", collisions=("handle",))
    assert obs.task is None and obs.category_prior["cup"] == 1.0
    assert obs.containment == {"full": 1.0} and obs.collisions == ("handle",)
    with pytest.raises(RuleError, match="11 entries"):
        Observations.from_object(obj, prior=CategoryDistribution(probabilities=np.ones(3) / 3))
    with pytest.raises(RuleError, match="unknown task 'fly'"):
        Observations.from_object(obj, task="fly")


def test_theory_files_open_with_a_comment_and_load():
    directory = rules_dir()
    files = sorted(directory.glob("*.pl"))
    assert len(files) >= 9
    for path in files:
        assert path.read_text().lstrip().startswith("%"), path.name
    for theory in ("specific", "general"):
        clauses = load_theory(TheoryConfig.named(theory))
        assert any(c.file == f"category_{theory}.pl" for c in clauses)


def test_malformed_theory_raises_rule_error_with_file_and_line(tmp_path):
    for path in rules_dir().glob("*.pl"):
        (tmp_path / path.name).write_text(path.read_text())
    broken = tmp_path / "affordances.pl"
    broken.write_text(broken.read_text() + "\npossible(X, T) :- kind(X, object\n")
    with pytest.raises(RuleError, match="affordances.pl.*cannot parse"):
        load_theory(TheoryConfig(), tmp_path)
    (tmp_path / "affordances.pl").write_text("possible(a, b).\n")
    with pytest.raises(RuleError, match="affordances.pl:1.*opens with a % comment"):
        load_theory(TheoryConfig(), tmp_path)
    with pytest.raises(RuleError, match="unknown theory 'vague'; allowed: specific, general"):
        TheoryConfig.named("vague")
