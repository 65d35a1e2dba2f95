"""Tests of the hybrid leg: model, loops, mobility, analytic kinematics (legkin.hybrid_leg), checks."""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

import legkin
from legkin import (
    ConvergenceError,
    InvalidInputError,
    InvalidParameterError,
    SingularityError,
    UnreachableError,
)
from legkin.hybrid_leg import checks as ch
from legkin.hybrid_leg import configuration as cfg
from legkin.hybrid_leg import kinematics as ah
from legkin.hybrid_leg.geometry import LL0, H

DEG = math.pi / 180
ACTUATED = ("MCS1", "MCS2", "LL")


@pytest.fixture(scope="module")
def robot():
    return legkin.load("hybrid_leg")


@pytest.fixture(scope="module")
def spherical():
    return legkin.load("hybrid_leg", center="spherical")


def _q(theta1, theta2, theta0):
    """Motor angles (theta1, theta2, theta0) broadcast and stacked into q (..., 3)."""
    return np.stack(np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (theta1, theta2, theta0))), -1)


def _in_mode(roll, pitch, sigma_min=1e-2):
    r, p = np.atleast_1d(roll), np.atleast_1d(pitch)
    ok = cfg.neutral_mode(r, p)
    return bool(ok[0]) and float(cfg.sigma_min(r, p)[0]) >= sigma_min


# ------------------------------------------------------------------------------------------ model and checks
def test_check_rows_pass():
    rows = ch.run(150, np.random.default_rng(3))
    assert len(rows) >= 20
    failed = [r for r in rows if not r.passed]
    assert not failed, failed


def test_committed_urdf_matches_xacro():
    from legkin._generate import check_all

    assert check_all(["hybrid_leg"]) == []


def test_model_structure(robot, spherical):
    assert robot.model.nq == robot.model.nv == 11
    assert spherical.model.nq == spherical.model.nv == 12
    assert [(lp.name, lp.type, lp.frame1, lp.frame2) for lp in robot.loops] == [
        ("rod_1", "point", "rod_1_end", "P_sph_1"),
        ("rod_2", "point", "rod_2_end", "P_sph_2"),
    ]
    assert robot.actuated_joints == ACTUATED
    assert set(robot.poses) == {"neutral", "zero_motors", "extended"}
    assert "LCS_z" not in robot.joint_names and "LCS_z" in spherical.joint_names
    # the base transforms of eqs 5, 12, re-orthonormalised (the seed prints 0.9306 / 0.3661)
    for i, sy in ((1, 1), (2, -1)):
        m = robot.model.jointPlacements[robot.joint_id(f"MCS{i}")]
        rot = m.rotation
        assert abs(np.linalg.det(rot) - 1) < 1e-15
        assert np.abs(rot.T @ rot - np.eye(3)).max() < 1e-15
        assert rot[0, 0] == pytest.approx(0.9306, abs=5e-5) and rot[1, 0] == pytest.approx(sy * 0.3661, abs=5e-5)
        assert np.allclose(m.translation, [0.139807669447128, sy * 0.0549998406976098, -0.051], atol=1e-15)
    # LL origin and the foot (eqs 18, 20), LCS centre (eq 2)
    assert np.allclose(robot.frame_placement(robot.q0, "FCS").translation, [0.405, 0, -0.023], atol=1e-15)
    assert np.allclose(robot.frame_placement(robot.q0, "P").translation, ah.CENTER, atol=1e-15)


def test_transmission_carries_eq19(robot, tmp_path, monkeypatch):
    def transmission(path):
        el = ET.parse(path).getroot().find("transmission")
        return float(el.find("joint/offset").text), float(el.find("actuator/mechanicalReduction").text)

    offset, reduction = transmission(robot.urdf_path)
    assert offset == 0.0
    # SimpleTransmission: joint = actuator / reduction + offset == eq 19
    assert 1.0 / reduction == pytest.approx(ah.ll_angle(1.0) - ah.ll_angle(0.0), rel=1e-15)
    monkeypatch.setenv("LEGKIN_CACHE", str(tmp_path))
    shifted = legkin.load("hybrid_leg", starting_value=0.25)
    assert transmission(shifted.urdf_path)[0] == 0.25


@pytest.mark.parametrize("center", ["universal", "spherical"])
def test_srdf_poses_close_loops(center, robot, spherical):
    rob = robot if center == "universal" else spherical
    for name, q in rob.poses.items():
        assert np.linalg.norm(rob.constraint_residual(q)) < 1e-15, name
    q = rob.poses["neutral"]
    th = ah.motor_angles(0.0, 0.0)
    assert q[rob.idx_q("MCS1")] == th[0] and q[rob.idx_q("MCS2")] == th[1]  # full precision in the SRDF
    sph = ah.sphere_joint_angles(np.eye(3))
    for i in (1, 2):
        for k, ax in enumerate("zyx"):
            assert q[rob.idx_q(f"Sph_{i}_1_{ax}")] == sph[i - 1, k]
    assert np.allclose(rob.frame_placement(q, "P").rotation, np.eye(3), atol=0)
    qz = rob.poses["zero_motors"]
    assert qz[rob.idx_q("LCS_y")] == pytest.approx(float(ah.platform_orientation(0.0, 0.0)[1]), abs=1e-15)
    qe = rob.poses["extended"]
    assert qe[rob.idx_q("LL")] == pytest.approx(float(ah.ll_angle(8 * math.pi)), abs=1e-16)


# ------------------------------------------------------------------------------------------ reference facts
def test_rod_span_at_zero_motors_does_not_close(robot):
    assert np.allclose(ah.rod_spans(0.0, 0.0), 0.0839, atol=5e-5)
    # the same span measured in Pinocchio: lever tip (sphere joint centre) to the platform point
    q = robot.configuration({"MCS1": 0.0, "MCS2": 0.0, "LCS_x": 0.0, "LCS_y": 0.0})
    for i in (1, 2):
        tip = robot.frame_placement(q, f"Sph_{i}_1_a").translation
        att = robot.frame_placement(q, f"P_sph_{i}").translation
        assert np.linalg.norm(att - tip) == pytest.approx(float(ah.rod_spans(0.0, 0.0)[i - 1]), abs=1e-15)
    # and the zero-motor pose closes with the platform pitched -20.48 deg
    assert np.allclose(ah.platform_orientation(0.0, 0.0) / DEG, [0.0, -20.48], atol=5e-3)


def test_neutral_motor_angles():
    assert np.allclose(ah.motor_angles(0.0, 0.0) / DEG, [18.255, -18.255], atol=5e-4)
    assert np.allclose(ah.motor_angles(0.0, 0.0, (-1, -1)) / DEG, [-82.22, 82.22], atol=5e-3)
    th = ah.motor_angles(0.0, 0.0)
    assert th[0] == -th[1]  # mirror symmetry of the two chains
    # lever at 86.8 deg to the rod at the neutral pose
    lever_x = np.stack([np.cos(th + ah.MOTOR_YAW), np.sin(th + ah.MOTOR_YAW), np.zeros(2)], -1)
    tip = ah.MOTOR_POS + ah.LEVER[0] * lever_x + [0.0, 0.0, ah.LEVER[2]]
    rod = ah.CENTER + ah.ATTACH - tip
    ang = np.arccos(np.sum(rod * lever_x, -1) / ah.ROD_LENGTH) / DEG
    assert np.allclose(ang, 86.8, atol=0.05)


def test_neutral_sensitivity():
    inv = np.linalg.inv(ah.motor_jacobian(0.0, 0.0))
    assert np.allclose(inv, [[0.586, 0.586], [0.655, -0.655]], atol=5e-4)
    assert np.linalg.cond(inv) == pytest.approx(1.12, abs=5e-3)


def test_spherical_free_axis_reference(spherical):
    axis = ah.spherical_free_axis(np.eye(3))
    assert np.allclose(axis, [-0.39, 0.0, 0.92], atol=5e-3)
    dof, measured = ch.platform_dof(spherical, spherical.q0)
    assert dof == 1
    assert np.abs(measured - axis).max() < 1e-12


def test_extension_four_turns():
    tll = ah.ll_angle(4 * 2 * math.pi)
    p = ah.foot_position_from_platform(0.0, 0.0, tll)
    p0 = ah.foot_position_from_platform(0.0, 0.0, 0.0)
    assert p[2] == pytest.approx(-0.301, abs=5e-4)
    assert p[0] - p0[0] == pytest.approx(0.026, abs=5e-4)
    # ~70 mm per revolution, almost straight down, at the start
    d1 = ah.foot_position_from_platform(0.0, 0.0, ah.ll_angle(2 * math.pi)) - p0
    assert np.linalg.norm(d1) == pytest.approx(0.07, abs=1e-4)


# ------------------------------------------------------------------------------------------ mobility
def test_mobility_counts(robot, spherical):
    spins = ["Sph_1_1_x", "Sph_2_1_x"]
    for rob, expected in ((robot, 0), (spherical, 1)):
        q = rob.q0
        free = rob.model.nv - 6
        assert rob.mobility(q) == free  # 6 independent rows: two point closures
        assert rob.mobility(q, locked=ACTUATED) == 2 + expected  # + 2 rod spins
        assert rob.mobility(q, locked=ACTUATED + tuple(spins)) == expected
        assert ch.platform_dof(rob, q)[0] == expected
        # the two extra DOF with motors locked are the rod spins: they move no other joint
        jc = rob.constraint_jacobian(q)
        for s in spins:
            v = np.zeros(rob.model.nv)
            v[rob.idx_v(s)] = 1.0
            assert np.abs(jc @ v).max() < 1e-15


# ------------------------------------------------------------------------------------------ round trips
workspace = st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.1))


@settings(max_examples=150, deadline=None)
@given(workspace)
@example((2.220446049250313e-16, 0.0))  # mirror-symmetric motors: roll = 0 is a double root of the FK polynomial
@example((2.220446049250313e-16, 0.7767573355751394))  # ... which the root finder lost (CI, derandomized)
def test_motor_angles_platform_orientation_round_trip(x):
    roll, pitch = x
    assume(_in_mode(roll, pitch))
    th = ah.motor_angles(roll, pitch)
    assert np.allclose(ah.rod_spans(th[0], th[1], roll, pitch), ah.ROD_LENGTH, atol=1e-15, rtol=0)
    back = ah.platform_orientation(th[0], th[1])
    assert np.abs(back - [roll, pitch]).max() < 1e-12


@settings(max_examples=60, deadline=None)
@given(st.floats(-0.9, 0.9), st.floats(-7.0, -2.0))
def test_platform_orientation_near_forward_singularity(roll, log_dist):
    """Just inside the forward-singularity curve: converges in the neutral mode, error ~ eps / sigma_min."""
    lo, hi = 0.0, 1.1
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if cfg.neutral_mode(np.array([roll]), np.array([mid]))[0] else (lo, mid)
    pitch = lo - 10.0**log_dist
    th = ah.motor_angles(roll, pitch)
    back = ah.platform_orientation(th[0], th[1])
    sigma = float(cfg.sigma_min(np.array([roll]), np.array([pitch]))[0])
    assert np.abs(back - [roll, pitch]).max() * sigma < ch.TOL_SCALED


@settings(max_examples=60, deadline=None)
@given(st.floats(-math.pi, math.pi), st.floats(-1.0, 1.0))
@example(0.0, 0.0)  # failed with a reach tolerance of 1e-12 (rod-length error 1.2e-13 m)
def test_motor_angles_at_reach_boundary(direction, log_gap):
    """Points just inside the reach boundary (|k| -> 1) still close the loops to 1e-15 m."""
    lo, hi = 0.0, 3.0
    d = np.array([math.cos(direction), math.sin(direction)])
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        _, ok = ah.motor_angles(*(mid * d)[:, None], return_mask=True)
        lo, hi = (mid, hi) if ok[0] else (lo, mid)
    roll, pitch = lo * d
    assert ah.motor_angles(roll, pitch, return_mask=True)[1]
    th = ah.motor_angles(roll, pitch)
    assert np.allclose(ah.rod_spans(th[0], th[1], roll, pitch), ah.ROD_LENGTH, atol=1e-14, rtol=0)
    # just outside: the scalar call raises, the batch returns NaN and a False mask
    out = hi * d * (1 + 1e-9) + 1e-12 * np.sign(d)
    with pytest.raises(UnreachableError):
        ah.motor_angles(out[0], out[1])
    val, ok = ah.motor_angles(out[:1], out[1:], return_mask=True)
    assert not ok[0] and np.all(np.isnan(val))


@settings(max_examples=150, deadline=None)
@given(workspace, st.floats(-0.3, 0.125), st.floats(-0.5, 0.5))
def test_foot_ik_round_trip(x, tll, starting_value):
    roll, pitch = x
    assume(_in_mode(roll, pitch))
    th = ah.motor_angles(roll, pitch)
    geo = ah.Geometry(starting_value=starting_value)
    t0 = ah.extension_motor_angle(tll, geometry=geo)
    p = ah.fk(_q(th[0], th[1], t0), geometry=geo)
    assert np.abs(p - ah.foot_position_from_platform(roll, pitch, tll)).max() < 1e-12
    kappa = float(ch.foot_ik_condition(p, np.array(tll), np.array(roll), np.array(pitch)))
    llb = -1 if tll <= ah.LL_DELTA else 1
    sol = ah.ik(p, geometry=geo, ll_branch=llb)
    err = max(np.abs(sol[:2] - th).max(), abs(ah.ll_angle(sol[2], geometry=geo) - tll))
    assert err < max(1e-12, kappa * ch.TOL_KAPPA)
    # the target is reached whatever the conditioning of the angles
    plat = ah.foot_platform_ik(p, ll_branch=llb)
    assert np.abs(ah.foot_position_from_platform(*plat[1:], plat[0]) - p).max() < 1e-14


@settings(max_examples=60, deadline=None)
@given(st.floats(-1.0, 1.0), st.floats(-8.0, -1.0), st.sampled_from([-1, 1]))
def test_foot_ik_near_ll_branch_merge(roll, log_alpha, side):
    """Near theta_LL = LL_DELTA the LL branches merge; both still reach the target."""
    tll = ah.LL_DELTA + side * 10.0**log_alpha
    p = ah.foot_position_from_platform(roll * 0.5, 0.2, tll)
    for llb in (-1, 1):
        plat = ah.foot_platform_ik(p, ll_branch=llb)
        assert np.abs(ah.foot_position_from_platform(*plat[1:], plat[0]) - p).max() < 1e-14
    plat = ah.foot_platform_ik(p, ll_branch=side)
    assert abs(plat[0] - tll) < 1e-15 / 10.0**log_alpha + 1e-15


def test_foot_ik_all_branches():
    p = ah.foot_position_from_platform(0.1, 0.2, -0.1)
    every = ah.ik_branches(p)
    allb, ok = every.motors, every.mask
    assert allb.shape == (16, 3) and ok.shape == (16,)
    assert ok.sum() >= 2 and ok[0]
    assert np.all(np.isnan(allb[~ok]))
    for (llb, rb, b1, b2), sol, good in zip(ah.FOOT_IK_BRANCHES, allb, ok):
        if good:
            x = ah.foot_platform_ik(p, ll_branch=llb, roll_branch=rb)
            assert np.allclose(ah.motor_angles(x[1], x[2], (b1, b2)), sol[:2], atol=0)
            assert abs(ah.ll_angle(sol[2]) - x[0]) < 1e-15
    assert np.array_equal(ah.ik(p), allb[0])


def test_batch_shapes_and_scalar_wrapper():
    rng = np.random.default_rng(0)
    r, p = cfg.sample_workspace(12, rng)
    r, p = r.reshape(3, 4), p.reshape(3, 4)
    th = ah.motor_angles(r, p)
    assert th.shape == (3, 4, 2)
    assert np.array_equal(ah.motor_angles(r[1, 2], p[1, 2]), th[1, 2])
    x = ah.platform_orientation(th[..., 0], th[..., 1])
    assert x.shape == (3, 4, 2) and np.abs(x - np.stack([r, p], -1)).max() < 1e-12
    t0 = np.zeros((3, 4))
    foot = ah.fk(_q(th[..., 0], th[..., 1], t0))
    assert foot.shape == (3, 4, 3)
    jac = ah.jacobian(_q(th[..., 0], th[..., 1], t0))
    assert jac.shape == (3, 4, 3, 3)
    assert np.array_equal(ah.jacobian(_q(th[1, 2, 0], th[1, 2, 1], 0.0)), jac[1, 2])
    sol = ah.ik(foot)
    assert sol.shape == (3, 4, 3)
    assert ah.ik_all(foot).shape == (3, 4, 16, 3)
    assert ah.sphere_joint_angles(ah.platform_rotation(r, p)).shape == (3, 4, 2, 3)


def test_ll_transmission_round_trip():
    t0 = np.linspace(-50, 50, 11)
    geo = ah.Geometry(starting_value=0.3)
    assert np.allclose(ah.extension_motor_angle(ah.ll_angle(t0, geometry=geo), geometry=geo), t0, atol=1e-12)
    assert ah.ll_angle(0.0, geometry=geo) == 0.3
    assert ah.ll_angle(2 * math.pi) == pytest.approx(-0.07 / 1.5, rel=1e-15)  # 70 mm of arc per turn


# ------------------------------------------------------------------------------------------ error paths
@pytest.mark.parametrize(
    "params",
    [{"center": "ball"}, {"center": 1.0}, {"starting_value": float("nan")}, {"starting_value": 4.0}, {"foo": 1}],
)
def test_bad_params_raise_before_writing(params, tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    monkeypatch.setenv("LEGKIN_CACHE", str(cache))
    with pytest.raises(InvalidParameterError) as info:
        legkin.load("hybrid_leg", **params)
    assert list(params)[0] in str(info.value)
    assert not cache.exists()


def test_floating_is_refused():
    with pytest.raises(legkin.LegkinError):
        legkin.load("hybrid_leg", floating=True)


@pytest.mark.parametrize(
    "call",
    [
        lambda: ah.motor_angles(float("nan"), 0.0),
        lambda: ah.motor_angles([0.0, 1.0], [0.0, 0.1, 0.2]),
        lambda: ah.motor_angles(0.0, 0.0, branch=(1, 0)),
        lambda: ah.motor_angles(0.0, 0.0, branch=1),
        lambda: ah.motor_angles_from_rotation(np.eye(3)[:2]),
        lambda: ah.motor_angles_from_rotation(2 * np.eye(3)),
        lambda: ah.motor_angles_from_rotation(np.diag([1.0, 1.0, -1.0])),
        lambda: ah.platform_orientation(0.3, float("inf")),
        lambda: ah.platform_orientation(0.3, -0.3, q_start=[0.0]),
        lambda: ah.fk(_q(0.3, -0.3, float("nan"))),
        lambda: ah.ik([0.4, 0.0, -0.2], ll_branch=0),
        lambda: ah.ik([0.4, 0.0, -0.2], geometry=ah.Geometry(starting_value=float("nan"))),
        lambda: ah.foot_platform_ik([0.4, 0.0, -0.2], roll_branch=2),
        lambda: ah.ll_angle("x"),
        lambda: ah.sphere_joint_angles(np.ones((3, 3))),
        lambda: ah.jacobian(_q(0.3, -0.3, [0.0, float("nan")])),
    ],
)
def test_invalid_input_raises_value_error(call):
    with pytest.raises(InvalidInputError) as info:
        call()
    assert isinstance(info.value, ValueError)


def test_unreachable_platform():
    with pytest.raises(UnreachableError, match="chain"):
        ah.motor_angles(0.0, -1.0)
    th, ok = ah.motor_angles([0.0, 0.0], [0.0, -1.0], return_mask=True)
    assert ok.tolist() == [True, False]
    assert np.all(np.isfinite(th[0])) and np.all(np.isnan(th[1]))
    rot = ah.platform_rotation(0.0, -1.0)
    with pytest.raises(UnreachableError):
        ah.motor_angles_from_rotation(rot)
    with pytest.raises(UnreachableError):
        ah.sphere_joint_angles(rot)
    with pytest.raises(UnreachableError):
        ah.spherical_free_axis(rot)
    with pytest.raises(UnreachableError):
        ah.motor_jacobian(0.0, -1.0)


def test_unreachable_foot():
    far = ah.CENTER + [0.0, 0.0, -3.5]
    near = ah.CENTER + [0.0, 0.0, -0.1]
    for p in (far, near):
        with pytest.raises(UnreachableError, match="LL arc"):
            ah.ik(p)
        with pytest.raises(UnreachableError):
            ah.foot_platform_ik(p)
        assert not ah.ik_branches(p).mask.any()
    # on the LL arc but beyond the motors on the extension side (ll_branch -1): needs the platform pitched
    # ~ -90 deg. (The default search also tries ll_branch +1, which reaches it in the neutral mode at pitch 0.66.)
    beyond = ah.foot_position_from_platform(0.0, -1.5, -0.2)
    with pytest.raises(UnreachableError, match="roll, pitch"):
        ah.ik(beyond, ll_branch=-1)
    sol, ok = ah.ik(np.stack([ah.foot_position_from_platform(0.0, 0.0, -0.1), far, beyond]), ll_branch=-1,
                    return_mask=True)
    assert ok.tolist() == [True, False, False]
    assert np.all(np.isnan(sol[1:])) and np.all(np.isfinite(sol[0]))


def test_singular_foot_on_roll_axis():
    on_axis = ah.CENTER + [0.3, 0.0, 0.0]
    with pytest.raises(SingularityError, match="roll axis"):
        ah.foot_platform_ik(on_axis)
    with pytest.raises(SingularityError):
        ah.ik(on_axis)
    x, ok = ah.foot_platform_ik(np.stack([on_axis, on_axis + [0, 0, -0.1]]), return_mask=True)
    assert ok.tolist() == [False, True] and np.all(np.isnan(x[0]))


def test_forward_kinematics_does_not_assemble():
    # motor angles no platform pose of the neutral mode reaches
    with pytest.raises(ConvergenceError):
        ah.platform_orientation(3.0, 3.0)
    with pytest.raises(ConvergenceError):
        ah.fk(_q(3.0, 3.0, 0.0))
    with pytest.raises(ConvergenceError):
        ah.jacobian(_q(3.0, 3.0, 0.0))
    x, ok = ah.platform_orientation([0.3, 3.0], [-0.3, 3.0], return_mask=True)
    assert ok.tolist() == [True, False] and np.all(np.isnan(x[1]))


# ------------------------------------------------------------------------------------------ IK contract (issue 10)
# (a) every foot_ik answer is reproduced by foot_position (default options) to 1e-9 m; (b) every target the
# default foot_position makes from in-limit joints is solved; (c) answers inside the URDF limits, JointLimitError
# where reachable only outside them; (d) the assembly mode is an argument of FK and IK (default: the SRDF
# reference pose's), AssemblyModeError names the modes that reach a target.
REPRO = 1e-9


def _aspect_box(n, rng):
    """Poses of the neutral aspect: branch (1, 1), the sign of det(dtheta/dx) of R_P = I, pitch below 1.2 rad."""
    r, p = rng.uniform(-1.3, 1.3, n), rng.uniform(-0.62, 0.98, n)
    keep = cfg.neutral_mode(r, p) & (p < 1.2)
    return r[keep], p[keep]


def _aspect_edge(n, rng):
    """Poses on the neutral aspect's edge (reach boundary, or forward singularity) by bisection along rays."""
    d = rng.normal(size=(n, 2))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    lo, hi = np.zeros(n), np.full(n, 2.0)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        inside = cfg.neutral_mode(mid * d[:, 0], mid * d[:, 1])
        lo, hi = np.where(inside, mid, lo), np.where(inside, hi, mid)
    return lo * d[:, 0], lo * d[:, 1]


def test_default_answers_are_reproduced_by_foot_position():
    """Defect 1: foot_ik answered targets of the other assembly mode, foot_position put the foot cm away."""
    rng = np.random.default_rng(7)
    p = ah.CENTER + rng.uniform(-1.6, 1.6, (20000, 3))
    sol, ok = ah.ik(p, return_mask=True)
    assert ok.sum() > 1000
    back, fk_ok = ah.fk(_q(sol[ok, 0], sol[ok, 1], sol[ok, 2]), return_mask=True)
    assert fk_ok.all()
    assert np.linalg.norm(back - p[ok], axis=-1).max() < REPRO


def test_fk_made_targets_are_solved():
    """Defect 1, other way round: 1,802 of 4,900 FK-made targets needed ll_branch=+1 and were refused."""
    rng = np.random.default_rng(8)
    th = rng.uniform(-0.6, 0.6, (4900, 2))
    t0 = rng.uniform(-20.0, 20.0, 4900)
    p, made = ah.fk(_q(th[:, 0], th[:, 1], t0), return_mask=True)
    assert made.sum() > 4500
    sol, ok = ah.ik(p[made], return_mask=True)
    assert ok.all()
    back = ah.fk(_q(sol[:, 0], sol[:, 1], sol[:, 2]))
    assert np.linalg.norm(back - p[made], axis=-1).max() < REPRO
    # every one of them is a solution of the mode foot_position was asked for
    assert np.all(ah.assembly_mode(*ah.platform_orientation(sol[:, 0], sol[:, 1]).T) == 1)


@pytest.mark.parametrize("tll", [ah.LL_DELTA - math.pi, ah.LL_DELTA, math.pi, -math.pi],
                         ids=["outer", "inner", "+pi", "-pi"])
def test_reach_boundary_targets_made_by_fk_are_solved(tll):
    """Defect 2: 262 of 10,000 FK-made targets at the outer reach (3.14042 m) were rejected."""
    rng = np.random.default_rng(9)
    r, pch = _aspect_box(4000, rng)
    th = ah.motor_angles(r, pch)
    p, made = ah.fk(_q(th[:, 0], th[:, 1], ah.extension_motor_angle(np.full(len(r), tll))), return_mask=True)
    sol, ok = ah.ik(p[made], return_mask=True)
    assert ok.all()
    assert np.linalg.norm(ah.fk(sol) - p[made], axis=-1).max() < REPRO


def test_motor_reach_boundary_targets_made_by_fk_are_solved():
    """Poses on the neutral aspect's reach boundary (|k| = 1, rounding either side) made into feet by FK."""
    rng = np.random.default_rng(10)
    r, pch = _aspect_edge(400, rng)
    th = ah.motor_angles(r, pch)
    p, made = ah.fk(_q(th[:, 0], th[:, 1], rng.uniform(-3, 3, len(r))), return_mask=True)
    assert made.sum() > 100
    sol, ok = ah.ik(p[made], return_mask=True)
    assert ok.all()
    assert np.linalg.norm(ah.fk(sol) - p[made], axis=-1).max() < REPRO


@pytest.mark.parametrize("p", [
    (0.35932548361747274, 0.052945636996343165, 0.12838996243829895),
    (3.017622853706293, -0.55479095007595769, 1.4202339468074257),
    (0.39687424261991033, 0.033343663692197233, 0.049344277550207906),
    (3.0737579217644839, 0.65394394635417552, 1.257130052827369),
])
def test_fk_made_at_the_aspect_edge(p):
    """FK-made targets (ik_robustness, 10^5 run) whose pose lies on the neutral aspect's reach boundary: the IK's
    pose, computed from the foot, exceeded |k| = 1 by 1e-14..1e-13 and was refused."""
    p = np.array(p)
    m = ah.ik(p)
    assert np.linalg.norm(ah.fk(m) - p) < REPRO


def test_unreachable_arc_message_is_consistent():
    """Defect 2: the message said '3.14042 m from the centre; the arc reaches [0.140417, 3.14042] m'."""
    hi = LL0 + H
    for r in (hi * (1 + 1e-11), hi + 1e-9, 0.5 * (LL0 - H)):
        p = ah.CENTER + [r, 0.0, 1e-3]
        with pytest.raises(UnreachableError) as info:
            ah.ik(p)
        msg = str(info.value)
        dist = float(msg.split(" m from the LCS centre")[0].rsplit(" ", 1)[1])
        lo_, hi_ = (float(v) for v in msg.split("reaches [")[1].split("]")[0].split(", "))
        assert not lo_ <= dist <= hi_, msg
        assert ("beyond its outer end" in msg) == (r > hi)


def test_other_assembly_mode_raises_and_modes_reach_it():
    """A target reachable only in another assembly mode: unsolved by default, AssemblyModeError names the modes,
    and foot_ik / foot_position with those mode arguments reproduce it."""
    p = ah.foot_position_from_platform(-0.8438537262935863, 0.989660622822937, 0.15765221087324321)
    with pytest.raises(legkin.AssemblyModeError) as info:
        ah.ik(p)
    err = info.value
    assert isinstance(err, UnreachableError) and err.modes
    sol, ok = ah.ik(p[None], return_mask=True)
    assert not ok[0] and np.all(np.isnan(sol))
    for mode in err.modes:
        assert f"branch=({mode['branch'][0]}, {mode['branch'][1]}), assembly={mode['assembly']:+d}" in str(err)
        m = ah.ik(p, **mode)
        back = ah.fk(_q(m[0], m[1], m[2]), branch=mode["branch"], assembly=mode["assembly"])
        assert np.linalg.norm(back - p) < REPRO
        # and foot_position with the default mode does not put the foot there
        fk, fk_ok = ah.fk(_q(m[:1], m[1:2], m[2:]), return_mask=True)
        assert not fk_ok[0] or np.linalg.norm(fk[0] - p) > 1e-6
    # all modes on request
    every = ah.ik_branches(p)
    assert every.valid.sum() == len(err.modes) and not (every.valid & (every.assembly == 1))[[0, 4, 8, 12]].any()


def test_ik_all_fk_certificate_agrees_with_forward_kinematics():
    """The cheap FK check of ik_all (_ik_certify.certify_k) accepts a candidate only where the full forward kinematics
    of its motors in its mode returns its pose; and ik_all.valid is exactly 'fk of the motors in that mode is the
    target' on branches off the neutral aspect (where it is not exact by construction)."""
    from legkin.hybrid_leg._ik_certify import CERTIFY_WORK, certify_k
    from legkin.hybrid_leg._ik_kernels import BRANCHES, ik_all_k
    from legkin.hybrid_leg.forward import fk_select_k
    from legkin.hybrid_leg.geometry import CENTER, FK_GAIN_MAX

    rng = np.random.default_rng(5)
    n = 300
    q = np.column_stack([rng.uniform(-np.pi, np.pi, n), rng.uniform(-np.pi, np.pi, n), rng.uniform(-16, 40, n)])
    targets = [ah.fk(q, branch=b, assembly=a, return_mask=True) for b in ((1, -1), (-1, 1), (-1, -1)) for a in (1, -1)]
    p = np.concatenate([x[ok] for x, ok in targets])
    work, xf = np.empty(CERTIFY_WORK), np.empty(2)
    motors, pose, info, fk = np.empty((16, 3)), np.empty((16, 3)), np.empty((16, 7)), np.empty(16, dtype=np.bool_)
    certified = checked = 0
    for u in p - CENTER:
        ik_all_k(u[0], u[1], u[2], 0.0, False, motors, pose, info, fk)
        for j in range(16):
            if not (info[j, 0] == 1 and info[j, 1] == 1 and info[j, 2] != 0 and info[j, 3] < FK_GAIN_MAX):
                continue
            b1, b2, s = BRANCHES[j, 2], BRANCHES[j, 3], info[j, 2]
            found = fk_select_k(motors[j, 0], motors[j, 1], b1, b2, s, 1e-12, 50, xf) == 0
            returned = found and max(abs(xf[0] - pose[j, 1]), abs(xf[1] - pose[j, 2])) <= 1e-7
            checked += 1
            if certify_k(pose[j], motors[j], b1, b2, s, work):
                certified += 1
                assert returned, (u, j)
            assert fk[j] == returned or (b1 == b2 == s == 1 and pose[j, 2] < 1.2)
    assert checked > 500 and certified > 0.9 * checked


def test_joint_limit_error():
    """Reachable only with |roll| > pi/2 (LCS_x limit): JointLimitError, mask False; no answer outside the limits."""
    p = ah.foot_position_from_platform(-0.06284610557749781, -1.0207832560887642, 0.23457715140921453)
    with pytest.raises(legkin.JointLimitError, match="outside the joint limits") as info:
        ah.ik(p)
    err = info.value  # the data: the first platform joint (LCS_x: roll, LCS_y: pitch) outside its URDF limits
    assert err.joint in ("LCS_x", "LCS_y") and (err.lower, err.upper) == (-ah.PLATFORM_LIMIT, ah.PLATFORM_LIMIT)
    assert abs(err.value) > ah.PLATFORM_LIMIT and np.array_equal(err.target, p)
    every = ah.ik_branches(p)
    assert every.mask.any() and not every.within_limits[every.mask].any()
    k = 1 if err.joint == "LCS_x" else 2  # that joint's value is the branch's roll or pitch
    assert np.isclose(every.pose[every.mask][:, k], err.value).any()
    assert not ah.ik(p[None], return_mask=True)[1][0]


def test_fk_mode_arguments_and_all_poses():
    """(d): branch and assembly in FK; platform_poses lists every mode, foot_position follows the argument."""
    th = ah.motor_angles(0.1, 0.3)
    poses = ah.platform_poses(th[0], th[1])
    assert poses.x.shape == (8, 2) and poses.mask[0]
    assert np.allclose(poses.x[0], [0.1, 0.3], atol=1e-12)
    assert tuple(poses.branch[0]) == (1, 1) and poses.assembly[0] == 1
    assert np.allclose(ah.platform_orientation(th[0], th[1]), [0.1, 0.3], atol=1e-12)
    for x, b, a in zip(poses.x[poses.mask], poses.branch[poses.mask], poses.assembly[poses.mask]):
        if 0 in b:
            continue
        got = ah.platform_orientation(th[0], th[1], tuple(b), assembly=int(a))
        assert np.linalg.norm(got) <= np.linalg.norm(x) + 1e-12  # the mode's pose nearest R_P = I
        foot = ah.fk(_q(th[0], th[1], 0.0), branch=tuple(b), assembly=int(a), return_mask=True)
        if foot[1]:
            m = ah.ik(foot[0], branch=tuple(b), assembly=int(a))
            back = ah.fk(_q(m[0], m[1], m[2]), branch=tuple(b), assembly=int(a))
            assert np.linalg.norm(back - foot[0]) < REPRO
    # R_P = I on the other motor branches: the default mode does not assemble, the message says where it does
    th = ah.motor_angles(0.0, 0.0, (-1, -1))
    with pytest.raises(ConvergenceError, match=r"it does at \(roll, pitch\) = \(0, 0\) on branch \(-1, -1\)"):
        ah.platform_orientation(th[0], th[1])
    assert np.abs(ah.platform_orientation(th[0], th[1], (-1, -1))).max() < 1e-12
    foot = ah.fk(_q(th[0], th[1], 0.0), branch=(-1, -1))
    m = ah.ik(foot, branch=(-1, -1))
    assert np.allclose(m[:2], th, atol=1e-12)


def test_forward_singularity_band():
    """Near det N = 0 double-precision motor angles do not fix the foot to 1e-9 m: foot_position refuses the band,
    foot_ik too; just outside it both work and agree."""
    roll = 0.2
    lo, hi = 0.0, 1.1
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if cfg.neutral_mode(np.array([roll]), np.array([mid]))[0] else (lo, mid)
    for dist, refused in ((1e-9, True), (1e-2, False)):
        th = ah.motor_angles(roll, lo - dist)
        foot, ok = ah.fk(_q([th[0]], [th[1]], [0.0]), return_mask=True)
        assert ok[0] != refused
        p = ah.foot_position_from_platform(roll, lo - dist, 0.0)
        if refused:
            with pytest.raises(SingularityError, match="forward singularity"):
                ah.fk(_q(th[0], th[1], 0.0))
            with pytest.raises(SingularityError, match="forward singularity"):
                ah.ik(p, ll_branch=-1)
        else:
            m = ah.ik(p)
            assert np.linalg.norm(ah.fk(m) - p) < REPRO


_BAD_KEYWORDS = [
    ("ik", {"ll_branch": np.array([1, -1])}, "ll_branch"),
    ("ik", {"ll_branch": True}, "ll_branch"),
    ("ik", {"ll_branch": 0.5}, "ll_branch"),
    ("ik", {"roll_branch": "1"}, "roll_branch"),
    ("ik", {"roll_branch": float("nan")}, "roll_branch"),
    ("ik", {"branch": np.array([[1, 1]])}, "branch"),
    ("ik", {"branch": "11"}, "branch"),
    ("ik", {"branch": (1, 1j)}, "branch"),
    ("ik", {"assembly": 0}, "assembly"),
    ("ik", {"assembly": "all"}, "assembly"),
    ("ik_all", {"return_mask": 1}, "return_mask"),
    ("ik", {"return_mask": "yes"}, "return_mask"),
    ("foot_platform_ik", {"ll_branch": np.array([1])}, "ll_branch"),
    ("foot_platform_ik", {"assembly": 2}, "assembly"),
]


@pytest.mark.parametrize("func, kwargs, name", _BAD_KEYWORDS,
                         ids=[f"{f}-{n}-{i}" for i, (f, _, n) in enumerate(_BAD_KEYWORDS)])
def test_bad_keyword_arguments(func, kwargs, name):
    """Defect 3: every keyword validated, a legkin error naming it and its valid values (never a numpy error)."""
    with pytest.raises(InvalidParameterError) as info:
        getattr(ah, func)([0.4, 0.0, -0.2], **kwargs)
    assert isinstance(info.value, InvalidInputError)
    assert name in str(info.value) and repr(kwargs[name])[:20] in str(info.value)


@pytest.mark.parametrize(
    "call",
    [
        lambda: ah.platform_orientation(0.3, -0.3, tol=0.0),
        lambda: ah.platform_orientation(0.3, -0.3, tol=float("nan")),
        lambda: ah.platform_orientation(0.3, -0.3, tol=1.0),
        lambda: ah.platform_orientation(0.3, -0.3, tol="1e-12"),
        lambda: ah.platform_orientation(0.3, -0.3, max_iter=0),
        lambda: ah.platform_orientation(0.3, -0.3, max_iter=2.5),
        lambda: ah.platform_orientation(0.3, -0.3, max_iter=True),
        lambda: ah.platform_orientation(0.3, -0.3, assembly=-2),
        lambda: ah.platform_orientation(0.3, -0.3, branch=[1, 1, 1]),
        lambda: ah.platform_poses(0.3, -0.3, tol=-1.0),
        lambda: ah.fk(_q(0.3, -0.3, 0.0), assembly=None),
        lambda: ah.fk(_q(0.3, -0.3, 0.0), geometry=ah.Geometry(starting_value=True)),
        lambda: ah.jacobian(_q(0.3, -0.3, 0.0), branch=np.array([1.0, -1.0, 1.0])),
        lambda: ah.motor_angles(0.0, 0.0, branch=np.array([1, 1]) * 1j),
        lambda: ah.assembly_mode(0.0, 0.0, return_mask=None),
        lambda: ah.ll_angle(0.0, geometry=ah.Geometry(starting_value=np.nan)),
    ],
)
def test_bad_parameters_of_other_functions(call):
    with pytest.raises(InvalidParameterError):
        call()


@pytest.mark.parametrize(
    "call",
    [
        lambda: ah.ik([[0.4, 0.0, -0.2], [0.4, 0.0]]),
        lambda: ah.ik(["0.4", "0", "-0.2"]),
        lambda: ah.ik_branches([0.4, 0.0, float("nan")]),
        lambda: ah.foot_platform_ik(np.zeros(2)),
        lambda: ah.platform_poses([0.3, 0.2], [0.1, 0.2, 0.3]),
        lambda: ah.platform_orientation(0.3, -0.3, q_start=[0.0, float("nan")]),
        lambda: ah.platform_orientation([0.3, 0.3], [-0.3, 0.3], q_start=np.zeros((3, 2))),
        lambda: ah.assembly_mode(float("nan"), 0.0),
    ],
)
def test_bad_inputs_raise_invalid_input(call):
    with pytest.raises(InvalidInputError):
        call()


def test_extreme_inputs_give_nan_and_mask_or_legkin_errors():
    """No numpy exception escapes: huge, tiny and empty inputs; a batch gives NaN + mask, a single call a legkin
    error."""
    big = np.array([[1e308, 1e308, 1e308], [-1e300, 0.0, 1e-300], [5e-324, 0.0, 0.0], ah.CENTER, [0.4, 0.0, -0.2]])
    for f in (ah.ik, ah.foot_platform_ik):
        out, ok = f(big, return_mask=True)
        assert ok.tolist()[:4] == [False, False, False, False] and np.all(np.isnan(out[:4]))
        for p in big[:4]:
            with pytest.raises(legkin.LegkinError):
                f(p)
    every = ah.ik_branches(big)
    assert not every.mask[[0, 1, 3]].any()
    assert ah.ik(np.zeros((0, 3))).shape == (0, 3)
    assert ah.ik_all(np.zeros((0, 3))).shape == (0, 16, 3)
    assert ah.fk(_q(np.zeros(0), np.zeros(0), np.zeros(0))).shape == (0, 3)
    assert ah.platform_orientation(np.zeros((2, 0)), np.zeros((2, 0))).shape == (2, 0, 2)
    assert ah.platform_poses(np.zeros(0), np.zeros(0)).x.shape == (0, 8, 2)
    th, ok = ah.platform_orientation([1e300, -1e300, 0.3], [1e300, 0.0, -0.3], return_mask=True)
    assert ok.tolist() == [False, False, True]
    foot, ok = ah.fk(_q([1e300, 0.3], [0.0, -0.3], [1e300, 1e300]), return_mask=True)
    assert not ok[0] and np.all(np.isnan(foot[0]))
    with pytest.raises(legkin.LegkinError):
        ah.fk(_q(1e300, 0.0, 0.0))


def test_roll_axis_targets_made_by_fk():
    """FK-made feet can land exactly on the roll axis (u_y = u_z = 0 in floating point): solved with roll 0."""
    # found by random search (roll, theta_LL random, pitch putting the foot in P on the x axis): which poses land
    # exactly on the axis depends on the last bits of acos / atan2 (numpy's SIMD loops and libm, which the compiled
    # kernels use, differ by an ulp), so the search was rerun for the kernels of issue 16
    for roll, pitch, tll in ((-0.29684081726065514, 0.3928812109894282, 0.06424568367655326),
                             (-0.15205468195581676, -0.45561409836429995, -0.021177949055006404)):
        th = ah.motor_angles(roll, pitch)
        p = ah.fk(_q(th[0], th[1], ah.extension_motor_angle(tll)))
        assert p[1] == 0.0 and p[2] == ah.CENTER[2]
        m = ah.ik(p)
        assert np.linalg.norm(ah.fk(m) - p) < REPRO


def test_ik_robustness_row():
    row = ch.ik_robustness(3000, np.random.default_rng(4), classify=300)
    assert row.passed, row.name
    assert row.counts.made >= 1400 and row.counts.exceptions == 0


def _fold_pitch(roll):
    lo, hi = 0.0, 1.1
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if cfg.neutral_mode(np.array([roll]), np.array([mid]))[0] else (lo, mid)
    return lo


_ENDS = (ah.LL_DELTA - math.pi, ah.LL_DELTA, math.pi, -math.pi)
_cases = st.one_of(
    # a pose (in the neutral aspect or not) and theta_LL (anywhere in the LL limits, or at the arc's ends)
    st.tuples(st.just("pose"), st.floats(-1.6, 1.6), st.floats(-1.6, 1.6),
              st.one_of(st.floats(-math.pi, math.pi), st.sampled_from(_ENDS))),
    # the neutral aspect's edge along a direction (reach boundary or forward singularity)
    st.tuples(st.just("edge"), st.floats(-math.pi, math.pi), st.floats(-8.0, -1.0),
              st.one_of(st.floats(-math.pi, math.pi), st.sampled_from(_ENDS))),
    # just inside the forward singularity
    st.tuples(st.just("fold"), st.floats(-0.9, 0.9), st.floats(-10.0, -2.0), st.floats(-1.0, 1.0)),
    # the roll axis: pitch = atan2(f_z, f_x) for theta_LL
    st.tuples(st.just("axis"), st.floats(-1.3, 1.3), st.floats(-0.6, 0.6), st.floats(-12.0, -1.0)),
    # anywhere around the workspace
    st.tuples(st.just("box"), st.floats(-3.3, 3.3), st.floats(-3.3, 3.3), st.floats(-3.3, 3.3)),
)


def _build(case):
    """(target, made): made = produced by the default foot_position from in-limit joints."""
    kind, a, b, c = case
    if kind == "pose":
        roll, pitch, tll = a, b, c
    elif kind == "edge":
        d = np.array([math.cos(a), math.sin(a)])
        lo, hi = 0.0, 2.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            mode, ok = ah.assembly_mode(*(mid * d)[:, None], return_mask=True)
            lo, hi = (mid, hi) if ok[0] and mode[0] == 1 else (lo, mid)
        roll, pitch = (lo - 10.0**b) * d
        tll = c
    elif kind == "fold":
        roll, pitch, tll = a, _fold_pitch(a) - 10.0**b, c
    elif kind == "axis":
        tll = b
        f = ah.LL_ORIGIN + ah.FOOT_X * np.array([math.cos(tll), 0.0, -math.sin(tll)])
        roll, pitch = a, math.atan2(f[2], f[0]) + (10.0**c if c > -11.5 else 0.0)
    else:
        return ah.CENTER + np.array([a, b, c]), False
    th, ok = ah.motor_angles([roll], [pitch], return_mask=True)
    if ok[0] and abs(tll) <= math.pi:
        foot, made = ah.fk(_q(th[:, 0], th[:, 1], [ah.extension_motor_angle(tll)]), return_mask=True)
        if made[0]:
            return foot[0], True
    return ah.foot_position_from_platform(roll, pitch, tll), False


@settings(max_examples=250, deadline=None)
@given(_cases)
@example(("axis", 0.23340081963333725, 0.05348909126616064, -12.0))  # FK-made, exactly on the roll axis
@example(("pose", 0.23340081963333725, 0.2950143493035182, 0.05348909126616064))
@example(("pose", -0.8438537262935863, 0.989660622822937, 0.15765221087324321))  # another mode only
@example(("pose", 0.3, 0.2, ah.LL_DELTA - math.pi))  # the outer end of the LL arc
@example(("pose", 0.0, 0.0, ah.LL_DELTA))  # the inner end: LL branches meet
@example(("edge", -math.pi / 2, -8.0, 0.1))  # reach boundary
@example(("fold", 0.0, -10.0, 0.0))  # forward-singularity band
@example(("box", 0.3, 0.0, 0.0))  # exactly on the roll axis, no roll of 0 / pi in the mode
@example(("box", 0.0, 0.0, 0.0))  # the centre
@example(("axis", 0.0, -0.5, -1.0))  # AssemblyModeError whose valid modes include branch (1, 1), assembly -1
def test_ik_contract_property(case):
    p, made = _build(case)
    try:
        m = ah.ik(p)
        err = None
    except (UnreachableError, SingularityError) as exc:
        m, err = None, exc
    sol, ok = ah.ik(p[None], return_mask=True)
    assert bool(ok[0]) == (err is None)  # batch and single call agree
    if made:
        assert err is None, (case, err)  # (b)
    if err is None:
        assert np.array_equal(sol[0], m)
        assert np.linalg.norm(ah.fk(m) - p) < REPRO  # (a)
        assert np.all(np.abs(m[:2]) <= ah.MOTOR_LIMIT) and abs(ah.ll_angle(m[2])) <= ah.LL_LIMIT  # (c)
        x = ah.platform_orientation(m[0], m[1])
        assert np.all(np.abs(x) <= ah.PLATFORM_LIMIT)
        assert ah.assembly_mode(x[0], x[1]) == 1  # (d) the default mode
        return
    assert np.all(np.isnan(sol[0]))
    every = ah.ik_branches(p)
    if isinstance(err, legkin.AssemblyModeError):
        assert not (every.valid & (every.assembly == 1))[[0, 4, 8, 12]].any()  # no default-mode answer ...
        for mode in err.modes[:3]:  # ... but each named mode reaches it
            assert f"assembly={mode['assembly']:+d}" in str(err)
            m2 = ah.ik(p, **mode)
            back = ah.fk(_q(m2[0], m2[1], m2[2]), branch=mode["branch"], assembly=mode["assembly"])
            assert np.linalg.norm(back - p) < REPRO
    elif isinstance(err, legkin.JointLimitError):
        assert every.mask.any() and not every.within_limits.any()
    elif isinstance(err, UnreachableError):
        assert not every.valid.any()


# ------------------------------------------------------------------------------------------ API 0.2 (issue 11)
def test_geometry_defaults_range_and_from_params(robot):
    assert ah.Geometry() == ah.Geometry("universal", 0.0) == ah.Geometry.from_params(robot.params)
    assert ah.Geometry.from_params(None) == ah.Geometry()
    shifted = legkin.load("hybrid_leg", starting_value=0.25, center="spherical")
    assert ah.Geometry.from_params(shifted.params) == ah.Geometry(center="spherical", starting_value=0.25)
    assert ah.Geometry.from_params({"starting_value": 0.1, "unrelated": 3}) == ah.Geometry(starting_value=0.1)
    for bad in ({"starting_value": 3.5}, {"starting_value": float("nan")}, {"center": "ball"}):
        with pytest.raises(InvalidParameterError, match=list(bad)[0]):
            ah.Geometry(**bad)
    with pytest.raises(InvalidParameterError, match="geometry"):
        ah.ik(np.array([0.4, 0.0, -0.2]), geometry={"starting_value": 0.1})
    # the universal-centre forward kinematics refuses the spherical centre (the motors do not fix the platform)
    sph = ah.Geometry(center="spherical")
    q = np.array([0.3, -0.3, 0.0])
    for call in (lambda: ah.fk(q, geometry=sph), lambda: ah.jacobian(q, geometry=sph),
                 lambda: ah.platform_orientation(0.3, -0.3, geometry=sph), lambda: ah.ik(ah.fk(q), geometry=sph)):
        with pytest.raises(InvalidParameterError, match="universal centre"):
            call()
    # but the closed forms of a platform rotation hold for either centre
    assert np.array_equal(ah.motor_angles_from_rotation(np.eye(3), geometry=sph), ah.motor_angles(0.0, 0.0))


def test_starting_value_shifts_ll_only():
    geo = ah.Geometry(starting_value=0.2)
    q = np.array([*ah.motor_angles(0.1, 0.2), 3.0])
    assert ah.ll_angle(3.0, geometry=geo) == pytest.approx(ah.ll_angle(3.0) + 0.2, abs=1e-16)
    p = ah.fk(q, geometry=geo)
    assert np.abs(p - ah.foot_position_from_platform(0.1, 0.2, ah.ll_angle(3.0, geometry=geo))).max() < 1e-12
    sol = ah.ik(p, geometry=geo)
    assert np.linalg.norm(ah.fk(sol, geometry=geo) - p) < 1e-12
    assert not np.allclose(ah.fk(sol), p)


def test_ik_all_is_the_motors_and_mask_of_ik_branches():
    """ik_all: (..., 16, 3) motors, NaN rows exactly where ik_branches says a branch does not exist; the mask is
    that; a single target without any branch raises, a batch gives all-NaN rows."""
    q = np.array([*ah.motor_angles(0.1, 0.2), 1.0])
    p = ah.fk(q)
    far = np.array([0.0, 0.0, -5.0])
    every = ah.ik_branches(np.stack([p, far]))
    sols, mask = ah.ik_all(np.stack([p, far]), return_mask=True)
    assert sols.shape == (2, 16, 3) and mask.shape == (2, 16)
    assert np.array_equal(mask, every.mask) and mask[0].any() and not mask[1].any()
    assert np.array_equal(np.isnan(sols).any(-1), ~mask)
    assert np.array_equal(sols[mask], every.motors[mask])
    single, single_mask = ah.ik_all(p, return_mask=True)
    assert np.array_equal(single, sols[0], equal_nan=True) and np.array_equal(single_mask, mask[0])
    assert np.array_equal(ah.ik_all(p), single, equal_nan=True)
    with pytest.raises(legkin.UnreachableError) as info:
        ah.ik_all(far)
    assert np.array_equal(info.value.target, far)


def test_new_api_does_not_warn():
    q = np.array([*ah.motor_angles(0.1, 0.2), 1.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        p = ah.fk(q)
        ah.jacobian(q[None])
        ah.ik(p, q_near=q)
        ah.ik_branches(p)
        ah.platform_orientation(q[0], q[1], q_start=[0.0, 0.0])
        ah.ll_angle(np.zeros(2), geometry=ah.Geometry())


def test_q_near_picks_the_nearest_valid_branch():
    """Of the candidates the default IK keeps (in the mode, in the limits), q_near selects the nearest in the joints."""
    p = ah.fk(np.array([*ah.motor_angles(0.1, 0.2), 1.0]))  # both LL sides reach it in the mode, in the limits
    every = ah.ik_branches(p)
    keep = every.valid & (every.assembly == 1) & np.array([b[2:] == (1, 1) for b in ah.FOOT_IK_BRANCHES])
    assert keep.sum() >= 2
    first = ah.ik(p)
    assert np.array_equal(first, every.motors[keep][0]) or np.array_equal(first, every.motors[keep][1])
    for target in every.motors[keep]:
        got = ah.ik(p, q_near=target + 1e-3)
        assert np.array_equal(got, target)
    both = ah.ik(np.stack([p, p]), q_near=every.motors[keep][:2])
    assert np.array_equal(both, every.motors[keep][:2])


def test_docs_examples_run():
    """The code blocks of docs/hybrid_leg.md run (and their asserts hold) without a warning."""
    import pathlib
    import re

    text = (pathlib.Path(__file__).resolve().parents[1] / "docs" / "hybrid_leg.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        for block in blocks:
            exec(compile(block, "docs/hybrid_leg.md", "exec"), {})
