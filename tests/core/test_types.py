import numpy as np
import pytest

from tg_drake.errors import RuleError, TgDrakeError, unknown_name
from tg_drake.types import CATEGORIES, PART_LABELS, as_distribution, part_index


def test_part_index_round_trips():
    assert [part_index(p) for p in PART_LABELS] == list(range(5))
    with pytest.raises(ValueError, match="unknown part 'lid'; allowed: top, middle"):
        part_index("lid")


def test_as_distribution_orders_and_checks_names():
    v = as_distribution({"cup": 0.56, "can": 0.36}, CATEGORIES)
    assert v.shape == (11,)
    np.testing.assert_allclose(v[CATEGORIES.index("cup")], 0.56)
    assert v.sum() == pytest.approx(0.92)
    with pytest.raises(ValueError, match="mugg"):
        as_distribution({"mugg": 1.0}, CATEGORIES)


def test_unknown_name_lists_allowed_values_and_location():
    e = unknown_name("category", "mugg", ["cup", "can"], error=RuleError, file="obs.yaml")
    assert isinstance(e, TgDrakeError) and isinstance(e, ValueError)
    assert str(e) == "obs.yaml: unknown category 'mugg'; allowed: cup, can"
