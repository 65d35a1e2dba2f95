"""Canonical geometric subproblems of inverse kinematics, as compiled kernels (the 6-DOF legs' building blocks).

The names and the argument order follow the literature: Paden-Kahan subproblems 1-3 (Paden 1985, Kahan; Murray,
Li & Sastry, *A Mathematical Introduction to Robotic Manipulation*, 1994, sec. 3.3) in the form of Elias & Wen,
"IK-Geo: unified robot inverse kinematics using subproblem decomposition" (2024), whose subproblem 4 is also here.
Every vector is a 3-tuple of floats (no allocation), every axis ``k`` a unit vector, every angle in rad, and
``R(k, t)`` the rotation by ``t`` about ``k`` (Rodrigues: ``R(k, t) p = cos t p + sin t k x p + (1 - cos t)(k.p) k``).

* **SP1** (circle and point): ``t`` with ``R(k, t) p1 = p2``; the least-squares angle when ``|p1|, |p2|`` or
  their components along ``k`` differ.
* **SP2** (two circles): ``(t1, t2)`` with ``R(k1, t1) p1 = R(k2, t2) p2``, ``k1`` not parallel to ``k2``: 0, 1
  (tangent cones) or 2 solutions.
* **SP3** (circle and sphere): ``t`` with ``|R(k, t) p1 - p2| = d``: 0, 1 or 2 solutions.
* **SP4** (circle and plane): ``t`` with ``h . R(k, t) p = d``: 0, 1 or 2 solutions.

Each kernel returns the count of exact solutions (0 when the circle misses) and the angles; where it returns 0
it still gives the least-squares angle(s) in the first slot(s) and the miss, so that a caller with a tolerance can
decide. No kernel raises.
"""

from __future__ import annotations

import math

from .._kernels import kernel

__all__ = ["sp1", "sp1_cs", "sp2", "sp2_cs", "sp3", "sp4", "rot", "rot_cs", "dot", "cross"]


@kernel
def dot(a, b) -> float:
    """``a . b``."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@kernel
def cross(a, b):
    """``a x b``."""
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


@kernel
def rot(k, t, p):
    """``R(k, t) p`` (Rodrigues' formula), ``k`` a unit vector."""
    return rot_cs(k, math.cos(t), math.sin(t), p)


@kernel
def rot_cs(k, c, s, p):
    """``R(k, t) p`` for ``c = cos t``, ``s = sin t`` (Rodrigues without trigonometry), ``k`` a unit vector."""
    w = (1.0 - c) * (k[0] * p[0] + k[1] * p[1] + k[2] * p[2])
    return (
        c * p[0] + s * (k[1] * p[2] - k[2] * p[1]) + w * k[0],
        c * p[1] + s * (k[2] * p[0] - k[0] * p[2]) + w * k[1],
        c * p[2] + s * (k[0] * p[1] - k[1] * p[0]) + w * k[2],
    )


@kernel
def _sp1_parts(p1, p2, k):
    """``(k . (p1 x p2), p1 . p2 - (k . p1)(k . p2))``: the sine and cosine of SP1's angle, each times the product
    of the projections' lengths; computed as ``(k . (w1 x w2), w1 . w2)`` with ``w_i = k x p_i`` (the projections
    turned by 90 degrees): for ``p_i`` within ``beta`` of ``k`` both parts are ``~beta^2``, and the direct formulas
    (differences of O(1) terms) lost them entirely below ``beta ~ 1e-8``."""
    w1, w2 = cross(k, p1), cross(k, p2)
    return dot(k, cross(w1, w2)), dot(w1, w2)


@kernel
def sp1(p1, p2, k) -> float:
    """Subproblem 1: the angle ``t`` with ``R(k, t) p1 = p2`` (least squares: the angle between the projections of
    ``p1`` and ``p2`` on the plane normal to ``k``), ``t = atan2(k . (p1 x p2), p1 . p2 - (k . p1)(k . p2))``."""
    sn, cs = _sp1_parts(p1, p2, k)
    return math.atan2(sn, cs)


@kernel
def sp1_cs(p1, p2, k):
    """:func:`sp1`'s angle as ``(cos t, sin t)`` (no trigonometry; ``(1, 0)`` where a projection vanishes)."""
    sn, cs = _sp1_parts(p1, p2, k)
    r = math.sqrt(sn * sn + cs * cs)
    return (cs / r, sn / r) if r > 0.0 else (1.0, 0.0)


@kernel
def sp4(h, p, k, d):
    """Subproblem 4: ``t`` with ``h . R(k, t) p = d`` (``h``, ``k`` unit vectors).

    ``h . R(k, t) p = A cos t + B sin t + C`` with ``A = h . p - (k . p)(k . h)``, ``B = h . (k x p)``,
    ``C = (k . p)(k . h)``; so ``t = atan2(B, A) +- acos((d - C) / sqrt(A^2 + B^2))``.

    Returns:
        ``(n, t_a, t_b, miss)``: ``n`` = 2 (two roots, ``t_a`` with ``-acos``), 0 when ``|d - C| > sqrt(A^2 + B^2)``
        (``t_a = t_b`` = the closest angle, ``miss`` = ``|d - C| - sqrt(A^2 + B^2)`` > 0), ``miss = 0`` otherwise.
    """
    kp, kh = dot(k, p), dot(k, h)
    a = dot(h, p) - kp * kh
    b = dot(h, cross(k, p))
    r = math.hypot(a, b)
    phi = math.atan2(b, a)
    x = d - kp * kh
    if abs(x) > r:
        t = phi if x > 0 else phi + math.pi
        return 0, t, t, abs(x) - r
    g = math.acos(x / r) if r > 0.0 else 0.0
    return 2, phi - g, phi + g, 0.0


@kernel
def sp3(p1, p2, k, d):
    """Subproblem 3: ``t`` with ``|R(k, t) p1 - p2| = d`` (``d >= 0``).

    ``|R p1 - p2|^2 = |p1|^2 + |p2|^2 - 2 p2 . R(k, t) p1``: subproblem 4 with ``h = p2 / |p2|`` and
    ``h . R(k, t) p1 = (|p1|^2 + |p2|^2 - d^2) / (2 |p2|)``.

    Returns:
        ``(n, t_a, t_b, miss)`` as :func:`sp4`, ``miss`` in units of ``h . R p1`` (m): the circle of ``p1`` about
        ``k`` misses the sphere ``|x - p2| = d`` by ``2 |p2| miss / (|R p1 - p2| + d)`` m.
    """
    n2 = math.sqrt(dot(p2, p2))
    h = (p2[0] / n2, p2[1] / n2, p2[2] / n2)
    return sp4(h, p1, k, (dot(p1, p1) + n2 * n2 - d * d) / (2.0 * n2))


@kernel
def sp2_cs(p1, p2, k1, k2):
    """Subproblem 2: ``(t1, t2)`` with ``R(k1, t1) p1 = R(k2, t2) p2`` (``k1`` not parallel to ``k2``), each angle as
    its ``(cos, sin)`` pair (:func:`sp1_cs`).

    Solved on the directions ``u_i = p_i / |p_i|`` (exact when ``|p1| = |p2|``, else the directions align and
    ``miss`` reports ``| |p1| - |p2| |``): both sides are the unit vector ``x`` where the cone of ``u1`` about ``k1``
    meets the cone of ``u2`` about ``k2``, ``x = a k1 + b k2 + c (k1 x k2)`` with ``k1 . x = k1 . u1``,
    ``k2 . x = k2 . u2`` (so, with ``g = k1 . k2``, ``a = (k1.u1 - g k2.u2) / (1 - g^2)``,
    ``b = (k2.u2 - g k1.u1) / (1 - g^2)``) and ``|x| = 1``; then ``t1 = SP1(u1 -> x)`` about ``k1`` and
    ``t2 = SP1(u2 -> x)`` about ``k2``. ``|x| = 1`` gives ``c^2 (1 - g^2) = 1 - a^2 - b^2 - 2 a b g``, i.e.
    ``c^2 (1 - g^2)^2 = |k1 x k2|^2 |k2 x u2|^2 - (k1.u1 - g k2.u2)^2`` (or the same with 1 and 2 swapped), computed
    on the narrower cone's ``|k x u|`` from its cross product: ``1 - a^2 - b^2 ...`` cancels to nothing when a cone is
    narrow (``u2`` within ``beta`` of ``k2``: ``c ~ beta`` came out with an absolute error ``1e-16 / beta``, a leg's
    foot off by ``1e-16 / beta`` m near the pose where the hip centre lies on the ankle roll axis).

    Returns:
        ``(n, (c1, s1)_a, (c2, s2)_a, (c1, s1)_b, (c2, s2)_b, miss)``: ``n`` = 2 (``c = -+ sqrt``), 0 when the cones
        do not meet (``c = 0``: the least-squares pair, ``miss`` = ``sqrt(-c^2 (1 - g^2))`` > 0, in units of
        ``|x|``).
    """
    n1, n2 = math.sqrt(dot(p1, p1)), math.sqrt(dot(p2, p2))
    u1 = (p1[0] / n1, p1[1] / n1, p1[2] / n1)
    u2 = (p2[0] / n2, p2[1] / n2, p2[2] / n2)
    g = dot(k1, k2)
    n = cross(k1, k2)
    s2 = dot(n, n)  # 1 - g^2
    ku1, ku2 = dot(k1, u1), dot(k2, u2)
    a = (ku1 - g * ku2) / s2
    b = (ku2 - g * ku1) / s2
    w1, w2 = cross(k1, u1), cross(k2, u2)
    r1, r2 = dot(w1, w1), dot(w2, w2)  # 1 - (k.u)^2 of each cone, from the cross product
    c2 = (s2 * r2 - (ku1 - g * ku2) ** 2 if r2 <= r1 else s2 * r1 - (ku2 - g * ku1) ** 2) / (s2 * s2)
    miss, count = abs(n1 - n2), 2
    if c2 < 0.0:
        miss, c2, count = max(miss, math.sqrt(-c2 * s2)), 0.0, 0
    c = math.sqrt(c2)
    xa = (a * k1[0] + b * k2[0] - c * n[0], a * k1[1] + b * k2[1] - c * n[1], a * k1[2] + b * k2[2] - c * n[2])
    xb = (a * k1[0] + b * k2[0] + c * n[0], a * k1[1] + b * k2[1] + c * n[1], a * k1[2] + b * k2[2] + c * n[2])
    return count, sp1_cs(u1, xa, k1), sp1_cs(u2, xa, k2), sp1_cs(u1, xb, k1), sp1_cs(u2, xb, k2), miss


@kernel
def sp2(p1, p2, k1, k2):
    """Subproblem 2 (:func:`sp2_cs`) with the angles.

    Returns:
        ``(n, t1_a, t2_a, t1_b, t2_b, miss)`` as :func:`sp2_cs`.
    """
    n, c1a, c2a, c1b, c2b, miss = sp2_cs(p1, p2, k1, k2)
    return (n, math.atan2(c1a[1], c1a[0]), math.atan2(c2a[1], c2a[0]), math.atan2(c1b[1], c1b[0]),
            math.atan2(c2b[1], c2b[0]), miss)
