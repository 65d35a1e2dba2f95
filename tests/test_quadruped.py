"""The quadruped (POPI's legs as legs.Leg): IK properties, branch order, seed 002 cross-check, error paths."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import legkin
from legkin._rotations import wrap
from legkin.quadruped import checks as checks
from legkin.quadruped import configuration as cfg
from legkin.quadruped import kinematics as aq

LEGS = aq.LEGS
L1 = math.hypot(aq.X23, aq.Z23)
L2 = aq.X34
G015 = aq.Geometry(foot_z=-0.015)  # POPI's own URDF value


def test_urdf_limits_match_analytic_constants(quadruped):
    for leg in LEGS:
        for k, joint in enumerate(("HAA", "HFE", "KFE")):
            iq = quadruped.idx_q(f"{leg}_{joint}")
            assert quadruped.model.lowerPositionLimit[iq] == aq.JOINT_LIMITS[k, 0]
            assert quadruped.model.upperPositionLimit[iq] == pytest.approx(aq.JOINT_LIMITS[k, 1], abs=1e-15)
        leg_model = aq.legs()[leg]  # the measured leg's limits: what ik keeps to
        np.testing.assert_allclose(np.stack([leg_model.lower, leg_model.upper], 1), aq.JOINT_LIMITS, atol=1e-15, rtol=0)


def test_folded_leg_at_zero_matches_reference():
    # reference: q = 0 is a folded leg, foot at (-0.05588, 0.1077, -0.041509) from the hip
    p = aq.fk(np.zeros(3), "LF") - aq.hip_position("LF")
    np.testing.assert_allclose(p, [aq.X23 + aq.X34, aq.Y12, aq.Z23], atol=1e-15)


def test_jacobian_matches_central_differences(rng):
    q = rng.uniform(-3, 3, (50, 3))
    h = 1e-6
    for leg in LEGS:
        jac = aq.jacobian(q, leg, geometry=G015)
        for k in range(3):
            dq = np.zeros(3)
            dq[k] = h
            fd = (aq.fk(q + dq, leg, geometry=G015) - aq.fk(q - dq, leg, geometry=G015)) / (2 * h)
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
    """Every branch of ik_all lands on the target, over the whole workspace incl. its boundary."""
    p = _reachable_target(leg, direction, frac, s_u)
    # rotate the target about the abduction axis: still reachable
    h = aq.hip_position(leg)
    d = p - h
    c, s = math.cos(tilt), math.sin(tilt)
    p = h + np.array([d[0], c * d[1] - s * d[2], s * d[1] + c * d[2]])
    q_all = aq.ik_all(p, leg)
    assert q_all.shape == (4, 3)
    err = np.linalg.norm(aq.fk(q_all, leg) - p, axis=-1)
    assert np.all(err < 1e-12), err


@settings(max_examples=300, deadline=None)
@given(
    leg=st.sampled_from(LEGS),
    u=st.tuples(st.floats(0, 1), st.floats(0, 1), st.floats(0, 1)),
)
@example(leg="LF", u=(0.0, 0.43359375, 0.0))  # q1, q3 on their lower limits (failed during the clip change)
def test_ik_round_trip_inside_limits(leg, u):
    lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
    q = lo + np.array(u) * (hi - lo)
    p = aq.fk(q, leg)
    q_ik = aq.ik(p, leg, q_near=q)
    assert aq.within_limits(q_ik)
    assert np.linalg.norm(aq.fk(q_ik, leg) - p) < 1e-12
    # joint agreement is conditioned by rho (distance to the abduction cylinder): 1.6e-16 m / rho
    d = p - aq.hip_position(leg)
    rho = math.sqrt(max(d[1] ** 2 + d[2] ** 2 - aq.Y12**2, 0.0))
    assert np.max(np.abs(q_ik - q)) < max(1e-12, 1e-15 / max(rho, 1e-300)) or rho < 1e-9


def test_four_branches_are_distinct_solutions():
    p = aq.fk(np.array([0.1, 0.8, 1.2]), "RF")
    q_all = aq.ik_all(p, "RF")
    assert len({tuple(np.round(q, 9)) for q in q_all}) == 4


def test_branch_choice_follows_q_near_and_limits():
    # a pose with large q2 has its limit-respecting solution on the s_u = +1 branch
    q = np.array([0.2, 2.9, 1.0])
    p = aq.fk(q, "LH")
    np.testing.assert_allclose(aq.ik(p, "LH"), q, atol=1e-12)
    q_all = aq.ik_all(p, "LH")
    inside = aq.within_limits(q_all)
    assert inside.sum() >= 1
    # nearest-to-q_near picks the given branch among those inside the limits
    for q_in in q_all[inside]:
        np.testing.assert_allclose(aq.ik(p, "LH", q_near=q_in), q_in, atol=1e-12)


def test_batch_returns_nan_and_mask():
    good = aq.fk(np.array([0.0, 0.75, 1.5]), "LF")
    far = aq.hip_position("LF") + np.array([0.0, 0.0, -1.0])
    inside = aq.hip_position("LF") + np.array([0.0, 0.05, 0.0])
    limits_only = aq.fk(np.array([0.0, -0.5, 1.0]), "LF")  # q2 < 0: outside the limits
    p = np.stack([good, far, inside, limits_only])
    q, mask = aq.ik(p, "LF", return_mask=True)
    assert mask.tolist() == [True, False, False, False]
    assert np.all(np.isfinite(q[0])) and np.all(np.isnan(q[1:]))
    q_all, reach = aq.ik_all(p, "LF", return_mask=True)
    assert reach.shape == (4, 4)
    assert reach[:, 0].tolist() == [True, False, False, True]
    assert np.all(np.isnan(q_all[1:3]))
    q_plain = aq.ik(p, "LF")
    np.testing.assert_array_equal(np.isnan(q_plain), np.isnan(q))


def test_scalar_errors_say_why_and_carry_by_how_much():
    h = aq.hip_position("LF")
    far = h + np.array([0.0, 0.0, -1.0])  # straight down: rho = sqrt(1 - y12^2) in the leg plane
    stretch = math.sqrt(1.0 - aq.Y12**2) - (L1 + L2)
    for call in (aq.ik, aq.ik_all):
        with pytest.raises(legkin.UnreachableError, match="beyond the leg's full stretch") as info:
            call(far, "LF")
        assert not isinstance(info.value, legkin.JointLimitError)
        assert info.value.distance == pytest.approx(stretch, abs=1e-12)
        assert f"{stretch:.6g} m" in str(info.value) and np.array_equal(info.value.target, far)
    with pytest.raises(legkin.UnreachableError, match="abduction cylinder") as info:
        aq.ik(h + np.array([0.0, 0.05, 0.0]), "LF")
    assert info.value.distance == pytest.approx(aq.Y12 - 0.05, abs=1e-12)
    with pytest.raises(legkin.UnreachableError, match="inner reach") as info:
        aq.ik(h + np.array([0.0, aq.Y12, -0.01]), "LF")
    assert info.value.distance == pytest.approx((L1 - L2) - 0.01, abs=1e-12)
    with pytest.raises(legkin.JointLimitError, match="outside the joint limits") as info:
        aq.ik(aq.fk(np.array([0.0, -0.5, 1.0]), "LF"), "LF")
    err = info.value
    assert (err.joint, err.lower, err.upper) == ("LF_HFE", 0.0, math.pi)
    assert err.value == pytest.approx(-0.5, abs=1e-12) and err.distance == pytest.approx(0.5, abs=1e-12)
    np.testing.assert_allclose(err.closest, [0.0, -0.5, 1.0], atol=1e-12)


@pytest.mark.parametrize("foot_z", [0.0, -0.015])
def test_ik_all_rows_are_the_seed_branches_on_every_leg(foot_z, rng):
    """Row b of ik_all is BRANCHES[b] = (s_u, k) on every leg: s_u the sign of u_z (the foot's height in the frame
    turned by seed 004's R_x(s_y q1)), k the sign of acos K in q3 = (beta - alpha) + k acos K."""
    g = aq.Geometry(foot_z=foot_z)
    offset = math.atan2(foot_z, aq.X34) - math.atan2(aq.Z23, aq.X23)
    for leg in LEGS:
        sy = 1.0 if leg[0] == "L" else -1.0
        p = aq.fk(cfg.sample_joints(rng, 500), leg, geometry=g)
        d = p - aq.hip_position(leg)
        q_all = aq.ik_all(p, leg, geometry=g)
        for b, (s_u, k) in enumerate(aq.BRANCHES):
            a = sy * q_all[:, b, 0]
            u_z = np.sin(-a) * d[:, 1] + np.cos(-a) * d[:, 2]  # R_x(-s_y q1) d, z component
            knee = wrap(q_all[:, b, 2] - offset)
            assert np.all(np.sign(u_z) == s_u), (leg, b)
            assert np.all(np.sign(knee) == k), (leg, b)


def test_unknown_leg():
    with pytest.raises(legkin.InvalidParameterError, match="LF, LH, RF, RH"):
        aq.fk(np.zeros(3), "XX")


# ----------------------------------------------------------------------------- seed 002
def _q_textbook_region(rng, n):
    """Configurations inside the limits whose foot is below the hip (z_f > 0 in seed 002's frame)."""
    lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
    q = rng.uniform(lo, hi, (n, 3))
    return q


@pytest.mark.parametrize("leg", LEGS)
def test_textbook_ik_agrees_with_closed_form_on_its_branch(leg, rng):
    q = _q_textbook_region(rng, 2000)
    p = aq.fk(q, leg)
    theta = aq.textbook_ik(aq.textbook_frame(p, leg), aq.Y12, L1, L2)
    q_tb = aq.textbook_to_joints(theta, leg)
    q_branch = aq.ik_all(p, leg)[:, 0, :]  # (s_u, k) = (-1, -1)
    ok = np.all(np.isfinite(q_tb), axis=-1)
    assert ok.mean() > 0.99
    np.testing.assert_allclose(q_tb[ok], q_branch[ok], atol=2e-11)
    # and it is a solution: the foot lands on the target
    np.testing.assert_allclose(aq.fk(q_tb[ok], leg), p[ok], atol=1e-12)


@pytest.mark.xfail(strict=True, reason="seed 002 as printed uses atan(x_f/z_f): wrong for z_f < 0")
def test_textbook_literal_atan_fails_for_negative_zf():
    # a foot above the abduction axis (z_f < 0 in seed 002's z-down frame) on the textbook branch
    q = np.array([0.3, 2.6, 1.0])
    p = aq.fk(q, "LF")
    pf = aq.textbook_frame(p, "LF")
    assert pf[2] < 0
    theta = aq.textbook_ik(pf, aq.Y12, L1, L2, literal=True)
    np.testing.assert_allclose(aq.fk(aq.textbook_to_joints(theta, "LF"), "LF"), p, atol=1e-9)


def test_textbook_literal_and_atan2_agree_for_positive_zf():
    q = np.array([0.1, 0.75, 1.5])
    pf = aq.textbook_frame(aq.fk(q, "RH"), "RH")
    assert pf[2] > 0
    np.testing.assert_allclose(
        aq.textbook_ik(pf, aq.Y12, L1, L2, literal=True), aq.textbook_ik(pf, aq.Y12, L1, L2), atol=1e-15
    )


# ----------------------------------------------------------------------------- input validation
def test_scalar_target_with_batch_q_near_is_a_batch():
    """Rule: p and q_near broadcast; a single target with a batch of q_near is a batch (one answer per q_near)."""
    q_true = np.array([0.1, 0.75, 1.5])
    p = aq.fk(q_true, "LF")
    q_near = np.array([q_true, q_true + 0.05, [0.0, 0.5, 1.0]])
    q, ok = aq.ik(p, "LF", q_near=q_near, return_mask=True)
    assert q.shape == (3, 3) and ok.shape == (3,) and ok.all()
    np.testing.assert_allclose(q, np.broadcast_to(aq.ik(p, "LF", q_near=q_true), (3, 3)), atol=1e-12)
    assert aq.ik(p, "LF", q_near=q_near[None, :1]).shape == (1, 1, 3)
    # an unreachable single target with a batch of q_near: NaN rows and a False mask, no exception
    far = aq.hip_position("LF") + np.array([0.0, 0.0, -1.0])
    q, ok = aq.ik(far, "LF", q_near=q_near, return_mask=True)
    assert not ok.any() and np.isnan(q).all()
    with pytest.raises(legkin.InvalidInputError, match="do not broadcast"):
        aq.ik(np.stack([p, p]), "LF", q_near=q_near)


@pytest.mark.parametrize(
    "bad", ["abc", ["a", "b", "c"], np.zeros(3) + 1j, [[0.0, 0.0, 0.0], [0.0, 0.0]], np.zeros(2), None]
)
def test_within_limits_refuses_non_numeric(bad):
    with pytest.raises(legkin.InvalidInputError):
        aq.within_limits(bad)


def test_within_limits_nan_rows_are_outside():
    q = np.array([[0.0, 1.0, 1.0], [np.nan, 1.0, 1.0], [np.inf, 1.0, 1.0]])
    assert aq.within_limits(q).tolist() == [True, False, False]


@pytest.mark.parametrize(
    "value, match",
    [
        (float("nan"), r"foot_z=nan is out of range: must be in \[-0.1, 0.1\]"),
        (5, r"foot_z=5.0 is out of range: must be in \[-0.1, 0.1\]"),
        (-0.2, r"out of range: must be in \[-0.1, 0.1\]"),
        (float("inf"), r"out of range"),
        ("0.01", r"foot_z must be a real number, got '0.01'; valid range \[-0.1, 0.1\]"),
        (True, r"foot_z must be a real number"),
        (0.01 + 0j, r"foot_z must be a real number"),
        ([0.01], r"foot_z must be a real number"),
    ],
)
def test_geometry_is_validated(value, match):
    with pytest.raises(legkin.InvalidParameterError, match=match):
        aq.Geometry(foot_z=value)
    with pytest.raises(legkin.InvalidParameterError, match=match):
        aq.Geometry.from_params({"foot_z": value})


@pytest.mark.parametrize("bad", [0.0, {"foot_z": 0.0}, "default", aq.DEFAULT_GEOMETRY.foot_z])
def test_geometry_keyword_takes_a_geometry_only(bad):
    q = np.array([0.0, 0.75, 1.5])
    p = aq.fk(q, "LF")
    for call in (
        lambda: aq.fk(q, "LF", geometry=bad), lambda: aq.jacobian(q, "LF", geometry=bad),
        lambda: aq.ik(p, "LF", geometry=bad), lambda: aq.ik_all(p, "LF", geometry=bad),
        lambda: aq.hip_position("LF", geometry=bad), lambda: aq.within_limits(q, geometry=bad),
        lambda: aq.textbook_frame(p, "LF", geometry=bad), lambda: aq.textbook_to_joints(q, "LF", geometry=bad),
    ):
        with pytest.raises(legkin.InvalidParameterError, match="geometry must be a legkin.quadruped.Geometry"):
            call()


@pytest.mark.parametrize("bad", [["LF"], {"LF": 1}, "XX", None, 3, b"LF"])
@pytest.mark.parametrize("geometry", [None, aq.Geometry(foot_z=0.01)])
def test_bad_leg_is_a_legkin_error_on_every_path(bad, geometry):
    """The single-call fast paths look the leg up in a dict: an unhashable or unknown leg still gets the legkin
    error naming the legs (not numpy's or Python's TypeError), with and without a geometry."""
    q = np.array([0.0, 0.75, 1.5])
    p = aq.fk(q, "LF")
    for call in (lambda: aq.fk(q, bad, geometry=geometry), lambda: aq.jacobian(q, bad, geometry=geometry),
                 lambda: aq.ik(p, bad, geometry=geometry), lambda: aq.ik(p, bad, q_near=q, geometry=geometry),
                 lambda: aq.ik_all(p, bad, geometry=geometry)):
        with pytest.raises(legkin.InvalidParameterError, match="LF, LH, RF, RH"):
            call()


def test_geometry_single_calls_equal_the_measured_legs():
    """The fast path of a non-default geometry uses that geometry's measured leg (not the default's)."""
    q = np.array([0.1, 0.75, 1.5])
    for foot_z in (0.02, -0.03):
        g = aq.Geometry(foot_z=foot_z)
        for leg in aq.LEGS:
            measured = aq.legs(g)[leg]
            p = aq.fk(q, leg, geometry=g)
            np.testing.assert_array_equal(p, measured.fk(q))
            np.testing.assert_array_equal(aq.jacobian(q, leg, geometry=g), measured.jacobian(q))
            np.testing.assert_array_equal(aq.ik(p, leg, geometry=g), measured.ik(p))
            np.testing.assert_array_equal(aq.ik(p, leg, q_near=q, geometry=g), measured.ik(p, q_near=q))
            assert np.abs(aq.fk(q, leg) - p).max() > 0.01  # the default geometry's foot is elsewhere


def test_return_mask_is_validated():
    p = aq.fk(np.array([0.0, 0.75, 1.5]), "LF")
    q = np.array([0.0, 0.75, 1.5])
    for call in (lambda: aq.ik(p, "LF", return_mask="yes"), lambda: aq.ik_all(p, "LF", return_mask="yes"),
                 lambda: aq.fk(q, "LF", return_mask=1.5), lambda: aq.jacobian(q, "LF", return_mask="no")):
        with pytest.raises(legkin.InvalidParameterError, match="return_mask must be True or False"):
            call()


def test_foot_z_range_is_the_registry_one():
    from legkin.quadruped.spec import SPEC

    param = SPEC.params["foot_z"]
    assert aq.Geometry(foot_z=param.low).foot_z == param.low
    assert aq.Geometry(foot_z=np.float64(param.high)).foot_z == param.high
    assert type(aq.Geometry(foot_z=np.float32(0.0625)).foot_z) is float
    assert aq.Geometry(foot_z=np.array(0.0)) == aq.Geometry() == aq.DEFAULT_GEOMETRY
    assert aq.Geometry().foot_z == param.default
    with pytest.raises(legkin.InvalidParameterError):
        aq.Geometry(foot_z=param.high * (1 + 1e-12))


def test_geometry_of_a_loaded_robot_and_from_params():
    robot = legkin.load("quadruped", foot_z=-0.015)
    assert robot.geometry == G015
    assert aq.Geometry.from_params(None) == aq.Geometry.from_params({}) == aq.Geometry()
    assert aq.Geometry.from_params({"foot_z": 0.02, "not_kinematic": "x"}) == aq.Geometry(foot_z=0.02)
    with pytest.raises(legkin.InvalidParameterError):
        aq.Geometry.from_params([("foot_z", 0.0)])
    with pytest.raises(AttributeError):
        G015.foot_z = 0.0  # frozen
    # the geometry changes the foot by foot_z along the shank's normal, and nothing at the hip
    q = np.array([0.1, 0.75, 1.5])
    assert np.linalg.norm(aq.fk(q, "LF", geometry=G015) - aq.fk(q, "LF")) == pytest.approx(0.015, abs=1e-15)
    np.testing.assert_array_equal(aq.hip_position("LF", geometry=G015), aq.hip_position("LF"))


@pytest.mark.parametrize(
    "call",
    [
        lambda: aq.within_limits(np.zeros(3), tol=-1e-9),
        lambda: aq.within_limits(np.zeros(3), tol=float("nan")),
        lambda: aq.within_limits(np.zeros(3), tol="0"),
        lambda: aq.textbook_ik(np.array([0.1, 0.0, 0.4]), aq.Y12, 0.0, L2),
        lambda: aq.textbook_ik(np.array([0.1, 0.0, 0.4]), float("nan"), L1, L2),
        lambda: aq.textbook_ik(np.array([0.1, 0.0, 0.4]), aq.Y12, L1, "x"),
        lambda: aq.textbook_ik(np.array([0.1, 0.0, 0.4]), aq.Y12, L1, L2, literal="no"),
        lambda: aq.ik(np.zeros(3), 3),
    ],
)
def test_other_parameters_are_validated(call):
    with pytest.raises(legkin.InvalidParameterError):
        call()


@pytest.mark.parametrize(
    "call",
    [
        lambda: aq.ik(np.array([0.3, 0.3, -0.4]), "LF", q_near=np.zeros(3) + 0j),
        lambda: aq.ik([[0.3, 0.3, -0.4], [0.3, 0.3]], "LF"),
        lambda: aq.ik(np.array([0.3, 0.3, -0.4]), "LF", q_near=np.zeros(2)),
        lambda: aq.ik(np.array([0.3, 0.3, -0.4]), "LF", q_near=[0.0, np.nan, 0.0]),
        lambda: aq.fk(np.array([1.0, 2.0, 3.0], dtype=object), "LF"),
        lambda: aq.textbook_frame(np.zeros(3) + 1j, "LF"),
        lambda: aq.textbook_to_joints(np.zeros(3) + 1j, "LF"),
    ],
)
def test_bad_arrays_raise_invalid_input(call):
    with pytest.raises(legkin.InvalidInputError):
        call()


# ----------------------------------------------------------------------------- the IK contract (property tests)
LO, HI = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
ATOL_CONTRACT = 1e-9


def _joint(k):
    """A joint value inside limit row k: anywhere, exactly on a limit, or a hair inside one."""
    lo, hi = float(LO[k]), float(HI[k])
    hair = st.floats(1e-15, 1e-6)
    return st.one_of(
        st.floats(lo, hi),
        st.sampled_from([lo, hi]),
        hair.map(lambda h: lo + h),
        hair.map(lambda h: hi - h),
    )


def _check_answer(q, p, leg, tol=ATOL_CONTRACT):
    """Contract (a) and (c) for one answer."""
    assert q.shape == (3,) and np.all(np.isfinite(q))
    assert np.all(q >= LO) and np.all(q <= HI), q  # inside the URDF limits, no slack
    assert np.linalg.norm(aq.fk(q, leg) - p) <= tol


def _near_cylinder_joints(q, log_rho, sign):
    """Replace q2 of q so that the foot is rho = sign 10**log_rho from the abduction cylinder (u_z = rho)."""
    vx, vz = cfg.knee_vector(q[2])
    r, rho = math.hypot(vx, vz), sign * 10.0**log_rho
    return np.array([q[0], float(wrap(math.atan2(rho, math.sqrt(r * r - rho * rho)) - math.atan2(vz, vx))), q[2]])


@settings(max_examples=400, deadline=None)
@example(leg="LF", q1=-0.4, q2=0.0, q3=1.5, log_rho=-8.0, sign=-1.0, with_ref=False)  # q1 1.3e-9 off its limit
@example(leg="LF", q1=-0.4, q2=1.36, q3=0.26, log_rho=None, sign=1.0, with_ref=False)  # two joints on limits
@example(leg="LF", q1=0.4, q2=0.0, q3=1.92, log_rho=-5.847934859038284, sign=1.0, with_ref=False)  # q3 1 ulp out
@example(leg="LF", q1=0.399999999999999, q2=0.0, q3=0.26, log_rho=-8.0, sign=1.0, with_ref=False)  # q1 and q3 at
# their limits, rho = 1e-8 m: the branch's q1 6e-10 rad out (the abduction singularity), the repair's step pushed q3
@given(
    leg=st.sampled_from(LEGS),
    q1=_joint(0), q2=_joint(1), q3=_joint(2),
    log_rho=st.one_of(st.none(), st.floats(-12, -2)),
    sign=st.sampled_from([-1.0, 1.0]),
    with_ref=st.booleans(),
)
def test_contract_targets_made_by_fk_are_solved(leg, q1, q2, q3, log_rho, sign, with_ref):
    """(b): every foot_position of in-limit joints is solved by the default foot_ik, (a) and (c) hold;
    incl. joints on their limits and feet rho -> 0 from the abduction cylinder (the branches merge)."""
    q = np.array([q1, q2, q3])
    if log_rho is not None:
        q = _near_cylinder_joints(q, log_rho, sign)
        if not aq.within_limits(q, 0.0):
            return
    p = aq.fk(q, leg)
    q_ik = aq.ik(p, leg, q_near=q if with_ref else None)
    _check_answer(q_ik, p, leg)
    qb, ok = aq.ik(p[None], leg, q_near=q[None] if with_ref else None, return_mask=True)
    assert ok.tolist() == [True] and np.array_equal(qb[0], q_ik)


def _target(leg, kind, a, b, c, hair):
    """Targets in and around the workspace: a box about the hip, or a hair off a boundary surface."""
    h = aq.hip_position(leg)
    sy = 1.0 if leg[0] == "L" else -1.0
    l1, l2 = L1, L2
    if kind == "box":
        return h + 0.8 * np.array([a, b, c])
    if kind == "cylinder":  # distance to the abduction axis = Y12 + hair
        axis, dx = aq.Y12 + hair, 0.6 * a
    else:
        radius = (l1 + l2 if kind == "stretch" else abs(l1 - l2)) + hair
        rho = abs(radius * math.sin(math.pi * b))
        axis, dx = math.sqrt(aq.Y12**2 + rho * rho), radius * math.cos(math.pi * b)
    t = math.pi * c
    return h + np.array([dx, sy * axis * math.cos(t), axis * math.sin(t)])


@settings(max_examples=400, deadline=None)
@given(
    leg=st.sampled_from(LEGS),
    kind=st.sampled_from(["box", "cylinder", "stretch", "inner"]),
    a=st.floats(-1, 1), b=st.floats(-1, 1), c=st.floats(-1, 1),
    hair=st.one_of(st.just(0.0), st.floats(-1e-3, 1e-3), st.floats(-1e-12, 1e-12)),
)
def test_contract_random_targets(leg, kind, a, b, c, hair):
    """Any target: a single call returns a contract answer or raises Unreachable/JointLimitError; the
    batch call agrees with it item by item (NaN + mask False where the single call raises)."""
    p = _target(leg, kind, a, b, c, hair)
    try:
        q = aq.ik(p, leg)
    except legkin.UnreachableError as exc:  # JointLimitError included
        assert exc.target is not None
        q = None
    qb, ok = aq.ik(np.stack([p, p]), leg, return_mask=True)
    if q is None:
        assert not ok.any() and np.isnan(qb).all()
    else:
        _check_answer(q, p, leg)
        assert ok.all() and np.array_equal(qb[0], q)


finite = st.floats(allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(
    p=st.tuples(finite, finite, finite),
    q_near=st.one_of(st.none(), st.tuples(finite, finite, finite)),
    leg=st.sampled_from(LEGS),
    foot_z=st.sampled_from([0.0, -0.015, 0.1]),  # each new foot_z measures a generated URDF (xacro, ~0.3 s)
)
def test_no_foreign_exception_or_warning_on_any_finite_input(p, q_near, leg, foot_z):
    """Huge or tiny finite inputs: only legkin errors, and no numpy warning (overflow etc.) either."""
    import warnings

    geometry = aq.Geometry(foot_z=foot_z)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for call in (
            lambda: aq.ik(np.array(p), leg, q_near=q_near, geometry=geometry),
            lambda: aq.ik_all(np.array(p), leg, geometry=geometry),
            lambda: aq.fk(np.array(p), leg, geometry=geometry),
            lambda: aq.jacobian(np.array(p), leg, geometry=geometry),
            lambda: aq.within_limits(np.array(p)),
            lambda: aq.textbook_to_joints(np.array(p), leg),
        ):
            try:
                call()
            except legkin.LegkinError:
                pass
        q, ok = aq.ik(np.array([p, p]), leg, q_near=q_near, geometry=geometry, return_mask=True)
        assert q.shape == (2, 3) and ok.shape == (2,)


def test_ik_robustness_row_passes():
    import time

    t0 = time.perf_counter()
    row = checks.ik_robustness(10_000, np.random.default_rng(3))
    assert row.passed, row.name
    assert row.counts.made == 5000 and row.counts.wrong == 0 and row.counts.missed == 0
    assert row.counts.exceptions == 0 and row.max_error <= 1e-9
    assert time.perf_counter() - t0 < 10


# ----------------------------------------------------------------------------- compiled kernels (issue 16)
def test_batch_is_the_single_call_kernel_item_by_item(rng):
    """The batch is a compiled loop over the single-call kernel: identical answers, bit for bit, on both
    the serial (small) and the parallel (large) path, with and without q_near, and on non-contiguous input."""
    from legkin.legs._ik_kernels import _ik_batch

    lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
    n = _ik_batch.min_parallel + 44  # the leg's batch loop runs on numba's threads from min_parallel items
    q = rng.uniform(lo - 0.05, hi + 0.05, (n, 3))
    p = aq.fk(q, "RH", geometry=G015)
    q_near = rng.uniform(lo, hi, (n, 3))
    for rows in (p[:7], p):
        qb, ok = aq.ik(rows, "RH", geometry=G015, return_mask=True)
        qr = aq.ik(rows, "RH", q_near=q_near[: len(rows)], geometry=G015)
        for i in range(len(rows)):
            try:
                single = aq.ik(rows[i], "RH", geometry=G015)
                assert ok[i] and np.array_equal(single, qb[i])
                assert np.array_equal(aq.ik(rows[i], "RH", q_near=q_near[i], geometry=G015), qr[i])
            except legkin.UnreachableError:
                assert not ok[i] and np.isnan(qb[i]).all()
        np.testing.assert_array_equal(aq.ik(np.asfortranarray(rows), "RH", geometry=G015), qb)
    fp = aq.fk(q, "LF")
    assert all(np.array_equal(aq.fk(q[i], "LF"), fp[i]) for i in range(0, n, 37))
    jac = aq.jacobian(q[::2], "LF")
    assert np.array_equal(jac[3], aq.jacobian(q[6], "LF"))


def test_list_input_and_float64_fast_path_agree():
    q = [0.1, 0.75, 1.5]
    p = aq.fk(np.array(q), "LF")
    np.testing.assert_array_equal(aq.fk(q, "LF"), p)
    strided = np.repeat(np.array(q), 2)[::2]  # a non-contiguous (3,) view
    np.testing.assert_array_equal(aq.fk(strided, "LF"), p)
    np.testing.assert_array_equal(aq.fk(np.array(q, dtype=np.float32), "LF"),
                                  aq.fk(np.array(q, dtype=np.float32).astype(np.float64), "LF"))
    np.testing.assert_array_equal(aq.ik(p.tolist(), "LF"), aq.ik(p, "LF"))
    np.testing.assert_array_equal(aq.ik_all([p.tolist()], "LF")[0], aq.ik_all(p, "LF"))
    assert aq.within_limits(np.array(q)) == aq.within_limits(q) == True  # noqa: E712
    q3d = np.tile(np.array(q), (2, 3, 1))
    assert aq.fk(q3d, "LF").shape == (2, 3, 3) and aq.jacobian(q3d, "LF").shape == (2, 3, 3, 3)
    assert aq.ik(np.zeros((0, 3)), "LF").shape == (0, 3)


def test_thread_count_does_not_change_results(rng, monkeypatch):
    """numba's parallel loops on one thread, on all, and their serial compilation (legkin check's workers,
    ``_kernels.serial_parfor_loops``) give the same batch results bit for bit."""
    import numba

    import legkin._kernels as kernels

    lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
    q = rng.uniform(lo, hi, (2000, 3))
    p = aq.fk(q, "LF")
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = aq.ik(p, "LF"), aq.fk(q, "LF"), aq.jacobian(q, "LF")
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        for a, b in zip((aq.ik(p, "LF"), aq.fk(q, "LF"), aq.jacobian(q, "LF")), one):
            np.testing.assert_array_equal(a, b)
        monkeypatch.setattr(kernels, "serial_parfor_loops", True)
        for a, b in zip((aq.ik(p, "LF"), aq.fk(q, "LF"), aq.jacobian(q, "LF")), one):
            np.testing.assert_array_equal(a, b)
    finally:
        numba.set_num_threads(before)


def test_importing_legkin_does_not_import_numba():
    import subprocess
    import sys

    code = (
        "import sys, legkin; assert 'numba' not in sys.modules, 'numba imported by import legkin'; "
        "g = legkin.load('quadruped', foot_z=0.01).geometry; assert g == legkin.quadruped.Geometry(foot_z=0.01); "
        "assert 'numba' not in sys.modules, 'numba imported by Robot.geometry'"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


# ----------------------------------------------------------------------------- seed 002 with a geometry
@pytest.mark.parametrize("foot_z", [-0.015, 0.05])
def test_textbook_ik_with_a_foot_drop(foot_z, rng):
    """Seed 002 with c = |t34| = hypot(x34, foot_z) and the foot's angle beta in textbook_to_joints: still the
    (s_u, k) = (-1, -1) branch of the closed form."""
    g = aq.Geometry(foot_z=foot_z)
    q = cfg.sample_joints(rng, 2000)
    p = aq.fk(q, "LH", geometry=g)
    theta = aq.textbook_ik(aq.textbook_frame(p, "LH", geometry=g), aq.Y12, L1, math.hypot(L2, foot_z))
    q_tb = aq.textbook_to_joints(theta, "LH", geometry=g)
    ok = np.all(np.isfinite(q_tb), axis=-1)
    assert ok.mean() > 0.95
    np.testing.assert_allclose(q_tb[ok], aq.ik_all(p, "LH", geometry=g)[ok, 0], atol=2e-11)
    # without the geometry the knee is off by beta: the test can fail
    assert np.abs(aq.textbook_to_joints(theta, "LH")[ok, 2] - q_tb[ok, 2]).min() > 0.04


# ----------------------------------------------------------------------------- configuration helpers
def test_configuration_helpers(quadruped, rng):
    assert cfg.joint_names("RH") == ("RH_HAA", "RH_HFE", "RH_KFE")
    with pytest.raises(legkin.InvalidParameterError):
        cfg.joint_names("XX")
    q = cfg.sample_joints(rng, 7)
    assert aq.within_limits(q).all()
    full = cfg.pinocchio_configuration(quadruped, {"LF": q, "RH": q[0]})
    assert full.shape == (7, quadruped.model.nq)
    np.testing.assert_array_equal(full[:, cfg.leg_slice(quadruped, "LF")], q)
    np.testing.assert_array_equal(full[:, cfg.leg_slice(quadruped, "RH")], np.broadcast_to(q[0], (7, 3)))
    lh = cfg.leg_slice(quadruped, "LH")
    np.testing.assert_array_equal(full[:, lh], np.broadcast_to(quadruped.q0[lh], (7, 3)))
    for leg in LEGS:
        placement = quadruped.frame_placement(full[3], f"{leg}_FOOT")
        foot = aq.fk(full[3, cfg.leg_slice(quadruped, leg)], leg)
        np.testing.assert_allclose(placement.translation, foot, atol=1e-15)
    near = cfg.near_singular_joints(50, "RF", rng)
    r = cfg.rho(aq.fk(near, "RF"), "RF")
    assert aq.within_limits(near, 0.0).all() and (r < 1.1e-3).all() and (r > 0.9e-6).all()
    made = cfg.made_joints(200, rng)
    assert aq.within_limits(made, 0.0).all()
    legs = np.asarray(LEGS)[rng.integers(0, 4, 100)]
    assert cfg.random_targets(100, rng, legs).shape == (100, 3)


def test_package_attributes_resolve_once():
    """The lazy re-export keeps what it found: ``quadruped.fk`` in a loop is a plain attribute read."""
    import legkin.quadruped as pkg

    assert pkg.fk is aq.fk and pkg.Geometry is aq.Geometry
    assert vars(pkg)["fk"] is aq.fk and vars(pkg)["Geometry"] is aq.Geometry
    assert set(aq.__all__) <= set(dir(pkg)) and "SPEC" in pkg.__all__
    with pytest.raises(AttributeError):
        pkg.no_such_name  # noqa: B018


def test_legs_are_measured_once_per_geometry_from_the_models_urdf():
    """``legs(geometry)``: the four :class:`legkin.legs.Leg` of the URDF ``legkin.load`` uses for that geometry,
    measured once (equal geometries share them), and what fk/ik run on."""
    from legkin import legs as generic

    assert aq.legs(aq.Geometry(foot_z=-0.015)) is aq.legs(G015) is not aq.legs()
    assert aq.legs(None) is aq.legs(aq.DEFAULT_GEOMETRY)
    robot = legkin.load("quadruped", foot_z=-0.015)
    floating = generic.from_model(robot.model)  # the loaded (floating-base) model, measured on its own
    q = np.array([[0.1, 0.75, 1.5], [-0.3, 2.9, 0.4]])
    for leg in LEGS:
        mine = aq.legs(G015)[leg]
        assert mine.foot_frame == f"{leg}_FOOT" and mine.joint_names == cfg.joint_names(leg)
        np.testing.assert_allclose(mine.fk(q), floating[leg].fk(q), atol=1e-15, rtol=0)
        np.testing.assert_array_equal(aq.fk(q, leg, geometry=G015), mine.fk(q))
    with pytest.raises(legkin.InvalidParameterError, match="geometry must be"):
        aq.legs(-0.015)
