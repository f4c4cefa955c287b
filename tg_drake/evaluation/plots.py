"""PNG plots of the evaluation tables, ours beside the paper's figures (matplotlib, Agg).

- `accuracy.png`: category accuracy per method and dataset (bars: ours; black ticks: the paper).
- `task_ei.png`, `pregrasp_ei.png`: accuracy over the evaluation settings E_i per dataset for PLM
  and PLM_uniform, like the paper's Figs. "task_plm" and "pregrasp_taskgiven_plm" (the paper's
  E_0 from its tables as markers; its curves for i > 0 exist only as figures not in the text).
- `pipeline_vs_local.png`: share of successful grasps below each visual-graspability threshold.
"""

from __future__ import annotations

from pathlib import Path

from tg_drake.evaluation.paper import PAPER
from tg_drake.evaluation.suite import DATASETS
from tg_drake.evaluation.tables import CATEGORY_METHODS, LABELS, THRESHOLDS

DPI = 80  # small files for the repository


def _plt():
    # matplotlib when a plot is drawn, not when tables are computed: its import is slow, and the
    # backend is chosen before pyplot loads.
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def accuracy_plot(tables: dict, path: Path) -> None:
    plt = _plt()
    datasets = list(tables["category"])
    fig, ax = plt.subplots(figsize=(10, 4))
    width = 0.8 / max(len(datasets), 1)
    for j, d in enumerate(datasets):
        xs = [i + (j - (len(datasets) - 1) / 2) * width for i in range(len(CATEGORY_METHODS))]
        ours = [tables["category"][d].get(m) for m in CATEGORY_METHODS]
        ax.bar(xs, [v or 0 for v in ours], width, label=DATASETS[d] + " (ours)")
        paper = [PAPER["category"].get(d, {}).get(m) for m in CATEGORY_METHODS]
        ax.scatter([x for x, p in zip(xs, paper, strict=False) if p is not None],
                   [p for p in paper if p is not None], marker="_", s=200, color="black",
                   zorder=3, label="paper" if j == 0 else None)
    ax.set_xticks(range(len(CATEGORY_METHODS)), [LABELS[m] for m in CATEGORY_METHODS],
                  rotation=20, fontsize=8)
    ax.set_ylabel("category accuracy [%]")
    ax.set_ylim(0, 105)
    ax.legend(fontsize=7, ncol=4)
    ax.set_title("Category prediction: ours (bars) and the paper (black ticks)")
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def ei_plot(tables: dict, key: str, path: Path, title: str) -> None:
    plt = _plt()
    rows = {d: r for d, r in tables[key].items() if "plm" in r}
    if not rows:
        return
    fig, axes = plt.subplots(1, len(rows), figsize=(3.2 * len(rows), 3.2), squeeze=False)
    for ax, (d, r) in zip(axes[0], rows.items(), strict=False):
        for m, style in (("plm", "-o"), ("plm_uniform", "--s")):
            ks = list(r[m])
            ax.plot(range(len(ks)), [r[m][k] or 0 for k in ks], style, label=LABELS[m] + " (ours)")
            p = PAPER[key].get(d, {}).get(m)
            if p is not None:
                ax.plot([0], [p], "k" + style[-1], fillstyle="none", markersize=9,
                        label=LABELS[m] + " E0 (paper)")
        ax.set_xticks(range(len(ks)), ks)
        ax.set_ylim(0, 105)
        ax.set_title(DATASETS[d], fontsize=9)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("accuracy [%]")
    axes[0][0].legend(fontsize=6)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def pipeline_plot(tables: dict, path: Path) -> None:
    plt = _plt()
    rows = tables["pipeline_vs_local"]
    if not rows:
        return
    fig, axes = plt.subplots(1, len(rows), figsize=(4.5 * len(rows), 3.2), squeeze=False)
    for ax, (d, r) in zip(axes[0], rows.items(), strict=False):
        vs = [v for v in ("local", "pipeline", "pipeline_uniform") if v in r]
        width = 0.8 / len(vs)
        for j, v in enumerate(vs):
            xs = [i + (j - (len(vs) - 1) / 2) * width for i in range(len(THRESHOLDS))]
            ax.bar(xs, [r[v][str(t)] or 0 for t in THRESHOLDS], width, label=LABELS[v])
            p = PAPER["pipeline_vs_local"].get(d, {}).get(v, {})
            if p:
                ax.scatter(xs, [p[str(t)] for t in THRESHOLDS], marker="_", s=150,
                           color="black", zorder=3, label="paper" if j == 0 else None)
        ax.set_xticks(range(len(THRESHOLDS)), [f"lt {t}" for t in THRESHOLDS])
        ax.set_ylabel("successful grasps [%]")
        ax.set_title(f"{DATASETS[d]}: low visual graspability", fontsize=9)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def save_plots(tables: dict, folder: Path, prefix: str = "") -> list[Path]:
    """The plots that have data, as `<prefix><name>.png` in `folder`."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    if tables["category"]:
        accuracy_plot(tables, folder / f"{prefix}accuracy.png")
        paths.append(folder / f"{prefix}accuracy.png")
    for key, title in (("task", "Task prediction over E_i (task inferred)"),
                       ("pregrasp", "Pre-grasp prediction over E_i (task given)")):
        path = folder / f"{prefix}{key}_ei.png"
        ei_plot(tables, key, path, title)
        if path.exists():
            paths.append(path)
    path = folder / f"{prefix}pipeline_vs_local.png"
    pipeline_plot(tables, path)
    if path.exists():
        paths.append(path)
    return paths
