"""Exact kinematics of a 6-DOF leg (a humanoid's) measured from any URDF (issue 26).

The leg, in the model's root frame (the URDF root link) at the neutral configuration: six revolute joints with
unit axes ``a_1 .. a_6`` through points ``o_1 .. o_6`` (the joint origins) and the foot frame's pose ``M_0``. The
forward map is the product of exponentials (what Pinocchio computes, with the measured axes)::

    T(q) = E_1(q_1) E_2(q_2) ... E_6(q_6) M_0,      E_j(t) = (R(a_j, t), o_j - R(a_j, t) o_j)

**Structure** (:attr:`Leg6.structure`, classified from the measured axes with :data:`AXIS_TOL`):

* ``"6R-spherical-hip"``: axes 1-3 meet at the hip centre ``c`` and axes 5, 6 at the ankle centre ``a`` (talos,
  romeo, icub, simple_humanoid). Every solution in closed form, by subproblems (:mod:`.subproblems`): with
  ``G = T M_0^-1`` and ``d = G^-1 c`` the knee and ankle satisfy ``E_4 E_5 E_6 d = c``, so

  1. SP3: ``|E_4^-1 c - a| = |d - a|`` (the knee, 2 solutions);
  2. SP2: ``R(a_5, -q_5) (E_4^-1 c - a) = R(a_6, q_6) (d - a)`` (the ankle, 2);
  3. SP2 then SP1 on the hip rotation ``R_h = R_G R_6^T R_5^T R_4^T``: ``R(a_1, -q_1) R_h a_3 = R(a_2, q_2) a_3``
     (2), ``R(a_3, q_3) v = R_2^T R_1^T R_h v`` for ``v`` normal to ``a_3``.

  Up to 8 solutions (:attr:`Leg6.n_solutions` rows of :meth:`Leg6.ik_all`, in the order knee, ankle, hip
  branch). Where URDF rounding leaves the axes up to :data:`AXIS_TOL` off meeting (icub's ``rpy="... 1.5708"``:
  2e-6 m), the closed form lands that close and damped Newton steps on the exact forward map finish it.
* ``"6R-three-parallel"`` (alexander: joints 3-5 parallel) and ``"6R-offset-hip"`` (g1: axes 2, 3 meet, 4 and 5
  parallel, the hip pitch axis 1 off them): every solution by a one-dimensional search (:mod:`._search_kernels`),
  up to 16 rows.
* ``"6R-general"``: any other 6R chain: ``fk`` and ``jacobian`` only; :meth:`Leg6.ik` raises
  :class:`~legkin.errors.LegStructureError`.

Every answer is checked on the forward map (polished by Newton steps where it misses 1e-13) and kept only if it
reproduces the target to ``tol`` (default :data:`IK_TOL` = 1e-7:
position error <= ``tol`` m and rotation error <= ``tol`` rad, above what float32 rounding does to a pose, see
``legs.kinematics.IK_TOL``; pass ``tol=1e-9`` for a tighter check); a target within ``tol`` of the
reachable set is solved at its nearest reachable pose (the polish's least-squares limit). Single/batch contract
of :mod:`legkin._batch`; kernels in :mod:`._sixdof_kernels`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .. import _batch
from .._batch import as_input, check_flag, check_number, finish, in_chunks
from .._kernels import OK, as_rows
from ..errors import InvalidInputError, JointLimitError, LegStructureError, UnreachableError
from ._ik6_kernels import _ik6_batch, _ik6_one, _ik_all6_batch, _ik_all6_one
from ._sixdof_kernels import _fk6_batch, _fk6_k, _jacobian6_batch, _jacobian6_k
from ._sixdof_layout import (
    _ANK,
    _AX,
    _BAD_INPUT,
    _GRID,
    _HI6,
    _HIP,
    _JOINT_LIMIT,
    _KIND,
    _LO6,
    _M0,
    _NP6,
    _NSOL,
    _NSOL_SEARCH,
    _NSOLS,
    _OR,
    _QREF,
    AXIS_TOL,
    HIP_SPHERICAL,
    IK_TOL,
    OFFSET_HIP,
    SEARCH_GRID,
    THREE_PARALLEL,
)

__all__ = ["Leg6", "AXIS_TOL", "IK_TOL", "STRUCTURES", "nearest_point"]

#: The structures a 6-DOF leg is classified into (all but the last have an IK: a closed form, then two
#: one-dimensional searches).
STRUCTURES = ("6R-spherical-hip", "6R-three-parallel", "6R-offset-hip", "6R-general")
_KINDS = dict(zip(STRUCTURES, (HIP_SPHERICAL, THREE_PARALLEL, OFFSET_HIP, 0.0)))
_ROWS = dict(zip(STRUCTURES, (_NSOL, _NSOL_SEARCH, _NSOL_SEARCH, 0)))
_Q6 = (6,)
_T44 = (4, 4)
_F64 = np.dtype(np.float64)


def nearest_point(origins, axes) -> tuple[np.ndarray, float]:
    """The point nearest (least squares) the lines ``o_i + t a_i`` and its largest distance to them (m).

    ``sum_i (I - a_i a_i^T) x = sum_i (I - a_i a_i^T) o_i``; the distance of ``x`` to line i is
    ``|(I - a_i a_i^T)(x - o_i)|``. Parallel lines have no such point: ``(nan, inf)``.
    """
    o = np.asarray(origins, dtype=float).reshape(-1, 3)
    a = np.asarray(axes, dtype=float).reshape(-1, 3)
    proj = np.eye(3)[None] - a[:, :, None] * a[:, None, :]
    m, rhs = proj.sum(axis=0), np.einsum("kij,kj->i", proj, o)
    if np.linalg.cond(m) > 1e8:
        return np.full(3, np.nan), math.inf
    x = np.linalg.solve(m, rhs)
    gap = float(np.linalg.norm(np.einsum("kij,kj->ki", proj, x[None] - o), axis=-1).max())
    return x, gap


def _classify(a: np.ndarray, hip_gap: float, ankle_gap: float, gap23: float) -> str:
    """The structure of unit axes ``a`` (6, 3) with the given gaps (m; ``gap23``: axes 2 and 3):
    :data:`STRUCTURES`, within :data:`AXIS_TOL`."""
    if hip_gap <= AXIS_TOL and ankle_gap <= AXIS_TOL:
        return STRUCTURES[0]

    def sin(i: int, j: int) -> float:
        return float(np.linalg.norm(np.cross(a[i], a[j])))

    if max(sin(2, 3), sin(2, 4)) <= AXIS_TOL and min(sin(0, 1), sin(2, 5)) > 0.1:
        return STRUCTURES[1]
    if gap23 <= AXIS_TOL and sin(3, 4) <= AXIS_TOL and min(sin(1, 2), sin(3, 5)) > 0.1:
        return STRUCTURES[2]
    return STRUCTURES[3]


def _frozen(a) -> np.ndarray:
    arr = np.array(a, dtype=float)
    arr.flags.writeable = False
    return arr


def _pose_input(target, name: str = "target") -> np.ndarray:
    """``target`` (4, 4) or (..., 4, 4) as a checked float array: finite, bottom row ``(0, 0, 0, 1)``, rotation
    orthonormal with determinant +1 to 1e-6."""
    arr = as_input(target, name, _T44)
    bottom = ortho = det = 0.0
    flat = arr.reshape(-1, 4, 4)
    for lo in range(0, flat.shape[0], _batch.CHUNK):  # by chunks: the (n, 3, 3) temporaries were 2x the answer of ik
        part = flat[lo:lo + _batch.CHUNK]
        rot = part[:, :3, :3]
        bottom = max(bottom, float(np.abs(part[:, 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max()))
        ortho = max(ortho, float(np.abs(np.einsum("...ji,...jk->...ik", rot, rot) - np.eye(3)).max()))
        det = max(det, float(np.abs(np.linalg.det(rot) - 1.0).max()))
    if not (bottom <= 1e-12 and ortho <= 1e-6 and det <= 1e-6):
        raise InvalidInputError(
            f"{name} must be 4x4 homogeneous transforms (bottom row 0 0 0 1, a rotation block with R^T R = I and "
            f"det R = 1 to 1e-6): bottom row off by {bottom:.3g}, R^T R - I by {ortho:.3g}, det R - 1 by {det:.3g}"
        )
    return arr


@dataclass(frozen=True, eq=False)
class Leg6:
    """One 6-DOF leg, measured in the model's root frame at the neutral configuration.

    Build one with :func:`legkin.legs.from_model` / :func:`legkin.legs.from_urdf` (or :meth:`from_geometry`).

    Attributes:
        name: the leg's name (``"left"``, ``"right"``, or the common prefix of its joint names).
        joint_names: its six joints in model order (hip to ankle).
        foot_frame: the frame whose pose :meth:`fk` gives (a sole frame when the URDF has one).
        lower, upper: the URDF limits (rad) of the six joints.
        axes, origins: (6, 3) the unit joint axes and the joint origins (root frame, neutral configuration).
        foot_pose: (4, 4) the foot frame at the neutral configuration (root frame).
        structure: one of :data:`STRUCTURES`.
        hip_centre, ankle_centre: the points nearest axes 1-3 and axes 5-6 (m), and ``hip_gap``, ``ankle_gap``:
            their largest distances to those axes (m; 0 for an exact spherical hip).
        q_ref: the default reference of :meth:`ik` (mid-limit; 0 where a limit is infinite).
        idx_q, idx_v: the joints' indices in the source model's configuration / velocity vectors (-1 if none).
        params: the float64 geometry array the kernels read.
    """

    name: str
    joint_names: tuple[str, ...]
    foot_frame: str
    lower: np.ndarray
    upper: np.ndarray
    axes: np.ndarray
    origins: np.ndarray
    foot_pose: np.ndarray
    structure: str
    hip_centre: np.ndarray
    ankle_centre: np.ndarray
    hip_gap: float
    ankle_gap: float
    q_ref: np.ndarray
    idx_q: tuple[int, ...] = (-1,) * 6
    idx_v: tuple[int, ...] = (-1,) * 6
    params: np.ndarray = field(default=None, repr=False)  # type: ignore[arg-type]  # always set by from_geometry

    dof = 6

    @property
    def n_solutions(self) -> int:
        """The rows of :meth:`ik_all`: 8 (spherical hip), 16 (the searched structures), 0 (no IK)."""
        return int(self.params[_NSOLS])

    @classmethod
    def from_geometry(
        cls, name: str, joint_names, foot_frame: str, origins, axes, foot_pose, lower, upper, *,
        idx_q=(-1,) * 6, idx_v=(-1,) * 6,
    ) -> Leg6:
        """A leg from its joint origins (6, 3), unit axes (6, 3), foot pose (4, 4) at the neutral configuration and
        limits (6,) each (rad; infinite for a continuous joint); classifies :attr:`structure`.

        Raises:
            LegStructureError: non-finite geometry, an axis without direction, or bad limits.
        """
        o = np.asarray(origins, dtype=float).reshape(6, 3)
        a = np.asarray(axes, dtype=float).reshape(6, 3)
        m0 = np.asarray(foot_pose, dtype=float).reshape(4, 4)
        lo = np.asarray(lower, dtype=float).reshape(6)
        hi = np.asarray(upper, dtype=float).reshape(6)
        if not (np.isfinite(o).all() and np.isfinite(a).all() and np.isfinite(m0).all()):
            raise LegStructureError(f"leg {name}: non-finite joint origins, axes or foot pose", found=name)
        norms = np.linalg.norm(a, axis=-1)
        if not (norms > 1e-12).all():
            raise LegStructureError(f"leg {name}: a joint axis has no direction (norms {norms.tolist()})", found=name)
        a = a / norms[:, None]
        if np.isnan(lo).any() or np.isnan(hi).any() or (lo > hi).any():
            raise LegStructureError(f"leg {name}: bad joint limits lower={lo.tolist()}, upper={hi.tolist()}")
        hip, hip_gap = nearest_point(o[:3], a[:3])
        ank, ank_gap = nearest_point(o[4:], a[4:])
        h23, gap23 = nearest_point(o[1:3], a[1:3])
        structure = _classify(a, hip_gap, ank_gap, gap23)
        g = np.zeros(_NP6)
        g[_AX:_AX + 18], g[_OR:_OR + 18] = a.ravel(), o.ravel()
        g[_M0:_M0 + 9], g[_M0 + 9:_M0 + 12] = m0[:3, :3].ravel(), m0[:3, 3]
        spherical = structure == STRUCTURES[0]
        g[_HIP:_HIP + 3] = hip if spherical else (h23 if structure == STRUCTURES[2] else 0.0)
        g[_ANK:_ANK + 3] = ank if spherical else 0.0
        g[_LO6:_LO6 + 6], g[_HI6:_HI6 + 6] = lo, hi
        g[_KIND], g[_NSOLS] = _KINDS[structure], _ROWS[structure]
        g[_GRID] = SEARCH_GRID.get(structure, 0)
        finite = np.isfinite(lo) & np.isfinite(hi)
        mid = np.where(finite, 0.5 * (np.where(finite, lo, 0.0) + np.where(finite, hi, 0.0)), np.clip(0.0, lo, hi))
        g[_QREF:_QREF + 6] = mid
        return cls(
            name=str(name), joint_names=tuple(str(j) for j in joint_names), foot_frame=str(foot_frame),
            lower=_frozen(lo), upper=_frozen(hi), axes=_frozen(a), origins=_frozen(o), foot_pose=_frozen(m0),
            structure=structure, hip_centre=_frozen(hip),
            ankle_centre=_frozen(ank), hip_gap=hip_gap, ankle_gap=ank_gap, q_ref=_frozen(mid),
            idx_q=tuple(int(i) for i in idx_q), idx_v=tuple(int(i) for i in idx_v), params=_frozen(g),
        )

    def __repr__(self) -> str:
        return (f"Leg6({self.name!r}, {self.structure}, joints={self.joint_names}, foot={self.foot_frame!r}, "
                f"hip gap {self.hip_gap:.2g} m, ankle gap {self.ankle_gap:.2g} m)")

    # ------------------------------------------------------------ forward
    def fk(self, q: ArrayLike, *, return_mask: bool = False) -> Any:
        """The foot frame's pose ``T(q)`` (4, 4) in the root frame, or (..., 4, 4) for ``q`` (..., 6) (rad).

        Args:
            q: joint values (6,) or (..., 6), rad.
            return_mask: also return the mask (all True: every finite ``q`` has a pose).

        Returns:
            ``T`` (4, 4) or (..., 4, 4) (translation in m), and the mask if asked.

        Raises:
            InvalidInputError: ``q`` not a finite real array (..., 6).
        """
        if q.__class__ is np.ndarray and q.shape == _Q6 and q.dtype is _F64 and return_mask is False:
            one = np.empty(16)  # a single call: straight to the kernel
            if _fk6_k(q, self.params, one) == OK:
                return one.reshape(4, 4)
        arr = as_input(q, "q", _Q6)
        rows = as_rows(arr, 6)
        out = np.empty((rows.shape[0], 16))
        _fk6_batch(rows, self.params, out)
        res = out.reshape(arr.shape[:-1] + _T44)
        return finish(res, np.ones(arr.shape[:-1], dtype=bool), arr.ndim == 1, check_flag(return_mask, "return_mask"),
                      lambda: AssertionError("unreachable"))

    def jacobian(self, q: ArrayLike, *, return_mask: bool = False) -> Any:
        """The foot Jacobian (6, 6) or (..., 6, 6): rows ``(v, w)`` = linear velocity of the foot frame's origin
        (m/s) then angular velocity (rad/s), both in root-frame axes, per unit joint rate (Pinocchio's
        ``getFrameJacobian(..., LOCAL_WORLD_ALIGNED)`` on the leg's columns, fixed base). Column j:
        ``(w_j x (p - o_j), w_j)`` with joint j's axis ``w_j`` and origin ``o_j`` at ``q``.

        Args:
            q: joint values (6,) or (..., 6), rad.
            return_mask: also return the mask (all True: every finite ``q`` has a Jacobian).

        Returns:
            ``J`` (6, 6) or (..., 6, 6) (m/rad rows, then rad/rad rows), and the mask if asked.

        Raises:
            InvalidInputError: ``q`` not a finite real array (..., 6).
        """
        if q.__class__ is np.ndarray and q.shape == _Q6 and q.dtype is _F64 and return_mask is False:
            one = np.empty((6, 6))  # a single call: straight to the kernel
            if _jacobian6_k(q, self.params, one) == OK:
                return one
        arr = as_input(q, "q", _Q6)
        rows = as_rows(arr, 6)
        out = np.empty((rows.shape[0], 6, 6))
        _jacobian6_batch(rows, self.params, out)
        res = out.reshape(arr.shape[:-1] + (6, 6))
        return finish(res, np.ones(arr.shape[:-1], dtype=bool), arr.ndim == 1, check_flag(return_mask, "return_mask"),
                      lambda: AssertionError("unreachable"))

    # ------------------------------------------------------------ inverse
    def _prepare(self, target, q_near, tol):
        if self.params[_KIND] == 0.0:
            raise LegStructureError(
                f"leg {self.name}: no IK for its structure {self.structure!r} (hip axes meet within "
                f"{self.hip_gap:.3g} m, ankle axes within {self.ankle_gap:.3g} m; axes 3-5 not parallel; tolerance "
                f"{AXIS_TOL:g})", found=self.structure, expected=list(STRUCTURES[:2]),
            )
        tol = check_number(tol, "tol", 0.0, 1e-3, low_open=True)
        arr = as_input(target, "target", _T44)  # the rotation and bottom row are checked by the kernel (_bad_poses)
        batch = arr.shape[:-2]
        if q_near is None:
            ref = self.q_ref.reshape(1, 6).copy()
        else:
            r = as_input(q_near, "q_near", _Q6)
            try:
                batch = np.broadcast_shapes(batch, r.shape[:-1])
            except ValueError:
                raise InvalidInputError(
                    f"target (shape {arr.shape}) and q_near (shape {r.shape}) do not broadcast together"
                ) from None
            ref = as_rows(r, 6) if r.ndim == 1 else as_rows(np.broadcast_to(r, batch + _Q6), 6)
        if arr.shape[:-2] != batch:
            arr = np.broadcast_to(arr, batch + _T44)
        return as_rows(arr, 16), ref, batch, len(batch) == 0, tol

    def _single(self, kernel: Any, rows: int, target: Any) -> np.ndarray | None:
        """The fast path of :meth:`ik` (``rows`` 1) and :meth:`ik_all` (``rows`` K) for one float64 pose with the
        default options: the kernel's answer ``(rows, 6)``, or None when ``target`` is not such a pose or the
        kernel refused it (bad input, no answer, a leg without an IK: the full path then runs and says why)."""
        if not (target.__class__ is np.ndarray and target.shape == _T44 and target.dtype is _F64):
            return None
        out = np.empty((rows, 6))
        return out if kernel(target, self.params, out) == OK else None

    @staticmethod
    def _bad_poses(status: np.ndarray, rows: np.ndarray) -> None:
        """Raise where the kernel refused a pose (``_BAD_INPUT``: not a homogeneous transform, the test of
        :func:`_pose_input`, which then says why).

        Raises:
            InvalidInputError: some row of ``rows`` (n, 16) is not a 4x4 homogeneous transform.
        """
        bad = status == _BAD_INPUT
        if bad.any():
            _pose_input(rows[bad].reshape(-1, 4, 4))
            raise InvalidInputError("target must be 4x4 homogeneous transforms (R^T R = I and det R = 1 to 1e-6)")

    def _solve(self, kernel: Any, shape: tuple[int, ...], rows: np.ndarray, ref: np.ndarray,
               tol: float) -> tuple[np.ndarray, ...]:
        """An IK batch kernel on the pose rows (n, 16), by chunks (``legkin._batch.in_chunks``: the temporaries of a
        large batch take one chunk's memory): ``(out (n, *shape), status (n,), info (n, 2))``."""
        def solve(r: np.ndarray, rf: np.ndarray | None) -> tuple[np.ndarray, ...]:
            m = r.shape[0]
            out, status, info = np.empty((m,) + shape), np.empty(m, dtype=np.int64), np.zeros((m, 2))
            kernel(r, self.params, ref if rf is None else rf, tol, out, status, info)
            return out, status, info

        return in_chunks(solve, [rows, ref if ref.shape[0] == rows.shape[0] else None])

    def _error(self, status: int, info: np.ndarray, target: np.ndarray, tol: float):
        t = target.reshape(4, 4)
        if status == _JOINT_LIMIT:
            return JointLimitError(
                f"foot pose of leg {self.name} at {t[:3, 3].round(6).tolist()} is reachable only outside the joint "
                f"limits (by {float(info[0]):.6g} rad at least, {int(info[1])} solutions)", target=t,
                distance=float(info[0]),
            )
        return UnreachableError(
            f"foot pose of leg {self.name} at {t[:3, 3].round(6).tolist()} is out of reach: the nearest pose the "
            f"solutions reach misses it by {float(info[0]):.6g} (m and rad; tol {tol:g})", target=t,
            distance=float(info[0]),
        )

    def ik_all(self, target: ArrayLike, *, q_near: ArrayLike | None = None, tol: float = IK_TOL,
               return_mask: bool = False) -> Any:
        """Every solution of the foot pose(s) ``target`` (4, 4) or (..., 4, 4), joint limits ignored.

        Args:
            target: foot poses in the root frame (m).
            q_near: each angle is given as its 2 pi representative nearest ``q_near`` (default :attr:`q_ref`).
            tol: a solution reproduces the target to this: position error (m) and rotation error (rad) each;
                (0, 1e-3], default 1e-7.
            return_mask: also return the mask of the rows that exist.

        Returns:
            ``(8, 6)`` or ``(..., 8, 6)`` (rad), NaN rows where a branch does not exist (rows: knee, ankle, hip
            branch, see the module docstring); with ``return_mask=True`` also the mask ``(8,)`` / ``(..., 8)``.

        Raises:
            UnreachableError: a single target with no solution.
            LegStructureError: a leg without a closed form (:attr:`structure` ``"6R-general"``).
            InvalidInputError, InvalidArgumentError: bad ``target`` / ``q_near`` / ``tol`` / ``return_mask``.
        """
        if q_near is None and tol is IK_TOL and return_mask is False:  # a single float64 pose: the kernel directly
            fast = self._single(_ik_all6_one, self.n_solutions, target)
            if fast is not None:
                return fast
        rows, ref, batch, single, tol = self._prepare(target, q_near, tol)
        flag = check_flag(return_mask, "return_mask")
        k = self.n_solutions
        out, status, info = self._solve(_ik_all6_batch, (k, 6), rows, ref, tol)
        self._bad_poses(status, rows)
        if single and status[0] != OK:
            raise self._error(int(status[0]), info[0], rows[0], tol)
        q_all = out.reshape(batch + (k, 6))
        return (q_all, np.isfinite(q_all[..., 0])) if flag else q_all

    def ik(self, target: ArrayLike, *, q_near: ArrayLike | None = None, tol: float = IK_TOL,
           return_mask: bool = False) -> Any:
        """The solution inside the URDF limits nearest ``q_near`` (default :attr:`q_ref`, mid-limits).

        Each solution of :meth:`ik_all` takes, joint by joint, its 2 pi representative inside the limits nearest
        ``q_near``; the one with the least ``|q - q_near|^2`` wins.

        Args:
            target: foot poses (4, 4) or (..., 4, 4), root frame (m).
            q_near: reference (6,) or broadcastable with the targets.
            tol: as :meth:`ik_all`.
            return_mask: also return the mask of the solved targets.

        Returns:
            ``q`` (6,) or (..., 6) (rad; NaN rows for unsolved batch items), and the mask if asked.

        Raises:
            UnreachableError: a single target out of reach; JointLimitError: reachable only outside the limits.
            LegStructureError, InvalidInputError, InvalidArgumentError: as :meth:`ik_all`.
        """
        if q_near is None and tol is IK_TOL and return_mask is False:  # a single float64 pose: the kernel directly
            fast = self._single(_ik6_one, 1, target)
            if fast is not None:
                return fast[0]
        rows, ref, batch, single, tol = self._prepare(target, q_near, tol)
        flag = check_flag(return_mask, "return_mask")
        out, status, info = self._solve(_ik6_batch, _Q6, rows, ref, tol)
        self._bad_poses(status, rows)
        ok = status == OK
        if single:
            return finish(out[0], ok[0], True, flag, lambda: self._error(int(status[0]), info[0], rows[0], tol))
        return finish(out.reshape(batch + _Q6), ok.reshape(batch), False, flag, lambda: AssertionError("batch"))

    def within_limits(self, q: ArrayLike, tol: float = 0.0) -> np.ndarray | bool:
        """Whether joint values lie inside the URDF limits.

        Args:
            q: joint values (6,) or (..., 6) (rad).
            tol: how far outside a limit still counts as inside (rad).

        Returns:
            A bool for a single ``q``, else the mask (...,).
        """
        arr = as_input(q, "q", _Q6)
        inside = np.all((arr >= self.lower - tol) & (arr <= self.upper + tol), axis=-1)
        return bool(inside) if arr.ndim == 1 else inside
