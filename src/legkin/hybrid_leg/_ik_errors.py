"""Why a single foot-IK call found nothing: the error (and its message) for the target, from the 16 closed-form
branches labelled by :func:`._ik_kernels.ik_all_k` (run only on failure)."""

from __future__ import annotations

import math

import numpy as np

from ..errors import AssemblyModeError, JointLimitError, SingularityError, UnreachableError
from ._ik_kernels import ik_all_k, platform_pose_k
from ._options import fmt, mode_text, unreachable
from .chains import chains_k, rot_k
from .foot import band_message
from .geometry import (
    CENTER,
    FK_GAIN_MAX,
    FOOT_IK_BRANCHES,
    FOOT_IK_ORDER,
    K_TOL,
    LL0,
    LL_TOL,
    MOTOR_BRANCHES,
    PLATFORM_LIMIT,
    H,
)

#: The 16 branches in the order the errors report them (FOOT_IK_ORDER x MOTOR_BRANCHES), as indices of
#: FOOT_IK_BRANCHES.
_ROWS = [(llb, rb, bb) for llb, rb in FOOT_IK_ORDER for bb in MOTOR_BRANCHES]
_ORDER = np.array([FOOT_IK_BRANCHES.index((llb, rb, bb[0], bb[1])) for llb, rb, bb in _ROWS])


def arc_error(p: np.ndarray) -> UnreachableError:
    r = math.hypot(*(float(v) for v in p - CENTER))  # no overflow for |p| near the float limit
    lo, hi = LL0 - H, LL0 + H
    distance = r - hi if r > hi else lo - r
    side = f"{distance:.3g} m beyond its outer end" if r > hi else f"{distance:.3g} m inside its inner end"
    return UnreachableError(
        f"foot target {fmt(p)} is {r:.17g} m from the LCS centre; the LL arc reaches [{lo:.17g}, {hi:.17g}] m "
        f"(+- {LL_TOL:g} in the arc's cosine for rounding): the target is {side}",
        target=p, distance=distance,
    )


def _limit_error(message: str, p: np.ndarray, pose: np.ndarray) -> JointLimitError:
    """A :class:`JointLimitError` for the platform pose (theta_LL, roll, pitch): the first of the joints LCS_x
    (roll), LCS_y (pitch) outside [-PLATFORM_LIMIT, PLATFORM_LIMIT]."""
    k = 1 if not abs(float(pose[1])) <= PLATFORM_LIMIT else 2
    return JointLimitError(message, target=p, joint=("LCS_x", "LCS_y")[k - 1], value=float(pose[k]),
                           lower=-PLATFORM_LIMIT, upper=PLATFORM_LIMIT)


def axis_error(p: np.ndarray, pose: bool = True) -> SingularityError:
    if pose:
        return SingularityError(
            f"foot target {fmt(p)} lies exactly on the platform's roll axis (x through the LCS centre): roll is "
            "undetermined, any roll reaches it (ik takes roll = 0 or pi there; or move the target off the axis "
            "by any amount)"
        )
    return SingularityError(
        f"foot target {fmt(p)} lies exactly on the platform's roll axis (x through the LCS centre), where roll is "
        "undetermined, and neither roll = 0 nor roll = pi reaches it in the mode asked for (another roll might)"
    )


def platform_pose(p: np.ndarray, llb: float, rb: float) -> tuple[np.ndarray, np.ndarray]:
    """(theta_LL, roll, pitch) of one branch for the single target p, and (kk, reach, rho)."""
    u = p - CENTER
    pose, info = np.empty(3), np.empty(3)
    platform_pose_k(u[0], u[1], u[2], float(llb), float(rb), pose, info)
    return pose, info


def _mode_dict(llb: float, rb: float, b: np.ndarray, s: float) -> dict:
    return {"ll_branch": int(llb), "roll_branch": int(rb), "branch": (int(b[0]), int(b[1])), "assembly": int(s)}


def _mode_str(m: dict) -> str:
    return (f"ll_branch={m['ll_branch']:+d}, roll_branch={m['roll_branch']:+d}, branch=({m['branch'][0]}, "
            f"{m['branch'][1]}), assembly={m['assembly']:+d}")


def _candidates(p: np.ndarray, sv: float) -> list[dict]:
    """The 16 branches of p in the reporting order, each a dict (pose, exists, inlim, mode, gain, fk, ll, rb, b)."""
    u = p - CENTER
    motors, pose, info, fk = np.empty((16, 3)), np.empty((16, 3)), np.empty((16, 7)), np.empty(16, dtype=np.bool_)
    ik_all_k(u[0], u[1], u[2], sv, True, motors, pose, info, fk)
    out = []
    for j, (llb, rb, bb) in zip(_ORDER, _ROWS):
        out.append({"pose": pose[j], "exists": info[j, 0] == 1.0, "inlim": info[j, 1] == 1.0, "mode": info[j, 2],
                    "gain": info[j, 3], "fk": bool(fk[j]), "ll": llb, "rb": rb, "b": np.array(bb, dtype=float)})
    return out


def ik_error(p: np.ndarray, sv: float, combos: list, b: np.ndarray, s: float, limits_only: bool = False) -> Exception:
    """Why the mode-checked search found nothing for the single target p (3,)."""
    _, arc = platform_pose(p, -1.0, 1.0)
    if arc[1] != 1.0:
        return arc_error(p)
    if not arc[2] > 0.0:
        return axis_error(p, limits_only)
    asked = f"ll_branch, roll_branch in {combos}" + ("" if limits_only else f", {mode_text(b, s)}")
    cands = _candidates(p, sv)
    for c in cands:
        c["requested"] = (c["ll"], c["rb"]) in combos and (limits_only or bool(np.all(c["b"] == b)))
    if limits_only and not [c for c in cands if c["requested"] and c["inlim"]]:
        x = platform_pose(p, combos[0][0], combos[0][1])[0]
        return _limit_error(
            f"foot target {fmt(p)} needs (theta_LL, roll, pitch) = ({x[0]:.6g}, {x[1]:.6g}, {x[2]:.6g}) or the "
            f"other branches asked for ({asked}): outside the joint limits |roll|, |pitch| <= pi/2 (LCS_x, LCS_y)",
            p, x,
        )
    # reachable in the mode asked for, but in the forward-singularity band
    band = [c for c in cands if c["requested"] and c["exists"] and c["inlim"] and c["mode"] == s and c["fk"]
            and not c["gain"] < FK_GAIN_MAX]
    if band:
        return SingularityError(band_message(f"foot target {fmt(p)}", band[0]["pose"][1:], band[0]["gain"]))
    valid = [c for c in cands if c["exists"] and c["inlim"] and c["fk"] and c["gain"] < FK_GAIN_MAX]
    if valid:
        modes = [_mode_dict(c["ll"], c["rb"], c["b"], c["mode"]) for c in valid]
        where = "; ".join(f"{_mode_str(m)} at (roll, pitch) = ({c['pose'][1]:.6g}, {c['pose'][2]:.6g})"
                          for m, c in zip(modes, valid))
        return AssemblyModeError(
            f"foot target {fmt(p)} is reachable within the joint limits, but not in the mode asked for ({asked}); "
            f"it is reachable with {where}",
            target=p, modes=modes,
        )
    inl = [c for c in cands if c["exists"] and c["inlim"]]
    if inl:
        c = inl[0]
        return AssemblyModeError(
            f"foot target {fmt(p)} needs (roll, pitch) = ({c['pose'][1]:.6g}, {c['pose'][2]:.6g}) (branch "
            f"({int(c['b'][0])}, {int(c['b'][1])})), a pose the forward kinematics of its motor angles does not "
            "return (another pose of the same mode is nearer R_P = I, or it is in the forward-singularity band); "
            f"asked: {asked}",
            target=p, modes=[],
        )
    out = [c for c in cands if c["exists"]]
    if out:
        c = out[0]
        raw = platform_pose(p, c["ll"], c["rb"])[0]
        return _limit_error(
            f"foot target {fmt(p)} is reachable only outside the joint limits |roll|, |pitch| <= pi/2 (LCS_x, LCS_y): "
            f"{len(out)} of the 16 closed-form branches reach it, none within the limits (e.g. (roll, pitch) = "
            f"({raw[1]:.6g}, {raw[2]:.6g}) with ll_branch={c['ll']:+d}, roll_branch={c['rb']:+d})",
            p, raw,
        )
    x = platform_pose(p, combos[0][0], combos[0][1])[0]
    rot, th, k = np.empty((3, 3)), np.empty(2), np.empty(2)
    rot_k(x[1], x[2], rot)
    chains_k(rot, float(b[0]), float(b[1]), K_TOL, th, k)
    return UnreachableError(
        f"foot target {fmt(p)} needs (roll, pitch) = ({x[1]:.6g}, {x[2]:.6g}) (ll_branch={combos[0][0]:+d}, "
        f"roll_branch={combos[0][1]:+d}): " + str(unreachable("that platform pose", k)).split(": ", 1)[1].replace(
            "is out", "out", 1) + "; no other branch reaches it either",
        target=p,
    )
