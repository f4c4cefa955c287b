"""The trained local-shape grasp model: DGI feature settings plus the fitted SVM + Platt sigmoid.

`tools/train_dgi.py` writes it to `tg_drake/data/dgi_svm.joblib`; `load_default_model()` reads that
file once per process. `DgiGraspModel.p_grasp(p_W, X_WG)` is P(grasp | local shape) for many
hypotheses at once.
"""

from __future__ import annotations

import functools
import importlib.resources
from dataclasses import asdict, dataclass, field
from pathlib import Path

import joblib
import numpy as np
from threadpoolctl import ThreadpoolController

from tg_drake.errors import GraspingError
from tg_drake.grasping.dgi import DgiConfig, dgi_features
from tg_drake.grasping.svm import PlattSvmClassifier

FORMAT_VERSION = 1
DEFAULT_MODEL = "data/dgi_svm.joblib"  # inside the tg_drake package.


@dataclass
class DgiGraspModel:
    """A fitted classifier and the feature settings it was trained with."""

    classifier: PlattSvmClassifier
    config: DgiConfig = field(default_factory=DgiConfig)
    info: dict = field(default_factory=dict)  # training provenance: data size, CV scores, ...

    def __post_init__(self):
        n = getattr(self.classifier, "n_features_in_", None)
        if n is None:
            raise GraspingError("the DGI model's classifier is not fitted")
        if n != self.config.n_features:
            raise GraspingError(
                f"the classifier expects {n} features but DgiConfig gives {self.config.n_features}")

    def features(self, p_W: np.ndarray, X_WG: np.ndarray) -> np.ndarray:
        return dgi_features(p_W, X_WG, self.config)

    def p_grasp(self, p_W: np.ndarray, X_WG: np.ndarray) -> np.ndarray:
        """(M,) P(grasp | local shape) of the cloud `p_W` for each gripper pose X_WG (M, 4, 4).

        BLAS runs on one thread here: the matrix products are small, and on a loaded machine
        (a simulator beside us, other processes) OpenBLAS threads wait on each other — measured
        4× slower with two threads than with one on our shared 2-core machine.
        """
        with _blas_controller().limit(limits=1, user_api="blas"):
            return self.classifier.predict_proba(self.features(p_W, X_WG))[:, 1]

    def save(self, path: Path) -> None:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        joblib.dump({"format": FORMAT_VERSION, "classifier": self.classifier,
                     "config": asdict(self.config), "info": self.info}, path, compress=3)


def load_model(path: str | Path) -> DgiGraspModel:
    """Reads a model written by `DgiGraspModel.save`."""
    path = Path(path)
    if not path.is_file():
        raise GraspingError("no DGI model file; train one with tools/train_dgi.py", file=str(path))
    data = joblib.load(path)
    if not isinstance(data, dict) or data.get("format") != FORMAT_VERSION:
        raise GraspingError(f"not a DGI model file of format {FORMAT_VERSION}", file=str(path))
    return DgiGraspModel(data["classifier"], DgiConfig(**data["config"]), data["info"])


@functools.cache
def _blas_controller() -> ThreadpoolController:
    """Inspects the loaded thread pools once; limiting them through it is then cheap."""
    return ThreadpoolController()


@functools.cache
def load_default_model() -> DgiGraspModel:
    """The model shipped with the package (tg_drake/data/dgi_svm.joblib), loaded once."""
    resource = importlib.resources.files("tg_drake").joinpath(DEFAULT_MODEL)
    with importlib.resources.as_file(resource) as path:
        return load_model(path)
