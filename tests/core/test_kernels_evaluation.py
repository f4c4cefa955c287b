"""The paper's claim on the S_SYN analogue: manifold information beats label fractions."""

from __future__ import annotations

import numpy as np

from tg_drake.kernels.evaluation import best, leave_one_object_out
from tg_drake.kernels.graph import cloud_transition
from tg_drake.kernels.library import library_clouds
from tg_drake.kernels.propagation import LshProjections, graph_features, normalise


def test_manifolds_beat_label_fractions_on_the_library():
    rng = np.random.default_rng(2024)
    clouds, ids, cats = library_clouds(n_samplings=2, rng=rng)
    features = graph_features([cloud_transition(c) for c in clouds], [c.labels for c in clouds],
                              LshProjections.sample(rng=rng))
    scores = leave_one_object_out(normalise(features.kernel()), ids, cats)
    label_fractions, manifolds = scores[0], best(scores)
    # Over 5 seeds of 3 samplings: 60.8 ± 4.2 % at T = 0 and 83.3 ± 2.6 % at T = 13
    # (docs/results/kernel_prior.md); 0.1 is several standard deviations of the difference.
    assert manifolds.T > 0
    assert manifolds.accuracy > label_fractions.accuracy + 0.1
    assert manifolds.mean_rank < label_fractions.mean_rank
    assert label_fractions.accuracy > 3 / 11  # far above random (1/11).
