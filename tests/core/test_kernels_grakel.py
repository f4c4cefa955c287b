"""Side-by-side check of our propagation kernel against GraKeL's `Propagation` on the same graphs.

Where the definitions agree the kernel values agree exactly (they are sums of products of integer
counts). The differences to mind:
- GraKeL sums t = 0..t_max − 1, the paper t = 0..T: GraKeL's t_max is our T + 1.
- GraKeL builds D⁻¹A from an unweighted adjacency unless given a transition matrix as the fourth
  graph element; the paper's graph is weighted, so we pass our D⁻¹A.
- GraKeL draws its projections from a `RandomState`: per t, u = randn(m) / randn(m) (Cauchy, for
  M = "TV") then b = w · rand(). We rebuild the same numbers as an `LshProjections`.
- GraKeL's `PropagationAttr` would take the distributions as node attributes, but it hashes each
  of their entries separately (floor((x ⊙ u + b) / w), one bin per dimension) instead of one
  random projection of the whole distribution, so its features are not the paper's; we compare
  against `Propagation`, whose hash is the paper's.
"""

from __future__ import annotations

import numpy as np
import pytest

from tg_drake.kernels import synthetic
from tg_drake.kernels.graph import cloud_transition, voxel_resample
from tg_drake.kernels.propagation import BIN_WIDTH, LshProjections, graph_features

grakel = pytest.importorskip("grakel")


def grakel_projections(seed: int, t_max: int, n_labels: int, w: float) -> LshProjections:
    """The projections GraKeL's Propagation(random_state=seed) draws, as ours (T = t_max − 1)."""
    rs = np.random.RandomState(seed)
    v, b = [], []
    for _ in range(t_max):
        u = rs.randn(n_labels)
        v.append(u / rs.randn(n_labels))
        b.append(w * rs.rand())
    return LshProjections(v=np.array(v), b=np.array(b), w=w)


@pytest.fixture(scope="module")
def graphs():
    rng = np.random.default_rng(21)
    raw = [
        synthetic.cylinder(radius=0.03, height=0.1, n=4000, rng=rng),
        synthetic.mug(radius=0.035, height=0.09, n=4000, rng=rng),
        synthetic.tool(handle_length=0.15, handle_radius=0.012, head_size=(0.03, 0.08, 0.02),
                       n=4000, rng=rng),
        synthetic.box(size=(0.06, 0.05, 0.14), n=4000, rng=rng),
    ]
    clouds = [voxel_resample(c, 0.01) for c in raw]
    # Every label must occur, so that GraKeL enumerates all five (its columns are the sorted
    # labels it has seen, ours are PART_LABELS).
    assert set(np.concatenate([c.labels for c in clouds]).tolist()) == {0, 1, 2, 3, 4}
    return clouds, [cloud_transition(c) for c in clouds]


@pytest.mark.parametrize("T", [0, 3, 8])
def test_kernel_values_match_grakel(graphs, T):
    clouds, transitions = graphs
    seed = 1234
    gk = grakel.kernels.Propagation(t_max=T + 1, w=BIN_WIDTH, M="TV", random_state=seed)
    data = [[(tr > 0).toarray().astype(float), dict(enumerate(c.labels.tolist())), {},
             tr.toarray()] for c, tr in zip(clouds, transitions, strict=True)]
    k_grakel = gk.fit_transform(data)
    ours = graph_features(transitions, [c.labels for c in clouds],
                          grakel_projections(seed, T + 1, 5, BIN_WIDTH)).kernel()[T]
    # Exact: integer counts; only a node within ~1e-16 of a bin edge could differ (probability
    # ~1e-10 here), since GraKeL diffuses with dense products and we with sparse ones.
    np.testing.assert_array_equal(ours, k_grakel)
    # Not a vacuous match: the graphs differ from each other.
    assert len(np.unique(np.round(ours[np.triu_indices(4, 1)]))) > 1
