"""The object database of the kernel prior and the prior query against it.

The database holds, per graph of the object library, its hashed features φ(G_t) for t = 0..15
(not the raw graphs), where it came from (a ground-truth sampling of the mesh, or a perceived
view: pose, yaw, viewpoint), the LSH projections that made them (queries must hash with the same
ones), the resampling density, and the T and entries chosen by leave-one-object-out
cross-validation for perceived queries.
`tools/build_kernel_db.py` writes it to `tg_drake/data/kernel_db.npz`; `load_default_database()`
reads that file once per process.
"""


import functools
import importlib.resources
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from tg_drake.errors import KernelError, unknown_name
from tg_drake.kernels.graph import (
    K_NEIGHBOURS,
    LabelledCloud,
    cloud_transition,
    size_normalised,
    validate_cloud,
    voxel_resample,
)
from tg_drake.kernels.prior import N_NEIGHBOURS, category_priors
from tg_drake.kernels.propagation import (
    FeatureCounts,
    LshProjections,
    graph_features,
    propagation_hashes,
)
from tg_drake.types import CATEGORIES, PART_LABELS, CategoryDistribution, source_objects

FORMAT_VERSION = 3  # 3: clouds scaled to unit size before resampling (spacing relative).
SOURCES = ("ground_truth", "perceived")  # where a database graph came from.
# Which database graphs a query is compared with: every graph, or those of one source.
ENTRIES = ("all",) + SOURCES
DEFAULT_DATABASE = "data/kernel_db.npz"  # inside the tg_drake package.


@dataclass
class KernelPriorConfig:
    """Parameters of the kernel prior stage."""

    iterations: int | None = None  # T of K_T; None: the database's cross-validated T for
    # `clouds` (leave-one-object-out).
    entries: str | None = None  # database graphs compared with: "all", "ground_truth",
    # "perceived"; None: the database's cross-validated choice for `clouds`.
    clouds: str | None = None  # what the queries are: "perceived" clouds (perception's), or
    # "ground_truth" samplings of the meshes; picks the database's choice of T and entries.
    # None: "perceived" (the pipeline sets it from its perception variant).
    n_neighbours: int = N_NEIGHBOURS  # n most similar database graphs averaged into the prior.
    database: str | None = None  # path of a kernel_db.npz; None: the one shipped in tg_drake/data.


def prepare_cloud(points, normals, labels, *, spacing: float, k: int = K_NEIGHBOURS
                  ) -> LabelledCloud:
    """Validates a cloud, scales it to unit size (`graph.size_normalised`) and resamples it to
    `spacing` (a fraction of the object's size), as queries and perceived database entries are
    (the grid starts at the cloud's lowest corner)."""
    cloud = size_normalised(validate_cloud(points, normals, labels, k=k))
    resampled = voxel_resample(cloud, spacing)
    if resampled.points.shape[0] < k + 1:
        raise KernelError(
            f"a cloud of {resampled.points.shape[0]} point(s) after resampling at "
            f"{spacing:.3f} of its size is too small: the k-nn graph with k = {k} "
            f"needs at least {k + 1} points")
    return resampled


@dataclass
class KernelDatabase:
    """Hashed propagation-kernel features of labelled object graphs, with their categories."""

    object_ids: np.ndarray  # (G,) str: library object of each graph (several graphs per object).
    categories: np.ndarray  # (G,) int: index into CATEGORIES.
    features: FeatureCounts  # φ(G_t) for t = 0..t_max.
    projections: LshProjections  # the LSH projections of database and queries.
    spacing: float  # voxel size clouds are resampled to before their graph is built, as a
    # fraction of the cloud's size (clouds are scaled to a largest principal extent of 1).
    k: int = K_NEIGHBOURS  # neighbours per node in the k-nn graph.
    t_default: int = 0  # T used when a query gives none.
    library_fingerprint: str = ""  # of the object library the graphs were sampled from.
    sources: np.ndarray | None = None  # (G,) str in SOURCES; None: all "ground_truth".
    poses: np.ndarray | None = None  # (G,) str: resting pose of a perceived view ("" otherwise).
    yaws: np.ndarray | None = None  # (G,) [deg] yaw of a perceived view (NaN otherwise).
    viewpoints: np.ndarray | None = None  # (G,) int: viewpoint index of a view (−1 otherwise).
    entries_default: str = "all"  # ENTRIES a query compares with when it names none.
    t_ground_truth: int = 0  # T and entries chosen for ground-truth samplings as queries
    entries_ground_truth: str = "all"  # (the defaults above serve perceived clouds).
    floor_default: float = 0.0  # the prior's floor ε for perceived queries and for ground-truth
    floor_ground_truth: float = 0.0  # samplings: (1 − ε)·prior + ε/11 is the calibrated prior,
    # ε fitted at build time by maximum likelihood of the true category over the database's own
    # graphs as leave-one-object-out queries (tools/build_kernel_db.py). 0: not fitted.

    def __post_init__(self):
        g = self.object_ids.shape[0]
        if self.sources is None:
            self.sources = np.full(g, SOURCES[0])
        if self.poses is None:
            self.poses = np.full(g, "")
        if self.yaws is None:
            self.yaws = np.full(g, np.nan)
        if self.viewpoints is None:
            self.viewpoints = np.full(g, -1, dtype=np.int64)
        self.sources, self.poses = np.asarray(self.sources, str), np.asarray(self.poses, str)
        self.yaws = np.asarray(self.yaws, np.float64)
        self.viewpoints = np.asarray(self.viewpoints, np.int64)
        if not all(a.shape == (g,) for a in (self.sources, self.poses, self.yaws,
                                             self.viewpoints)):
            raise KernelError(f"one source, pose, yaw and viewpoint per graph ({g} graphs)")
        unknown = sorted(set(self.sources.tolist()) - set(SOURCES))
        if unknown:
            raise unknown_name("database source", unknown[0], SOURCES, error=KernelError)
        self.resolve_entries(self.entries_default)
        self.resolve_entries(self.entries_ground_truth)
        self._self_kernels = self.features.self_kernels()
        self._source_ids = source_objects(self.object_ids)  # for leave-one-object-out

    @property
    def t_max(self) -> int:
        return self.features.t_max

    @classmethod
    def build(cls, clouds: list[LabelledCloud], object_ids, categories, *,
              projections: LshProjections, spacing: float, k: int = K_NEIGHBOURS,
              t_default: int = 0, **entry_info) -> "KernelDatabase":
        """Hashes already resampled clouds into a database (one block-diagonal diffusion).
        `entry_info`: sources, poses, yaws, viewpoints (one per cloud), entries_default."""
        ids = np.asarray(object_ids, dtype=str)
        cats = np.asarray(categories, dtype=np.int64)
        if not (len(clouds) == len(ids) == len(cats)):
            raise KernelError(f"{len(clouds)} clouds, {len(ids)} object ids and {len(cats)} "
                              "categories: one of each per graph")
        if len(clouds) == 0:
            raise KernelError("an empty kernel database: give at least one cloud")
        transitions = [cloud_transition(c, k=k) for c in clouds]
        features = graph_features(transitions, [c.labels for c in clouds], projections)
        return cls(ids, cats, features, projections, float(spacing), k, int(t_default),
                   **entry_info)

    # -- queries ---------------------------------------------------------------------------

    def choice(self, clouds: str) -> tuple[str, int]:
        """(entries, T) chosen by cross-validation for queries of this kind (`SOURCES`)."""
        if clouds not in SOURCES:
            raise unknown_name("kind of query clouds", clouds, SOURCES, error=KernelError)
        return ((self.entries_default, self.t_default) if clouds == "perceived"
                else (self.entries_ground_truth, self.t_ground_truth))

    def floor(self, clouds: str) -> float:
        """The prior's fitted floor ε for queries of this kind (`SOURCES`): the logic sees
        (1 − ε)·prior + ε/11 (`Observations.from_object`)."""
        self.choice(clouds)  # checks the kind
        return self.floor_default if clouds == "perceived" else self.floor_ground_truth

    def resolve_entries(self, entries: str | None) -> str:
        entries = self.entries_default if entries is None else entries
        if entries not in ENTRIES:
            raise unknown_name("database entries", entries, ENTRIES, error=KernelError)
        if entries != "all" and not np.any(self.sources == entries):
            raise KernelError(f"the kernel database holds no {entries} graphs")
        return entries

    def entry_mask(self, entries: str | None = None) -> np.ndarray:
        """(G,) bool: the graphs a query with these `entries` is compared with."""
        entries = self.resolve_entries(entries)
        return np.ones(self.sources.shape, bool) if entries == "all" else self.sources == entries

    def resolve_iterations(self, t: int | None) -> int:
        t = self.t_default if t is None else int(t)
        if not 0 <= t <= self.t_max:
            raise KernelError(f"iterations T = {t} out of range; allowed: 0..{self.t_max}")
        return t

    def prepare(self, points, normals, labels) -> LabelledCloud:
        """Validates a query cloud and resamples it to the database's density (`spacing`)."""
        return prepare_cloud(points, normals, labels, spacing=self.spacing, k=self.k)

    def similarity_profile(self, points, normals, labels, *, t: int | None = None
                           ) -> np.ndarray:
        """(t + 1, G): K̂_0 .. K̂_t between the query cloud and every database graph
        (t = None: all T the database holds)."""
        t = self.t_max if t is None else self.resolve_iterations(t)
        cloud = self.prepare(points, normals, labels)
        hashes = propagation_hashes(cloud_transition(cloud, k=self.k), cloud.labels,
                                    self.projections, t_max=t)
        row, self_k = self.features.cross(hashes)
        return row / np.sqrt(self_k[:, None] * self._self_kernels[:t + 1])

    def member_profile(self, rows) -> np.ndarray:
        """(t_max + 1, Q, G): K̂_0 .. K̂_t_max between the database graphs `rows` (indices) and
        every database graph: what `similarity_profile` gives for the clouds they were built
        from (leave-one-out evaluation drops the columns it must not see)."""
        rows = np.asarray(rows, dtype=np.int64)
        per_t = np.stack([(c[rows] @ c.T).toarray() for c in self.features.counts])
        k = np.cumsum(per_t, axis=0)
        s = self._self_kernels
        return k / np.sqrt(s[:, rows][:, :, None] * s[:, None, :])

    def similarities(self, points, normals, labels, *, t: int | None = None) -> np.ndarray:
        """(G,) K̂_T between the query cloud and every database graph (T = t, or the
        database's T when t is None)."""
        t = self.resolve_iterations(t)
        return self.similarity_profile(points, normals, labels, t=t)[t]

    def prior(self, points, normals, labels, *, t: int | None = None,
              n_neighbours: int = N_NEIGHBOURS, exclude_object: str | None = None,
              entries: str | None = None) -> CategoryDistribution:
        """The category prior of one cloud: the n most similar graphs weighted by exp(−rank).

        `entries` picks the graphs compared with ("all", "ground_truth", "perceived"; None: the
        database's default). `exclude_object` leaves every graph of that object (and of its
        scan-like version or original) out (leave-one-object-out); an object the database does
        not hold (one imported after it was built) leaves nothing out.
        """
        mask = self.entry_mask(entries)
        sim = np.where(mask, self.similarities(points, normals, labels, t=t), -np.inf)
        if exclude_object is not None:  # the object and its scan-like version or original
            own = self._source_ids == source_objects(exclude_object)[0]
            sim = np.where(own, -np.inf, sim)
        priors, neighbours = category_priors(sim, self.categories, n_neighbours=n_neighbours)
        return CategoryDistribution(
            probabilities=priors[0],
            neighbours=[(str(self.object_ids[j]), CATEGORIES[self.categories[j]], float(sim[j]))
                        for j in neighbours[0] if np.isfinite(sim[j])])

    # -- file ------------------------------------------------------------------------------

    def save(self, path: str | Path) -> None:
        """Writes the database as a compressed .npz to a path or binary file (counts as small
        integers)."""
        f = self.features
        max_count = max(int(c.data.max()) for c in f.counts)
        arrays = dict(
            format_version=np.array(FORMAT_VERSION),
            category_names=np.array(CATEGORIES), part_labels=np.array(PART_LABELS),
            object_ids=self.object_ids, categories=self.categories.astype(np.int16),
            proj_v=self.projections.v, proj_b=self.projections.b,
            w=np.array(self.projections.w), spacing=np.array(self.spacing),
            k=np.array(self.k), t_default=np.array(self.t_default),
            library_fingerprint=np.array(self.library_fingerprint),
            sources=np.argmax(self.sources[:, None] == np.array(SOURCES),
                              axis=1).astype(np.uint8),
            poses=self.poses, yaws=self.yaws.astype(np.float32),
            viewpoints=self.viewpoints.astype(np.int8),
            entries_default=np.array(self.entries_default),
            t_ground_truth=np.array(self.t_ground_truth),
            entries_ground_truth=np.array(self.entries_ground_truth),
            floor_default=np.array(self.floor_default),
            floor_ground_truth=np.array(self.floor_ground_truth),
            vocab_sizes=np.array([len(v) for v in f.vocabularies], dtype=np.int64),
            vocab=np.concatenate(f.vocabularies),
            # Per bin (column): how many graphs have it; then those graphs and their counts.
            column_nnz=np.concatenate([np.diff(c.indptr) for c in f.counts]).astype(
                np.uint16 if f.n_graphs < 2 ** 16 else np.uint32),
            graph_ids=np.concatenate([c.indices for c in f.counts]).astype(
                np.uint16 if f.n_graphs < 2 ** 16 else np.uint32),
            counts=np.concatenate([c.data for c in f.counts]).astype(
                np.uint16 if max_count < 2 ** 16 else np.uint32),
        )
        np.savez_compressed(path, **arrays)

    @classmethod
    def load(cls, path) -> "KernelDatabase":
        """Reads a database written by `save` (a path or a binary file object)."""
        try:
            data = np.load(path, allow_pickle=False)
        except (OSError, ValueError) as e:
            raise KernelError(f"cannot read the kernel database: {e}", file=str(path)) from None
        with data:
            if int(data["format_version"]) != FORMAT_VERSION:
                raise KernelError(f"kernel database format {int(data['format_version'])}, "
                                  f"expected {FORMAT_VERSION}; rebuild it with "
                                  "tools/build_kernel_db.py", file=str(path))
            if tuple(data["category_names"].tolist()) != CATEGORIES or \
                    tuple(data["part_labels"].tolist()) != PART_LABELS:
                raise KernelError("kernel database built for other categories or part labels; "
                                  "rebuild it with tools/build_kernel_db.py", file=str(path))
            n_graphs = data["object_ids"].shape[0]
            sizes = data["vocab_sizes"]
            vocab_ends = np.cumsum(sizes)
            vocabularies = np.split(data["vocab"], vocab_ends[:-1])
            column_nnz = np.split(data["column_nnz"].astype(np.int64), vocab_ends[:-1])
            nnz_ends = np.cumsum([c.sum() for c in column_nnz])
            graph_ids = np.split(data["graph_ids"].astype(np.int32), nnz_ends[:-1])
            counts = np.split(data["counts"].astype(np.float64), nnz_ends[:-1])
            matrices = [
                sp.csc_matrix((cnt, gid, np.concatenate([[0], np.cumsum(nnz)])),
                              shape=(n_graphs, len(voc)))
                for voc, nnz, gid, cnt in zip(vocabularies, column_nnz, graph_ids, counts,
                                              strict=False)]
            return cls(
                object_ids=data["object_ids"].astype(str),
                categories=data["categories"].astype(np.int64),
                features=FeatureCounts(vocabularies, matrices),
                projections=LshProjections(v=data["proj_v"], b=data["proj_b"],
                                           w=float(data["w"])),
                spacing=float(data["spacing"]), k=int(data["k"]),
                t_default=int(data["t_default"]),
                library_fingerprint=str(data["library_fingerprint"]),
                sources=np.array(SOURCES)[data["sources"].astype(np.int64)],
                poses=data["poses"].astype(str), yaws=data["yaws"].astype(np.float64),
                viewpoints=data["viewpoints"].astype(np.int64),
                entries_default=str(data["entries_default"]),
                t_ground_truth=int(data["t_ground_truth"]),
                entries_ground_truth=str(data["entries_ground_truth"]),
                floor_default=float(data["floor_default"]) if "floor_default" in data
                else 0.0,
                floor_ground_truth=float(data["floor_ground_truth"])
                if "floor_ground_truth" in data else 0.0)


@functools.lru_cache(maxsize=4)
def _load_cached(path: str | None) -> KernelDatabase:
    if path is not None:
        if not Path(path).is_file():
            raise KernelError("kernel database not found", file=path)
        return KernelDatabase.load(path)
    resource = importlib.resources.files("tg_drake").joinpath(DEFAULT_DATABASE)
    if not resource.is_file():
        raise KernelError("the shipped kernel database is missing; build it with "
                          "`python tools/build_kernel_db.py`", file=f"tg_drake/{DEFAULT_DATABASE}")
    with resource.open("rb") as fh:
        return KernelDatabase.load(fh)


def load_database(path: str | None = None) -> KernelDatabase:
    """The kernel database at `path` (None: the one shipped with the package), loaded once."""
    return _load_cached(None if path is None else str(Path(path).resolve()))
