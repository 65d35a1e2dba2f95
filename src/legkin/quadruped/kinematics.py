"""Closed-form kinematics of the quadruped's legs (seeds 004 and 002): the public API, re-exported.

Conventions (base frame: x forward, y left, z up; metres, radians):

* legs ``"LF"``, ``"LH"``, ``"RF"``, ``"RH"``; ``sx = +1`` front / ``-1`` hind, ``sy = +1`` left / ``-1`` right;
* joint vector ``q = (q1, q2, q3)`` = (``<LEG>_HAA``, ``<LEG>_HFE``, ``<LEG>_KFE``), the seed's
  (aile, epaule, coude) angles; the foot frame ``<LEG>_FOOT`` is the seed's "pied";
* seed 004's transforms with its sign typo resolved: ``T01 = Tr(h) Rx(sy q1)``, ``T12 = Tr(0, sy y12, 0) Ry(-q2)``,
  ``T23 = Tr(x23, 0, z23) Ry(q3)``, ``T34 = Tr(x34, 0, foot_z)``; ``foot_z`` is the one xacro argument
  (:class:`Geometry`), the offsets are POPI's constants (:mod:`legkin.quadruped.constants`).

Where the code is, by concept: :mod:`~legkin.quadruped.forward` (``fk``, ``jacobian``, ``hip_position``),
:mod:`~legkin.quadruped.closed_form` (``ik_all``), :mod:`~legkin.quadruped.inverse` (``ik``, the branch choice),
:mod:`~legkin.quadruped.repair` (the clip-into-limits repair), :mod:`~legkin.quadruped.limits`
(``within_limits``), :mod:`~legkin.quadruped.textbook` (seed 002), :mod:`~legkin.quadruped.deprecated`
(the 0.1 names).

Every function takes arrays with leading batch dimensions. A single input (``q`` or ``p`` of shape (3,))
returns plain arrays and raises on failure; a batch returns NaN rows where an item fails, and
``return_mask=True`` also returns the boolean mask of successes. Where two arrays come in (``ik``'s ``p``
and ``q_near``) their leading shapes broadcast, and the call is a single one only if the broadcast shape is
``()`` (a single target with a batch of ``q_near`` is a batch).

Implementation (issue 16, see :mod:`legkin._kernels`): every function is a compiled numba kernel,
written once beside its seed equations; a batch is a compiled loop over the same kernel (``prange``, threads:
``numba.set_num_threads`` or ``NUMBA_NUM_THREADS``; batches below the loop's ``min_parallel`` (256) items run
on the calling thread). The Python wrappers only check the inputs and apply the single/batch rule.

Inputs are checked at every public function: arrays as by :func:`legkin._batch.as_input` (wrong shape,
NaN/inf, complex, strings, ragged: ``InvalidInputError``; a float64 array of the right shape goes straight to
the kernel, which tests finiteness and reports it by its status code), keyword parameters for kind and range
(``InvalidParameterError`` naming the value and the valid range). No numpy exception escapes: a failed item
is NaN in a batch (mask False) and a legkin error in a single call.
"""

from __future__ import annotations

from .closed_form import ik_all
from .constants import (
    BRANCHES,
    CLIP_TOL,
    JOINT_LIMITS,
    KNEE_OFFSET,
    LEGS,
    LIMIT_SLACK,
    LIMIT_TOL,
    REACH_TOL,
    X01,
    X23,
    X34,
    Y01,
    Y12,
    Z01,
    Z23,
)
from .deprecated import foot_ik, foot_ik_all, foot_jacobian, foot_position
from .forward import fk, hip_position, jacobian
from .geometry import DEFAULT_GEOMETRY, Geometry
from .inverse import ik
from .limits import within_limits
from .textbook import textbook_frame, textbook_ik, textbook_to_joints

__all__ = [
    "Geometry",
    "DEFAULT_GEOMETRY",
    "LEGS",
    "X01",
    "Y01",
    "Z01",
    "Y12",
    "X23",
    "Z23",
    "X34",
    "JOINT_LIMITS",
    "REACH_TOL",
    "BRANCHES",
    "LIMIT_TOL",
    "LIMIT_SLACK",
    "CLIP_TOL",
    "KNEE_OFFSET",
    "fk",
    "jacobian",
    "ik",
    "ik_all",
    "hip_position",
    "within_limits",
    "textbook_ik",
    "textbook_frame",
    "textbook_to_joints",
    # deprecated (legkin 0.1 names, kept for one release)
    "foot_position",
    "foot_jacobian",
    "foot_ik",
    "foot_ik_all",
]
