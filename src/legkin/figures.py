"""PNG figures for ``legkin check --plots``: error histograms of every check, and per-model figures.

A model's own figures come from ``legkin.<model>.figures.figures(outdir) -> list[Path]`` when that module exists.
"""

from __future__ import annotations

import importlib
import math
from pathlib import Path

import numpy as np

__all__ = ["write_check_plots", "error_histograms", "new_figure"]


def new_figure(*args, **kwargs):
    """A matplotlib figure on the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt.subplots(*args, **kwargs)


def error_histograms(model: str, rows, outdir: Path) -> Path:
    """One panel per check row: histogram of log10(error), with the tolerance marked."""
    n = len(rows)
    cols = min(4, n)
    nrows = math.ceil(n / cols)
    fig, axes = new_figure(nrows, cols, figsize=(4.0 * cols, 2.6 * nrows), squeeze=False)
    for ax, row in zip(axes.ravel(), rows):
        e = np.asarray(row.errors if row.errors is not None else [], dtype=float)
        e = e[np.isfinite(e)]
        floor = 1e-18
        logs = np.log10(np.maximum(e, floor)) if e.size else np.array([])
        log_tol = math.log10(max(row.tolerance, floor))  # exact rows (e.g. mobility counts) have tolerance 0
        lo = min(float(logs.min()) if logs.size else -17, log_tol) - 0.5
        hi = max(float(logs.max()) if logs.size else -12, log_tol) + 0.5
        ax.hist(logs, bins=np.linspace(lo, hi, 50), color="tab:blue" if row.passed else "tab:red")
        ax.axvline(log_tol, color="k", ls="--", lw=1, label="tolerance")
        ax.set_yscale("log")
        ax.set_title(row.name, fontsize=8)
        ax.set_xlabel("log10(error)", fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    fig.suptitle(f"legkin check {model}: per-sample errors (floor 1e-18)")
    fig.tight_layout()
    path = outdir / f"check_{model}.png"
    fig.savefig(path, dpi=90)
    import matplotlib.pyplot as plt

    plt.close(fig)  # pyplot keeps every figure it made until closed (a warning past 20)
    return path


def write_check_plots(results, outdir) -> list[Path]:
    """Write every figure for the models in ``results`` (as returned by ``run_checks``)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    paths = []
    for model, (rows, _) in results.items():
        paths.append(error_histograms(model, rows, outdir))
        try:
            mod = importlib.import_module(f"legkin.{model}.figures")
        except ModuleNotFoundError:
            continue
        paths += mod.figures(outdir)
    return paths
