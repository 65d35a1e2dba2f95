"""Check rows of the tyre surface and the ground contact (issue 12): ``run(samples, rng) -> list[CheckResult]``.

Also :func:`lab_contact_map` (the lab's ``LegModel.contact_map`` recomputed from the formulas read in BioRoLa/LegWheel,
branch main, ``legwheel/models/leg_model.py``; no code copied) and :func:`standing_base_heights`.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from .._checkkit import CheckResult, compare, per_sample
from ._differences import derivative
from .configuration import configuration
from .frames import leg_frame_to_robot
from .geometry import ABAD_LIMIT, LEGS, THETA0, THETA_MAX, THETA_MIN, Geometry
from .ground import ground_contact
from .linkage import linkage_points
from .stance import stance_ik, stance_ik_all
from .tyre import LINK_NAMES, PIECES, TYRE_THICKNESS, tyre_pieces, tyre_point

TOL = 1e-12
TOL_FD = 1e-8
FD_STEP = 1e-6
#: The lab's tyre thicknesses (``LegModel.r``): 0.019 m "with tire" (sim=False), 0.01 m (sim=True).
LAB_R = (0.019, 0.01)
#: Samples of the costlier rows (brute force over the surface, Pinocchio Jacobians, stance IK).
BRUTE_SAMPLES, BRUTE_S = 400, 4000
PIN_SAMPLES = 300
IK_SAMPLES = 1000
#: The stance IK's completeness row scales the distance (rad) from the sampled q to the nearest solution by the
#: smallest singular value of the contact point's derivative (m/rad; central differences with this step): near a
#: fold the inverse is ill-conditioned, and a solution that reproduces the target to ~1e-16 m can be ~1e-9 rad from
#: the sampled q (theta 7e-7 rad from the fold of |H|^2, where sigma_min = 5e-8 m/rad). The differences' rounding,
#: ~eps |p| / h ~ 1e-9 m/rad, is below the sigma_min that matters.
SIGMA_STEP = 1e-7


class LabContact(NamedTuple):
    """The lab's contact_map answer: ``rim`` 1-5 (upper L, lower L, G, lower R, upper R) or 0 ("no normal
    contact"), and the contact point (x, y) in the leg plane relative to the hip (y = -height)."""

    rim: np.ndarray
    point: np.ndarray


def lab_contact_map(theta: np.ndarray, beta: np.ndarray, r_lab: float, geometry: Geometry | None = None) -> LabContact:
    """The lab's ``LegModel.contact_map(theta, beta)`` (slope 0) recomputed from its formulas.

    Read in BioRoLa/LegWheel (main, ``legwheel/models/leg_model.py``): five arcs of the outer rim, offset to
    ``radius = R + r`` about their centres: upper L about U_L from H_L to F_L, lower L about L_L from F_L to G,
    a toe circle of radius r about G from the lower L offset of G to the lower R offset of G, lower R, upper R.
    For each arc (p1 -> p2 about O): "in range" if ``Re(p2 - O) >= -1e-9`` and ``Re(p1 - O) <= 1e-9``, then its
    lowest point is ``O - i rho`` (rho = radius, or r for the toe), else the arc has no answer (1.0). The rim is
    the arc with the lowest point, or 0 when no arc is in range; the point is ``(Re O, -|lowest|)``. No fillet
    at F, no caps at the tips H.
    """
    pts = linkage_points(theta, beta, geometry=geometry)
    R = (geometry or Geometry()).R

    def z(k: str) -> np.ndarray:
        return pts[k][..., 0] + 1j * pts[k][..., 1]

    rad = R + r_lab

    def out(c: np.ndarray, p: np.ndarray) -> np.ndarray:
        return c + (p - c) / R * rad

    UL, UR, LL, LR, G = z("U_L"), z("U_R"), z("L_L"), z("L_R"), z("G")
    arcs = [
        (out(UL, z("H_L")), out(UL, z("F_L")), UL, rad), (out(LL, z("F_L")), out(LL, G), LL, rad),
        (out(LL, G), out(LR, G), G, r_lab), (out(LR, G), out(LR, z("F_R")), LR, rad),
        (out(UR, z("F_R")), out(UR, z("H_R")), UR, rad),
    ]
    low, xs = [], []
    for p1, p2, c, rho in arcs:
        inr = ((p2 - c).real >= -1e-9) & ((p1 - c).real <= 1e-9)
        low.append(np.where(inr, c.imag - rho, 1.0))
        xs.append(c.real)
    lows = np.stack(low + [np.zeros(np.shape(low[0]))])
    best = np.argmin(lows, axis=0)
    rim = np.where(lows.min(axis=0) == 0, 0, best + 1)
    idx = np.clip(rim - 1, 0, 4)
    x = np.take_along_axis(np.stack(xs), idx[None], 0)[0]
    height = np.abs(np.take_along_axis(lows[:5], idx[None], 0)[0])
    return LabContact(rim, np.stack([x, -height], -1))


#: legkin piece of each lab rim 1-5.
LAB_PIECES = (PIECES.index("upper_L"), PIECES.index("lower_L"), PIECES.index("G"), PIECES.index("lower_R"),
              PIECES.index("upper_R"))


def _leg_plane(p: np.ndarray, leg: str = "FL") -> np.ndarray:
    """(x_L, y_L) of robot-frame points of a left leg at gamma = 0 (x_L = -x_R, y_L = z_R, about O)."""
    O = leg_frame_to_robot(np.zeros(3), 0.0, leg)
    return np.stack([-(p[..., 0] - O[0]), p[..., 2] - O[2]], -1)


def lab_comparison(n: int, rng: np.random.Generator, r_lab: float) -> dict[str, Any]:
    """legkin's ground contact against :func:`lab_contact_map` on n uniform (theta, beta) (gamma = 0, n = z)."""
    theta = rng.uniform(THETA_MIN, THETA_MAX, n)
    beta = rng.uniform(-np.pi, np.pi, n)
    lab = lab_contact_map(theta, beta, r_lab)
    gc = ground_contact(np.stack([theta, beta, np.zeros(n)], -1), "FL", r=r_lab)
    ours = _leg_plane(gc.point)
    has = lab.rim > 0
    diff = per_sample(ours - lab.point)
    same = has & (diff <= TOL)
    lab_piece = np.where(has, np.array((-1,) + LAB_PIECES)[lab.rim], -1)
    return {
        "n": n, "answered": int(has.sum()), "agree": int(same.sum()), "diff": diff[has],
        "other": int((has & ~same).sum()),
        "other_height": (lab.point[has & ~same, 1] - ours[has & ~same, 1]),
        "same_piece": int((lab_piece[has] == gc.piece[has]).sum()),
        "none_pieces": {PIECES[k]: int(c) for k, c in enumerate(np.bincount(gc.piece[~has], minlength=16)) if c},
        "none_q": np.stack([theta, beta], -1)[~has],
        # the lab's arcs answer only heights below the hip (its min includes a 0 row): above it, "no contact"
        "none_above_hip": int((~has & (ours[:, 1] > 0)).sum()),
        "none_caps": int((~has & np.isin(gc.piece, (PIECES.index("cap_H_L"), PIECES.index("cap_H_R")))).sum()),
    }


def _brute_heights(q: np.ndarray, leg: str, normal: np.ndarray, r: float, m: int,
                   geo: Geometry) -> tuple[np.ndarray, np.ndarray]:
    """min over m uniform s samples x both edges (and the centre) of the height <p, n>; and the resolution
    bound (L/m/2)^2 / (2 r) per configuration."""
    s = np.linspace(0.0, 1.0, m + 1)
    out = np.empty(q.shape[0])
    for i in range(q.shape[0]):
        best = np.inf
        for w in (-geo.T / 2, 0.0, geo.T / 2):
            pL = tyre_point(np.full(s.shape, q[i, 0]), q[i, 1], s, w, r=r, geometry=geo)
            best = min(best, float((leg_frame_to_robot(pL, q[i, 2], leg, geometry=geo) @ normal).min()))
        out[i] = best
    length = tyre_pieces(q[:, 0], 0.0, r=r, geometry=geo).length
    return out, (length / m / 2) ** 2 / (2 * r)


def _pitch_distance(p: np.ndarray, theta: np.ndarray, geo: Geometry) -> np.ndarray:
    """Distance of leg-plane points p (n, 2) (beta = 0) from the pitch curve (the four rim arcs of radius R)."""
    pts = linkage_points(theta, 0.0, geometry=geo)

    def z(k: str) -> np.ndarray:
        return pts[k][..., 0] + 1j * pts[k][..., 1]

    zp = p[..., 0] + 1j * p[..., 1]
    best = np.full(zp.shape, np.inf)
    for c, a, b in (("U_L", "H_L", "F_L"), ("L_L", "F_L", "G"), ("L_R", "G", "F_R"), ("U_R", "F_R", "H_R")):
        C, A, B = z(c), z(a), z(b)
        span = np.mod(np.angle((B - C) / (A - C)), 2 * np.pi)
        rel = np.mod(np.angle((zp - C) / (A - C)), 2 * np.pi)
        inside = np.abs(np.abs(zp - C) - geo.R)
        ends = np.minimum(np.abs(zp - A), np.abs(zp - B))
        best = np.minimum(best, np.where(rel <= span, inside, ends))
    return best


def _surface_rows(rng: np.random.Generator, geo: Geometry, r: float) -> list[CheckResult]:
    theta = np.concatenate([[THETA0, THETA_MAX], rng.uniform(THETA_MIN, THETA_MAX, 198)])
    m = 2000
    s = np.linspace(0.0, 1.0, m + 1)
    th = np.repeat(theta[:, None], m + 1, 1)
    p = tyre_point(th, 0.0, np.broadcast_to(s, th.shape), r=r, geometry=geo)[..., :2]
    length = tyre_pieces(theta, 0.0, r=r, geometry=geo).length
    jump = np.linalg.norm(np.diff(p, axis=1), axis=-1).max(axis=1) - length / m
    closure = np.linalg.norm(p[:, 0] - p[:, -1], axis=-1)
    dist = _pitch_distance(p.reshape(-1, 2), th.reshape(-1), geo).reshape(th.shape)
    pieces = tyre_pieces(theta, 0.0, r=r, geometry=geo)
    outer = (s[None, :] <= pieces.s_end[:, PIECES.index("upper_R")][:, None])
    return [
        compare(f"tyre curve closed and continuous ({theta.size} theta incl. 17 and 160 deg, {m} s steps): "
                "max(|p(s + ds) - p(s)| - L ds, |p(0) - p(1)|)", np.maximum(np.maximum(jump, 0), closure), TOL),
        compare("tyre curve: outer side (pieces upper_L ... upper_R) at distance r from the pitch curve",
                np.where(outer, dist - r, 0.0).reshape(-1), TOL),
        compare("tyre curve: every point within r of the pitch curve (inner side, caps, joins inside the swept "
                "region)", np.maximum(dist - r, 0.0).reshape(-1), TOL),
    ]


def _support_rows(rng: np.random.Generator, geo: Geometry, r: float) -> list[CheckResult]:
    nb = BRUTE_SAMPLES
    legs = rng.integers(0, 4, nb)
    q = np.stack([rng.uniform(THETA_MIN, THETA_MAX, nb), rng.uniform(-np.pi, np.pi, nb),
                  rng.uniform(-1.2, 1.2, nb)], -1)
    normal = rng.normal(size=(nb, 3)) * [0.3, 0.3, 1.0]
    normal[: nb // 2] = (0.0, 0.0, 1.0)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    h = np.empty(nb)
    hmin = np.empty(nb)
    res = np.empty(nb)
    for k, leg in enumerate(LEGS):
        m = legs == k
        gc = ground_contact(q[m], leg, normal[m], r=r, geometry=geo)
        h[m] = np.einsum("ni,ni->n", gc.point, normal[m])
        for i in np.flatnonzero(m):
            b, rb = _brute_heights(q[i:i + 1], leg, normal[i], r, BRUTE_S, geo)
            hmin[i], res[i] = b[0], rb[0]
    return [
        compare(f"ground_contact height <= every sampled surface point ({nb} q x {BRUTE_S} s x 3 w, half n = z, "
                "half tilted normals, 4 legs)", np.maximum(h - hmin, 0.0), TOL),
        compare(f"ground_contact height vs the sampled minimum, in units of the sampling resolution "
                f"(L / {BRUTE_S} / 2)^2 / (2 r)", (hmin - h) / res, 1.0),
    ]


def _continuity_rows(geo: Geometry, r: float) -> list[CheckResult]:
    """Height of the support point over fine sweeps of theta (beta fixed) and beta (theta fixed), jumps between
    neighbouring samples in units of step x Lipschitz bound (the largest material-point speed |n . J| x 1.01)."""
    rows = []
    for name, col, n in (("theta", 0, 20001), ("beta", 1, 20001)):
        worst = []
        for fixed in (0.3, 1.2, 2.4):
            if col == 0:
                sweep = np.linspace(THETA_MIN, THETA_MAX, n)
                q = np.stack([sweep, np.full(n, fixed - 1.0), np.full(n, 0.2)], -1)
            else:
                sweep = np.linspace(-np.pi, np.pi, n)
                q = np.stack([np.full(n, THETA_MIN + fixed), sweep, np.full(n, 0.2)], -1)
            gc = ground_contact(q, "FL", r=r, geometry=geo)
            hz = gc.point[:, 2]
            speed = np.abs(gc.jacobian[:, 2, col]).max() * 1.01
            worst.append(np.abs(np.diff(hz)) / (speed * (sweep[1] - sweep[0])))
        rows.append(compare(f"support height continuous in {name}: max jump between neighbours of 3 sweeps of "
                            f"{n} / (step x Lipschitz bound max|dh/d{name}|)", np.concatenate(worst), 1.0))
    return rows


def _wheel_rows(rng: np.random.Generator, geo: Geometry, r: float) -> list[CheckResult]:
    n = 2000
    beta = rng.uniform(-np.pi, np.pi, n)
    gamma = np.where(np.arange(n) < n // 2, 0.0, rng.uniform(-1.2, 1.2, n))
    rows = []
    for leg in LEGS:
        gc = ground_contact(np.stack([np.full(n, THETA0), beta, gamma], -1), leg, r=r, geometry=geo)
        O = leg_frame_to_robot(np.zeros((n, 3)), gamma, leg, geometry=geo)  # the motor axis at that gamma
        depth = O[:, 2] - gc.point[:, 2]
        rows.append(depth - ((geo.R + r) * np.cos(gamma) + geo.T / 2 * np.abs(np.sin(gamma))))
    err = np.concatenate(rows)
    flat = np.concatenate([e[: n // 2] for e in np.split(err, 4)])
    return [
        compare(f"wheel mode (theta = 17 deg, gamma = 0): support point R + r = {geo.R + r:g} m below the motor "
                "axis O for every beta (4 legs)", flat, TOL),
        compare("wheel mode, ABAD tilt |gamma| <= 1.2: depth below O = (R + r) cos(gamma) + T/2 |sin(gamma)| "
                "(edge w = -+T/2)", err, TOL),
    ]


def _smooth_branch(gc: Any) -> np.ndarray:
    """The smooth branch of the support height at each ground contact: the lowest point's piece and tyre edge (w
    -T/2, 0, T/2); where either switches, the height has a kink (:mod:`legkin.wheel_leg._differences`)."""
    return np.asarray(gc.piece * 3 + np.sign(gc.w).astype(np.int64) + 1)


def _envelope_row(rng: np.random.Generator, geo: Geometry, r: float, n: int) -> CheckResult:
    q = np.stack([rng.uniform(THETA_MIN + 1e-5, THETA_MAX - 1e-5, n), rng.uniform(-np.pi, np.pi, n),
                  rng.uniform(-1.2, 1.2, n)], -1)
    err = np.zeros(n)
    one_sided = np.zeros(n, dtype=bool)
    for k, leg in enumerate(LEGS):
        m = np.flatnonzero(np.arange(n) % 4 == k)

        def height(x: np.ndarray, rows: np.ndarray, leg: str = leg) -> tuple[np.ndarray, np.ndarray]:
            gc = ground_contact(x, leg, r=r, geometry=geo)
            return gc.point[:, 2:], _smooth_branch(gc)

        gc = ground_contact(q[m], leg, r=r, geometry=geo)
        for c in range(3):
            lower, upper = (THETA_MIN, THETA_MAX) if c == 0 else (-np.inf, np.inf)
            d, fitted = derivative(height, q[m], c, FD_STEP, lower, upper, (gc.point[:, 2:], _smooth_branch(gc)))
            err[m] = np.maximum(err[m], np.abs(d[:, 0] - gc.jacobian[:, 2, c]))
            one_sided[m] |= fitted
    left = ~np.isfinite(err)
    return compare(f"support height derivative (central differences, h = {FD_STEP:g}; {one_sided.sum()} across a "
                   f"switch of the lowest piece or tyre edge: one-sided, second order, {left.sum()} left out) "
                   "= n . material Jacobian (envelope theorem; the rolling does not change the height)",
                   err[~left], TOL_FD)


def _pinocchio_rows(rng: np.random.Generator, r: float) -> list[CheckResult]:
    """The material-point Jacobian against Pinocchio's closed-loop Jacobian of that point on its rim link."""
    import pinocchio as pin

    from ..robot import load

    robot = load("wheel_leg")
    geo = Geometry.from_params(robot.params)
    n = PIN_SAMPLES
    leg_q = np.stack([rng.uniform(THETA_MIN, THETA_MAX, 4 * n), rng.uniform(-np.pi, np.pi, 4 * n),
                      rng.uniform(-1.2, 1.2, 4 * n)], -1).reshape(n, 4, 3)
    qs = configuration(robot, leg_q)
    legs = np.arange(n) % 4
    err = np.zeros(n)
    pos = np.zeros(n)
    counts = np.zeros(len(PIECES), dtype=int)
    S_ind = np.array([[1.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    model, data = robot.model, robot.data
    for i in range(n):
        leg = LEGS[legs[i]]
        gc = ground_contact(leg_q[i, legs[i]], leg, r=r, geometry=geo)
        counts[int(gc.piece)] += 1
        fid = robot.frame_id(f"{leg}_{LINK_NAMES[int(gc.link)]}")
        pin.computeJointJacobians(model, data, qs[i])
        pin.updateFramePlacements(model, data)
        J6 = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        rvec = gc.point - data.oMf[fid].translation
        Jp = J6[:3] - np.cross(rvec, J6[3:].T).T
        Jc = robot.constraint_jacobian(qs[i])
        iv = [robot.idx_v(f"{leg}_{j}") for j in ("phi_L", "phi_R", "abad")]
        pv = [robot.idx_v(f"{leg}_hinge_{h}_{side}") for h in "ABDF" for side in "LR"]
        S_pas = -np.linalg.pinv(Jc[:, pv], rcond=1e-10) @ (Jc[:, iv] @ S_ind)
        err[i] = np.abs(Jp[:, iv] @ S_ind + Jp[:, pv] @ S_pas - gc.jacobian).max()
        # the same material point at a nearby configuration: Pinocchio's link placement x the local point
        local = data.oMf[fid].rotation.T @ rvec
        dq = rng.normal(size=3) * 1e-4
        q2 = leg_q[i].copy()
        q2[legs[i]] += dq
        q2[legs[i], 0] = np.clip(q2[legs[i], 0], THETA_MIN, THETA_MAX)
        step = q2[legs[i]] - leg_q[i, legs[i]]
        qc2 = configuration(robot, q2[None])[0]
        pin.framesForwardKinematics(model, data, qc2)
        moved = data.oMf[fid].translation + data.oMf[fid].rotation @ local
        pos[i] = np.linalg.norm(moved - (gc.point + gc.jacobian @ step)) / max(np.linalg.norm(step) ** 2, 1e-300)
    used = ", ".join(f"{PIECES[k]} {c}" for k, c in enumerate(counts) if c)
    return [
        compare(f"material-point Jacobian vs Pinocchio closed-loop Jacobian of that point on its rim link "
                f"({n} q, pieces: {used})", err, TOL),
        compare("material point = Pinocchio link placement x local point after a 1e-4 rad move: second-order "
                "remainder / |dq|^2 (m/rad^2; bounded: a fixed point of the link)", pos, 1.0),
    ]


def _lab_rows(rng: np.random.Generator, n: int) -> list[CheckResult]:
    rows = []
    for r_lab in LAB_R:
        c = lab_comparison(n, rng, r_lab)
        nq = c["none_q"]
        hb = np.empty(0)
        res = np.empty(0)
        if nq.shape[0]:
            k = min(nq.shape[0], 60)
            q = np.stack([nq[:k, 0], nq[:k, 1], np.zeros(k)], -1)
            gc = ground_contact(q, "FL", r=r_lab)
            hmin, res = _brute_heights(q, "FL", np.array([0.0, 0.0, 1.0]), r_lab, BRUTE_S, Geometry())
            hb = (hmin - gc.point[:, 2]) / res
        pieces = ", ".join(f"{k} {v}" for k, v in c["none_pieces"].items())
        rows.append(compare(
            f"lab contact_map (r = {r_lab:g}): legkin = lab point where it answers ({c['answered']}/{n}; same "
            f"point {c['agree']}, same piece {c['same_piece']})", c["diff"], TOL))
        rows.append(compare(
            f"lab contact_map (r = {r_lab:g}) 'no normal contact' on {n - c['answered']}/{n} "
            f"({100 * (n - c['answered']) / n:.1f} %; {c['none_caps']} on the tip caps about H, "
            f"{c['none_above_hip']} above the hip): legkin's lowest point there [{pieces}] vs brute force "
            "(resolution units)", hb, 1.0))
    return rows


def _contact_sigma_min(q: np.ndarray, leg: str, r: float) -> np.ndarray:
    """sigma_min of d(ground contact point) / d(theta, beta, gamma) at each q (n, 3) (m/rad), by central differences
    (h = :data:`SIGMA_STEP`, theta kept in its limits): the contact point slides over the tyre, so the material-point
    Jacobian is not its derivative. Near a fold of the stance IK (theta at an extremum of a support circle's
    centre distance |c(theta)|) sigma_min -> 0 and the inverse is ill-conditioned."""
    jac = np.empty((len(q), 3, 3))
    lim_lo, lim_hi = [THETA_MIN, -9.0, -9.0], [THETA_MAX, 9.0, 9.0]
    for c in range(3):
        hi, lo = q.copy(), q.copy()
        hi[:, c] += SIGMA_STEP
        lo[:, c] -= SIGMA_STEP
        hi, lo = np.clip(hi, lim_lo, lim_hi), np.clip(lo, lim_lo, lim_hi)
        diff = ground_contact(hi, leg, r=r).point - ground_contact(lo, leg, r=r).point
        jac[:, :, c] = diff / (hi[:, c] - lo[:, c])[:, None]
    return np.linalg.svd(jac, compute_uv=False)[:, -1]


def _ik_rows(rng: np.random.Generator, r: float, n: int) -> list[CheckResult]:
    q = np.stack([rng.uniform(THETA_MIN, THETA_MAX, n), rng.uniform(-np.pi, np.pi, n),
                  rng.uniform(-ABAD_LIMIT * 0.9, ABAD_LIMIT * 0.9, n)], -1)
    err = np.full(n, np.nan)
    found = np.full(n, np.nan)
    nsol = np.zeros(n, dtype=int)
    for k, leg in enumerate(LEGS):
        m = np.arange(n) % 4 == k
        target = ground_contact(q[m], leg, r=r).point
        qs, ok = stance_ik(target, leg, r=r, return_mask=True)
        back = ground_contact(np.where(ok[:, None], qs, q[m]), leg, r=r).point
        err[m] = np.where(ok, per_sample(back - target), np.nan)
        allq = stance_ik_all(target, leg, r=r)
        d = allq - q[m][:, None, :]
        d[..., 1:] = np.pi - np.mod(np.pi - d[..., 1:], 2 * np.pi)
        found[m] = np.min(np.where(np.isnan(d[..., 0]), np.inf, np.abs(d).max(-1)), axis=1)
        found[m] *= _contact_sigma_min(q[m], leg, r)
        nsol[m] = np.isfinite(allq[..., 0]).sum(-1)
    return [
        compare(f"stance_ik round trip: ground_contact(stance_ik(target)) = target, {np.isfinite(err).sum()}/{n} "
                f"solved (targets = ground contacts of in-limit q, 4 legs)", err, TOL),
        compare(f"stance_ik_all: the sampled q among the solutions ({nsol.min()}-{nsol.max()} solutions per target; "
                "q distance, max-norm rad, x sigma_min(d contact / dq), m)", found, TOL),
    ]


def standing_base_heights(r: float = TYRE_THICKNESS) -> dict[str, float]:
    """Base heights (m) that put the lowest foot / tyre point of the SRDF standing poses at z = 0 (floating
    base, identity orientation): wheel_leg pose ``wheel`` (ground_contact of each leg at the pose's (theta,
    beta, gamma) = (17 deg, 0, 0), n = z) and quadruped pose ``standing`` (Pinocchio foot frames minus the
    collision sphere radius 0.022 m; also without it). Measured from the poses' own base heights (the SRDFs'
    ``root_joint`` entries, 0 where absent), which are also returned."""
    import pinocchio as pin

    from ..robot import load

    out = {}
    wl_robot = load("wheel_leg", floating=True)
    geo = Geometry.from_params(wl_robot.params)
    z = [float(ground_contact(np.array([THETA0, 0.0, 0.0]), leg, r=r, geometry=geo).point[2]) for leg in LEGS]
    out["wheel_leg"] = -min(z)
    pin.framesForwardKinematics(wl_robot.model, wl_robot.data, wl_robot.poses["wheel"])
    o_z = [float(wl_robot.data.oMf[wl_robot.frame_id(f"{leg}_leg")].translation[2]) for leg in LEGS]
    z_base = float(wl_robot.poses["wheel"][2])  # the SRDF pose's own base height (0 before it had one)
    out["wheel_leg (Pinocchio: R + r - z of O)"] = geo.R + r - (min(o_z) - z_base)
    out["wheel_leg (SRDF pose 'wheel' base z)"] = z_base
    quad = load("quadruped", floating=True)
    pin.framesForwardKinematics(quad.model, quad.data, quad.poses["standing"])
    zq = float(quad.poses["standing"][2])  # measured from the pose's own base height
    feet = [float(quad.data.oMf[quad.frame_id(f"{f}_FOOT")].translation[2]) - zq for f in ("LF", "LH", "RF", "RH")]
    out["quadruped (foot spheres r = 0.022)"] = -min(feet) + 0.022
    out["quadruped (foot frames)"] = -min(feet)
    return out


def run(samples: int, rng: np.random.Generator) -> list[CheckResult]:
    """The check rows of the tyre surface, ground contact and stance IK (``samples`` sets the lab comparison
    and the Jacobian rows' sizes; the brute-force rows use :data:`BRUTE_SAMPLES`)."""
    geo = Geometry()
    r = TYRE_THICKNESS
    rows = _surface_rows(rng, geo, r)
    rows += _support_rows(rng, geo, r)
    rows += _continuity_rows(geo, r)
    rows += _wheel_rows(rng, geo, r)
    rows.append(_envelope_row(rng, geo, r, max(samples, 100)))
    rows += _pinocchio_rows(rng, r)
    rows += _lab_rows(rng, max(samples, 1000))
    rows += _ik_rows(rng, r, min(max(samples // 10, 20), IK_SAMPLES))
    heights = standing_base_heights(r)
    rows.append(compare(f"standing base height, wheel_leg pose 'wheel': {heights['wheel_leg']:.6f} m "
                        "(ground_contact) vs R + r - z(O) (Pinocchio)",
                        [heights["wheel_leg"] - heights["wheel_leg (Pinocchio: R + r - z of O)"]], TOL))
    return rows


__all__ = ["run", "lab_contact_map", "lab_comparison", "standing_base_heights", "LabContact", "LAB_R"]
_ = math
