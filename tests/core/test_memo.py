"""LastResult: a stage's last answer, given again for the same inputs (tg_drake.systems.memo)."""

import numpy as np

from tg_drake.systems.memo import LastResult


def test_the_same_objects_or_equal_small_values_give_the_last_answer():
    last = LastResult()
    big = np.arange(3)
    calls = []

    def compute():
        calls.append(1)
        return object()

    a = last((big, ("middle",), "pass"), compute)
    # The same array object, an equal tuple of names and an equal task built anew: the last answer.
    assert last((big, tuple(["middle"]), "".join(["pa", "ss"])), compute) is a
    assert len(calls) == 1 and last.computed == 1
    # An equal array that is another object, another part, another task: computed again.
    for key in ((big.copy(), ("middle",), "pass"), (big, ("top",), "pass"),
                (big, ("top",), "pourOut")):
        assert last(key, compute) is not a
    assert last.computed == 4
    # A key of another length is another key.
    last((big,), compute)
    assert last.computed == 5
