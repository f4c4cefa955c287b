"""A compiled SDD as a NumPy arithmetic circuit, evaluated for many roots and weightings at once.

An SDD decision node is a disjunction of (prime, sub) pairs whose primes are mutually exclusive
and exhaustive over the variables of the node's left vtree, and whose subs live on the right
vtree. Its weighted model count is therefore sum_i WMC(prime_i) * WMC(sub_i), *provided* every
variable that a node does not mention contributes the factor w(x) + w(not x). When every
variable is an independent probabilistic fact, w(x) + w(not x) = 1 and no smoothing is needed:
the circuit is evaluated with literal x -> w_x, literal not x -> 1 - w_x, true -> 1, false -> 0.
The theory is rewritten so that this holds (tg_drake/logic/theory.py: annotated disjunctions
become chains of independent facts).

Evaluation goes level by level (a node's level is one more than its deepest child), each level a
gather, a product and a segmented sum over a (nodes, batch) array, so all query roots and a batch
of weightings (a scene and its ablations, for explanations) cost one pass.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Circuit:
    """The union of the SDDs of several roots."""

    n_nodes: int
    true_nodes: np.ndarray  # node ids of constant true.
    false_nodes: np.ndarray  # node ids of constant false.
    literal_nodes: np.ndarray  # node ids of literals.
    literal_vars: np.ndarray  # their variable (1-based SDD variable index).
    literal_positive: np.ndarray  # bool: x (True) or not x (False).
    levels: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]
    # per level: (owner node ids, start of each owner's elements, prime ids, sub ids).
    roots: np.ndarray  # node id of each root, in the order given.

    @classmethod
    def from_sdd(cls, roots) -> Circuit:
        """From pysdd SddNode roots sharing one manager."""
        ids: dict[int, int] = {}
        kind: list[str] = []
        literal: list[int] = []
        elements: list[list[tuple[int, int]]] = []
        level: list[int] = []
        # Iterative post-order walk, so deep SDDs do not hit Python's recursion limit.
        for root in roots:
            stack = [(root, False)]
            while stack:
                node, expanded = stack.pop()
                if node.id in ids:
                    continue
                if node.is_decision():
                    pairs = node.elements()
                    if not expanded:
                        stack.append((node, True))
                        for prime, sub in pairs:
                            for child in (prime, sub):
                                if child.id not in ids:
                                    stack.append((child, False))
                        continue
                    children = [(ids[p.id], ids[s.id]) for p, s in pairs]
                    ids[node.id] = len(kind)
                    kind.append("and-or")
                    literal.append(0)
                    elements.append(children)
                    level.append(1 + max(max(level[a], level[b]) for a, b in children))
                else:
                    ids[node.id] = len(kind)
                    if node.is_true():
                        kind.append("true")
                        literal.append(0)
                    elif node.is_false():
                        kind.append("false")
                        literal.append(0)
                    else:
                        kind.append("literal")
                        literal.append(int(node.literal))
                    elements.append([])
                    level.append(0)
        kind_a = np.array(kind)
        literal_a = np.array(literal, dtype=np.int64)
        level_a = np.array(level, dtype=np.int64)
        literal_nodes = np.flatnonzero(kind_a == "literal")
        levels = []
        for lv in range(1, int(level_a.max(initial=0)) + 1):
            owners = np.flatnonzero(level_a == lv)
            counts = np.array([len(elements[i]) for i in owners])
            starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
            pairs = np.array([pair for i in owners for pair in elements[i]], dtype=np.int64)
            levels.append((owners, starts, pairs[:, 0], pairs[:, 1]))
        return cls(
            n_nodes=len(kind),
            true_nodes=np.flatnonzero(kind_a == "true"),
            false_nodes=np.flatnonzero(kind_a == "false"),
            literal_nodes=literal_nodes,
            literal_vars=np.abs(literal_a[literal_nodes]),
            literal_positive=literal_a[literal_nodes] > 0,
            levels=levels,
            roots=np.array([ids[r.id] for r in roots], dtype=np.int64),
        )

    @property
    def n_edges(self) -> int:
        return int(sum(len(p) for _, _, p, _ in self.levels))

    def evaluate(self, weights: np.ndarray) -> np.ndarray:
        """Weighted model counts of the roots.

        weights: (n_vars + 1,) or (n_vars + 1, B) probabilities of the positive literals, indexed
        by SDD variable (row 0 unused). Returns (n_roots,) or (n_roots, B).
        """
        w = np.asarray(weights, dtype=float)
        single = w.ndim == 1
        if single:
            w = w[:, None]
        values = np.empty((self.n_nodes, w.shape[1]))
        values[self.true_nodes] = 1.0
        values[self.false_nodes] = 0.0
        lit = w[self.literal_vars]
        values[self.literal_nodes] = np.where(self.literal_positive[:, None], lit, 1.0 - lit)
        for owners, starts, primes, subs in self.levels:
            values[owners] = np.add.reduceat(values[primes] * values[subs], starts, axis=0)
        out = values[self.roots]
        return out[:, 0] if single else out
