"""The NumPy circuit evaluates an SDD like PySDD's own weighted model counter."""

from __future__ import annotations

import numpy as np
import pytest
from pysdd.sdd import SddManager, Vtree

from tg_drake.logic.circuit import Circuit
from tg_drake.logic.observations import stick_breaking


def _random_formula(manager, n_vars, rng, depth=4):
    if depth == 0:
        lit = int(rng.integers(1, n_vars + 1))
        return manager.literal(lit if rng.uniform() < 0.5 else -lit)
    a = _random_formula(manager, n_vars, rng, depth - 1)
    b = _random_formula(manager, n_vars, rng, depth - 1)
    return a & b if rng.uniform() < 0.5 else a | b


@pytest.mark.parametrize("vtree_type", ["right", "balanced"])
def test_circuit_matches_pysdd_wmc(vtree_type):
    rng = np.random.default_rng(0)
    n = 10
    manager = SddManager.from_vtree(Vtree(var_count=n, var_order=list(range(1, n + 1)),
                                          vtree_type=vtree_type))
    roots = [_random_formula(manager, n, rng) for _ in range(8)] + [manager.true(),
                                                                    manager.false()]
    circuit = Circuit.from_sdd(roots)
    weights = np.concatenate([[0.0], rng.uniform(size=n)])
    batch = np.stack([weights, np.concatenate([[0.0], rng.uniform(size=n)])], axis=1)
    ours, ours_batch = circuit.evaluate(weights), circuit.evaluate(batch)
    for r, root in enumerate(roots):
        for b in range(2):
            wmc = root.wmc(log_mode=False)
            for v in range(1, n + 1):
                wmc.set_literal_weight(v, batch[v, b])
                wmc.set_literal_weight(-v, 1.0 - batch[v, b])
            # Float rounding of sums of at most 2^10 products: 1e-12 is generous.
            assert ours_batch[r, b] == pytest.approx(wmc.propagate(), abs=1e-12)
        assert ours[r] == pytest.approx(ours_batch[r, 0], abs=1e-15)


def test_stick_breaking_encodes_an_annotated_disjunction():
    rng = np.random.default_rng(1)
    for p in [np.array([0.56, 0.36, 0.05, 0.02]), np.array([0.0, 1.0, 0.0]),
              np.array([0.5, 0.5]), rng.dirichlet(np.ones(11)) * 0.9, np.zeros(3)]:
        q = stick_breaking(p)
        assert np.all((q >= 0) & (q <= 1))
        # Outcome i: not c_1 ... not c_{i-1}, c_i.
        survive = np.concatenate([[1.0], np.cumprod(1.0 - q)[:-1]])
        np.testing.assert_allclose(survive * q, p, atol=1e-15)  # float rounding only.
