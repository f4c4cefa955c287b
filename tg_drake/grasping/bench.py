"""`dgi_us_per_hypothesis`: DGI features + SVM + sigmoid per grasp hypothesis, in microseconds.

For every library object in its first resting pose: its cloud at the perception's density (4 mm,
`dataset.scene_cloud`, 550–19 000 points) and the grasp hypotheses of the training scenes
(`dataset.scene_grasps`, 28–112 per object). Measured: `DgiGraspModel.p_grasp` on all hypotheses of
the object at once (one matrix product for all gripper frames, the RBF expansion as one matrix
product); the figure is the median over objects of the time per hypothesis. Reference: the same
features scored one hypothesis at a time through scikit-learn's libSVM `decision_function` and the
same sigmoid, median over objects likewise.
"""

from __future__ import annotations

import statistics

from tg_drake.bench import Figure, figure, median_time
from tg_drake.grasping.dataset import scene_cloud, scene_grasps
from tg_drake.grasping.model import load_default_model
from tg_drake.grasping.svm import platt_probability
from tg_drake.objects import load_library


def dgi_us_per_hypothesis() -> Figure:
    model = load_default_model()
    clf = model.classifier
    ours, reference = [], []
    for obj in load_library().values():
        pose = next(iter(obj.poses))
        p_W, _, _ = scene_cloud(obj, pose, seed=0)
        X_WG = scene_grasps(obj, pose, seed=0).X_WG
        if len(X_WG) == 0:
            continue

        def batch(p_W=p_W, X_WG=X_WG):
            model.p_grasp(p_W, X_WG)

        def one_at_a_time(p_W=p_W, X_WG=X_WG):
            for X in X_WG:
                f = clf.svm_.decision_function(model.features(p_W, X))
                platt_probability(f, clf.A_, clf.b_)

        ours.append(median_time(batch, repeats=3) * 1e6 / len(X_WG))
        reference.append(median_time(one_at_a_time, repeats=1, warmup=0) * 1e6 / len(X_WG))
    return figure(statistics.median(ours), "us",
                  "one hypothesis at a time through scikit-learn's libSVM decision_function",
                  statistics.median(reference))
