"""`dgi_us_per_hypothesis`: DGI features + SVM + sigmoid per grasp hypothesis, in microseconds.

The scene: an upright cylinder (r 3 cm, h 10 cm) sampled with 5000 surface points, and 200 grasp
hypotheses from its part boxes, perturbed — about what DgiScoringSystem sees for one object.
Measured: `DgiGraspModel.p_grasp` on all of them at once (vectorised features, the RBF expansion as
one matrix product). Reference: the same features scored one hypothesis at a time through
scikit-learn's libSVM `decision_function` and the same sigmoid.
"""

from __future__ import annotations

import numpy as np

from tg_drake.bench import Figure, figure, median_time
from tg_drake.grasping.hypotheses import box_grasps, perturb_grasps
from tg_drake.grasping.model import load_default_model
from tg_drake.grasping.svm import platt_probability

N_POINTS = 5000
N_HYPOTHESES = 200


def _scene(rng):
    t = rng.uniform(0, 2 * np.pi, N_POINTS)
    h = rng.uniform(0, 0.1, N_POINTS)
    p_W = np.stack([0.5 + 0.03 * np.cos(t), 0.03 * np.sin(t), h], axis=1)
    X_WB = np.eye(4)
    X_WB[:3, 3] = [0.5, 0, 0.05]
    boxes = box_grasps(X_WB, np.array([0.03, 0.03, 0.05]))
    X_WG = perturb_grasps(np.resize(boxes, (N_HYPOTHESES, 4, 4)), rng)
    return p_W, X_WG


def dgi_us_per_hypothesis() -> Figure:
    model = load_default_model()
    p_W, X_WG = _scene(np.random.default_rng(0))
    clf = model.classifier

    def ours():
        model.p_grasp(p_W, X_WG)

    def reference():
        for k in range(len(X_WG)):
            f = clf.svm_.decision_function(model.features(p_W, X_WG[k]))
            platt_probability(f, clf.A_, clf.b_)

    scale = 1e6 / N_HYPOTHESES
    return figure(median_time(ours, repeats=7) * scale, "us",
                  "per-hypothesis loop through scikit-learn's libSVM decision_function",
                  median_time(reference, repeats=3) * scale)
