"""Figure of the tyre surface (:mod:`.tyre`) with its fillets, trims and caps, and of the ground contact point
(:mod:`.ground`) over a theta sweep."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np

from ..figures import new_figure
from .ground import ground_contact
from .linkage import linkage_points
from .rim import rim_point
from .tyre import PIECES, TYRE_THICKNESS, tyre_pieces

THETAS_DEG = (17.0, 45.0, 90.0, 130.0, 160.0)
BETAS = (0.0, 0.6, 1.2, 2.4)
#: Repository copy of the figure (docs/img), written too when the repository is found.
DOC_NAME = "wheel_leg_tyre.png"


def _kind(name: str) -> str:
    if name.startswith("cap"):
        return "cap"
    if name.endswith("_inner"):
        return "inner fillet" if name[0] in "FG" else "inner"
    return "fillet" if name[0] in "FG" else "outer"


_COLOURS = {"outer": "tab:blue", "fillet": "tab:red", "cap": "tab:green", "inner": "0.6", "inner fillet": "tab:purple"}


def figures(outdir: Path) -> list[Path]:
    """``wheel_leg_tyre.png``: top row, the tyre curve at theta = 17, 45, 90, 130, 160 deg (beta = 0, leg frame)
    by piece kind, the pitch curve (dashed), the hinges and the lowest point along n = z with the ground line;
    bottom, the lowest point's depth below the motor axis O and its piece over a theta sweep for four beta.
    Also copied to ``docs/img/wheel_leg_tyre.png`` when run inside the repository."""
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    fig, axes = new_figure(2, 5, figsize=(18, 8.6), gridspec_kw={"height_ratios": [1.3, 1.0]})
    alpha = np.linspace(-np.pi, np.pi, 1441)
    u = np.linspace(0.0, 1.0, 60)
    for col, th_deg in enumerate(THETAS_DEG):
        theta = math.radians(th_deg)
        ax = axes[0, col]
        pit = rim_point(theta, 0.0, alpha)
        ax.plot(pit[:, 0], pit[:, 1], color="k", lw=0.8, ls="--")
        pcs = tyre_pieces(theta, 0.0)
        for k, name in enumerate(PIECES):
            p = pcs.point(k, u)
            kind = _kind(name)
            if pcs.radius[k] * abs(pcs.span[k]) == 0.0:
                ax.plot(*p[0], "x", color="tab:orange", ms=6, mew=1.5)
                continue
            ax.plot(p[:, 0], p[:, 1], color=_COLOURS[kind], lw=2.2 if kind in ("outer", "fillet", "cap") else 1.2)
        pts = linkage_points(theta, 0.0)
        for name in ("F_L", "F_R", "G", "H_L", "H_R"):
            ax.plot(*pts[name][:2], "o", color="0.25", ms=3)
        ax.plot(0.0, 0.0, "ko", ms=4)
        gc = ground_contact(np.array([theta, 0.0, 0.0]), "FL")
        y = float(gc.point[2] - 0.057166)  # leg plane y_L = z_R - z(O) at gamma = 0 (d_abad of the default geometry)
        x = float(-(gc.point[0] - 0.255))
        ax.axhline(y, color="tab:brown", lw=1.0)
        ax.plot(x, y, "*", color="tab:brown", ms=12)
        ax.set_aspect("equal")
        ax.set_xlim(-0.24, 0.24)
        ax.set_ylim(-0.5, 0.2)
        ax.grid(alpha=0.3)
        mode = {17.0: " (wheel mode)", 160.0: " (leg mode)"}.get(th_deg, "")
        ax.set_title(f"theta = {th_deg:g} deg{mode}\nlowest point: {gc.piece_name}, s = {float(gc.s):.3f}, "
                     f"depth {-y * 1e3:.1f} mm", fontsize=9)
        ax.set_xlabel("x_L (m)", fontsize=8)
        if col == 0:
            ax.set_ylabel("y_L (m), beta = 0", fontsize=8)
        ax.tick_params(labelsize=7)
    gs = axes[1, 0].get_gridspec()
    for a in axes[1]:
        a.remove()
    ax_d = fig.add_subplot(gs[1, :3])
    ax_p = fig.add_subplot(gs[1, 3:])
    th = np.linspace(math.radians(17.0), math.radians(160.0), 1431)
    for k, beta in enumerate(BETAS):
        q = np.stack([th, np.full(th.shape, beta), np.zeros(th.shape)], -1)
        gc = ground_contact(q, "FL")
        depth = 0.057166 - gc.point[:, 2]
        ax_d.plot(np.degrees(th), depth, lw=1.6, label=f"beta = {beta:g} rad")
        ax_p.plot(np.degrees(th), gc.piece + 0.08 * (k - 1.5), ".", ms=1.5, label=f"beta = {beta:g} rad")
    ax_d.axhline(0.1 + TYRE_THICKNESS, color="0.5", ls=":", lw=0.8)
    ax_d.set_xlabel("theta (deg)", fontsize=8)
    ax_d.set_ylabel("depth of the lowest tyre point below O (m), n = z", fontsize=8)
    ax_d.legend(fontsize=8)
    ax_d.grid(alpha=0.3)
    ax_p.set_yticks(range(len(PIECES)))
    ax_p.set_yticklabels(PIECES, fontsize=6)
    ax_p.set_xlabel("theta (deg)", fontsize=8)
    ax_p.set_title("piece carrying the lowest point", fontsize=9)
    ax_p.grid(alpha=0.3)
    handles = [Line2D([], [], color=c, lw=2, label=k) for k, c in _COLOURS.items()]
    handles += [Line2D([], [], color="tab:orange", marker="x", ls="none",
                       label="zero-length piece (trimmed corner; fillet in wheel mode)"),
                Line2D([], [], color="k", ls="--", lw=0.8, label="pitch curve (R = 0.1 m)"),
                Line2D([], [], color="tab:brown", marker="*", ls="none", label="lowest point (n = z), ground")]
    fig.legend(handles=handles, loc="lower center", ncol=8, fontsize=8, frameon=False)
    fig.suptitle(f"wheel-leg tyre surface: pitch curve swept by a disk of radius r = {TYRE_THICKNESS} m "
                 "(fillets where offsets part, trims where they overlap, caps at the tips H)", fontsize=11)
    fig.tight_layout(rect=(0, 0.04, 1, 0.96))
    out = Path(outdir) / DOC_NAME
    fig.savefig(out, dpi=85)
    plt.close(fig)
    outs = [out]
    docs = Path(__file__).resolve().parents[3] / "docs" / "img"
    if docs.is_dir() and docs.resolve() != Path(outdir).resolve():
        shutil.copyfile(out, docs / DOC_NAME)
    return outs
