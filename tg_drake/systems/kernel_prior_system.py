"""The kernel prior stage as a Drake system (paper section III-C)."""

from __future__ import annotations

import dataclasses

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem

from tg_drake.kernels.database import KernelDatabase, KernelPriorConfig, load_database
from tg_drake.types import CategoryPrior, SceneDescription


class KernelPriorSystem(LeafSystem):
    """A category prior for every perceived object from the propagation kernel.

    .. pydrake_system::

        name: KernelPriorSystem
        input_ports:
        - scene_description
        output_ports:
        - category_prior

    For each object of ``scene_description`` (a `SceneDescription`), its completed cloud, normals
    and part labels make a weighted k-nn graph; its propagation kernel against the object
    database ranks the database graphs (by default the entries and T the database chose by
    cross-validation for `config.clouds`: for perceived clouds, perceived views of the library,
    so that a perceived object meets perceived objects), and the n most similar, weighted by
    exp(−rank), give a
    `CategoryDistribution` (with the neighbours listed). ``category_prior`` is a `CategoryPrior`,
    one distribution per object, in the order of the scene description.

    The database is the one shipped with the package unless `config.database` or `database`
    names another; it is loaded once per process.
    """

    def __init__(self, config: KernelPriorConfig | None = None, *,
                 database: KernelDatabase | None = None):
        super().__init__()
        self._config = config if config is not None else KernelPriorConfig()
        self._database = database if database is not None else load_database(
            self._config.database)
        # The database's cross-validated T and entries for these clouds, unless the config
        # names them; checked now rather than at the first evaluation.
        entries, t = self._database.choice(self._config.clouds or "perceived")
        self._floor = self._database.floor(self._config.clouds or "perceived")
        self._entries = self._database.resolve_entries(
            entries if self._config.entries is None else self._config.entries)
        self._iterations = self._database.resolve_iterations(
            t if self._config.iterations is None else self._config.iterations)
        self._scene_port = self.DeclareAbstractInputPort(
            "scene_description",
            AbstractValue.Make(SceneDescription(objects=[], X_WT=np.eye(4))))
        self._prior_port = self.DeclareAbstractOutputPort(
            "category_prior", lambda: AbstractValue.Make(CategoryPrior(distributions=[])),
            self._calc_category_prior,
            prerequisites_of_calc={self.input_port_ticket(self._scene_port.get_index())})

    @property
    def database(self) -> KernelDatabase:
        return self._database

    def get_scene_description_input_port(self):
        return self._scene_port

    def get_category_prior_output_port(self):
        return self._prior_port

    def _calc_category_prior(self, context, output):
        scene: SceneDescription = self._scene_port.Eval(context)
        output.set_value(CategoryPrior(distributions=[
            dataclasses.replace(
                self._database.prior(obj.p_W, obj.n_W, obj.labels, t=self._iterations,
                                     n_neighbours=self._config.n_neighbours,
                                     entries=self._entries), floor=self._floor)
            for obj in scene.objects]))
