"""Figures of the quadruped: reachable workspace slices of a leg, coloured by IK branch."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..figures import new_figure
from . import kinematics as aq

#: Region codes of :func:`branch_regions`.
REGIONS = (
    "unreachable",
    "reachable, outside joint limits",
    "in limits: s_u = -1 only",
    "in limits: s_u = +1 only",
    "in limits: both s_u branches",
)


def branch_regions(points: np.ndarray, leg: str) -> np.ndarray:
    """Region code (index into :data:`REGIONS`) of each foot target (..., 3)."""
    q_all, reach = aq.ik_all(points, leg, return_mask=True)
    inside = aq.within_limits(q_all) & reach
    below = inside[..., 0] | inside[..., 1]
    above = inside[..., 2] | inside[..., 3]
    code = np.where(reach[..., 0], 1, 0)
    code = np.where(below & ~above, 2, code)
    code = np.where(above & ~below, 3, code)
    return np.where(below & above, 4, code)


def figures(outdir: Path) -> list[Path]:
    import matplotlib.colors as mcolors
    from matplotlib.patches import Patch

    leg = "LF"
    h = aq.hip_position(leg)
    n = 301
    ext = 0.7
    a = np.linspace(-ext, ext, n)
    # sagittal slice through the leg plane at q1 = 0 (y = hip y + 0.1077), and frontal slice x = hip x
    sag = np.stack(np.meshgrid(h[0] + a, [h[1] + aq.Y12], h[2] + a, indexing="ij"), -1)[:, 0]
    fro = np.stack(np.meshgrid([h[0]], h[1] + a, h[2] + a, indexing="ij"), -1)[0]
    fig, axes = new_figure(1, 2, figsize=(11, 5))
    cmap = mcolors.ListedColormap(["white", "0.8", "tab:blue", "tab:orange", "tab:green"])
    for ax, pts, (i, j), title in (
        (axes[0], sag, (0, 2), "sagittal slice y = y_hip + 0.1077 m"),
        (axes[1], fro, (1, 2), "frontal slice x = x_hip"),
    ):
        code = branch_regions(pts, leg)
        ax.imshow(
            code.T, origin="lower", cmap=cmap, vmin=-0.5, vmax=4.5, interpolation="nearest",
            extent=(pts[0, 0, i], pts[-1, 0, i], pts[0, 0, j], pts[0, -1, j]),
        )
        ax.plot(h[i], h[j], "k+", ms=12)
        ax.set_title(f"{leg} foot targets, {title}", fontsize=9)
        ax.set_xlabel(f"{'xyz'[i]} (m, base frame)")
        ax.set_ylabel("z (m, base frame)")
    handles = [Patch(color=cmap(k), label=label) for k, label in enumerate(REGIONS)]
    fig.legend(handles=handles, loc="lower center", ncol=5, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    path = Path(outdir) / "quadruped_workspace.png"
    fig.savefig(path, dpi=90)
    return [path]
