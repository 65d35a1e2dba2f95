"""Figures of the tripod: the reachable (alpha_y, alpha_z) set with its singular curves."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..figures import new_figure
from . import kinematics as at

LEG_COLOURS = {"A": "tab:red", "B": "tab:green", "C": "tab:blue"}


def _tilt_axis(theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    return np.stack([np.cos(theta), np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi)], axis=-1)


def figures(outdir: Path) -> list[Path]:
    """``tripod_workspace.png``: reachable set coloured by the distance to the boundary (min_K sin q_K2).

    Left: the (alpha_y, alpha_z) plane (alpha_y in [-90, 90] deg covers every orientation once). Right: the
    same set in tilt coordinates, the platform axis ``R e_x = (cos theta, sin theta cos phi, sin theta sin phi)``
    drawn at radius theta in direction phi. Singular curves: sin q_K2 = 0 of each leg (solid, its colour) and
    the platform singularity 1 + c_y c_z = 0 (tilt 180 deg: the points (0, +-180 deg), the outer circle).
    """
    from matplotlib.lines import Line2D

    from .clips import MARGIN, TILT_CAP

    ws = at.workspace(n=361, m=1441)
    deg = np.degrees
    s2 = np.sqrt(np.clip(1.0 - ws.cos_q2**2, 0.0, None)).min(axis=0)  # min_K sin q_K2
    field = np.where(ws.reachable, s2, np.nan)
    fig = new_figure(figsize=(12.5, 5.4))[0]
    fig.clf()
    ax = fig.add_subplot(1, 2, 1)
    pol = fig.add_subplot(1, 2, 2, projection="polar")
    ax.set_facecolor("0.85")
    im = ax.imshow(
        field.T, origin="lower", cmap="viridis", vmin=0.0, vmax=1.0, interpolation="nearest", aspect="auto",
        extent=(deg(ws.alpha_y[0]), deg(ws.alpha_y[-1]), deg(ws.alpha_z[0]), deg(ws.alpha_z[-1])),
    )  # fmt: skip
    for leg, curve in ws.leg_singular.items():
        ax.plot(deg(curve[:, 0]), deg(curve[:, 1]), color=LEG_COLOURS[leg], lw=1.6)
    ax.plot(deg(ws.boundary[:, 0]), deg(ws.boundary[:, 1]), color="k", lw=0.8, ls=":")
    ax.plot([0, 0], [-180, 180], "kX", ms=10, clip_on=False, zorder=5)
    ax.set_xlim(-90, 90)
    ax.set_ylim(-180, 180)
    ax.set_xticks(np.arange(-90, 91, 30))
    ax.set_yticks(np.arange(-180, 181, 45))
    ax.set_xlabel("alpha_y (deg)")
    ax.set_ylabel("alpha_z (deg)")
    ax.set_title("reachable (alpha_y, alpha_z), grey: unreachable", fontsize=10)
    cb = fig.colorbar(im, ax=ax, fraction=0.05, pad=0.02)
    cb.set_label("min over legs of sin q_K2 (0 on the boundary)")

    # tilt coordinates: radius theta (deg), angle phi
    phi = np.linspace(-np.pi, np.pi, 721)
    theta = np.radians(np.linspace(0.0, 180.0, 181))
    P, T = np.meshgrid(phi, theta, indexing="ij")
    ay, az = at.orientation_from_axis(_tilt_axis(T, P))
    q, ok = at.ik_joints(np.stack([ay, az], axis=-1), return_mask=True)
    s2p = np.where(ok, np.abs(np.sin(q[..., [1, 5, 9]])).min(axis=-1), np.nan)
    pol.set_facecolor("0.85")
    pol.pcolormesh(P, deg(T), s2p, cmap="viridis", vmin=0.0, vmax=1.0, shading="nearest", rasterized=True)
    for k, leg in enumerate(at.LEGS):
        with np.errstate(divide="ignore"):
            ratio = math.cos(at.ALPHA / 2) / np.abs(np.sin(ws.phi - at.ETA[k]))
        tk = np.where(ratio <= 1.0, 2.0 * np.arcsin(np.minimum(ratio, 1.0)), np.nan)
        pol.plot(ws.phi, deg(tk), color=LEG_COLOURS[leg], lw=1.6)
        pol.plot([at.ETA[k]] * 2, [0, 180], color=LEG_COLOURS[leg], lw=0.6, ls="--")
    pol.plot(ws.phi, np.full_like(ws.phi, 180.0), "k", lw=2.5)
    path = np.minimum(ws.tilt_max - MARGIN, TILT_CAP)
    pol.plot(ws.phi, deg(path), color="w", lw=1.2, ls="--")
    pol.set_ylim(0, 180)
    pol.set_yticks([45, 90, 135, 180])
    pol.set_yticklabels(["45", "90", "135", "180 deg"], fontsize=8)
    pol.set_title(
        "same set in tilt coordinates: tilt theta (radius, deg)\ntowards phi (angle; 0 = +y, 90 deg = +z)",
        fontsize=10, pad=14,
    )  # fmt: skip

    handles = [Line2D([], [], color=LEG_COLOURS[k], lw=1.6, label=f"leg {k}: sin q_{k}2 = 0") for k in at.LEGS]
    handles += [
        Line2D([], [], color=LEG_COLOURS["A"], lw=0.6, ls="--", label="leg placement eta_K"),
        Line2D([], [], color="k", marker="X", ls="none", ms=8, label="1 + c_y c_z = 0 (tilt 180 deg, outer circle)"),
        Line2D([], [], color="k", lw=0.8, ls=":", label="workspace boundary"),
        Line2D([], [], color="w", lw=1.2, ls="--", label="clip workspace_boundary"),
    ]
    leg = fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=8, frameon=True)
    leg.get_frame().set_facecolor("0.75")
    fig.suptitle(
        f"tripod workspace (d = {at.D} m, alpha = {math.degrees(at.ALPHA):.0f} deg, eta = "
        f"{', '.join(f'{math.degrees(e):.0f}' for e in at.ETA)} deg): "
        "constant-velocity orientations R = Rz(alpha_z) Ry(alpha_y) Rx(alpha_x)", fontsize=10,
    )  # fmt: skip
    fig.tight_layout(rect=(0, 0.08, 1, 0.97))
    out = Path(outdir) / "tripod_workspace.png"
    fig.savefig(out, dpi=90)
    _close(fig)
    return [out]


def _close(fig) -> None:
    import matplotlib.pyplot as plt

    plt.close(fig)
