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
from typing import Any

import numpy as np

from ..errors import InvalidParameterError, LegStructureError
from .kinematics import Leg
from .sixdof import Leg6

__all__ = ["from_model", "from_urdf", "find_chains", "VERIFY_TOL", "REVOLUTE"]

#: Pinocchio joint models that count as a revolute leg joint.
REVOLUTE = ("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned")
#: URDF ``continuous`` joints: Pinocchio's unbounded revolute joints (two configuration entries, cos and sin; a
#: leg's ``idx_q`` then points at the cos entry, its limits are infinite).
CONTINUOUS = ("JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned")
#: Largest difference (m) allowed between the closed form and Pinocchio on the verification configurations.
VERIFY_TOL = 1e-9
#: The joint vectors (besides zero) on which the closed form is compared with Pinocchio at construction.
_VERIFY_Q = np.array([[0.31, -0.52, 0.83], [-1.13, 2.21, -0.41], [2.9, -2.7, 1.7]])
_FOOT = re.compile(r"foot|toe", re.IGNORECASE)
_SOLE = re.compile(r"sole", re.IGNORECASE)
_SENSOR = re.compile(r"imu|sensor|_ft|camera", re.IGNORECASE)
#: The leg lengths (revolute joints from the root) legkin builds: 3 (:class:`Leg`), 6 (:class:`Leg6`).
SUPPORTED_DOF = (3, 6)
#: The structures legkin supports (for :class:`LegStructureError`'s ``expected``).
EXPECTED = ("HAA-HFE-KFE (3 revolute joints, Leg)", "6R leg (6 revolute joints, Leg6; closed-form IK for "
            "intersecting hip axes)")


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
    """A revolute joint with limits (one configuration entry) or a continuous one (two: cos, sin)."""
    if j <= 0:
        return False
    kind, nq = model.joints[j].shortname(), model.joints[j].nq
    return (kind in REVOLUTE and nq == 1) or (kind in CONTINUOUS and nq == 2)


def _set_angles(model, q: np.ndarray, chain, angles) -> np.ndarray:
    """``q`` with the joints of ``chain`` at ``angles`` (rad): a continuous joint's entries are (cos, sin)."""
    for j, a in zip(chain, angles):
        i = model.joints[j].idx_q
        if model.joints[j].nq == 2:
            q[i], q[i + 1] = math.cos(a), math.sin(a)
        else:
            q[i] = a
    return q


def _limits(model, chain) -> tuple[np.ndarray, np.ndarray]:
    """The URDF limits (rad) of the joints of ``chain``: infinite for a continuous joint."""
    lo, hi = [], []
    for j in chain:
        i = model.joints[j].idx_q
        unbounded = model.joints[j].nq == 2
        lo.append(-math.inf if unbounded else model.lowerPositionLimit[i])
        hi.append(math.inf if unbounded else model.upperPositionLimit[i])
    return np.array(lo), np.array(hi)


def _foot_frame(model, j: int) -> str | None:
    """The foot frame on joint ``j``: a frame named *sole*, else *foot* / *toe* (any case; a BODY frame preferred,
    then one not named for a sensor (*imu*, *sensor*, *_ft*, *camera*), then the last in frame order); None if it
    has neither."""
    for pattern in (_SOLE, _FOOT):
        named = [f for f in model.frames if f.parentJoint == j and pattern.search(f.name)]
        if named:  # a BODY frame, not a sensor's, the last in frame order
            k = max(range(len(named)), key=lambda i: (str(named[i].type) == "BODY",
                                                      not _SENSOR.search(named[i].name), i))
            return named[k].name
    return None


def _last_frame(model, j: int) -> str:
    frames = [f for f in model.frames if f.parentJoint == j]
    bodies = [f for f in frames if str(f.type) == "BODY"]
    return (bodies or frames)[-1].name


def _walk(model, j1: int) -> tuple[list[int], str | None]:
    """The chain j1 -> ... of revolute joints each the only child of the previous, and the foot frame: on the
    first joint (from j1) of length 3 or 6 that carries a sole/foot/toe frame, else the last frame of the chain's
    end if it is a leaf (no child joint), else None."""
    chain = [j1]
    while len(kids := _children(model, chain[-1])) == 1 and _is_revolute(model, kids[0]) and len(chain) < 12:
        chain.append(kids[0])
    for n in SUPPORTED_DOF:
        if len(chain) >= n and (foot := _foot_frame(model, chain[n - 1])) is not None:
            return chain[:n], foot
    if not _children(model, chain[-1]):
        return chain, _foot_frame(model, chain[-1]) or _last_frame(model, chain[-1])
    return chain, None


def _describe(model, chain: Iterable[int]) -> str:
    return "-".join(f"{model.names[j]} ({model.joints[j].shortname().replace('JointModel', '')})" for j in chain)


def _above(model, name: str, root: int) -> tuple[int, ...]:
    """The revolute joints from the root down to the frame ``name`` (LegStructureError if any is not revolute)."""
    j = model.frames[model.getFrameId(name)].parentJoint
    chain: list[int] = []
    while j > 0 and j != root:
        chain.insert(0, j)
        j = model.parents[j]
    bad = [model.names[k] for k in chain if not _is_revolute(model, k)]
    if bad or len(chain) not in SUPPORTED_DOF:
        raise LegStructureError(
            f"foot frame {name!r} does not end a leg: it hangs from {len(chain)} joints under the root "
            f"{model.names[root]!r} ({_describe(model, chain) or 'none'}"
            f"{'; not revolute: ' + ', '.join(bad) if bad else ''}); legkin supports chains of three revolute "
            f"joints (HAA-HFE-KFE) or six (6R)",
            found=_describe(model, chain), expected=list(EXPECTED),
        )
    return tuple(chain)


def find_chains(model: Any, foot_frames: Iterable[str] | None = None) -> list[tuple[tuple[int, ...], str]]:
    """The candidate legs of ``model``: ``[((j1, ..., jn), foot frame name), ...]`` in model order, n in
    :data:`SUPPORTED_DOF`.

    Without ``foot_frames``: every chain root -> j1 -> j2 -> ... of revolute joints, each the only child of the
    previous, whose 3rd or 6th joint carries a sole / foot / toe frame (a sole frame preferred), or that ends at
    a leaf joint after 3 or 6 joints (its last BODY frame is the foot). With ``foot_frames``: exactly the chains
    ending at those frames.

    Args:
        model: a ``pinocchio.Model``.
        foot_frames: the foot frames' names to use instead of the name search.

    Returns:
        The chains: each its joint ids from the root and its foot frame's name.

    Raises:
        LegStructureError: a given foot frame that does not hang from 3 or 6 revolute joints under the root.
        InvalidParameterError: a given foot frame that is not in the model.
    """
    root = _root(model)
    if foot_frames is not None:
        if isinstance(foot_frames, str):
            foot_frames = [foot_frames]
        out = []
        for name in foot_frames:
            if not isinstance(name, str) or not model.existFrame(name):
                known = [f.name for f in model.frames if _FOOT.search(f.name) or _SOLE.search(f.name)]
                raise InvalidParameterError(
                    f"foot frame {name!r} is not a frame of the model (foot-like frames: {known})"
                )
            out.append((_above(model, name, root), name))
        return out
    out = []
    for j1 in _children(model, root):
        if _is_revolute(model, j1):
            chain, foot = _walk(model, j1)
            if foot is not None and len(chain) in SUPPORTED_DOF:
                out.append((tuple(chain), foot))
    return out


def _unsupported(model) -> list[str]:
    """What hangs from the root (for the error when no leg fits): each child chain, described."""
    root = _root(model)
    found = []
    for j1 in _children(model, root):
        if not _is_revolute(model, j1):
            found.append(f"{_describe(model, [j1])}: not a revolute joint")
            continue
        chain, foot = _walk(model, j1)
        end = "ends at a leaf" if not _children(model, chain[-1]) else "branches"
        found.append(f"{_describe(model, chain)}: {len(chain)} joints, {end}, foot frame {foot!r}")
    return found


def _leg_name(names: tuple[str, ...]) -> str:
    prefix = os.path.commonprefix(list(names))
    return re.sub(r"[^0-9A-Za-z]+$", "", prefix)


def _position_names(hips: np.ndarray) -> list[str] | None:
    """Leg names from the hips' positions (root frame): ``left`` / ``right`` for two legs (sign of y), ``FL``,
    ``FR``, ``RL``, ``RR`` for four (signs of x and y); None when that does not name them apart."""
    if len(hips) == 2:
        names = ["left" if h[1] > 0 else "right" for h in hips]
    elif len(hips) == 4:
        names = [("F" if h[0] > 0 else "R") + ("L" if h[1] > 0 else "R") for h in hips]
    else:
        return None
    return names if len(set(names)) == len(names) else None


def _measure(model, data, root: int, chain: tuple[int, ...], foot: str):
    """Origins (n, 3), unit axes (n, 3) and the foot frame's pose (4, 4) in the root frame at the data's
    configuration."""
    pin = _pin()
    base = data.oMi[root].inverse()
    origins, axes = [], []
    for j in chain:
        jac = pin.getJointJacobian(model, data, j, pin.LOCAL)[:, model.joints[j].idx_v]
        if np.linalg.norm(jac[:3]) > 1e-12 or abs(np.linalg.norm(jac[3:]) - 1.0) > 1e-9:
            raise LegStructureError(
                f"joint {model.names[j]} is not a pure rotation about a unit axis "
                f"(motion subspace {jac.round(6).tolist()})", found=model.names[j], expected=list(EXPECTED),
            )
        m = base * data.oMi[j]
        origins.append(np.array(m.translation))
        axes.append(np.array(m.rotation) @ jac[3:])
    foot_pose = np.array((base * data.oMf[model.getFrameId(foot)]).homogeneous)
    return np.array(origins), np.array(axes), foot_pose


def _foot_rel(model, data, root: int, fid: int, q) -> np.ndarray:
    """The foot frame's pose (4, 4) in the root frame at the model configuration ``q``."""
    pin = _pin()
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    return np.array((data.oMi[root].inverse() * data.oMf[fid]).homogeneous)


def _verify_fk(model, root: int, chain, leg, fk, q0, data) -> tuple[float, np.ndarray]:
    """The largest difference between ``fk(q_leg)`` and Pinocchio's foot (position (3,) or pose (4, 4)) over zero
    and :data:`_VERIFY_Q`, and where."""
    n = len(leg.idx_q)
    fid = model.getFrameId(leg.foot_frame)
    worst, where = 0.0, np.zeros(n)
    for qleg in np.vstack([np.zeros(n), np.resize(_VERIFY_Q.ravel(), (3, n))]):
        ref = _foot_rel(model, data, root, fid, _set_angles(model, q0.copy(), chain, qleg))
        got = fk(qleg)
        err = float(np.abs(got - (ref[:3, 3] if got.shape == (3,) else ref)).max())
        if not err <= worst:
            worst, where = err, qleg
    return worst, where


def _build(model, root: int, chain: tuple[int, ...], foot: str, name: str) -> Leg | Leg6:
    """The :class:`Leg` (3 joints) or :class:`Leg6` (6 joints) of ``chain``, checked against Pinocchio."""
    pin = _pin()
    data = model.createData()
    q0 = pin.neutral(model)
    pin.computeJointJacobians(model, data, q0)
    pin.updateFramePlacements(model, data)
    origins, axes, foot_pose = _measure(model, data, root, chain, foot)
    iq = tuple(model.joints[j].idx_q for j in chain)
    iv = tuple(model.joints[j].idx_v for j in chain)
    lower, upper = _limits(model, chain)
    names = tuple(model.names[j] for j in chain)
    leg: Leg | Leg6
    if len(chain) == 6:
        leg = Leg6.from_geometry(name, names, foot, origins, axes, foot_pose, lower, upper, idx_q=iq, idx_v=iv)
    else:
        leg = Leg.from_geometry(name, names, foot, origins, axes, foot_pose[:3, 3], lower, upper,  # type: ignore[arg-type]
                                idx_q=iq, idx_v=iv)  # type: ignore[arg-type]
    worst, where = _verify_fk(model, root, chain, leg, leg.fk, q0, data)
    if not worst <= VERIFY_TOL:
        raise LegStructureError(
            f"leg {name}: the forward map misses Pinocchio's {foot} by {worst:.3g} at joint values "
            f"{where.tolist()} (tolerance {VERIFY_TOL:g})", found=leg.structure, expected=list(EXPECTED),
        )
    if isinstance(leg, Leg):
        _check_neutral_ik(leg, foot_pose[:3, 3])
    return leg


def _check_neutral_ik(leg: Leg, f: np.ndarray) -> None:
    q_all, mask = leg.ik_all(f, return_mask=True)
    if mask.any():
        miss = float(np.min(np.linalg.norm(leg.fk(q_all[mask]) - f, axis=-1)))
    else:  # pragma: no cover - ik_all raises instead
        miss = math.inf
    if not miss <= VERIFY_TOL:
        raise LegStructureError(
            f"leg {leg.name}: no closed-form IK branch reproduces the neutral foot {f.tolist()} "
            f"(best miss {miss:.3g} m)",
            found=leg.structure, expected=list(EXPECTED),
        )


def _named(model, chains) -> list[tuple[str, tuple[int, ...], str]]:
    """``(name, chain, foot)`` per chain: the common prefix of its joint names when the legs' prefixes are
    distinct and nonempty, else the position names (``left``/``right``, ``FL``/``FR``/``RL``/``RR``) from the
    hips in the root frame, else the first joint's name."""
    prefixes = [_leg_name(tuple(model.names[j] for j in chain)) for chain, _ in chains]
    if all(prefixes) and len(set(prefixes)) == len(prefixes):
        return [(n, c, f) for n, (c, f) in zip(prefixes, chains)]
    pin = _pin()
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    root = _root(model)
    hips = np.array([(data.oMi[root].inverse() * data.oMi[c[0]]).translation for c, _ in chains]).reshape(-1, 3)
    by_position = _position_names(hips)
    if by_position is not None:
        return [(n, c, f) for n, (c, f) in zip(by_position, chains)]
    return [(model.names[c[0]], c, f) for c, f in chains]


def from_model(
    model: Any, name: str | None = None, *, foot_frames: Iterable[str] | Mapping[str, str] | None = None
) -> Any:
    """Every leg of a Pinocchio model, measured at its neutral configuration: HAA-HFE-KFE legs (:class:`Leg`) and
    6-DOF legs (:class:`Leg6`).

    Args:
        model: a ``pinocchio.Model`` (fixed or floating base: geometry is in the root frame, i.e. the URDF root
            link, not the base's centre of mass).
        name: a leg name (the common prefix of its joint names, e.g. ``"FL"``, ``"lf"``, or its position name),
            its first joint's name or its foot frame's name: return that one leg (and check only it).
        foot_frames: the foot frames (names) to use instead of the name search; a mapping's values are used.

    Returns:
        ``{leg name: Leg or Leg6}`` in model order, or one leg when ``name`` is given.

    Raises:
        LegStructureError: no leg found (``found``: what hangs from the root, ``expected``: the supported
            structures), or a chain that is not a supported leg (the deviation named).
        InvalidParameterError: not a model, an unknown ``name`` or foot frame.
    """
    pin = _pin()
    if not isinstance(model, pin.Model):
        raise InvalidParameterError(f"model must be a pinocchio.Model, got {type(model).__name__}")
    if name is not None and not isinstance(name, str):
        raise InvalidParameterError(f"name must be a leg name (str) or None, got {name!r}")
    if isinstance(foot_frames, Mapping):
        foot_frames = list(foot_frames.values())
    root = _root(model)
    named = _named(model, find_chains(model, foot_frames))
    if name is not None:
        for leg_name, chain, foot in named:
            if name in (leg_name, model.names[chain[0]], foot):
                return _build(model, root, chain, foot, leg_name)
        raise InvalidParameterError(
            f"no leg {name!r} in the model; its legs: {[n for n, _, _ in named] or 'none'}"
        )
    if not named:
        found = _unsupported(model)
        raise LegStructureError(
            f"no leg found: no chain of 3 or 6 revolute joints from the root {model.names[root]!r} ends at a foot "
            f"frame (a frame named *sole*, *foot* or *toe*, or a leaf joint's link; or pass foot_frames). Found: "
            f"{'; '.join(found) or 'nothing'}. Supported: {'; '.join(EXPECTED)}",
            found=found, expected=list(EXPECTED),
        )
    return {leg_name: _build(model, root, chain, foot, leg_name) for leg_name, chain, foot in named}


def from_urdf(
    path: str | os.PathLike,
    name: str | None = None,
    *,
    foot_frames: Iterable[str] | Mapping[str, str] | None = None,
) -> Any:
    """:func:`from_model` of the URDF file at ``path`` (built with a fixed base: the root frame is the base link).

    Args:
        path: the URDF file.
        name: one leg to return, as :func:`from_model`'s ``name``.
        foot_frames: the foot frames to use, as :func:`from_model`'s.

    Returns:
        ``{leg name: Leg or Leg6}`` (positions in m, angles in rad, in the URDF root link's frame), or one leg.

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
