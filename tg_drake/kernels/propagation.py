"""The propagation kernel on labelled graphs (paper section III-C, after Neumann et al. 2012/2016).

Every node starts with the one-hot distribution of its part label over the m = 5 part labels,
L_0. All nodes are labelled (the paper's "full label information"), so the labels are diffused
without pushing labelled nodes back to their labels: L_t = D⁻¹A L_(t−1). At each iteration t the
node distributions are quantised by locality-sensitive hashing that preserves the total-variation
distance (an l1 distance, so the random projection is 1-stable: standard Cauchy),

    h_t(l) = floor((l · v_t + b_t) / w),   v_t ~ Cauchy(0, 1)^m,  b_t ~ U[0, w),  w = 1e-4,

with a fresh (v_t, b_t) per iteration and the same ones for every graph. The feature φ(G_t) counts
the nodes of G per hash value, and

    K_T(G', G'') = Σ_{t=0..T} ⟨φ(G'_t), φ(G''_t)⟩,   K̂_ij = K_ij / sqrt(K_ii K_jj).

At T = 0 the hashes separate the five one-hot labels, so K_0 is the linear kernel on label counts
(the paper's "Label fractions" baseline once normalised).

Many graphs are processed at once as one block-diagonal sparse transition matrix; the only Python
loops run over the iterations t, never over nodes or graphs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from tg_drake.errors import KernelError
from tg_drake.types import PART_LABELS

BIN_WIDTH = 1e-4  # the paper's LSH bin width w.
T_MAX = 15  # the paper sweeps T in {0, ..., 15}.


@dataclass(frozen=True)
class LshProjections:
    """The random projections of the LSH, one per iteration t = 0..t_max.

    Database and queries must hash with the same projections; the database file stores them.
    """

    v: np.ndarray  # (t_max + 1, m) standard Cauchy projection vectors.
    b: np.ndarray  # (t_max + 1,) offsets in [0, w).
    w: float = BIN_WIDTH  # bin width.

    @classmethod
    def sample(cls, *, t_max: int = T_MAX, n_labels: int = len(PART_LABELS),
               w: float = BIN_WIDTH, rng: np.random.Generator) -> LshProjections:
        """Draws the projections: v = X / Y with X, Y ~ N(0, 1) is standard Cauchy."""
        if t_max < 0:
            raise KernelError(f"the number of iterations t_max must be >= 0, got {t_max}")
        if not w > 0:
            raise KernelError(f"the LSH bin width w must be positive, got {w}")
        v = rng.standard_normal((t_max + 1, n_labels)) / rng.standard_normal((t_max + 1, n_labels))
        return cls(v=v, b=w * rng.random(t_max + 1), w=float(w))

    @property
    def t_max(self) -> int:
        return self.v.shape[0] - 1


def one_hot(labels: np.ndarray, n_labels: int = len(PART_LABELS)) -> np.ndarray:
    """L_0: (N, n_labels) one-hot label distributions."""
    out = np.zeros((labels.shape[0], n_labels))
    out[np.arange(labels.shape[0]), labels] = 1.0
    return out


def lsh(distributions: np.ndarray, v: np.ndarray, b: float, w: float) -> np.ndarray:
    """h(l) = floor((l · v + b) / w) for every row l of `distributions`, as int64.

    Two distributions at l1 distance d land in one bin with a probability that falls with d/w
    (Datar et al. 2004): at w = 1e-4 only nearly equal distributions share a bin.
    """
    return np.floor((distributions @ v + b) / w).astype(np.int64)


def propagation_hashes(transition: sp.spmatrix, labels: np.ndarray, projections: LshProjections,
                       *, t_max: int | None = None) -> np.ndarray:
    """(t_max + 1, N) int64: the LSH bin of every node at every diffusion iteration t.

    `transition` is D⁻¹A (block-diagonal when it holds many graphs); `labels` the part labels.
    """
    t_max = projections.t_max if t_max is None else t_max
    if t_max > projections.t_max:
        raise KernelError(
            f"T = {t_max} iterations asked for, but the projections cover only "
            f"T <= {projections.t_max}")
    dist = one_hot(labels, projections.v.shape[1])
    out = np.empty((t_max + 1, labels.shape[0]), dtype=np.int64)
    for t in range(t_max + 1):
        if t > 0:
            dist = transition @ dist
        out[t] = lsh(dist, projections.v[t], projections.b[t], projections.w)
    return out


@dataclass
class FeatureCounts:
    """φ(G_t) for a set of graphs: per iteration t, a sparse (n_graphs × bins) count matrix.

    Column j of `counts[t]` counts the nodes that hash to `vocabularies[t][j]` (sorted).
    Stored column-compressed so that a query selects the columns of its own bins cheaply.
    """

    vocabularies: list[np.ndarray]  # per t: sorted unique int64 bins.
    counts: list[sp.csc_matrix]  # per t: (n_graphs, len(vocabularies[t])) float64 counts.

    @property
    def t_max(self) -> int:
        return len(self.counts) - 1

    @property
    def n_graphs(self) -> int:
        return self.counts[0].shape[0]

    def self_kernels(self) -> np.ndarray:
        """(t_max + 1, n_graphs): K_T(G, G) for every T, i.e. cumulative Σ_t ‖φ(G_t)‖²."""
        per_t = np.stack([np.asarray(c.multiply(c).sum(axis=1)).ravel() for c in self.counts])
        return np.cumsum(per_t, axis=0)

    def kernel(self, *, t_max: int | None = None) -> np.ndarray:
        """(t_max + 1, n, n): K_T between all graphs for every T = 0..t_max (unnormalised)."""
        t_max = self.t_max if t_max is None else t_max
        per_t = np.stack([(c @ c.T).toarray() for c in self.counts[:t_max + 1]])
        return np.cumsum(per_t, axis=0)

    def cross(self, hashes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """K_T between one new graph and every graph here, for T = 0..len(hashes) − 1.

        `hashes` is the new graph's (T + 1, N) bins from `propagation_hashes` with the same
        projections. Returns (K_row (T + 1, n_graphs), K_self (T + 1,)), both cumulative in T.
        Bins the database never saw count towards K_self only.
        """
        if hashes.shape[0] > len(self.counts):
            raise KernelError(
                f"T = {hashes.shape[0] - 1} iterations asked for, but the database holds "
                f"features for T <= {self.t_max}")
        rows = np.zeros((hashes.shape[0], self.n_graphs))
        selfs = np.zeros(hashes.shape[0])
        for t, bins in enumerate(hashes):
            uniq, cnt = np.unique(bins, return_counts=True)
            vocab = self.vocabularies[t]
            pos = np.searchsorted(vocab, uniq)
            found = pos < len(vocab)
            found[found] = vocab[pos[found]] == uniq[found]
            rows[t] = self.counts[t][:, pos[found]] @ cnt[found].astype(np.float64)
            selfs[t] = float(np.sum(cnt.astype(np.float64) ** 2))
        return np.cumsum(rows, axis=0), np.cumsum(selfs)


def count_features(hashes: np.ndarray, graph_index: np.ndarray, n_graphs: int) -> FeatureCounts:
    """Counts the bins per graph: `hashes` (T + 1, N) of all nodes, `graph_index` (N,) their
    graph."""
    vocabularies, counts = [], []
    for bins in hashes:
        vocab, inverse = np.unique(bins, return_inverse=True)
        c = sp.csc_matrix((np.ones(bins.shape[0]), (graph_index, inverse)),
                          shape=(n_graphs, vocab.shape[0]))
        c.sum_duplicates()
        vocabularies.append(vocab)
        counts.append(c)
    return FeatureCounts(vocabularies, counts)


def batch(transitions: list[sp.spmatrix], labels: list[np.ndarray]
          ) -> tuple[sp.csr_matrix, np.ndarray, np.ndarray]:
    """Stacks graphs into one block-diagonal transition matrix.

    Returns (transition, labels, graph_index), graph_index[i] naming the graph of node i.
    """
    sizes = np.array([lab.shape[0] for lab in labels])
    return (sp.block_diag(transitions, format="csr"), np.concatenate(labels),
            np.repeat(np.arange(len(labels)), sizes))


def graph_features(transitions: list[sp.spmatrix], labels: list[np.ndarray],
                   projections: LshProjections, *, t_max: int | None = None) -> FeatureCounts:
    """φ(G_t), t = 0..t_max, of many graphs at once (one block-diagonal diffusion)."""
    transition, all_labels, graph_index = batch(transitions, labels)
    hashes = propagation_hashes(transition, all_labels, projections, t_max=t_max)
    return count_features(hashes, graph_index, len(labels))


def normalise(kernel: np.ndarray) -> np.ndarray:
    """K̂_ij = K_ij / sqrt(K_ii K_jj) on the last two axes (a stack of square kernels)."""
    diag = np.sqrt(np.diagonal(kernel, axis1=-2, axis2=-1))
    return kernel / (diag[..., :, None] * diag[..., None, :])
