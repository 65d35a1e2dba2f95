"""The picture of a study: one panel per metric over the swept parameter(s), with the 95 % confidence bands
(one parameter: lines and bands; two: heat maps of the value, the largest band half-width in each title)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import InvalidArgumentError

__all__ = ["plot_study", "PANELS"]

#: Panel title -> the columns drawn (each with its ``_lo``/``_hi`` band when the table has them).
PANELS = {
    "workspace volume": ("volume",),
    "Jacobian condition number kappa": ("cond_p50", "cond_p90", "cond_p99"),
    "singular fraction (1/kappa <= eps)": ("singular_fraction",),
    "constant-velocity error, max (rad)": ("cv_error_max",),
    "reachable fraction per rim link": tuple(f"rim_contact_{k}" for k in ("upper_L", "lower_L", "lower_R", "upper_R")),
}


def _panels(frame: Any) -> list[tuple[str, tuple[str, ...]]]:
    return [(t, tuple(c for c in cols if c in frame)) for t, cols in PANELS.items() if any(c in frame for c in cols)]


def _line_panel(ax: Any, frame: Any, x: str, title: str, cols: tuple[str, ...], unit: str) -> None:
    for col in cols:
        line, = ax.plot(frame[x], frame[col], marker=".", label=col)
        if f"{col}_lo" in frame:
            ax.fill_between(frame[x], frame[f"{col}_lo"], frame[f"{col}_hi"], color=line.get_color(), alpha=0.25,
                            label="95 % CI" if col == cols[0] else None)
    if title.startswith("Jacobian") or title.startswith("constant"):
        ax.set_yscale("log")
    ax.set_title(title + (f" ({unit})" if title == "workspace volume" else ""), fontsize=9)
    ax.set_xlabel(x)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)


def _heat_panel(fig: Any, ax: Any, frame: Any, xy: tuple[str, str], title: str, col: str) -> None:
    table = frame.pivot(index=xy[1], columns=xy[0], values=col)
    im = ax.pcolormesh(table.columns, table.index, table.values, shading="nearest")
    fig.colorbar(im, ax=ax)
    half = ((frame[f"{col}_hi"] - frame[f"{col}_lo"]) / 2).max() if f"{col}_lo" in frame else None
    ax.set_title(f"{col}" + (f" (95 % CI half-width <= {half:.2g})" if half is not None else ""), fontsize=9)
    ax.set_xlabel(xy[0])
    ax.set_ylabel(xy[1])


def plot_study(frame: Any, params: list[str], path: str | Path, title: str = "") -> Path:
    """Write the study's picture (PNG).

    Args:
        frame: the table of :func:`legkin.study.study`.
        params: the swept parameters' names (one: lines with bands; two: heat maps).
        path: the PNG to write.
        title: the figure's title.

    Returns:
        The path written.

    Raises:
        InvalidArgumentError: not one or two swept parameters.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if len(params) not in (1, 2):
        raise InvalidArgumentError(f"a study plot shows 1 or 2 swept parameters, got {len(params)}: {params}")
    panels = _panels(frame)
    if len(params) == 2:
        panels = [(t, (c,)) for t, cols in panels for c in cols]
    ncols = 2 if len(panels) in (2, 4) else min(len(panels), 3)
    nrows = -(-len(panels) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.6 * ncols, 3.6 * nrows), squeeze=False)
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    for ax, (t, cols) in zip(axes.flat, panels):
        if len(params) == 1:
            _line_panel(ax, frame.sort_values(params[0]), params[0], t, cols, frame.attrs.get("unit", ""))
        else:
            _heat_panel(fig, ax, frame, (params[0], params[1]), t, cols[0])
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
