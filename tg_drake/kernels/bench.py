"""Speed figures of the kernel prior, each against GraKeL's propagation kernel on the same graphs.

- `kernel_query_ms`: one category prior of a fresh cloud against a database of the library
  (validation, resampling, k-nn graph, diffusion, hashing, kernel row, prior). Reference: GraKeL's
  `Propagation.transform` of the same query graph against the same graphs, already fitted.
- `kernel_loo_s`: the full leave-one-out kernel matrix of the database graphs for every
  T = 0..15 (diffusion, hashing, counts, K_T). Reference: GraKeL's `fit_transform` of the same
  graphs for T = 15 only (t_max = 16).

Both use one sampling per library object at the shipped database's density and T = 15 (the largest
T of the paper's sweep). GraKeL gets our weighted transition matrix D⁻¹A as the fourth graph
element (it needs it dense: its diffusion is a dense product), so both compute the same kernel.
GraKeL is used here and in tests only, never at run time.
"""

from __future__ import annotations

import numpy as np

from tg_drake.bench import Figure, figure, median_time
from tg_drake.kernels.database import KernelDatabase
from tg_drake.kernels.graph import LabelledCloud, cloud_transition
from tg_drake.kernels.library import SPACING, library_clouds
from tg_drake.kernels.propagation import BIN_WIDTH, T_MAX, LshProjections, graph_features

SEED = 0


def _grakel_graph(cloud: LabelledCloud):
    """GraKeL input for one graph: adjacency (only its size is read), labels, no edge labels,
    and our transition matrix, one dense array serving as both to save memory."""
    dense = cloud_transition(cloud).toarray()
    return [dense, dict(enumerate(cloud.labels.tolist())), {}, dense]


def _inputs():
    rng = np.random.default_rng(SEED)
    clouds, ids, cats = library_clouds(n_samplings=1, spacing=SPACING, rng=rng)
    return clouds, ids, cats, LshProjections.sample(t_max=T_MAX, rng=rng)


def kernel_query_ms() -> Figure:
    """Milliseconds for one category prior against the database (median of 20)."""
    from grakel.kernels import Propagation  # optional (the test extra): only the reference

    clouds, ids, cats, projections = _inputs()
    query, held_out = clouds[0], ids[0]
    keep = [i for i, o in enumerate(ids) if o != held_out]
    db = KernelDatabase.build([clouds[i] for i in keep], [ids[i] for i in keep],
                              [cats[i] for i in keep], projections=projections, spacing=SPACING,
                              t_default=T_MAX)
    ours = median_time(lambda: db.prior(query.points, query.normals, query.labels), repeats=20)

    gk = Propagation(t_max=T_MAX + 1, w=BIN_WIDTH, M="TV", normalize=True, random_state=SEED)
    gk.fit([_grakel_graph(clouds[i]) for i in keep])
    graph = _grakel_graph(db.prepare(query.points, query.normals, query.labels))
    reference = median_time(lambda: gk.transform([graph]), repeats=3)
    return figure(ours * 1e3, "ms",
                  f"GraKeL Propagation.transform of the same query graph against the same "
                  f"{len(keep)} fitted graphs, T = {T_MAX}", reference * 1e3)


def kernel_loo_s() -> Figure:
    """Seconds for the leave-one-out kernel matrices K_0..K_15 of all database graphs."""
    from grakel.kernels import Propagation  # optional (the test extra): only the reference

    clouds, _, _, projections = _inputs()

    def ours():
        transitions = [cloud_transition(c) for c in clouds]
        return graph_features(transitions, [c.labels for c in clouds], projections).kernel()

    t_ours = median_time(ours, repeats=3)
    graphs = [_grakel_graph(c) for c in clouds]

    def reference():
        Propagation(t_max=T_MAX + 1, w=BIN_WIDTH, M="TV", random_state=SEED).fit_transform(graphs)

    t_ref = median_time(reference, repeats=1, warmup=0)
    return figure(t_ours, "s",
                  f"GraKeL Propagation.fit_transform of the same {len(clouds)} graphs, "
                  f"T = {T_MAX} only", t_ref)
