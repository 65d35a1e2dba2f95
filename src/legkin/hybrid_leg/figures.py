"""Figures of the hybrid leg: the reachable platform (roll, pitch) set per motor branch, with its singular curves."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..figures import new_figure
from . import kinematics as ah


def figures(outdir: Path) -> list[Path]:
    """``hybrid_leg_workspace.png``: reachable (roll, pitch) of the universal-centre platform, one panel per branch.

    A pose is reachable when both rod-length equations have a solution (``|k_i| <= 1`` in
    :func:`~legkin.hybrid_leg.motor_angles`); the set is the same for the four motor branches
    (each equation has two solutions or none), bounded by the curves where a rod end reaches its extreme
    (the two branches of that chain meet; dtheta/d(roll, pitch) is infinite). Inside, the branches differ by
    their parallel singularity ``det(dtheta/d(roll, pitch)) = 0`` (:func:`~legkin.hybrid_leg.motor_jacobian`):
    there the platform can move with both motors locked. The frame is the centre joint's range, +-90 deg.
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    from .clips import tilt_path

    n = 361
    deg = np.linspace(-90.0, 90.0, n)
    roll, pitch = np.meshgrid(np.radians(deg), np.radians(deg), indexing="ij")
    fig, axes = new_figure(2, 2, figsize=(10.5, 9.8), sharex=True, sharey=True)
    cmap = ListedColormap(["0.85", "#a6cee3", "#fdbf6f"])  # unreachable, det > 0, det < 0
    path_roll, path_pitch = tilt_path()
    for ax, branch in zip(axes.ravel(), ah.MOTOR_BRANCHES):
        with np.errstate(invalid="ignore"):
            jac, ok = ah.motor_jacobian(roll, pitch, branch, return_mask=True)
            det = np.linalg.det(np.where(ok[..., None, None], jac, 0.0))
        code = np.where(ok, np.where(det > 0, 1, 2), 0)
        ax.imshow(code.T, origin="lower", cmap=cmap, vmin=-0.5, vmax=2.5, interpolation="nearest",
                  extent=(deg[0], deg[-1], deg[0], deg[-1]))  # fmt: skip
        ax.contour(deg, deg, ok.T.astype(float), levels=[0.5], colors="tab:red", linewidths=1.6)
        ax.contour(deg, deg, np.ma.masked_invalid(np.where(ok, det, np.nan)).T, levels=[0.0], colors="k",
                   linewidths=1.6)  # fmt: skip
        if branch == (1, 1):
            ax.plot(np.degrees(path_roll), np.degrees(path_pitch), "w--", lw=1.3)
            ax.plot(0.0, 0.0, "k*", ms=11)
        theta0 = ah.motor_angles(0.0, 0.0, branch)
        ax.set_title(
            f"motor branch (b1, b2) = ({branch[0]:+d}, {branch[1]:+d}): at roll = pitch = 0,\n"
            f"theta1, theta2 = {np.degrees(theta0[0]):.1f}, {np.degrees(theta0[1]):.1f} deg",
            fontsize=9,
        )
        ax.set_xticks(np.arange(-90, 91, 30))
        ax.set_yticks(np.arange(-90, 91, 30))
        ax.grid(alpha=0.25)
        ax.set_aspect("equal")
    for ax in axes[1]:
        ax.set_xlabel("roll (deg), joint LCS_x")
    for ax in axes[:, 0]:
        ax.set_ylabel("pitch (deg), joint LCS_y")
    handles = [
        Patch(color=cmap(1), label="reachable, det(dtheta/d(roll, pitch)) > 0"),
        Patch(color=cmap(2), label="reachable, det < 0"),
        Patch(color=cmap(0), label="unreachable (a rod cannot close)"),
        Line2D([], [], color="tab:red", lw=1.6, label="reach boundary: a rod end at its extreme (branches meet)"),
        Line2D([], [], color="k", lw=1.6, label="det = 0: parallel singularity (platform free with motors locked)"),
        Line2D([], [], color="k", marker="*", ls="none", ms=10, label="neutral pose (SRDF 'neutral')"),
        Line2D([], [], color="w", lw=1.3, ls="--", label="clip extend_and_tilt"),
    ]
    legend = fig.legend(handles=handles, loc="lower center", ncol=2, fontsize=8, frameon=True)
    legend.get_frame().set_facecolor("0.7")
    fig.suptitle("hybrid leg: reachable platform orientation R_P = Rx(roll) Ry(pitch) (universal centre), "
                 "per motor branch", fontsize=10)  # fmt: skip
    fig.tight_layout(rect=(0, 0.1, 1, 0.97))
    out = Path(outdir) / "hybrid_leg_workspace.png"
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return [out]
