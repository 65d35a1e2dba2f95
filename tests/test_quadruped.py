"""Quadruped analytic kinematics: checks against Pinocchio, IK properties, seed 002, error paths."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import legkin
from legkin.analytic import quadruped as aq
from legkin.checks import quadruped as checks

LEGS = aq.LEGS
L1 = math.hypot(aq.X23, aq.Z23)
L2 = aq.X34


def test_checks_pass():
    rows = checks.run(300, np.random.default_rng(7))
    failed = [r for r in rows if not r.passed]
    assert not failed, failed
    assert all(r.samples > 0 for r in rows)


def test_urdf_limits_match_analytic_constants(quadruped):
    for leg in LEGS:
        for k, joint in enumerate(("HAA", "HFE", "KFE")):
            iq = quadruped.idx_q(f"{leg}_{joint}")
            assert quadruped.model.lowerPositionLimit[iq] == aq.JOINT_LIMITS[k, 0]
            assert quadruped.model.upperPositionLimit[iq] == pytest.approx(aq.JOINT_LIMITS[k, 1], abs=1e-15)


def test_folded_leg_at_zero_matches_reference():
    # reference: q = 0 is a folded leg, foot at (-0.05588, 0.1077, -0.041509) from the hip
    p = aq.foot_position(np.zeros(3), "LF") - aq.hip_position("LF")
    np.testing.assert_allclose(p, [aq.X23 + aq.X34, aq.Y12, aq.Z23], atol=1e-15)


def test_jacobian_matches_central_differences(rng):
    q = rng.uniform(-3, 3, (50, 3))
    h = 1e-6
    for leg in LEGS:
        jac = aq.foot_jacobian(q, leg, foot_z=-0.015)
        for k in range(3):
            dq = np.zeros(3)
            dq[k] = h
            fd = (aq.foot_position(q + dq, leg, foot_z=-0.015) - aq.foot_position(q - dq, leg, foot_z=-0.015)) / (2 * h)
            np.testing.assert_allclose(jac[..., k], fd, atol=1e-9)


def _reachable_target(leg, direction, radius_fraction, s_u):
    """A foot target built from geometry: distance r in the leg plane, any direction."""
    h = aq.hip_position(leg)
    r = abs(L1 - L2) + radius_fraction * (L1 + L2 - abs(L1 - L2))
    ux, uz = r * math.cos(direction), r * math.sin(direction)
    uz = s_u * abs(uz)
    _, sy = (1.0, 1.0) if leg[0] == "L" else (1.0, -1.0)
    return h + np.array([ux, sy * aq.Y12, uz])


@settings(max_examples=300, deadline=None)
@given(
    leg=st.sampled_from(LEGS),
    direction=st.floats(-math.pi, math.pi),
    frac=st.one_of(st.floats(0.0, 1.0), st.sampled_from([0.0, 1e-12, 1 - 1e-12, 1.0])),
    s_u=st.sampled_from([-1.0, 1.0]),
    tilt=st.floats(-math.pi, math.pi),
)
def test_ik_all_branches_reach_target_everywhere(leg, direction, frac, s_u, tilt):
    """Every branch of foot_ik_all lands on the target, over the whole workspace incl. its boundary."""
    p = _reachable_target(leg, direction, frac, s_u)
    # rotate the target about the abduction axis: still reachable
    h = aq.hip_position(leg)
    d = p - h
    c, s = math.cos(tilt), math.sin(tilt)
    p = h + np.array([d[0], c * d[1] - s * d[2], s * d[1] + c * d[2]])
    q_all = aq.foot_ik_all(p, leg)
    assert q_all.shape == (4, 3)
    err = np.linalg.norm(aq.foot_position(q_all, leg) - p, axis=-1)
    assert np.all(err < 1e-12), err


@settings(max_examples=300, deadline=None)
@given(
    leg=st.sampled_from(LEGS),
    u=st.tuples(st.floats(0, 1), st.floats(0, 1), st.floats(0, 1)),
)
def test_ik_round_trip_inside_limits(leg, u):
    lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
    q = lo + np.array(u) * (hi - lo)
    p = aq.foot_position(q, leg)
    q_ik = aq.foot_ik(p, leg, q_ref=q)
    assert aq.within_limits(q_ik)
    assert np.linalg.norm(aq.foot_position(q_ik, leg) - p) < 1e-12
    # joint agreement is conditioned by rho (distance to the abduction cylinder): 1.6e-16 m / rho
    d = p - aq.hip_position(leg)
    rho = math.sqrt(max(d[1] ** 2 + d[2] ** 2 - aq.Y12**2, 0.0))
    assert np.max(np.abs(q_ik - q)) < max(1e-12, 1e-15 / max(rho, 1e-300)) or rho < 1e-9


def test_four_branches_are_distinct_solutions():
    p = aq.foot_position(np.array([0.1, 0.8, 1.2]), "RF")
    q_all = aq.foot_ik_all(p, "RF")
    assert len({tuple(np.round(q, 9)) for q in q_all}) == 4


def test_branch_choice_follows_q_ref_and_limits():
    # a pose with large q2 has its limit-respecting solution on the s_u = +1 branch
    q = np.array([0.2, 2.9, 1.0])
    p = aq.foot_position(q, "LH")
    np.testing.assert_allclose(aq.foot_ik(p, "LH"), q, atol=1e-12)
    q_all = aq.foot_ik_all(p, "LH")
    inside = aq.within_limits(q_all)
    assert inside.sum() >= 1
    # nearest-to-q_ref picks the given branch among those inside the limits
    for q_in in q_all[inside]:
        np.testing.assert_allclose(aq.foot_ik(p, "LH", q_ref=q_in), q_in, atol=1e-12)


def test_batch_returns_nan_and_mask():
    good = aq.foot_position(np.array([0.0, 0.75, 1.5]), "LF")
    far = aq.hip_position("LF") + np.array([0.0, 0.0, -1.0])
    inside = aq.hip_position("LF") + np.array([0.0, 0.05, 0.0])
    limits_only = aq.foot_position(np.array([0.0, -0.5, 1.0]), "LF")  # q2 < 0: outside the limits
    p = np.stack([good, far, inside, limits_only])
    q, mask = aq.foot_ik(p, "LF", return_mask=True)
    assert mask.tolist() == [True, False, False, False]
    assert np.all(np.isfinite(q[0])) and np.all(np.isnan(q[1:]))
    q_all, reach = aq.foot_ik_all(p, "LF", return_mask=True)
    assert reach.shape == (4, 4)
    assert reach[:, 0].tolist() == [True, False, False, True]
    assert np.all(np.isnan(q_all[1:3]))
    q_plain = aq.foot_ik(p, "LF")
    np.testing.assert_array_equal(np.isnan(q_plain), np.isnan(q))


def test_scalar_errors_say_why_and_by_how_much():
    h = aq.hip_position("LF")
    with pytest.raises(legkin.UnreachableError, match="beyond full stretch") as info:
        aq.foot_ik(h + np.array([0.0, 0.0, -1.0]), "LF")
    assert "by" in str(info.value)
    with pytest.raises(legkin.UnreachableError, match="abduction cylinder"):
        aq.foot_ik(h + np.array([0.0, 0.05, 0.0]), "LF")
    with pytest.raises(legkin.UnreachableError, match="too close"):
        aq.foot_ik(h + np.array([0.0, aq.Y12, -0.01]), "LF")
    with pytest.raises(legkin.JointLimitError, match="outside the joint limits"):
        aq.foot_ik(aq.foot_position(np.array([0.0, -0.5, 1.0]), "LF"), "LF")
    with pytest.raises(legkin.UnreachableError):
        aq.foot_ik_all(h + np.array([0.0, 0.0, -1.0]), "LF")


@pytest.mark.parametrize(
    "call",
    [
        lambda: aq.foot_position(np.array([0.0, np.nan, 0.0]), "LF"),
        lambda: aq.foot_position(np.zeros(2), "LF"),
        lambda: aq.foot_jacobian(np.zeros((4, 2)), "LF"),
        lambda: aq.foot_ik(np.array([np.inf, 0.0, 0.0]), "LF"),
        lambda: aq.foot_ik(np.zeros(4), "LF"),
        lambda: aq.foot_ik_all(np.zeros((2, 2)), "LF"),
        lambda: aq.foot_ik(np.array([0.3, 0.3, -0.4]), "LF", q_ref=np.zeros(2)),
    ],
)
def test_bad_input_raises_value_error(call):
    with pytest.raises(ValueError):
        call()


def test_unknown_leg():
    with pytest.raises(legkin.InvalidParameterError, match="LF, LH, RF, RH"):
        aq.foot_position(np.zeros(3), "XX")


# ----------------------------------------------------------------------------- seed 002
def _q_textbook_region(rng, n):
    """Configurations inside the limits whose foot is below the hip (z_f > 0 in seed 002's frame)."""
    lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
    q = rng.uniform(lo, hi, (n, 3))
    return q


@pytest.mark.parametrize("leg", LEGS)
def test_textbook_ik_agrees_with_closed_form_on_its_branch(leg, rng):
    q = _q_textbook_region(rng, 2000)
    p = aq.foot_position(q, leg)
    theta = aq.textbook_ik(aq.textbook_frame(p, leg), aq.Y12, L1, L2)
    q_tb = aq.textbook_to_joints(theta, leg)
    q_branch = aq.foot_ik_all(p, leg)[:, 0, :]  # (s_u, k) = (-1, -1)
    ok = np.all(np.isfinite(q_tb), axis=-1)
    assert ok.mean() > 0.99
    np.testing.assert_allclose(q_tb[ok], q_branch[ok], atol=2e-11)
    # and it is a solution: the foot lands on the target
    np.testing.assert_allclose(aq.foot_position(q_tb[ok], leg), p[ok], atol=1e-12)


@pytest.mark.xfail(strict=True, reason="seed 002 as printed uses atan(x_f/z_f): wrong for z_f < 0")
def test_textbook_literal_atan_fails_for_negative_zf():
    # a foot above the abduction axis (z_f < 0 in seed 002's z-down frame) on the textbook branch
    q = np.array([0.3, 2.6, 1.0])
    p = aq.foot_position(q, "LF")
    pf = aq.textbook_frame(p, "LF")
    assert pf[2] < 0
    theta = aq.textbook_ik(pf, aq.Y12, L1, L2, literal=True)
    np.testing.assert_allclose(aq.foot_position(aq.textbook_to_joints(theta, "LF"), "LF"), p, atol=1e-9)


def test_textbook_literal_and_atan2_agree_for_positive_zf():
    q = np.array([0.1, 0.75, 1.5])
    pf = aq.textbook_frame(aq.foot_position(q, "RH"), "RH")
    assert pf[2] > 0
    np.testing.assert_allclose(
        aq.textbook_ik(pf, aq.Y12, L1, L2, literal=True), aq.textbook_ik(pf, aq.Y12, L1, L2), atol=1e-15
    )
