"""wheel_leg tyre surface, ground contact and stance IK (issue 12)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from legkin.errors import InvalidInputError, InvalidParameterError, JointLimitError, UnreachableError
from legkin.wheel_leg import ground as gd
from legkin.wheel_leg import stance as sk
from legkin.wheel_leg import tyre as ty
from legkin.wheel_leg import tyre_checks as tc
from legkin.wheel_leg.frames import leg_frame_to_robot
from legkin.wheel_leg.geometry import ABAD_LIMIT, LEGS, THETA0, THETA_MAX, THETA_MIN, Geometry

DEG = math.pi / 180
GEO = Geometry()
R_T = ty.TYRE_THICKNESS


def _heights(q, leg, normal, m=3000, r=R_T):
    """Sampled minimum height of the tyre (m s samples x 3 w) and the sampling resolution bound."""
    h, res = tc._brute_heights(np.asarray(q, dtype=float)[None], leg, np.asarray(normal, dtype=float), r, m, GEO)
    return h[0], res[0]


# ---------------------------------------------------------------- the surface
@pytest.mark.parametrize("theta_deg", [17.0, 17.5, 30.0, 90.0, 110.4, 111.0, 140.0, 160.0])
def test_tyre_curve_closed_and_continuous(theta_deg):
    pcs = ty.tyre_pieces(theta_deg * DEG, 0.4)
    for k in range(16):
        assert np.linalg.norm(pcs.point(k, 1.0) - pcs.point((k + 1) % 16, 0.0)) < 1e-15
    assert np.all(np.diff(pcs.s_start) >= 0) and pcs.s_start[0] == 0 and abs(pcs.s_end[-1] - 1) < 1e-15
    s = np.linspace(0, 1, 5001)
    p = ty.tyre_point(np.full(s.shape, theta_deg * DEG), 0.4, s)
    assert np.linalg.norm(np.diff(p, axis=0), axis=1).max() <= float(pcs.length) / 5000 * (1 + 1e-9)
    assert np.linalg.norm(p[0] - p[-1]) < 1e-15


def test_tyre_pieces_kinds():
    # wheel mode: one circle of radius R + r about O on the outer side, the fillets have zero span
    pcs = ty.tyre_pieces(THETA0)
    for k in (0, 2, 4, 6):
        assert np.linalg.norm(pcs.centre[k]) < 1e-15 and pcs.radius[k] == pytest.approx(GEO.R + R_T, abs=1e-16)
    assert np.abs(pcs.span[[1, 3, 5]]).max() < 1e-12
    # open leg: a fillet about G on the outer side, the outer offsets at F trimmed (a point), caps of 180 deg
    pcs = ty.tyre_pieces(90 * DEG)
    G = pcs.names.index("G")
    assert pcs.span[G] > 1.0 and pcs.radius[G] == R_T
    assert pcs.radius[pcs.names.index("F_L")] == 0.0 and pcs.span[pcs.names.index("F_L_inner")] > 1.0
    assert pcs.span[pcs.names.index("cap_H_R")] == pytest.approx(math.pi)


# ---------------------------------------------------------------- ground contact
@settings(max_examples=25, deadline=None)
@given(theta=st.floats(THETA_MIN, THETA_MAX), beta=st.floats(-math.pi, math.pi), gamma=st.floats(-1.3, 1.3),
       tilt=st.tuples(st.floats(-0.4, 0.4), st.floats(-0.4, 0.4)), leg=st.sampled_from(LEGS))
def test_support_point_is_the_lowest(theta, beta, gamma, tilt, leg):
    n = np.array([tilt[0], tilt[1], 1.0])
    n /= np.linalg.norm(n)
    gc = gd.ground_contact(np.array([theta, beta, gamma]), leg, n)
    h = float(gc.point @ n)
    hmin, res = _heights([theta, beta, gamma], leg, n)
    assert h <= hmin + 1e-13  # never above a sampled surface point
    assert hmin - h <= res  # and the sampled minimum to the sampling resolution


def test_wheel_mode_depth():
    rng = np.random.default_rng(3)
    beta = rng.uniform(-np.pi, np.pi, 500)
    for leg in LEGS:
        gc = gd.ground_contact(np.stack([np.full(500, THETA0), beta, np.zeros(500)], -1), leg)
        O = leg_frame_to_robot(np.zeros(3), 0.0, leg)
        np.testing.assert_allclose(O[2] - gc.point[:, 2], GEO.R + R_T, rtol=0, atol=1e-12)
        assert np.all(gc.w == 0.0)


def test_tilt_moves_contact_to_an_edge():
    q = np.array([60 * DEG, 0.2, 0.3])
    for leg in LEGS:
        gc = gd.ground_contact(q, leg)
        assert abs(float(gc.w)) == GEO.T / 2
        qm = q * [1, 1, -1]
        assert float(gd.ground_contact(qm, leg).w) == -float(gc.w)
        assert float(gd.ground_contact(q * [1, 1, 0], leg).w) == 0.0


def test_envelope_jacobian():
    rng = np.random.default_rng(5)
    q = np.stack([rng.uniform(THETA_MIN + 1e-4, THETA_MAX - 1e-4, 50), rng.uniform(-3, 3, 50),
                  rng.uniform(-1, 1, 50)], -1)
    gc = gd.ground_contact(q, "RR")
    for c in range(3):
        dq = np.zeros(3)
        dq[c] = 1e-6
        fd = (gd.ground_contact(q + dq, "RR").point[:, 2] - gd.ground_contact(q - dq, "RR").point[:, 2]) / 2e-6
        np.testing.assert_allclose(fd, gc.jacobian[:, 2, c], atol=1e-8)


def test_pinocchio_material_jacobian(monkeypatch):
    monkeypatch.setattr(tc, "PIN_SAMPLES", 24)
    rows = tc._pinocchio_rows(np.random.default_rng(2), R_T)
    assert all(r.passed for r in rows), [(r.name, r.max_error) for r in rows]


def test_lab_contact_map_comparison():
    c = tc.lab_comparison(2000, np.random.default_rng(11), 0.019)
    assert c["agree"] == c["answered"] and c["diff"].max() < 1e-12
    frac = 1 - c["answered"] / c["n"]
    assert 0.10 < frac < 0.25  # the lab's ~16 % "no normal contact"
    assert c["none_caps"] + c["none_above_hip"] >= 0.9 * (c["n"] - c["answered"])


# ---------------------------------------------------------------- contract rules
def test_single_equals_batch_row():
    rng = np.random.default_rng(8)
    q = np.stack([rng.uniform(THETA_MIN, THETA_MAX, 7), rng.uniform(-3, 3, 7), rng.uniform(-1, 1, 7)], -1)
    n = np.array([0.1, -0.2, 1.0])
    for leg in ("FL", "RR"):
        b = gd.ground_contact(q, leg, n)
        for i in range(7):
            s = gd.ground_contact(q[i], leg, n)
            assert np.array_equal(s.point, b.point[i]) and np.array_equal(s.jacobian, b.jacobian[i])
            assert int(s.piece) == b.piece[i] and float(s.s) == b.s[i] and float(s.w) == b.w[i]
        bz = gd.ground_contact(q, leg)
        for i in range(7):  # the single-call fast path (default normal) gives the batch row bit for bit
            s = gd.ground_contact(q[i], leg)
            assert np.array_equal(s.point, bz.point[i]) and np.array_equal(s.jacobian, bz.jacobian[i])
            assert int(s.piece) == bz.piece[i] and float(s.s) == bz.s[i] and int(s.link) == bz.link[i]
    s_ = np.linspace(0, 1, 7)
    pb = ty.tyre_point(q[:, 0], q[:, 1], s_)
    for i in range(7):
        assert np.array_equal(ty.tyre_point(q[i, 0], q[i, 1], s_[i]), pb[i])


def test_bad_inputs():
    q = np.array([1.0, 0.1, 0.0])
    for bad in ([np.nan, 0, 0], [1.0, np.inf, 0], [1.0 + 0j, 0, 0], [1.0, 0.0], [0.1, 0, 0], [3.0, 0, 0]):
        with pytest.raises(InvalidInputError):
            gd.ground_contact(np.array(bad), "FL")
    with pytest.raises(InvalidInputError):
        gd.ground_contact(q, "FL", (0.0, 0.0, 0.0))
    with pytest.raises(InvalidInputError):
        gd.ground_contact(q, "FL", (0.0, np.nan, 1.0))
    with pytest.raises(InvalidParameterError):
        gd.ground_contact(q, "XX")
    with pytest.raises(InvalidParameterError):
        gd.ground_contact(q, "FL", r=0.2)
    with pytest.raises(InvalidInputError):
        ty.tyre_point(1.0, 0.0, 1.5)
    with pytest.raises(InvalidInputError):
        ty.tyre_point(1.0, 0.0, np.nan)
    with pytest.raises(InvalidInputError):
        sk.stance_ik(np.array([np.nan, 0, 0]), "FL")
    with pytest.raises(InvalidInputError):
        sk.stance_ik(np.zeros(2), "FL")


# ---------------------------------------------------------------- stance IK
def test_stance_ik_round_trip_and_all_solutions():
    rng = np.random.default_rng(21)
    n = 12
    q = np.stack([rng.uniform(THETA_MIN, THETA_MAX, n), rng.uniform(-np.pi, np.pi, n),
                  rng.uniform(-1.4, 1.4, n)], -1)
    for leg in ("FL", "FR"):
        target = gd.ground_contact(q, leg).point
        qs, ok = sk.stance_ik(target, leg, return_mask=True)
        assert ok.all()
        assert np.abs(qs[:, 2]).max() <= ABAD_LIMIT
        np.testing.assert_allclose(gd.ground_contact(qs, leg).point, target, atol=1e-12, rtol=0)
        allq = sk.stance_ik_all(target, leg)
        d = allq - q[:, None, :]
        d[..., 1:] = np.pi - np.mod(np.pi - d[..., 1:], 2 * np.pi)
        assert np.nanmin(np.abs(d).max(-1), axis=1).max() < 1e-9
        for i in range(n):  # q_near: the sampled q itself (it is among the in-limit solutions)
            near = sk.stance_ik(target[i], leg, q_near=q[i])
            d = near - q[i]
            d[1:] = np.pi - np.mod(np.pi - d[1:], 2 * np.pi)
            assert np.abs(d).max() < 1e-9


def test_stance_ik_unreachable():
    far = np.array([2.0, 2.0, -2.0])
    with pytest.raises(UnreachableError):
        sk.stance_ik(far, "FL")
    t = np.stack([far, gd.ground_contact(np.array([1.0, 0.2, 0.1]), "FL").point])
    qs, ok = sk.stance_ik(t, "FL", return_mask=True)
    assert ok.tolist() == [False, True] and np.isnan(qs[0]).all() and np.isfinite(qs[1]).all()


def test_stance_ik_single_equals_batch_and_rules():
    """The single-call fast path (one kernel call) and the batch loop give the same bits; the default answer is
    the first solution of stance_ik_all inside the limits, q_near the nearest; a tilted normal takes the batch
    path; JointLimitError when only |gamma| > ABAD_LIMIT solutions exist."""
    rng = np.random.default_rng(5)
    n = 8
    q = np.stack([rng.uniform(THETA_MIN, THETA_MAX, n), rng.uniform(-np.pi, np.pi, n),
                  rng.uniform(-1.4, 1.4, n)], -1)
    for leg in ("RR", "RL"):
        target = gd.ground_contact(q, leg).point
        batch = sk.stance_ik(target, leg)
        batch_all = sk.stance_ik_all(target, leg, limits=True)
        near_b = sk.stance_ik(target, leg, q_near=q)
        for i in range(n):
            single = sk.stance_ik(target[i].copy(), leg)
            assert np.array_equal(single, batch[i])
            assert np.array_equal(single, batch_all[i, 0])
            s_all = sk.stance_ik_all(target[i].copy(), leg, limits=True)
            k = s_all.shape[0]
            assert np.array_equal(s_all, batch_all[i, :k]) and np.isnan(batch_all[i, k:]).all()
            assert np.array_equal(sk.stance_ik(target[i].copy(), leg, q_near=q[i].copy()), near_b[i])
            lst = sk.stance_ik(target[i].tolist(), leg)  # a list: the checked path, the same answer
            assert np.array_equal(lst, single)
    tilt = np.array([0.1, -0.2, 1.0])
    tq = np.array([1.0, 0.4, 0.2])
    t = gd.ground_contact(tq, "FL", tilt).point
    sol = sk.stance_ik(t, "FL", normal=tilt)
    np.testing.assert_allclose(gd.ground_contact(sol, "FL", tilt).point, t, atol=1e-12, rtol=0)
    # a target reached only with |gamma| > ABAD_LIMIT (the leg swung over the top, gamma ~ 2.6 rad)
    t_out = gd.ground_contact(np.array([1.2, 0.3, 2.6]), "FL").point
    sols = sk.stance_ik_all(t_out, "FL")
    same, mask = sk.stance_ik_all(t_out, "FL", return_mask=True)
    assert np.array_equal(same, sols, equal_nan=True) and np.array_equal(mask, ~np.isnan(sols).any(-1))
    both, masks = sk.stance_ik_all(np.stack([t_out, t_out]), "FL", return_mask=True)
    assert masks.shape == both.shape[:-1] and np.array_equal(masks[0], ~np.isnan(both[0]).any(-1)) and masks.any()
    assert sols.shape[0] >= 1 and np.all(np.abs(sols[:, 2]) > ABAD_LIMIT)
    with pytest.raises(JointLimitError) as info:
        sk.stance_ik(t_out, "FL")
    assert (info.value.joint, info.value.upper) == ("FL_abad", ABAD_LIMIT) and np.array_equal(info.value.target, t_out)
    assert sk.stance_ik(t_out, "FL", limits=False)[2] == pytest.approx(2.6, abs=1e-9)


def test_tyre_point_batch_reuses_the_pieces_of_equal_theta_bit_for_bit():
    """A batch computes the pieces once per run of equal theta (one configuration's curve sampled in s); the points
    are the single calls' bit for bit, also where theta changes within the batch and in the threads' chunks."""
    rng = np.random.default_rng(5)
    theta = np.repeat(rng.uniform(THETA_MIN, THETA_MAX, 4), 100)  # runs of 100 equal theta
    theta[50] = THETA_MIN  # a run broken inside
    beta, s, w = rng.uniform(-3, 3, 400), rng.uniform(0, 1, 400), rng.uniform(-0.01, 0.01, 400)
    batch = ty.tyre_point(theta, beta, s, w)
    single = np.array([ty.tyre_point(float(t), float(b), float(x), float(y)) for t, b, x, y in zip(theta, beta, s, w)])
    np.testing.assert_array_equal(batch, single)


def test_stance_ik_all_finds_the_roots_next_to_a_fold():
    """The check sweep (issue 25): seed 14, 10^4 samples, leg FR at (theta, beta, gamma) = (2.3103, -2.9923, -1.1215),
    its contact on the tip cap about H_R: theta is 5e-4 rad from the fold of |H|^2(theta) (its minimum, at 2.3108),
    where the curve crosses the level and comes back between two grid nodes of one sign, and stance_ik found no
    solution. Now the roots on both sides of a fold are found: that sample, and samples of theta within two grid
    cells of each fold of the five |c|^2 rows, are among stance_ik_all's solutions, to the inverse's conditioning
    (the check row's measure)."""
    q0 = np.array([2.3103307936437836, -2.9922927397940575, -1.1214610495917927])
    allq = sk.stance_ik_all(gd.ground_contact(q0, "FR").point, "FR")
    assert np.abs(allq - q0).max(-1).min() < 1e-9, allq
    th, tab, runs, nrun = sk._centre_table(GEO)
    folds = np.unique(np.concatenate([th[runs[k, 1 : nrun[k] - 1]] for k in range(5)]))
    assert len(folds) >= 1, folds  # one: the minimum of |H|^2
    rng = np.random.default_rng(3)
    n = 200
    cell = th[1] - th[0]
    theta = np.repeat(folds, n) + rng.uniform(-2 * cell, 2 * cell, n * len(folds))
    q = np.stack([theta, rng.uniform(-np.pi, np.pi, theta.size), rng.uniform(-1.4, 1.4, theta.size)], -1)
    far = []
    for leg in ("FL", "FR"):
        allq = sk.stance_ik_all(gd.ground_contact(q, leg).point, leg)
        d = allq - q[:, None, :]
        d[..., 1:] = np.pi - np.mod(np.pi - d[..., 1:], 2 * np.pi)
        dist = np.min(np.where(np.isnan(d[..., 0]), np.inf, np.abs(d).max(-1)), axis=1)
        # the check row's measure: the q distance x sigma_min of the contact point's derivative (m)
        scaled = dist * tc._contact_sigma_min(q, leg, R_T)
        assert np.all(scaled <= tc.TOL), (leg, np.flatnonzero(~(scaled <= tc.TOL)))
        far.append(dist.max())
    # next to the fold the inverse is ill-conditioned: a solution reproducing the target can be > 1e-9 rad away
    assert max(far) > 1e-9, far


def test_difference_rows_stay_on_one_smooth_branch():
    """The check sweep (issue 25) failed two central-difference rows at 10^5 samples, by stencils that are not
    smooth: the support height across a switch of the lowest point (9.0e-3 against 1e-8 at gamma = 5.5e-7, the
    tyre edge switching at gamma = 0: seed 2; a jump between the tip caps, 6.9e-2; a jump from lower_L to upper_L,
    2.0e-2), and the contact point with theta 1.5e-7 rad above THETA_MIN (the stencil clipped off-centre: 3.7e-8,
    seed 2). Those stencils are now one-sided on the centre's branch (second order); the derivatives match."""
    from legkin import wheel_leg as wl
    from legkin.wheel_leg import checks as wc
    from legkin.wheel_leg._differences import derivative

    q = np.array([[2.5789600468405016, 1.0836373151802983, 5.510506475570054e-07],
                  [1.6660385160682967, -3.1415925257589272, 0.020420628913310868],
                  [1.3960195269973472, 0.8349840502419519, -0.20486316276301308]])
    for leg, qi, c in (("RL", q[0], 2), ("FR", q[1], 1), ("RR", q[2], 1)):
        def height(x, rows, leg=leg):
            g = gd.ground_contact(x, leg)
            return g.point[:, 2:], tc._smooth_branch(g)

        gc = gd.ground_contact(qi[None], leg)
        d, one_sided = derivative(height, qi[None], c, tc.FD_STEP, -np.inf, np.inf, height(qi[None], None))
        assert one_sided[0], (leg, qi)  # the central stencil crosses a switch
        assert abs(d[0, 0] - gc.jacobian[0, 2, c]) <= tc.TOL_FD, (leg, d[0, 0], gc.jacobian[0, 2, c])
    q3 = np.array([[0.29670612319213113, -1.8369875173680323, 0.48246826710999324]])
    kw = {"alpha": np.array([-2.3000814363123685]), "w": np.array([1.0189088797893375e-05])}

    def contact(x, rows):
        return wl.fk(x, "FL", **kw), None

    d, one_sided = derivative(contact, q3, 0, wc.FD_STEP, wl.THETA_MIN, wl.THETA_MAX, contact(q3, None))
    assert one_sided[0] and np.abs(d[0] - wl.jacobian(q3, "FL", **kw)[0, :, 0]).max() <= wc.TOL_FD
