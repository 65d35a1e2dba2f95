"""Find and measure the HAA-HFE-KFE legs of a Pinocchio model (issue 13).

A *leg* is a chain of three 1-DOF revolute joints (``JointModelRX/RY/RZ`` or ``JointModelRevoluteUnaligned``,
any axis) hanging from the model's root (the universe, or the floating base joint when the universe has a
single non-revolute child) and ending at a foot frame: the frame attached to the third joint whose name
contains ``foot`` or ``toe`` (any case; a BODY frame preferred, the last one in frame order), or given by
``foot_frames``; when the third joint has no such frame and no child joint, its last frame.

Everything is measured at the neutral configuration in the root frame: joint origins ``oMi`` relative to
the root, unit axes (angular part of the LOCAL joint Jacobian column, turned into the root frame), the foot
frame's origin. :meth:`Leg.from_geometry` then checks the structure (HAA axis perpendicular to the HFE axis,
HFE parallel to KFE, within 1e-9), and :func:`from_model` checks that the closed form reproduces Pinocchio:
the foot at the neutral configuration and at three further joint vectors (to :data:`VERIFY_TOL`), and the
inverse kinematics of the neutral foot.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np

from ..errors import InvalidParameterError
from .kinematics import Leg, LegStructureError

__all__ = ["from_model", "from_urdf", "find_chains", "VERIFY_TOL", "REVOLUTE"]

#: Pinocchio joint models that count as a revolute leg joint.
REVOLUTE = ("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned")
#: Largest difference (m) allowed between the closed form and Pinocchio on the verification configurations.
VERIFY_TOL = 1e-9
#: The joint vectors (besides zero) on which the closed form is compared with Pinocchio at construction.
_VERIFY_Q = np.array([[0.31, -0.52, 0.83], [-1.13, 2.21, -0.41], [2.9, -2.7, 1.7]])
_FOOT = re.compile(r"foot|toe", re.IGNORECASE)


def _pin():
    import pinocchio as pin

    return pin


def _root(model) -> int:
    """The root joint: the floating base when the universe has one non-revolute child, else the universe (0)."""
    kids = [j for j in range(1, model.njoints) if model.parents[j] == 0]
    if len(kids) == 1 and model.joints[kids[0]].shortname() not in REVOLUTE:
        return kids[0]
    return 0


def _children(model, j: int) -> list[int]:
    return [c for c in range(1, model.njoints) if model.parents[c] == j]


def _is_revolute(model, j: int) -> bool:
    return j > 0 and model.joints[j].shortname() in REVOLUTE and model.joints[j].nq == 1


def _foot_frame(model, j3: int) -> str | None:
    """The foot-named frame on joint ``j3`` (BODY preferred, last in frame order), else None."""
    named = [f for f in model.frames if f.parentJoint == j3 and _FOOT.search(f.name)]
    if not named:
        return None
    bodies = [f for f in named if str(f.type) == "BODY"]
    return (bodies or named)[-1].name


def _last_frame(model, j3: int) -> str:
    frames = [f for f in model.frames if f.parentJoint == j3]
    return frames[-1].name


def find_chains(model, foot_frames: Iterable[str] | None = None) -> list[tuple[tuple[int, int, int], str]]:
    """The candidate legs of ``model``: ``[((j1, j2, j3), foot frame name), ...]`` in model order.

    Without ``foot_frames``: every chain root -> j1 -> j2 -> j3 of revolute joints where j1's only child is j2,
    j2's only child is j3, and j3 carries a foot-named frame (or has no child joint: its last frame is the foot).
    With ``foot_frames``: exactly the chains ending at those frames.

    Raises:
        LegStructureError: a given foot frame that does not hang from three revolute joints under the root.
        InvalidParameterError: a given foot frame that is not in the model.
    """
    root = _root(model)
    if foot_frames is not None:
        if isinstance(foot_frames, str):
            foot_frames = [foot_frames]
        out = []
        for name in foot_frames:
            if not isinstance(name, str) or not model.existFrame(name):
                known = [f.name for f in model.frames if _FOOT.search(f.name)]
                raise InvalidParameterError(
                    f"foot frame {name!r} is not a frame of the model (foot-like frames: {known})"
                )
            j3 = model.frames[model.getFrameId(name)].parentJoint
            j2 = model.parents[j3] if j3 > 0 else 0
            j1 = model.parents[j2] if j2 > 0 else 0
            chain = (j1, j2, j3)
            bad = [model.names[j] for j in chain if not _is_revolute(model, j)]
            if bad or model.parents[j1] != root:
                kinds = [f"{model.names[j]} ({model.joints[j].shortname()})" for j in chain if j > 0]
                raise LegStructureError(
                    f"foot frame {name!r} does not end a chain of three revolute joints from the root "
                    f"{model.names[root]!r}: the joints above it are {kinds}, their root "
                    f"{model.names[model.parents[j1]] if j1 > 0 else 'universe'!r}"
                )
            out.append((chain, name))
        return out
    out = []
    for j1 in _children(model, root):
        if not _is_revolute(model, j1):
            continue
        k1 = _children(model, j1)
        if len(k1) != 1 or not _is_revolute(model, k1[0]):
            continue
        j2 = k1[0]
        k2 = _children(model, j2)
        if len(k2) != 1 or not _is_revolute(model, k2[0]):
            continue
        j3 = k2[0]
        foot = _foot_frame(model, j3)
        if foot is None:
            if _children(model, j3):
                continue
            foot = _last_frame(model, j3)
        out.append(((j1, j2, j3), foot))
    return out


def _leg_name(names: tuple[str, str, str]) -> str:
    prefix = os.path.commonprefix(list(names))
    return re.sub(r"[^0-9A-Za-z]+$", "", prefix)


def _measure(model, data, root: int, chain: tuple[int, int, int], foot: str):
    """Origins (3, 3), unit axes (3, 3) and foot (3,) in the root frame at the data's configuration."""
    pin = _pin()
    base = data.oMi[root].inverse()
    origins, axes = [], []
    for j in chain:
        jac = pin.getJointJacobian(model, data, j, pin.LOCAL)[:, model.joints[j].idx_v]
        if np.linalg.norm(jac[:3]) > 1e-12 or abs(np.linalg.norm(jac[3:]) - 1.0) > 1e-9:
            raise LegStructureError(
                f"joint {model.names[j]} is not a pure rotation about a unit axis "
                f"(motion subspace {jac.round(6).tolist()})"
            )
        m = base * data.oMi[j]
        origins.append(np.array(m.translation))
        axes.append(np.array(m.rotation) @ jac[3:])
    f = np.array((base * data.oMf[model.getFrameId(foot)]).translation)
    return np.array(origins), np.array(axes), f


def _foot_rel(model, data, root: int, fid: int, q) -> np.ndarray:
    pin = _pin()
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    return np.array((data.oMi[root].inverse() * data.oMf[fid]).translation)


def _build(model, root: int, chain: tuple[int, int, int], foot: str, name: str) -> Leg:
    pin = _pin()
    data = model.createData()
    q0 = pin.neutral(model)
    pin.computeJointJacobians(model, data, q0)
    pin.updateFramePlacements(model, data)
    origins, axes, f = _measure(model, data, root, chain, foot)
    iq = tuple(model.joints[j].idx_q for j in chain)
    iv = tuple(model.joints[j].idx_v for j in chain)
    lower = np.array([model.lowerPositionLimit[i] for i in iq])
    upper = np.array([model.upperPositionLimit[i] for i in iq])
    names = tuple(model.names[j] for j in chain)
    leg = Leg.from_geometry(name, names, foot, origins, axes, f, lower, upper, idx_q=iq, idx_v=iv)
    # The closed form must reproduce Pinocchio: at zero (the leg's joints) and at _VERIFY_Q.
    fid = model.getFrameId(foot)
    worst, where = 0.0, np.zeros(3)
    for qleg in np.vstack([np.zeros(3), _VERIFY_Q]):
        q = q0.copy()
        q[list(iq)] = qleg
        err = float(np.linalg.norm(leg.fk(qleg) - _foot_rel(model, data, root, fid, q)))
        if not err <= worst:
            worst, where = err, qleg
    if not worst <= VERIFY_TOL:
        raise LegStructureError(
            f"leg {name}: the HAA-HFE-KFE closed form misses Pinocchio's {foot} by {worst:.3g} m at joint values "
            f"{where.tolist()} (tolerance {VERIFY_TOL:g} m)"
        )
    q_all, mask = leg.ik_all(f, return_mask=True)
    if mask.any():
        miss = float(np.min(np.linalg.norm(leg.fk(q_all[mask]) - f, axis=-1)))
    else:  # pragma: no cover - ik_all raises instead
        miss = math.inf
    if not miss <= VERIFY_TOL:
        raise LegStructureError(
            f"leg {name}: no closed-form IK branch reproduces the neutral foot {f.tolist()} (best miss {miss:.3g} m)"
        )
    return leg


def from_model(model, name: str | None = None, *, foot_frames: Iterable[str] | Mapping[str, str] | None = None):
    """Every HAA-HFE-KFE leg of a Pinocchio model, measured at its neutral configuration.

    Args:
        model: a ``pinocchio.Model`` (fixed or floating base: geometry is in the root frame, i.e. the base).
        name: a leg name (the common prefix of its joint names, e.g. ``"FL"``, ``"lf"``), its first joint's
            name or its foot frame's name: return that one :class:`Leg` (and check only it).
        foot_frames: the foot frames (names) to use instead of the name search; a mapping's values are used.

    Returns:
        ``{leg name: Leg}`` in model order, or one :class:`Leg` when ``name`` is given.

    Raises:
        LegStructureError: a chain that is not an HAA-HFE-KFE leg (the deviation named: axes off perpendicular
            or parallel in degrees, zero thigh or shank, closed form not reproducing Pinocchio).
        InvalidParameterError: not a model, an unknown ``name`` or foot frame, or no leg found.
    """
    pin = _pin()
    if not isinstance(model, pin.Model):
        raise InvalidParameterError(f"model must be a pinocchio.Model, got {type(model).__name__}")
    if name is not None and not isinstance(name, str):
        raise InvalidParameterError(f"name must be a leg name (str) or None, got {name!r}")
    if isinstance(foot_frames, Mapping):
        foot_frames = list(foot_frames.values())
    root = _root(model)
    chains = find_chains(model, foot_frames)
    named = []
    for chain, foot in chains:
        joints = tuple(model.names[j] for j in chain)
        named.append((_leg_name(joints) or joints[0], chain, foot))
    counts = {n: sum(1 for m, _, _ in named if m == n) for n, _, _ in named}
    named = [(n if counts[n] == 1 else model.names[c[0]], c, f) for n, c, f in named]
    if name is not None:
        for leg_name, chain, foot in named:
            if name in (leg_name, model.names[chain[0]], foot):
                return _build(model, root, chain, foot, leg_name)
        raise InvalidParameterError(
            f"no leg {name!r} in the model; its legs: {[n for n, _, _ in named] or 'none'}"
        )
    if not named:
        raise InvalidParameterError(
            "no HAA-HFE-KFE leg found: no chain of three revolute joints from the root "
            f"{model.names[root]!r} ends at a foot frame (a frame named *foot* or *toe*, or pass foot_frames)"
        )
    return {leg_name: _build(model, root, chain, foot, leg_name) for leg_name, chain, foot in named}


def from_urdf(
    path: str | os.PathLike,
    name: str | None = None,
    *,
    foot_frames: Iterable[str] | Mapping[str, str] | None = None,
):
    """:func:`from_model` of the URDF file at ``path`` (built with a fixed base: the root frame is the base link).

    Raises:
        InvalidParameterError: the file is missing or Pinocchio cannot parse it (its message included).
        LegStructureError: as :func:`from_model`.
    """
    pin = _pin()
    p = Path(os.fspath(path))
    if not p.is_file():
        raise InvalidParameterError(f"URDF file {str(p)!r} does not exist")
    try:
        model = pin.buildModelFromUrdf(str(p))
    except Exception as exc:  # noqa: BLE001 - Pinocchio's parse errors become a legkin error
        raise InvalidParameterError(f"cannot read URDF {str(p)!r}: {exc}") from exc
    return from_model(model, name, foot_frames=foot_frames)
