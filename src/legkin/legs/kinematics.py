"""Closed-form kinematics of an HAA-HFE-KFE leg measured from any URDF (issue 13).

The leg, in the model's root frame at the neutral configuration (every length measured, nothing assumed):

* ``o1, a1``: origin and unit axis of the abduction joint (HAA), ``o2, a2``: the hip pitch joint (HFE),
  ``o3, a3``: the knee (KFE), ``f``: the foot frame's origin. The structure: ``a1 . a2 = 0`` and
  ``a3 = s3 a2`` with ``s3 = +-1`` (parallel pitch axes, same or opposite sense).
* The abduction frame ``(e1, e2, e3) = (a1, a2, a1 x a2)`` (right-handed, orthonormal).
* The product of exponentials about the neutral configuration (exact for a chain of revolute joints)::

      p(q) = o1 + R(a1, q1) [ (o2 - o1) + R(a2, q2) ( (o3 - o2) + R(a3, q3) (f - o3) ) ]

  ``R(a2, .)`` and ``R(a3, .)`` leave the ``e2`` components unchanged, so the foot lies at the fixed
  **lateral offset** ``d = e2 . (f - o1)`` along the pitch axis. In the pitch-plane coordinates
  ``(X, Y) = (v . e3, v . e1)`` (``R(e2, t)`` is the plane rotation ``Rot(t)`` there) with the measured
  offsets ``h = (o2 - o1)``, ``k = (o3 - o2)`` (thigh), ``l = (f - o3)`` (shank)::

      (u3, u1) = h + Rot(q2) [ k + Rot(s3 q3) l ]                                   (pitch plane)
      p = o1 + u1 e1 + (cos q1 d - sin q1 u3) e2 + (sin q1 d + cos q1 u3) e3        (abduction)

  The HAA axis need not pass through the HFE origin (``h`` is any vector) and the thigh and shank may have
  any offset angles ``phi_k = atan2(k_Y, k_X)``, ``phi_l = atan2(l_Y, l_X)``.

Inverse kinematics, with ``p' = p - o1`` and ``(x1, y, z) = (p'.e1, p'.e2, p'.e3)``:

1. abduction: ``r^2 = y^2 + z^2``; ``u3 = s_a sqrt(r^2 - d^2)`` (abduction branch ``s_a = +-1``, out of reach
   if ``r < |d|``: inside the abduction cylinder), ``q1 = atan2(z, y) - atan2(u3, d)``;
2. knee: ``w = (u3, x1) - h``; ``cos(beta) = (|w|^2 - |k|^2 - |l|^2) / (2 |k| |l|)``, ``beta = s_k acos(.)``
   (knee branch ``s_k = +-1``, out of reach if ``|w| > |k| + |l|`` or ``|w| < | |k| - |l| |``);
   ``beta = s3 q3 + phi_l - phi_k`` so ``q3 = s3 (beta - phi_l + phi_k)``;
3. hip pitch: ``v = k + Rot(s3 q3) l``; ``q2 = atan2(w_Y, w_X) - atan2(v_Y, v_X)``.

The forward map and Jacobian kernels use the measured axes exactly (the product of exponentials above, as
Pinocchio); each closed-form branch is polished by at most :data:`POLISH_STEPS` damped Newton steps on it when
its foot error exceeds :data:`POLISH_BELOW` (axes a few 1e-12 rad off the ideal structure, the knee's fold).
Each angle is then moved by a multiple of 2 pi: in :meth:`Leg.ik_all` to the representative nearest the
reference configuration, in :meth:`Leg.ik` to the representative inside the URDF limits nearest ``q_near``.
:meth:`Leg.ik` is limits-first: the branches are pruned joint by joint (q1, q3, q2) by the limits and by their
partial distance to ``q_near`` before any polish, and only the winner is polished. On a leg whose axes are
exactly the ideal structure, a branch away from the singular sets (:data:`~._layout.WELL_CONDITIONED`) is exact
to rounding and returned unpolished (docs/legs.md gives the measurement).

Implementation (issue 16, :mod:`legkin._kernels`): each function is one compiled scalar kernel; a batch is a
compiled loop over it. Where the code is: :mod:`._fk_kernels` (forward map, Jacobian), :mod:`._ik_kernels`
(closed-form branches, the Newton polish, the branch inside the limits), :mod:`._layout` (tolerances, the layout of
:attr:`Leg.params`, status codes); this module holds :class:`Leg` and re-exports the constants. The leg's geometry
reaches the kernels as one float64 array (:attr:`Leg.params`).
Single/batch contract of :mod:`legkin._batch`: a single input (3,) returns a plain array and raises a legkin
error on failure; a batch (..., 3) returns NaN rows where an item fails (``return_mask=True`` adds the mask).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Literal, overload

import numpy as np
from numba.core import types as _nbtypes
from numpy.typing import ArrayLike

from .._batch import as_input, check_flag, check_number, finish, same_signature
from .._kernels import OK, as_rows
from ..errors import InvalidInputError, JointLimitError, UnreachableError
from ..errors import LegStructureError as _LegStructureError
from ._fk_kernels import _fk_batch, _fk_k, _jacobian_batch, _jacobian_k
from ._ik_kernels import _ik_all_batch, _ik_all_k, _ik_all_near_k, _ik_batch, _ik_k, _ik_near_k
from ._layout import (
    _A1,
    _A2,
    _A3,
    _ARC,
    _BAD_INPUT,
    _CD,
    _D,
    _E1,
    _E2,
    _E3,
    _H,
    _HI,
    _IDEAL,
    _IN_CYLINDER,
    _JOINT_LIMIT,
    _K,
    _KN,
    _L,
    _LN,
    _LO,
    _NARROW,
    _NPARAMS,
    _O,
    _PK,
    _PL,
    _REF,
    _S3,
    _SD,
    _SLACK,
    _TOO_FAR,
    _UNREACHABLE,
    _V3F,
    _V21,
    _V32,
    _WHOLE,
    _WIDE,
    ARC_SLACK,
    BRANCHES,
    IK_TOL,
    LIMIT_TOL,
    PARALLEL_TOL,
    PERPENDICULAR_TOL,
    REACH_TOL,
)
from ._layout import POLISH_BELOW as POLISH_BELOW  # public constants, re-exported (not in __all__)
from ._layout import POLISH_DAMPING as POLISH_DAMPING
from ._layout import POLISH_STEPS as POLISH_STEPS

__all__ = [
    "Leg",
    "LegStructureError",
    "BRANCHES",
    "PERPENDICULAR_TOL",
    "PARALLEL_TOL",
    "REACH_TOL",
    "IK_TOL",
    "LIMIT_TOL",
]


#: A kinematic chain that is not a supported leg (the message names the deviation): legkin.errors' class.
LegStructureError = _LegStructureError


_S3SHAPE = (3,)
_F64 = np.dtype(np.float64)


def _vector3(x: object) -> np.ndarray | None:
    """``x`` itself if it is a float64 array (3,) (a single call's reference, for the fast path), else None."""
    if x.__class__ is np.ndarray and x.shape == _S3SHAPE and x.dtype is _F64:  # type: ignore[attr-defined]
        return x  # type: ignore[return-value]
    return None


def _rows3(x: object) -> bool:
    """Whether ``x`` is a C-contiguous, aligned, writeable float64 array (n, 3), n >= 1 (a batch the kernels take as
    is; ``flags.carray``: the three flags at once)."""
    return (x.__class__ is np.ndarray and x.ndim == 2 and x.shape[1] == 3 and x.dtype is _F64  # type: ignore[attr-defined]
            and x.shape[0] > 0 and x.flags.carray)  # type: ignore[attr-defined]


#: The status and info arguments of a batch loop whose caller needs neither (no row: the loop records nothing).
_NO_STATUS = np.empty(0, dtype=np.int64)
_NO_INFO = np.empty((0, 2))


class _Entry:
    """A kernel's compiled entry point for one signature, called without numba's dispatcher: the single calls'
    fast paths (numba's dispatcher resolves the argument types on each call: ~120 ns of a ~300 ns kernel call).

    Compiled (or loaded from numba's cache) on the first call. The signature reads the caller's arrays with any
    strides (layout ``"A"``): a float64 array of the right shape is all a fast path checks. Under
    ``NUMBA_DISABLE_JIT`` the kernel itself is called."""

    __slots__ = ("call", "_kernel", "_sig")

    def __init__(self, kernel: Any, *sig: Any) -> None:
        self._kernel, self._sig = kernel, sig
        self.call: Any = self._first

    def _first(self, *args: Any) -> int:
        compile_ = getattr(self._kernel, "compile", None)
        self.call = self._kernel if compile_ is None else compile_(self._sig)
        return self.call(*args)  # type: ignore[no-any-return]


_ANY1, _C1 = _nbtypes.Array(_nbtypes.float64, 1, "A"), _nbtypes.Array(_nbtypes.float64, 1, "C")
_C2 = _nbtypes.Array(_nbtypes.float64, 2, "C")
#: The single calls' entries: ``(q or p, params, [ref (the _NEAR ones),] [flip,] out)``.
_FK = _Entry(_fk_k, _ANY1, _C1, _C1)
_JACOBIAN = _Entry(_jacobian_k, _ANY1, _C1, _C2)
_IK = _Entry(_ik_k, _ANY1, _C1, _C1)
_IK_NEAR = _Entry(_ik_near_k, _ANY1, _C1, _ANY1, _C1)
_IK_ALL = _Entry(_ik_all_k, _ANY1, _C1, _nbtypes.int64, _C2)
_IK_ALL_NEAR = _Entry(_ik_all_near_k, _ANY1, _C1, _ANY1, _nbtypes.int64, _C2)
#: The batch IK loop on (n, 3) rows with one reference row (a batch below ``_ik_batch.min_parallel`` rows).
_IK_ROWS = _Entry(_ik_batch.kernel, _C2, _C1, _C2, _nbtypes.float64, _C2, _nbtypes.Array(_nbtypes.int64, 1, "C"),
                  _C2)


# ---------------------------------------------------------------- geometry helpers (Python)
def _limit_arc(lo: float, hi: float) -> tuple[float, float, float, float, float]:
    """The HAA limits ``[lo, hi]`` (rad) widened by :data:`ARC_SLACK` as an arc of the circle (see :data:`_ARC`):
    ``(cos a, sin a, cos b, sin b, kind)``."""
    a, b = lo - ARC_SLACK, hi + ARC_SLACK
    if not (math.isfinite(a) and math.isfinite(b)) or b - a >= 2.0 * math.pi:
        return 1.0, 0.0, 1.0, 0.0, _WHOLE
    return math.cos(a), math.sin(a), math.cos(b), math.sin(b), (_NARROW if b - a < math.pi else _WIDE)


def _never() -> Exception:  # pragma: no cover - a batch call never raises
    raise AssertionError("finish() asked a batch call for its error")


def _unit(v: np.ndarray, what: str) -> np.ndarray:
    n = float(np.linalg.norm(v))
    if not n > 1e-12 or not math.isfinite(n):
        raise LegStructureError(f"{what} has no direction (norm {n:g})")
    return np.asarray(v, dtype=float) / n


def _signed_angle(u: np.ndarray, v: np.ndarray, n: np.ndarray) -> float:
    """Angle (rad) from ``u`` to ``v`` about the unit axis ``n``."""
    return math.atan2(float(n @ np.cross(u, v)), float(u @ v))


def _axis_label(a: np.ndarray) -> str:
    """``"+x"``, ``"-y"``, ... for an axis along a root axis (to 1e-9), else the rounded vector."""
    i = int(np.argmax(np.abs(a)))
    if abs(abs(a[i]) - 1.0) <= 1e-9:
        return f"{'+' if a[i] > 0 else '-'}{'xyz'[i]}"
    return "(" + ", ".join(f"{c:+.4f}" for c in a) + ")"


def _frozen(a) -> np.ndarray:
    arr = np.array(a, dtype=float)
    arr.flags.writeable = False
    return arr


# ---------------------------------------------------------------- the leg
@dataclass(frozen=True, eq=False)
class Leg:
    """One HAA-HFE-KFE leg, measured in the model's root frame at the neutral configuration.

    Build one with :func:`legkin.legs.from_model` / :func:`legkin.legs.from_urdf` (or :meth:`from_geometry`).

    Attributes:
        name: the leg's name (the common prefix of its joint names, e.g. ``"FL"``, ``"lf"``).
        joint_names: its three joints in model order (HAA, HFE, KFE).
        foot_frame: the frame whose origin is the foot.
        lower, upper: the URDF limits (rad) of the three joints.
        origin: HAA origin ``o1`` (m, root frame).
        axes: (3, 3) rows: the unit joint axes ``a1, a2, a3`` at the neutral configuration (root frame).
        hfe_origin, kfe_origin, foot_origin: ``o2``, ``o3`` and the foot ``f`` at the neutral configuration.
        frame: (3, 3) rows ``e1, e2, e3``: the abduction frame ``(a1, a2, a1 x a2)``.
        lateral_offset: ``d = e2 . (f - o1)`` (m), the foot's fixed offset along the pitch axis.
        hip_offset, thigh, shank: ``h = o2 - o1``, ``k = o3 - o2``, ``l = f - o3`` in pitch-plane coordinates
            ``(X, Y) = (v . e3, v . e1)`` (m).
        knee_sign: ``s3``, +1 if the KFE axis has the HFE axis's sense, -1 if opposite.
        q_ref: the default reference of :meth:`ik` / :meth:`ik_all` (mid-limit; 0 where a limit is infinite).
        idx_q, idx_v: the joints' indices in the source model's configuration / velocity vectors (-1 if none).
        params: the float64 geometry array the kernels read.
    """

    name: str
    joint_names: tuple[str, str, str]
    foot_frame: str
    lower: np.ndarray
    upper: np.ndarray
    origin: np.ndarray
    axes: np.ndarray
    hfe_origin: np.ndarray
    kfe_origin: np.ndarray
    foot_origin: np.ndarray
    frame: np.ndarray
    lateral_offset: float
    hip_offset: np.ndarray
    thigh: np.ndarray
    shank: np.ndarray
    knee_sign: float
    q_ref: np.ndarray
    idx_q: tuple[int, int, int] = (-1, -1, -1)
    idx_v: tuple[int, int, int] = (-1, -1, -1)
    params: np.ndarray = field(default=None, repr=False)  # type: ignore[arg-type]  # always set by from_geometry
    _ref: np.ndarray = field(init=False, repr=False)  # q_ref, writeable: the kernels' one type of reference array
    _ref1: np.ndarray = field(init=False, repr=False)  # the same, one row (1, 3)
    #: params, writeable: what the kernels read. numba types a read-only array apart, and its dispatcher converts
    #: one by its slow path: ~50 ns more a call (a third of a single fk's kernel call).
    _g: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_ref", np.array(self.q_ref, dtype=float).reshape(3))
        object.__setattr__(self, "_ref1", self._ref.reshape(1, 3))
        object.__setattr__(self, "_g", np.array(self.params, dtype=float))

    #: The leg's structure (see :data:`legkin.legs.extract.EXPECTED`) and its number of joints.
    structure = "HAA-HFE-KFE"
    dof = 3

    # ------------------------------------------------------------ construction
    @classmethod
    def from_geometry(
        cls,
        name: str,
        joint_names: tuple[str, str, str],
        foot_frame: str,
        origins,
        axes,
        foot,
        lower,
        upper,
        *,
        idx_q: tuple[int, int, int] = (-1, -1, -1),
        idx_v: tuple[int, int, int] = (-1, -1, -1),
    ) -> Leg:
        """A leg from its joint origins (3, 3), unit axes (3, 3) and foot (3,) at the neutral configuration.

        Checks the structure: ``|a1 . a2| <= PERPENDICULAR_TOL`` (the HAA axis perpendicular to the HFE axis),
        ``|a2 x a3| <= PARALLEL_TOL`` (parallel pitch axes), nonzero thigh ``k`` and shank ``l`` in the pitch
        plane. Then ``e2 = a2``, ``e1`` = ``a1`` made exactly orthogonal to ``e2``, ``e3 = e1 x e2``,
        ``s3 = sign(a2 . a3)``, ``d = e2 . (f - o1)``, and ``h, k, l`` as pitch-plane coordinates.

        Raises:
            LegStructureError: the deviation, named (e.g. "HFE axis is 0.3 deg off parallel to KFE axis").
        """
        o = np.asarray(origins, dtype=float).reshape(3, 3)
        ax = np.asarray(axes, dtype=float).reshape(3, 3)
        f = np.asarray(foot, dtype=float).reshape(3)
        j1, j2, j3 = joint_names
        if not (np.isfinite(o).all() and np.isfinite(ax).all() and np.isfinite(f).all()):
            raise LegStructureError(f"leg {name}: non-finite joint origins, axes or foot position")
        a1 = _unit(ax[0], f"leg {name}: HAA axis ({j1})")
        a2 = _unit(ax[1], f"leg {name}: HFE axis ({j2})")
        a3 = _unit(ax[2], f"leg {name}: KFE axis ({j3})")
        dot12 = float(a1 @ a2)
        if abs(dot12) > PERPENDICULAR_TOL:
            off = math.degrees(math.asin(min(1.0, abs(dot12))))
            raise LegStructureError(
                f"leg {name}: HAA axis ({j1}, {a1.round(6).tolist()}) is {off:.3g} deg off perpendicular to the "
                f"HFE axis ({j2}, {a2.round(6).tolist()}); an HAA-HFE-KFE leg needs |a1 . a2| <= {PERPENDICULAR_TOL:g}"
            )
        cross23 = float(np.linalg.norm(np.cross(a2, a3)))
        if cross23 > PARALLEL_TOL:
            off = math.degrees(math.atan2(cross23, abs(float(a2 @ a3))))
            raise LegStructureError(
                f"leg {name}: HFE axis ({j2}, {a2.round(6).tolist()}) is {off:.3g} deg off parallel to the KFE axis "
                f"({j3}, {a3.round(6).tolist()}); an HAA-HFE-KFE leg needs |a2 x a3| <= {PARALLEL_TOL:g}"
            )
        e2 = a2
        e1 = _unit(a1 - (a1 @ e2) * e2, f"leg {name}: HAA axis")
        e3 = np.cross(e1, e2)
        s3 = 1.0 if float(a2 @ a3) > 0 else -1.0

        def plane(v):
            return np.array([float(v @ e3), float(v @ e1)])

        h, k, l = plane(o[1] - o[0]), plane(o[2] - o[1]), plane(f - o[2])
        kn, ln = float(np.hypot(*k)), float(np.hypot(*l))
        if kn <= 1e-9:
            raise LegStructureError(
                f"leg {name}: the KFE axis ({j3}) passes through the HFE axis ({j2}): thigh length {kn:.3g} m"
            )
        if ln <= 1e-9:
            raise LegStructureError(
                f"leg {name}: the foot ({foot_frame}) lies on the KFE axis ({j3}): shank length {ln:.3g} m"
            )
        d = float(e2 @ (f - o[0]))
        lo = np.asarray(lower, dtype=float).reshape(3)
        hi = np.asarray(upper, dtype=float).reshape(3)
        if np.any(np.isnan(lo)) or np.any(np.isnan(hi)) or np.any(lo > hi):
            raise LegStructureError(f"leg {name}: bad joint limits lower={lo.tolist()}, upper={hi.tolist()}")
        finite = np.isfinite(lo) & np.isfinite(hi)
        mid = np.where(finite, 0.5 * (np.where(finite, lo, 0.0) + np.where(finite, hi, 0.0)), np.clip(0.0, lo, hi))
        g = np.zeros(_NPARAMS)
        g[_O:_O + 3], g[_E1:_E1 + 3], g[_E2:_E2 + 3], g[_E3:_E3 + 3] = o[0], e1, e2, e3
        g[_D] = d
        g[_H:_H + 2], g[_K:_K + 2], g[_L:_L + 2] = h, k, l
        g[_S3] = s3
        g[_KN], g[_LN] = kn, ln
        g[_PK], g[_PL] = math.atan2(k[1], k[0]), math.atan2(l[1], l[0])
        g[_LO:_LO + 3], g[_HI:_HI + 3] = lo, hi
        g[_A1:_A1 + 3], g[_A2:_A2 + 3], g[_A3:_A3 + 3] = a1, a2, a3
        g[_V21:_V21 + 3], g[_V32:_V32 + 3], g[_V3F:_V3F + 3] = o[1] - o[0], o[2] - o[1], f - o[2]
        # The ideal structure (e1 perpendicular to e2 = +-a3) differs from the measured one by at most the axis
        # deviations (rad) times the lever arms: its reach boundaries get that much slack (then exact check).
        lever = float(np.linalg.norm(o[1] - o[0]) + np.linalg.norm(o[2] - o[1]) + np.linalg.norm(f - o[2]))
        g[_SLACK] = REACH_TOL + 4.0 * (abs(dot12) + cross23 + 1e-15) * lever
        g[_IDEAL] = 1.0 if dot12 == 0.0 and cross23 == 0.0 else 0.0
        g[_CD], g[_SD] = math.cos(g[_PK] - g[_PL]), math.sin(g[_PK] - g[_PL])
        g[_ARC:_ARC + 5] = _limit_arc(float(lo[0]), float(hi[0]))
        g[_REF:_REF + 3] = mid
        return cls(
            name=str(name), joint_names=(str(j1), str(j2), str(j3)), foot_frame=str(foot_frame),
            lower=_frozen(lo), upper=_frozen(hi), origin=_frozen(o[0]), axes=_frozen(np.stack([a1, a2, a3])),
            hfe_origin=_frozen(o[1]), kfe_origin=_frozen(o[2]), foot_origin=_frozen(f),
            frame=_frozen(np.stack([e1, e2, e3])), lateral_offset=d, hip_offset=_frozen(h), thigh=_frozen(k),
            shank=_frozen(l), knee_sign=s3, q_ref=_frozen(mid), idx_q=(int(idx_q[0]), int(idx_q[1]), int(idx_q[2])),
            idx_v=(int(idx_v[0]), int(idx_v[1]), int(idx_v[2])), params=_frozen(g),
        )

    # ------------------------------------------------------------ derived numbers
    @property
    def thigh_length(self) -> float:
        """``|k|`` (m): HFE axis to KFE axis in the pitch plane."""
        return float(self.params[_KN])

    @property
    def shank_length(self) -> float:
        """``|l|`` (m): KFE axis to the foot in the pitch plane."""
        return float(self.params[_LN])

    @property
    def axis_labels(self) -> tuple[str, str, str]:
        """The joint axes in the root frame as ``"+x"``, ``"-y"``, ... (a vector when not along a root axis)."""
        return tuple(_axis_label(a) for a in self.axes)  # type: ignore[return-value]

    @property
    def knee_offset_angles(self) -> tuple[float, float]:
        """``(thigh_zero, knee_zero)`` (rad): the angle about ``a2`` from the root's down direction (-z, projected
        on the pitch plane) to the thigh ``k`` at q2 = 0, and the angle about ``a3`` from the thigh ``k`` to the
        shank ``l`` at q3 = 0 (0 for a straight leg; the zero offset of the knee)."""
        e1, e2, e3 = self.frame
        k = self.thigh[0] * e3 + self.thigh[1] * e1
        l = self.shank[0] * e3 + self.shank[1] * e1
        down = np.array([0.0, 0.0, -1.0])
        down = down - (down @ e2) * e2
        thigh_zero = _signed_angle(down, k, e2) if np.linalg.norm(down) > 1e-9 else float("nan")
        return thigh_zero, _signed_angle(k, l, self.axes[2])

    @property
    def axis_deviation(self) -> tuple[float, float]:
        """``(|a1 . a2|, |a2 x a3|)``: how far (rad) the measured axes are from perpendicular / parallel."""
        a1, a2, a3 = self.axes
        return abs(float(a1 @ a2)), float(np.linalg.norm(np.cross(a2, a3)))

    @property
    def reach(self) -> tuple[float, float]:
        """``(| |k| - |l| |, |k| + |l|)``: the knee's inner and outer reach (m) in the pitch plane."""
        return abs(self.thigh_length - self.shank_length), self.thigh_length + self.shank_length

    def summary(self) -> dict[str, Any]:
        """The extracted geometry as plain numbers (for tables).

        Returns:
            The leg's name, joints, foot frame, axis labels, knee sign and its link vectors (m) and offset angles
            (rad), as JSON-friendly values.
        """
        tz, kz = self.knee_offset_angles
        return {
            "leg": self.name, "joints": list(self.joint_names), "foot": self.foot_frame,
            "axes": list(self.axis_labels), "knee_sign": self.knee_sign,
            "haa_origin": self.origin.tolist(), "lateral_offset": self.lateral_offset,
            "hip_offset": self.hip_offset.tolist(), "thigh": self.thigh.tolist(), "shank": self.shank.tolist(),
            "thigh_length": self.thigh_length, "shank_length": self.shank_length,
            "thigh_zero_deg": math.degrees(tz), "knee_zero_deg": math.degrees(kz),
            "lower": self.lower.tolist(), "upper": self.upper.tolist(),
        }

    def __repr__(self) -> str:
        return (
            f"Leg({self.name!r}, joints={self.joint_names}, foot={self.foot_frame!r}, axes={self.axis_labels}, "
            f"d={self.lateral_offset:.4f} m, thigh={self.thigh_length:.4f} m, shank={self.shank_length:.4f} m)"
        )

    # ------------------------------------------------------------ kinematics
    def fk(self, q: ArrayLike) -> np.ndarray:
        """Foot position (m, root frame) of joint values.

        ``p = o1 + u1 e1 + (cos q1 d - sin q1 u3) e2 + (sin q1 d + cos q1 u3) e3`` with
        ``(u3, u1) = h + Rot(q2) [k + Rot(s3 q3) l]`` (see the module docstring).

        Args:
            q: joint values (3,) or (..., 3) (rad).

        Returns:
            The foot position (3,) or (..., 3) (m, root frame).

        Raises:
            InvalidInputError: ``q`` not a finite real array (..., 3).
        """
        if q.__class__ is np.ndarray and q.shape == _S3SHAPE and q.dtype is _F64:  # a single call, fast
            out = np.empty(3)
            if _FK.call(q, self._g, out) == OK:
                return out
        arr = as_input(q, "q", _S3SHAPE)
        if arr.ndim == 1:
            out = np.empty(3)
            _FK.call(arr, self._g, out)
            return out
        rows = as_rows(arr, 3)
        out = np.empty_like(rows)
        _fk_batch(rows, self._g, out)
        return out.reshape(arr.shape)

    def jacobian(self, q: ArrayLike) -> np.ndarray:
        """``dp/dq`` (3, 3) or (..., 3, 3): column j is the foot velocity (root frame) per unit rate of joint j.

        ``dp/dq1 = e1 x (p - o1)``; with ``perp(X, Y) = (-Y, X)`` and the pitch-plane vectors
        ``w = Rot(q2) v``, ``g = Rot(q2) s3 perp(Rot(s3 q3) l)``: ``d(u3, u1)/dq2 = perp(w)``,
        ``d(u3, u1)/dq3 = g``, each mapped to the root frame by ``(X, Y) -> Y e1 - sin q1 X e2 + cos q1 X e3``.
        Equal to Pinocchio's LOCAL_WORLD_ALIGNED translational rows of the leg's columns (fixed base).

        Args:
            q: joint values (3,) or (..., 3) (rad).

        Returns:
            ``dp/dq`` (3, 3) or (..., 3, 3) (m/rad).

        Raises:
            InvalidInputError: ``q`` not a finite real array (..., 3).
        """
        if q.__class__ is np.ndarray and q.shape == _S3SHAPE and q.dtype is _F64:  # a single call, fast
            out = np.empty((3, 3))
            if _JACOBIAN.call(q, self._g, out) == OK:
                return out
        arr = as_input(q, "q", _S3SHAPE)
        if arr.ndim == 1:
            out = np.empty((3, 3))
            _JACOBIAN.call(arr, self._g, out)
            return out
        rows = as_rows(arr, 3)
        out = np.empty((rows.shape[0], 3, 3))
        _jacobian_batch(rows, self._g, out)
        return out.reshape(arr.shape + (3,))

    def _prepare(self, p, q_near, tol):
        """Checked target rows and reference rows (m = 1 or n), the batch shape and whether it is a single call."""
        arr = as_input(p, "p", _S3SHAPE)
        if q_near is None:
            ref = self._ref1
            batch = arr.shape[:-1]
        else:
            r = as_input(q_near, "q_near", _S3SHAPE)
            try:
                batch = np.broadcast_shapes(arr.shape[:-1], r.shape[:-1])
            except ValueError:
                raise InvalidInputError(
                    f"p (shape {arr.shape}) and q_near (shape {r.shape}) do not broadcast together; expected "
                    f"q_near of shape (3,) or the shape of p"
                ) from None
            if r.ndim == 1:
                ref = np.ascontiguousarray(r.reshape(1, 3))
            else:
                ref = as_rows(np.broadcast_to(r, batch + _S3SHAPE), 3)
            if arr.shape[:-1] != batch:
                arr = np.broadcast_to(arr, batch + _S3SHAPE)
        return as_rows(arr, 3), ref, batch, len(batch) == 0, check_number(tol, "tol", 0.0, 1e-3, low_open=True)

    def _error(self, status: int, info: np.ndarray, p: np.ndarray, tol: float = IK_TOL):
        tgt = [float(x) for x in p]
        if status == _UNREACHABLE:
            miss, why = float(info[0]), info[1]
            lo, hi = self.reach
            if why == _IN_CYLINDER:
                text = (f"it lies {miss:.6g} m inside the abduction cylinder "
                        f"(radius |d| = {abs(self.lateral_offset):.6g} m about the HAA axis)")
            elif why == _TOO_FAR:
                text = f"it lies {miss:.6g} m beyond the leg's full stretch (|k| + |l| = {hi:.6g} m in the pitch plane)"
            else:
                text = f"it lies {miss:.6g} m inside the knee's inner reach (| |k| - |l| | = {lo:.6g} m)"
            return UnreachableError(f"target {tgt} is out of reach of leg {self.name} by {miss:.6g} m: {text}",
                                    target=p, distance=miss)
        if status == _JOINT_LIMIT:
            branches = self.ik_all(p, tol=tol)
            j, value, closest, by = self._least_violation(branches)
            return JointLimitError(
                f"target {tgt} of leg {self.name} is reachable only outside the joint limits "
                f"[{self.lower.tolist()}, {self.upper.tolist()}] (by {by:.6g} rad at least: joint "
                f"{self.joint_names[j]} = {value:.6g} rad in the closest branch); "
                f"branches {np.round(branches, 6).tolist()}",
                target=p, closest=closest, distance=by, joint=self.joint_names[j], value=value,
                lower=float(self.lower[j]), upper=float(self.upper[j]),
            )
        return InvalidInputError(f"p must be finite, got {tgt}")  # pragma: no cover - as_input caught it

    def _single_error(self, batch_loop, width: tuple[int, ...], p: np.ndarray, ref: np.ndarray) -> Exception:
        """The error of a failed single call (default ``tol``): the batch loop run on its one row gives its data."""
        rows = np.array(p, dtype=float).reshape(1, 3)
        status = np.empty(1, dtype=np.int64)
        info = np.zeros((1, 2))
        ref1 = np.array(ref, dtype=float).reshape(1, 3)
        batch_loop(rows, self._g, ref1, IK_TOL, np.empty((1,) + width), status, info)
        return self._error(int(status[0]), info[0], rows[0])

    def _least_violation(self, branches: np.ndarray) -> tuple[int, float, np.ndarray, float]:
        """The branch least outside the limits (each angle's 2 pi representative nearest them): the index of its
        joint farthest outside, that joint's value (rad), the branch and by how much that joint is outside (rad)
        (error path only)."""
        best: tuple[float, int, float, np.ndarray] = (math.inf, 0, math.nan, branches[0])
        mid = 0.5 * (np.clip(self.lower, -1e9, 1e9) + np.clip(self.upper, -1e9, 1e9))
        for q in branches[np.isfinite(branches[:, 0])]:
            x = q + 2.0 * math.pi * np.round((mid - q) / (2.0 * math.pi))
            out_by = np.maximum(np.maximum(self.lower - x, x - self.upper), 0.0)
            j = int(np.argmax(out_by))
            if out_by[j] < best[0]:
                best = (float(out_by[j]), j, float(x[j]), x)
        return best[1], best[2], best[3], best[0]

    @overload
    def ik_all(self, target: ArrayLike, *, q_near: ArrayLike | None = ..., tol: float = ...,
               return_mask: Literal[False] = ...) -> np.ndarray: ...

    @overload
    def ik_all(self, target: ArrayLike, *, q_near: ArrayLike | None = ..., tol: float = ...,
               return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...

    @overload
    def ik_all(self, target: ArrayLike, *, q_near: ArrayLike | None = ..., tol: float = ...,
               return_mask: bool = ...) -> np.ndarray | tuple[np.ndarray, np.ndarray]: ...

    def ik_all(self, target: ArrayLike, *, q_near: ArrayLike | None = None, tol: float = IK_TOL,
               return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
        """Every IK branch of the target(s) ``target`` (m, root frame), joint limits ignored.

        Branches in :data:`BRANCHES` order ``(s_a, s_k)``: ``u3 = s_a sqrt(y^2 + z^2 - d^2)`` (abduction) and
        ``beta = s_k acos((|w|^2 - |k|^2 - |l|^2) / (2 |k||l|))`` (knee); each angle is the 2 pi representative
        nearest ``q_near`` (default :attr:`q_ref`, the mid-limit configuration). Coincident branches (on the
        singular sets ``u3 = 0`` or ``beta in {0, pi}``) appear twice.

        Args:
            target: targets (3,) or (..., 3).
            q_near: reference joint values (3,) or broadcastable with ``target``.
            tol: a target up to ``tol`` (m; (0, 1e-3], default :data:`IK_TOL` = 1e-7) outside the reachable set
                is solved at its nearest reachable point (a float32-rounded target, say); farther out it is not.
            return_mask: also return the boolean mask of the branches that exist (legkin 0.2.0 convention).

        Returns:
            ``q_all`` (4, 3) or (..., 4, 3) (rad) with NaN rows for absent branches; with ``return_mask=True``
            ``(q_all, mask)``, the mask (4,) or (..., 4).

        Raises:
            UnreachableError: a single target with no branch (the message says by how much it misses).
            InvalidInputError: ``target`` or ``q_near`` not finite real arrays (..., 3), or not broadcastable.
            InvalidParameterError: ``return_mask`` not a bool.
        """
        p: Any = target  # the fast paths below test its class, shape and dtype first
        if return_mask is not False and return_mask is not True:
            return_mask = check_flag(return_mask, "return_mask")
        if tol is IK_TOL and p.__class__ is np.ndarray and p.shape == _S3SHAPE and p.dtype is _F64:  # fast path
            ref = self._ref if q_near is None else _vector3(q_near)
            if ref is not None:
                out = np.empty((4, 3))
                st = (_IK_ALL.call(p, self._g, 0, out) if q_near is None
                      else _IK_ALL_NEAR.call(p, self._g, ref, 0, out))
                if st == OK:
                    return (out, np.isfinite(out[:, 0])) if return_mask else out
                if st != _BAD_INPUT:
                    raise self._single_error(_ik_all_batch, (4, 3), p, ref)
        rows, ref, batch, single, tol = self._prepare(p, q_near, tol)
        n = rows.shape[0]
        out = np.empty((n, 4, 3))
        status = np.empty(n, dtype=np.int64)
        info = np.zeros((n, 2))
        _ik_all_batch(rows, self._g, ref, tol, out, status, info)
        if single and status[0] != OK:
            raise self._error(int(status[0]), info[0], rows[0], tol)
        q_all = out.reshape(batch + (4, 3))
        if not return_mask:
            return q_all
        return q_all, np.isfinite(q_all[..., 0])

    @same_signature(ik_all)
    def ik(self, target: ArrayLike, *, q_near: ArrayLike | None = None, tol: float = IK_TOL,
           return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
        """Joint values placing the foot at ``target``: the branch inside the URDF limits nearest ``q_near``.

        For each branch of :meth:`ik_all`, each joint takes its 2 pi representative inside ``[lower, upper]``
        nearest ``q_near``; among the branches inside the limits the one with the least ``|q - q_near|^2`` wins
        (ties: the earlier branch). A branch up to ``LIMIT_SLACK`` (1e-7 rad) outside the limits (rounding at a
        limit, or the abduction singularity, where q1 errs along the singular direction) is moved onto them and
        its other joints re-solved, kept if it reaches ``target`` within :data:`REACH_TOL`; failing that, a branch up
        to :data:`LIMIT_TOL` outside is kept clipped onto the limit (foot within ``LIMIT_TOL`` x the reach).

        Args:
            target: targets (3,) or (..., 3), m, root frame.
            q_near: reference (3,) or broadcastable with ``target``; default :attr:`q_ref` (mid-limit).
            tol: a target up to ``tol`` (m; (0, 1e-3], default :data:`IK_TOL`) outside the reachable set is solved
                at its nearest reachable point (:meth:`ik_all`).
            return_mask: also return the boolean mask of the solved targets.

        Returns:
            ``q`` (3,) or (..., 3) (NaN rows for unsolved batch items), and the mask if asked.

        Raises:
            UnreachableError: a single target out of reach (the message says by how much, and why).
            JointLimitError: a single target reachable only outside the joint limits.
            InvalidInputError: ``target`` / ``q_near`` not finite real arrays (..., 3), or not broadcastable.
            InvalidParameterError: ``return_mask`` not a bool.
        """
        p: Any = target  # the fast paths below test its class, shape and dtype first
        if return_mask is not False and return_mask is not True:
            return_mask = check_flag(return_mask, "return_mask")
        if tol is IK_TOL and p.__class__ is np.ndarray and p.shape == _S3SHAPE and p.dtype is _F64:  # fast path
            ref = self._ref if q_near is None else _vector3(q_near)
            if ref is not None:
                out = np.empty(3)
                st = _IK.call(p, self._g, out) if q_near is None else _IK_NEAR.call(p, self._g, ref, out)
                if st == OK:
                    return (out, np.array(True)) if return_mask else out
                if st != _BAD_INPUT:
                    raise self._single_error(_ik_batch, (3,), p, ref)
        if q_near is None and tol is IK_TOL and _rows3(p):  # a batch (n, 3) the kernels read as is: no copy
            out = np.empty(p.shape)
            loop = _IK_ROWS.call if p.shape[0] < _ik_batch.min_parallel else _ik_batch
            if not loop(p, self._g, self._ref1, IK_TOL, out, _NO_STATUS, _NO_INFO):
                return (out, np.ones(p.shape[0], dtype=bool)) if return_mask else out
            if np.isfinite(p).all():  # NaN rows for the targets that failed (else as_input raises)
                return (out, np.isfinite(out[:, 0])) if return_mask else out
        rows, ref, batch, single, tol = self._prepare(p, q_near, tol)
        n = rows.shape[0]
        out = np.empty((n, 3))
        status = np.empty(n, dtype=np.int64)
        info = np.zeros((n, 2))
        _ik_batch(rows, self._g, ref, tol, out, status, info)
        ok = status == OK
        if single:
            return finish(out[0], ok[0], True, return_mask, lambda: self._error(int(status[0]), info[0], rows[0], tol))
        return finish(out.reshape(batch + (3,)), ok.reshape(batch), False, return_mask, _never)

    def within_limits(self, q: ArrayLike, tol: float = 0.0) -> np.ndarray | bool:
        """Whether joint values lie inside the URDF limits.

        Args:
            q: joint values (3,) or (..., 3) (rad; m for a prismatic joint).
            tol: how far outside a limit still counts as inside (rad or m).

        Returns:
            A bool for a single ``q``, else the mask (...,).
        """
        arr = as_input(q, "q", _S3SHAPE)
        inside = np.all((arr >= self.lower - tol) & (arr <= self.upper + tol), axis=-1)
        return bool(inside) if arr.ndim == 1 else inside
