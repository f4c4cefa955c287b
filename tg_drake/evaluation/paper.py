"""The paper's published figures, each once, with the table (LaTeX label) or passage it comes from.

Section VI ("Experiments") of the paper, and the grasp classifier's table of section V-D, which
`tools/train_dgi.py` compares with. Everything that prints a paper figure beside ours reads it
from here: `tg_drake.evaluation.tables` (tables.md), `tg_drake.evaluation.plots`,
`tg_drake.evaluation.bench` and the tools (eval_kernel_prior, eval_perception, train_dgi).

`FIGURES` is the list; `PAPER` the same figures as a nested dict, `PAPER[measure][row][column]`
(`figure(*key)` for one). Rows are our dataset labels (`tg_drake.evaluation.suite.DATASETS`:
syn = S_SYN, real_semi, real, real_noisy = S_REAL_*, grasp = S_GRASP_noisy, robot = S_ROBOT);
columns our method names (tables.LABELS). In the executed datasets the paper's PLM and
PLM_uniform columns are the `pipeline` and `pipeline_uniform` variants. Accuracies in %;
a "–" cell of the paper has no entry.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Figure:
    key: tuple[str, ...]  # (measure, row, column[, ...]): the path in PAPER
    value: float  # an int for a count or another whole number of unit ""
    unit: str  # "%", "ms", "" (a count, a rank or a parameter)
    source: str  # the paper's table label or passage ("VI-C-2 text"), the measure, row and column


FIGURES: list[Figure] = []


def _table(measure: str, source: str, cells: dict, unit: str = "%", _key=()) -> None:
    """Adds a table's cells: {row: {column: value}}, {row: value} or one level deeper."""
    for name, cell in cells.items():
        key = (*_key, name)
        if isinstance(cell, dict):
            _table(measure, source, cell, unit, key)
        else:
            where = ", ".join(f"{what} {k}"
                              for what, k in zip(("row", "column", "entry"), key, strict=False))
            value = int(cell) if unit == "" and float(cell).is_integer() else float(cell)
            FIGURES.append(Figure((measure, *key), value, unit, f"{source}: {measure}, {where}"))


# -- Section VI-A: the datasets ---------------------------------------------------------------
_table("datasets", "VI-A text", {
    "syn": {"objects": 41, "scenarios": 102},
    "real": {"objects": 26, "scenarios": 126},  # each of S_REAL_semi, S_REAL, S_REAL_noisy
    "grasp": {"objects": 18, "scenarios": 113},
}, unit="")

# -- Section VI-C-1: pose and part detection --------------------------------------------------
_table("detection", "Table tab:visualRepresentation", {
    "grasp": {"part_accuracy": 84.56, "pose_accuracy": 100.0},
    "robot": {"part_accuracy": 82.14, "pose_accuracy": 100.0},
})
_table("detection_ms", "VI-C-1 text (one core of a 2.67 GHz Xeon)", {
    "completion": 27.5, "pose": 15.71}, unit="ms")

# -- Section VI-C-2: object category ----------------------------------------------------------
_table("category", "Table tab:object_category_graphkernel", {
    "syn": {"random": 9.1, "label_fractions": 63.4, "manifolds": 87.8, "plm_uniform": 31.37,
            "plm_general_uniform": 31.37, "plm": 93.14, "plm_general": 92.16},
    "real_semi": {"random": 9.1, "label_fractions": 39.7, "manifolds": 39.7, "plm_uniform": 14.29,
                  "plm_general_uniform": 14.29, "plm": 49.21, "plm_general": 46.83},
    "real": {"random": 9.1, "label_fractions": 39.7, "manifolds": 39.7, "plm_uniform": 14.29,
             "plm_general_uniform": 14.29, "plm": 48.41, "plm_general": 46.83},
    "real_noisy": {"random": 9.1, "label_fractions": 39.7, "manifolds": 39.7,
                   "plm_uniform": 14.29, "plm_general_uniform": 14.29, "plm": 39.7,
                   "plm_general": 39.7},
    "grasp": {"random": 9.1, "manifolds": 37.95},
    "robot": {"random": 9.1, "manifolds": 50.0},
})
# The second definition (a tie that includes the true category is a success); "real" stands
# for the three S_REAL datasets, as the text says.
_table("category_ties_ok", "VI-C-2 text", {
    "syn": {"plm_uniform": 99.02, "plm_general_uniform": 94.12},
    "real": {"plm_uniform": 68.25, "plm_general_uniform": 62.70},
})
# Mean rank of the true category (lower is better); "real" for the S_REAL datasets.
_table("mean_rank", "VI-C-2 text", {
    "syn": {"random": 5.5, "label_fractions": 1.88, "manifolds": 1.39},
    "real": {"random": 5.5, "label_fractions": 2.54, "manifolds": 2.45},
}, unit="")
# The propagation kernel's iterations T the text names for each use.
_table("kernel_T", "VI-C-2 text", {
    "syn": {"manifolds_accuracy": 12, "manifolds_rank": 13, "plm_category": 13,
            "plm_task_pregrasp": 13},
    "real": {"manifolds_accuracy": 0, "manifolds_rank": 3, "plm_category": 0,
             "plm_task_pregrasp": 3},
}, unit="")

# -- Section VI-C-3: task (inferred) ----------------------------------------------------------
_table("task", "Table tab:task_plm_e0, E_0", {
    "syn": {"plm_uniform": 71.57, "plm_general_uniform": 65.69, "plm": 72.55,
            "plm_general": 72.55},
    "real_semi": {"plm_uniform": 98.41, "plm_general_uniform": 98.41, "plm": 95.24,
                  "plm_general": 93.65},
    "real": {"plm_uniform": 80.16, "plm_general_uniform": 80.16, "plm": 95.24,
             "plm_general": 93.65},
    "real_noisy": {"plm_uniform": 38.10, "plm_general_uniform": 38.10, "plm": 93.65,
                   "plm_general": 93.65},
    "grasp": {"pipeline_uniform": 30.00, "pipeline": 35.71},
    "robot": {"pipeline_uniform": 28.57, "pipeline": 25.00},
})
_table("task_E1", "Table tab:task_plm_e0, E_1", {
    "grasp": {"pipeline_uniform": 40.00, "pipeline": 50.00},
    "robot": {"pipeline_uniform": 85.71, "pipeline": 75.00},
})
# Only the top category fed to the PLM instead of the full prior.
_table("top_category_task", "VI-C-3 text", {"real_semi": 95.24, "real": 89.68,
                                            "real_noisy": 89.68})

# -- Section VI-C-4: pre-grasp (task given) ---------------------------------------------------
_table("pregrasp", "Table tab:pregrasp_taskgiven_e0, E_0", {
    "syn": {"plm_uniform": 81.23, "plm_general_uniform": 80.67, "plm": 85.29,
            "plm_general": 84.73},
    "real_semi": {"plm_uniform": 69.95, "plm_general_uniform": 72.00, "plm": 85.26,
                  "plm_general": 86.73},
    "real": {"plm_uniform": 72.00, "plm_general_uniform": 72.00, "plm": 85.26,
             "plm_general": 84.69},
    "real_noisy": {"plm_uniform": 69.16, "plm_general_uniform": 69.16, "plm": 85.49,
                   "plm_general": 86.73},
    "grasp": {"pipeline_uniform": 66.7, "pipeline": 75.51},
    "robot": {"pipeline_uniform": 66.7, "pipeline": 66.7},
})
_table("pregrasp_E1", "Table tab:pregrasp_taskgiven_e0, E_1", {
    "grasp": {"pipeline_uniform": 66.7, "pipeline": 75.51},
    "robot": {"pipeline_uniform": 66.7, "pipeline": 66.7},
})
# The task predicted by the PLM instead of given (E_0, "for both priors").
_table("pregrasp_task_inferred", "VI-C-4 text", {"syn": 95.10, "real_noisy": 100.0})
_table("top_category_pregrasp", "VI-C-4 text", {"real_semi": 81.63, "real": 81.63,
                                                "real_noisy": 82.88})
# Mean (mutually exclusive − not) over the datasets, in points.
_table("exclusive_minus_nonexclusive", "VI-C-4 text", {"category": 1.6, "task": 8.5,
                                                       "pregrasp": 2.6})

# -- Section VI-C-5: the full pipeline --------------------------------------------------------
# Share of successful grasps whose P(grasp | local shape) is below the threshold.
_table("pipeline_vs_local", "Table tab:pipeline", {
    "grasp": {"local": {"0.5": 44.55, "0.4": 27.27, "0.3": 4.55},
              "pipeline": {"0.5": 52.38, "0.4": 28.57, "0.3": 7.94},
              "pipeline_uniform": {"0.5": 50.0, "0.4": 21.15, "0.3": 7.69}},
    "robot": {"local": {"0.5": 37.5, "0.4": 25.0, "0.3": 12.5},
              "pipeline": {"0.5": 50.0, "0.4": 42.86, "0.3": 28.57},
              "pipeline_uniform": {"0.5": 46.15, "0.4": 23.08, "0.3": 23.08}},
})
# Rows: objects on the table (scenario1-3 = 2, 3, 4 objects); grasped and placed over the
# reachable pre-grasps.
_table("grasp_and_place", "Table tab:realRobotGlobalStats", {
    "2": {"total": 10, "reachable": 9, "grasped": 7, "placed": 7},
    "3": {"total": 15, "reachable": 10, "grasped": 7, "placed": 7},
    "4": {"total": 20, "reachable": 16, "grasped": 8, "placed": 8},
}, unit="")
_table("grasp_and_place_pct", "Table tab:realRobotGlobalStats", {
    "2": {"reachable": 90.0, "grasped": 77.8, "placed": 77.8},
    "3": {"reachable": 66.7, "grasped": 70.0, "placed": 70.0},
    "4": {"reachable": 80.0, "grasped": 50.0, "placed": 50.0},
})

# -- Section V-D: the grasp classifier on the grasping rectangle dataset ----------------------
_table("dgi", "Table tab:graspingAccuracy", {"jiang_et_al": 84.7, "lenz_et_al": 93.7,
                                             "this_work": 92.63})
_table("dgi_training", "V-D text", {"n_grasps": 4708, "n_positive": 2424, "n_negative": 2284,
                                    "cv_splits": 4, "rbf_gamma": 50.0, "sigmoid_A": 2.0,
                                    "sigmoid_b": 0.5}, unit="")


def _nested(figures: list[Figure]) -> dict:
    out: dict = {}
    for f in figures:
        node = out
        for k in f.key[:-1]:
            node = node.setdefault(k, {})
        if f.key[-1] in node:
            raise ValueError(f"paper figure {f.key} given twice")
        node[f.key[-1]] = f.value
    return out


PAPER: dict = _nested(FIGURES)


def figure(*key: str) -> float | None:
    """One figure by its key (None where the paper has none)."""
    node = PAPER
    for k in key:
        if not isinstance(node, dict) or k not in node:
            return None
        node = node[k]
    return node
