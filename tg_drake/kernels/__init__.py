"""The kernel category prior (paper section III-C): propagation kernels on labelled k-nn graphs.

- `graph`: validation of a labelled cloud, the weighted k-nn graph (k = 4, w_ij = |n_i · n_j|),
  its transition matrix D⁻¹A, voxel resampling to the database density.
- `propagation`: label diffusion, LSH preserving total variation (w = 1e-4), the count features
  φ(G_t), the kernels K_T and K̂.
- `prior`: the n = 10 most similar graphs weighted by exp(−rank), accuracy and rank measures.
- `database`: the shipped database of hashed library graphs (ground-truth samplings and
  perceived views) and the prior query against it.
- `library`, `evaluation`, `bench`: database clouds from the object library (mesh samplings,
  perceived views), leave-one-object-out evaluation (nested: parameters chosen without the
  held-out object), speed figures against GraKeL. `synthetic`: parametric clouds for tests.

Pure NumPy/SciPy: nothing here imports the Drake systems framework
(`tg_drake.systems.kernel_prior_system` wraps it).
"""
