"""Figures of the wheel-leg: the rim contact point over alpha, the seed's three-arc formula next to the real rims."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..figures import new_figure
from . import kinematics as wl
from . import tyre_figures

#: Leg opening angles of the figure (deg): wheel mode, slightly open, half open, leg mode.
THETAS_DEG = (17.0, 30.0, 90.0, 160.0)
#: Links drawn in the leg sketch (pairs of :data:`legkin.wheel_leg.POINTS`).
#: Both curves are drawn at the pitch radius (the seed's own default is the foot radius R + 0.0345 m): then they
#: coincide in wheel mode and on the upper rims, and differ only where the seed's toe arc replaces the lower rims.
RADIUS = 0.1
_LINKS = (("O", "A_L"), ("O", "A_R"), ("A_L", "E"), ("A_R", "E"), ("D_L", "C_L"), ("D_R", "C_R"))


def _seed_pieces(theta: float, alpha: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """rim_point_seed over ``alpha`` with NaN rows inserted at the jumps alpha = +-psi_FG (no false joins)."""
    p = wl.rim_point_seed(theta, 0.0, alpha, radius=RADIUS)
    # pieces: alpha < -psi_FG (upper rim, left), [-psi_FG, psi_FG] (toe arc), alpha > psi_FG (upper rim, right)
    cut = [np.searchsorted(alpha, -wl.PSI_FG, side="left"), np.searchsorted(alpha, wl.PSI_FG, side="right")]
    return np.insert(p, cut, np.nan, axis=0), np.insert(alpha, cut, np.nan)


def _jump_ends(theta: float) -> tuple[np.ndarray, np.ndarray]:
    """The two seed points at alpha = psi_FG (toe arc) and just above it (upper-rim arc)."""
    a = np.array([wl.PSI_FG, np.nextafter(wl.PSI_FG, 4.0)])
    p = wl.rim_point_seed(theta, 0.0, a, radius=RADIUS)
    return p[0], p[1]


def figures(outdir: Path) -> list[Path]:
    """``wheel_leg_contact.png``: contact-point curves over the rim parameter alpha at theta = 17, 30, 90, 160 deg.

    Top row: the leg in its plane (leg frame {L}, beta = 0, toe down) with the continuous contact curve of
    :func:`~legkin.wheel_leg.rim_point` (pitch radius R, on the four rim links) and the seed's
    three-arc formula :func:`~legkin.wheel_leg.rim_point_seed` at the same radius (see :data:`RADIUS`),
    whose jump at alpha = +-psi_FG = +-40 deg is drawn in red. Bottom row: both curves' x_L and y_L against alpha.
    """
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    alpha = np.linspace(-np.pi, np.pi, 1441)  # 0.25 deg steps: contains +-40 and +-50 deg exactly
    fig, axes = new_figure(2, 4, figsize=(16, 8.4), gridspec_kw={"height_ratios": [1.25, 1.0]})
    c_cont, c_seed, c_jump = "tab:blue", "tab:orange", "tab:red"
    for col, th_deg in enumerate(THETAS_DEG):
        theta = math.radians(th_deg)
        cont = wl.rim_point(theta, 0.0, alpha)
        seed, alpha_s = _seed_pieces(theta, alpha)
        lo, hi = _jump_ends(theta)
        jump = float(wl.rim_jump_seed(theta, radius=RADIUS))
        jump_foot = float(wl.rim_jump_seed(theta))
        pts = wl.linkage_points(theta, 0.0)

        ax = axes[0, col]
        for a, b in _LINKS:
            ax.plot([pts[a][0], pts[b][0]], [pts[a][1], pts[b][1]], color="0.55", lw=1.2)
        for name in ("U_L", "U_R", "L_L", "L_R"):
            ax.plot(*pts[name][:2], "+", color="0.4", ms=6)
        for name in ("F_L", "F_R", "G"):
            ax.plot(*pts[name][:2], "o", color="0.3", ms=3)
        ax.plot(0.0, 0.0, "ko", ms=4)
        ax.plot(cont[:, 0], cont[:, 1], color=c_cont, lw=2.0)
        ax.plot(seed[:, 0], seed[:, 1], color=c_seed, lw=1.4, ls="--")
        for sgn in (1.0, -1.0):  # the jump is mirror-symmetric: draw both sides
            ax.plot([sgn * lo[0], sgn * hi[0]], [lo[1], hi[1]], color=c_jump, lw=2.2)
            ax.plot([sgn * lo[0], sgn * hi[0]], [lo[1], hi[1]], "o", color=c_jump, ms=3.5)
        p0 = wl.rim_point(theta, 0.0, 0.0)
        ax.annotate("alpha = 0 (toe G)", p0[:2], xytext=(0, -22), textcoords="offset points", ha="center", fontsize=7)
        ax.set_aspect("equal")
        ax.set_xlim(-0.2, 0.2)
        ax.set_ylim(-0.42, 0.16)
        ax.grid(alpha=0.3)
        mode = {17.0: " (wheel mode)", 160.0: " (leg mode)"}.get(th_deg, "")
        ax.set_title(
            f"theta = {th_deg:g} deg{mode}\nseed jump at +-40 deg: {1e3 * jump:.1f} mm\n"
            f"({1e3 * jump_foot:.1f} mm at the seed's radius R + 0.0345 m)",
            fontsize=9,
        )
        ax.set_xlabel("x_L (m)", fontsize=8)
        if col == 0:
            ax.set_ylabel("y_L (m), leg frame, beta = 0", fontsize=8)
        ax.tick_params(labelsize=7)

        ax = axes[1, col]
        deg = np.degrees
        for k, (lab, ls) in enumerate((("x_L", "-"), ("y_L", "-"))):
            col_k = (c_cont, c_seed) if k == 0 else ("tab:green", "tab:purple")
            ax.plot(deg(alpha), cont[:, k], color=col_k[0], lw=1.8, ls=ls)
            ax.plot(deg(alpha_s), seed[:, k], color=col_k[1], lw=1.3, ls="--")
            ax.plot([40, 40], [lo[k], hi[k]], color=c_jump, lw=2.2)
            ax.plot([-40, -40], [lo[k] if k else -lo[k], hi[k] if k else -hi[k]], color=c_jump, lw=2.2)
        for a_deg in (-50, 50):
            ax.axvline(a_deg, color="0.5", lw=0.7, ls=":")
        for a_deg in (-40, 40):
            ax.axvline(a_deg, color=c_jump, lw=0.7, ls=":")
        ax.set_xlim(-180, 180)
        ax.set_xticks(np.arange(-180, 181, 60))
        ax.set_ylim(-0.48, 0.2)
        ax.grid(alpha=0.3)
        ax.set_xlabel("rim parameter alpha (deg)", fontsize=8)
        if col == 0:
            ax.set_ylabel("contact point coordinate (m)", fontsize=8)
        ax.tick_params(labelsize=7)

    handles = [
        Line2D([], [], color=c_cont, lw=2.0, label="rim_point (continuous, pitch radius R = 0.1 m): x_L"),
        Line2D([], [], color="tab:green", lw=1.8, label="rim_point: y_L"),
        Line2D([], [], color=c_seed, lw=1.4, ls="--", label="rim_point_seed (seed 1.1, same radius R): x_L"),
        Line2D([], [], color="tab:purple", lw=1.3, ls="--", label="rim_point_seed: y_L"),
        Line2D([], [], color=c_jump, lw=2.2, label="seed jump at alpha = +-psi_FG = +-40 deg"),
        Line2D([], [], color="0.5", lw=0.7, ls=":", label="rim links meet at alpha = +-50 deg (hinges F)"),
        Line2D([], [], color="0.55", lw=1.2, label="linkage (crank, bars)"),
        Line2D([], [], color="0.4", marker="+", ls="none", label="rim arc centres U, L"),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.suptitle(
        "wheel-leg rim contact point over the rim parameter alpha (0 at the toe G, > 0 towards the right half), "
        "theta = leg opening", fontsize=11,
    )  # fmt: skip
    fig.tight_layout(rect=(0, 0.07, 1, 0.97))
    out = Path(outdir) / "wheel_leg_contact.png"
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return [out] + tyre_figures.figures(outdir)
