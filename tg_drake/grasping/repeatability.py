"""How repeatable is a physics grasp label? The ceiling of any classifier trained on such labels.

tools/label_noise.py executes recorded grasps again (`tg_drake.simulation.episode`): with the same
gripper pose, and "nudged" — the pose moved a millimetre and turned a degree (`nudge`), a change
far below the perception's 4 mm resolution. This module holds the
pure parts: the stratified sample, the nudge, and the analysis of the repeated labels.

The ceiling: if a grasp's label is a coin that lands "success" with probability p under nudges,
no classifier is right on it more often than max(p, 1 − p), and two draws agree with probability
a = p² + (1 − p)², so max(p, 1 − p) = (1 + √(2a − 1)) / 2, a concave function of a. With ā the
mean agreement between the recorded label and the nudged ones (weighted to the data set's mix of
strata), the attainable accuracy lies between ā (each grasp's max(p, 1 − p) ≥ its a) and
(1 + √(2ā − 1)) / 2 (Jensen's inequality).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from tg_drake.errors import GraspingError, unknown_name
from tg_drake.grasping.dgi import PAD_CENTER_Y

Stratum = Callable[[dict], tuple]
REFERENCES = ("recorded", "exact")  # which label the nudged ones are compared with


def stratified_sample(records: list[dict], per_stratum: int, rng: np.random.Generator,
                      stratum: Stratum) -> list[dict]:
    """Up to `per_stratum` random records of status "ok" from every stratum (`stratum(record)`),
    in stratum order, each stratum's in file order."""
    if per_stratum < 1:
        raise GraspingError(f"per_stratum must be ≥ 1, got {per_stratum}")
    strata: dict[tuple, list[dict]] = defaultdict(list)
    for r in records:
        if r.get("status") == "ok":
            strata[stratum(r)].append(r)
    sample = []
    for key in sorted(strata):
        rows = strata[key]
        pick = rng.choice(len(rows), size=min(per_stratum, len(rows)), replace=False)
        sample.extend(rows[i] for i in sorted(pick))
    return sample


def stratum_weights(records: list[dict], sample: list[dict], stratum: Stratum
                    ) -> dict[tuple[str, int], float]:
    """(job, index) of each sampled record → its stratum's count in the data over its count in
    the sample: weighted means over the sample then estimate means over the data."""
    population: dict[tuple, int] = defaultdict(int)
    for r in records:
        if r.get("status") == "ok":
            population[stratum(r)] += 1
    sampled: dict[tuple, int] = defaultdict(int)
    for r in sample:
        sampled[stratum(r)] += 1
    return {(r["job"], r["index"]): population[stratum(r)] / sampled[stratum(r)] for r in sample}


def nudge(X_WG: np.ndarray, rng: np.random.Generator, *, distance: float, angle: float
          ) -> np.ndarray:
    """X_WG turned by `angle` [rad] about a random axis through its grasp point (the pads'
    centre, PAD_CENTER_Y along y_G), which moves `distance` [m] in a random direction."""
    X_WG = np.asarray(X_WG, dtype=float)
    if X_WG.shape != (4, 4):
        raise GraspingError(f"X_WG must be a 4×4 pose, got shape {X_WG.shape}")
    axis = rng.normal(size=3)
    shift = rng.normal(size=3)
    R = Rotation.from_rotvec(angle * axis / np.linalg.norm(axis)).as_matrix() @ X_WG[:3, :3]
    grasp_point = X_WG[:3, 3] + PAD_CENTER_Y * X_WG[:3, 1] + distance * shift / np.linalg.norm(
        shift)
    X = np.eye(4)
    X[:3, :3] = R
    X[:3, 3] = grasp_point - PAD_CENTER_Y * R[:, 1]
    return X


def held(result: dict) -> bool:
    """The object ended between both pads and off the table (whatever the finger gap)."""
    return bool(result.get("touches_left_pad") and result.get("touches_right_pad")
                and not result.get("touches_table"))


def accuracy_ceiling(agreement: float) -> tuple[float, float]:
    """(lower, upper) bound of the attainable accuracy from the mean label agreement ā."""
    if not 0.0 <= agreement <= 1.0:
        raise GraspingError(f"agreement must lie in [0, 1], got {agreement}")
    return agreement, float((1.0 + np.sqrt(max(2.0 * agreement - 1.0, 0.0))) / 2.0)


def analyse(rows: list[dict], *, groups: Callable[[dict], list[str]],
            weights: dict[tuple[str, int], float] | None = None,
            held_gap: float = 0.002, reference: str = "recorded") -> dict:
    """Repeat rates of re-executed grasps.

    `rows`: episode records with "source_job", "source_index" (the recorded grasp),
    "original_success", "trial" ("exact" or a nudge's name), "status" and, when "ok", "success",
    "finger_gap", "touches_table". `groups(row)` names the groups a grasp belongs to (kind,
    category, label), reported apart as plain means over the sample; with `weights` (per source
    grasp, `stratum_weights`) the headline agreement and the ceiling are weighted to the data set.
    Flips are sorted by what the re-execution saw (`held_gap`: fingers further apart than this
    closed on something); a row's optional "original_held" (`held` of the recorded episode) singles
    out the flips where both episodes held the object and only the label's finger-gap thresholds
    differed. `reference`: the label the nudged ones are compared with, "recorded"
    (the data set's) or "exact" (the re-execution with the same pose: for a changed episode
    script, whose labels the data set does not have); grasps without it are left out.
    """
    if reference not in REFERENCES:
        raise unknown_name("reference label", reference, REFERENCES, error=GraspingError)
    ok = [r for r in rows if r.get("status") == "ok"]
    by_grasp: dict[tuple[str, int], dict[str, dict]] = defaultdict(dict)
    for r in ok:
        by_grasp[(r["source_job"], r["source_index"])][r["trial"]] = r
    exact, nudged, all_agree, weighted = [], [], [], []
    per_group: dict[str, list[bool]] = defaultdict(list)
    flips: dict[str, int] = defaultdict(int)
    for key, trials in by_grasp.items():
        first = next(iter(trials.values()))
        if reference == "exact":
            if "exact" not in trials:
                continue
            original = bool(trials["exact"]["success"])
        else:
            original = bool(first["original_success"])
        if "exact" in trials:
            exact.append(trials["exact"]["success"] == bool(first["original_success"]))
        agree = [t["success"] == original for name, t in trials.items() if name != "exact"]
        nudged.extend(agree)
        if agree:
            all_agree.append(all(agree))
        w = weights.get(key, 1.0) if weights else 1.0
        weighted.extend((w, a) for a in agree)
        for g in groups(first):
            per_group[g].extend(agree)
        for t in trials.values():
            if t["success"] == original:
                continue
            if first.get("original_held") and held(t):
                flips["held both times, the finger-gap rule flipped"] += 1
            elif not original:
                flips["failure became success"] += 1
            elif t["touches_table"] and t["finger_gap"] > held_gap:
                flips["success became failure: closed on it, still on the table"] += 1
            else:
                flips["success became failure: lost it or closed on nothing"] += 1
    if not weighted:
        raise GraspingError("no nudged re-execution ended with status ok: nothing to analyse")
    agreement = float(np.average([a for _, a in weighted], weights=[w for w, _ in weighted]))
    return {
        "n_grasps": len(by_grasp),
        "n_episodes": len(rows),
        "n_sim_error": len(rows) - len(ok),
        "exact_repeat_rate": float(np.mean(exact)) if exact else None,
        "nudged_agreement_sample": float(np.mean(nudged)),
        "nudged_agreement": agreement,
        "nudged_all_agree": float(np.mean(all_agree)),
        "accuracy_ceiling_interval": list(accuracy_ceiling(agreement)),
        "by_group": {g: {"n": len(v), "nudged_agreement": float(np.mean(v))}
                     for g, v in sorted(per_group.items()) if v},
        "flips": dict(sorted(flips.items())),
    }
