"""One case of a suite → one record (or one per setting): what each method answered.

`run_case` is the function a sweep hands to the executor (module level, so that worker processes
and Ray import it by name). It keeps raw answers — distributions, not verdicts — so that every
table can be derived again from the records (tg_drake.evaluation.tables).

- synthetic: observations from the labelled mesh (parts certain, pose certain, containment, handle
  count); kernel priors at T = 0 (Label fractions) and T = kernel_T (Manifolds) from one labelled
  sampling of the mesh per object (seeded by the object and the suite's seed),
  leave-one-object-out; then every logic method (METHODS) answers category,
  task (inferred) and, for each ground-truth task given, the pre-grasp part.
- perceived: the object's depth image ray cast from the default camera's viewpoint and perceived;
  pose and part detection against the truth; then the same queries on observations of each setting.
- executed: `tg_drake.run.run_scenario` on the scenario in the case's variant (`scoring_of`) and
  the suite's task scene; `build_s` is the
  wall time of building its diagram and context [s] (the executor adds `worker_pid` and `rss_mb`).
"""

from __future__ import annotations

import functools
import zlib
from pathlib import Path

import numpy as np

from tg_drake.errors import KernelError, RuleError, TgDrakeError
from tg_drake.evaluation.suite import DATASET_OF_SETTING
from tg_drake.kernels.database import load_database
from tg_drake.kernels.library import sample_object
from tg_drake.logic.engine import LogicEngine
from tg_drake.logic.observations import (
    Observations,
    count_handles,
    handle_count,
    pair_probability_of,
)
from tg_drake.logic.theory import TheoryConfig
from tg_drake.objects import get_object, mesh
from tg_drake.perception.ground_truth import interior_visible
from tg_drake.perception.render import perceive
from tg_drake.perception.sensor_model import StructuredLight
from tg_drake.run import run_scenario
from tg_drake.scenario import (
    DepthPerception,
    DgiScorer,
    LocalOnly,
    PipelineConfig,
    RandomPart,
    Scenario,
    resolve_objects,
    validate,
)
from tg_drake.types import CATEGORIES

# Logic methods (the paper's columns, the paper's two ablations and ours): name → (category/task
# theory, pre-grasp theory, prior[, "no_interior"]). Theories as (category model, grasp model,
# exclusive); the pre-grasp
# columns keep the specific category model, as the paper's Table "pre-grasp" does.
METHODS = {
    "plm_uniform": (("specific", "specific", True), ("specific", "specific", True), "uniform"),
    "plm_general_uniform": (("general", "general", True), ("specific", "general", True),
                            "uniform"),
    "plm": (("specific", "specific", True), ("specific", "specific", True), "manifolds"),
    "plm_general": (("general", "general", True), ("specific", "general", True), "manifolds"),
    "plm_top": (("specific", "specific", True), ("specific", "specific", True), "top"),
    "plm_nonexclusive": (("specific", "specific", False), ("specific", "specific", False),
                         "manifolds"),
    # PLM on the paper's observations only: without `interior_seen` (ours).
    "plm_paper_observations": (("specific", "specific", True), ("specific", "specific", True),
                               "manifolds", "no_interior"),
}
CONFIDENT_PART = 0.5  # S_REAL: detected parts at least this likely are kept (as certain).
# The depth sensor the perceived and executed suites see: a realistic camera's measurement of the
# render (tg_drake.perception.sensor_model; a scenario's own default is the exact render).
EVALUATION_SENSOR = StructuredLight()

# The kernel database file the evaluation's priors and floors come from (None: the shipped one);
# a tool measuring another database sets it for its process with `use_database`.
_DATABASE: str | None = None


def use_database(path: str | Path | None) -> None:
    """Every kernel prior, floor and sampling density of this process's evaluation from the
    database file `path` (None: the shipped one again)."""
    global _DATABASE
    if path is not None and not Path(path).is_file():
        raise KernelError(f"{path}: no such kernel database file")
    _DATABASE = None if path is None else str(path)


def _database():
    return load_database(_DATABASE)


@functools.cache
def _engine(category: str, grasp: str, exclusive: bool):
    return LogicEngine(TheoryConfig(category=category, grasp=grasp, exclusive=exclusive))


def _round(v) -> list[float]:
    return [round(float(x), 6) for x in v]


def _prior(kind: str, priors: dict, floor: float) -> dict | None:
    if kind == "uniform":
        return None
    p = np.asarray(priors["manifolds"], dtype=float)
    if kind == "top":
        p = np.eye(len(CATEGORIES))[int(np.argmax(p))]
    p = (1.0 - floor) * p + floor / len(CATEGORIES)
    return dict(zip(CATEGORIES, p.tolist(), strict=True))


def logic_answers(observations, priors: dict, truth_tasks, methods=METHODS,
                  theory: str = "specific", clouds: str = "perceived") -> dict:
    """Every method's category and task distributions (task inferred) and, for each task of the
    ground truth, its part distribution. `theory` stands in for the specific model variant (e.g.
    "learned"); `clouds` is the kind of query the priors answered ("perceived" or
    "ground_truth"), whose fitted floor the kernel database gives (`KernelDatabase.floor`), as
    the pipeline's logic uses it. An impossible observation (probability 0) is recorded as the
    error it is, with no distributions."""
    floor = _database().floor(clouds)

    def variant(models):
        return tuple(theory if m == "specific" else m for m in models[:2]) + models[2:]

    out = {}
    for name, (cat_theory, grasp_theory, prior_kind, *flags) in methods.items():
        cat_theory, grasp_theory = variant(cat_theory), variant(grasp_theory)
        prior = _prior(prior_kind, priors, floor)
        interior = 0.0 if "no_interior" in flags else observations.interior_seen
        hidden = 0.0 if "no_interior" in flags else observations.interior_hidden

        def obs(task=None, prior=prior, interior=interior, hidden=hidden):
            return Observations(parts=observations.parts, pose=observations.pose,
                                containment=observations.containment, category_prior=prior,
                                task=task, handles=observations.handles,
                                handle_pair=observations.handle_pair,
                                interior_seen=interior, interior_hidden=hidden)

        try:
            answer = _engine(*cat_theory).query(obs())
            parts = {t: _round(_engine(*grasp_theory).query(obs(t)).part) for t in truth_tasks}
            out[name] = {"category": _round(answer.category), "task": _round(answer.task),
                         "part": parts}
        except RuleError as e:
            out[name] = {"error": str(e)}
    return out


def kernel_priors(points, normals, labels, *, object_id: str, t: int,
                  clouds: str = "perceived") -> dict:
    """Label fractions (T = 0) and Manifolds (T = t) priors, leave-one-object-out, against the
    database entries chosen for this kind of query cloud ("perceived" or "ground_truth")."""
    db = _database()
    entries, _ = db.choice(clouds)
    return {name: _round(db.prior(points, normals, labels, t=T, entries=entries,
                                  exclude_object=object_id).probabilities)
            for name, T in (("label_fractions", 0), ("manifolds", t))}


def _seed(key: str, seed: int) -> int:
    return zlib.crc32(key.encode()) + 1_000_003 * seed


def run_synthetic(case) -> dict:
    placement = case.target_placement
    obj = get_object(placement.id)
    vertices, _, labels = mesh(obj)
    handles = handle_count(vertices, labels) if "handle" in obj.parts else 1
    # One labelled sampling per object, whatever its pose and containment (the paper's S_SYN has
    # one point cloud per object, so its Manifolds accuracy is over objects: 36 of 41 = 87.8 %).
    cloud = sample_object(obj, spacing=_database().spacing,
                          rng=np.random.default_rng(_seed(obj.id, case.seed)))
    seen = interior_visible(obj.id, placement.pose)
    observations = Observations(parts={p: 1.0 for p in obj.parts}, pose={placement.pose: 1.0},
                                containment={placement.containment: 1.0}, handles=handles,
                                interior_seen=seen, interior_hidden=1.0 - seen)
    priors = kernel_priors(cloud.points, cloud.normals, cloud.labels, object_id=obj.id,
                           t=case.kernel_T, clouds="ground_truth")
    return {**case.meta(), "priors": priors,
            "methods": logic_answers(observations, priors, case.truth.tasks, clouds="ground_truth",
                                       theory=case.theory)}


def setting_observations(description, setting: str, *, true_pose: str, containment: str):
    """Observations of a perceived object in one of the paper's S_REAL settings."""
    detected = {p: float(v) for p, v in description.part_probabilities.items() if v > 0}
    if setting == "semi":
        parts, pose = {p: 1.0 for p in detected}, {true_pose: 1.0}
    elif setting == "real":
        parts = {p: 1.0 for p, v in detected.items() if v >= CONFIDENT_PART}
        pose = dict(description.pose_likelihood)
    else:
        parts, pose = detected, dict(description.pose_likelihood)
    return Observations(parts=parts, pose=pose, containment={containment: 1.0},
                        handles=(n := count_handles(description)),
                        handle_pair=pair_probability_of(description, n),
                        interior_seen=description.interior_seen,
                        interior_hidden=description.interior_hidden)


def run_perceived(case) -> list[dict]:
    placement = case.target_placement
    obj = get_object(placement.id)
    meta = case.meta()
    try:
        d = perceive(obj.id, placement.pose, placement.yaw, sensor=EVALUATION_SENSOR,
                     seed=_seed(case.key, case.seed))
        detection = {"found_pose": d.pose, "found_parts": sorted(
            p for p, v in d.part_probabilities.items() if v > 0)}
        priors = kernel_priors(d.p_W, d.n_W, d.labels, object_id=obj.id, t=case.kernel_T)
    except TgDrakeError as e:  # perception found nothing usable: a failure of every method
        detection = {"found_pose": None, "found_parts": None, "error": str(e)}
        priors, d = None, None
    detection["pose_ok"] = detection["found_pose"] == placement.pose
    detection["parts_ok"] = detection["found_parts"] == sorted(obj.parts)
    records = []
    for setting in case.settings:
        record = {**meta, "dataset": DATASET_OF_SETTING[setting], "setting": setting,
                  "detection": detection, "priors": priors}
        if d is not None:
            obs = setting_observations(d, setting, true_pose=placement.pose,
                                       containment=placement.containment)
            record["observed_parts"] = sorted(obs.parts)
            record["observations"] = {"parts": obs.parts, "pose": obs.pose,
                                      "handles": obs.handles,
                                      "handle_pair": round(obs.pair_probability, 6),
                                      "interior_seen": round(obs.interior_seen, 6),
                                      "interior_hidden": round(obs.interior_hidden, 6)}
            record["methods"] = logic_answers(obs, priors, case.truth.tasks,
                                                  theory=case.theory)
        records.append(record)
    return records


def scoring_of(case):
    """The scoring stage of an executed case's variant: the DGI (pipeline, pipeline_uniform),
    P(grasp | local shape) alone (local), or a part drawn at random, seeded by the case's scenario
    (its key without the variant) and the suite's seed, so that it repeats (random_part)."""
    if case.variant == "local":
        return LocalOnly()
    if case.variant == "random_part":
        return RandomPart(seed=_seed(case.key.split("@")[0], case.seed) % 2**31)
    return DgiScorer()


def scenario_of(case) -> Scenario:
    """The scenario an executed case runs (validated): its scene (and the suite's task scene)
    with the variant's pipeline."""
    pipeline = PipelineConfig(perception=DepthPerception(sensor=EVALUATION_SENSOR),
                              scoring=scoring_of(case))
    pipeline.logic.category = pipeline.logic.grasp = case.theory
    pipeline.logic.use_prior = case.variant != "pipeline_uniform"
    scenario = case.scenario()
    scenario.pipeline = pipeline
    validate(scenario, where=case.key)
    return scenario


def run_executed(case) -> dict:
    result = run_scenario(scenario_of(case), scenario_path=case.key)
    keep = ("perception", "category_prior", "category", "task", "part", "grasp",
            "grasp_probability", "n_hypotheses", "planning", "outcome", "timings")
    return {**case.meta(), **{k: result[k] for k in keep if k in result},
            "build_s": round(result["timings"]["build"], 3)}


def run_case(case) -> dict | list[dict]:
    """Runs one case of any kind (the sweep's job function)."""
    # A worker process starts with the shipped library only: register the case's user libraries
    # and imported objects (paths absolute since the suite was loaded; imports are cached).
    resolve_objects(Scenario(objects=list(case.objects),
                             object_libraries=list(case.object_libraries)), where=case.key)
    if case.kind == "synthetic":
        return run_synthetic(case)
    if case.kind == "perceived":
        return run_perceived(case)
    return run_executed(case)
