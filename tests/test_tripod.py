"""Tests of the tripod's own facts: model, loops, the seed's corrections, assembly modes, guards and the IK contract
near the flip / the boundary / the actuation singularities. The generic kinematic contract (round trips, Jacobian
vs differences, single == batch, NaN + mask, bad arrays) is tests/test_contract.py's, over legkin.tripod.contract."""

from __future__ import annotations

import functools
import math
import re

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import legkin
from legkin import InvalidInputError, InvalidParameterError, SingularityError, UnreachableError
from legkin._rotations import wrap
from legkin.tripod import checks as ct
from legkin.tripod import kinematics as at
from legkin.tripod.forward_kernels import STEP_RCOND, _k_gn_step, _k_initial_guess
from legkin.tripod.inverse import _run

ALPHAS = (math.pi / 4, math.pi / 3, math.pi / 2)
MOTORS = [0, 4, 8]  # the motor columns of ik_joints


def _u(ay, az):
    """Targets (..., 2) = (alpha_y, alpha_z) as float arrays."""
    ay, az = np.broadcast_arrays(np.asarray(ay, dtype=float), np.asarray(az, dtype=float))
    return np.stack([ay, az], axis=-1)


def _geo(alpha):
    return at.Geometry(alpha=alpha)


def _ik_aux(ay, az, alpha=at.ALPHA):
    """ik's kernel output without its guards, home mode: (joints (..., 12), aux (..., 6) = cos q_K2 (3),
    1 + c_y c_z, det M, |A_u|_F)."""
    ay, az = np.broadcast_arrays(np.asarray(ay, dtype=float), np.asarray(az, dtype=float))
    q, aux, _ = _run(ay, az, at.Geometry(alpha=alpha)._vector, at.HOME_MODE)
    return q[..., 0, :], aux[..., 0, :]


@pytest.fixture(scope="module")
def robot():
    return legkin.load("tripod")


def _tilt_u(theta, phi):
    r = np.stack([np.cos(theta), np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi)], axis=-1)
    return at.orientation_from_axis(r)


# ------------------------------------------------------------------------------------------ model
def test_committed_urdf_matches_xacro():
    from legkin._generate import check_all

    assert check_all(["tripod"]) == []


def test_model_structure(robot):
    assert robot.model.nq == 12 and len(robot.loops) == 2
    assert {lp.type for lp in robot.loops} == {"frame"}
    assert robot.actuated_joints == ("A_q1", "B_q1", "C_q1")
    assert set(robot.poses) >= {"home", "tilt_y", "tilt_z", "tilt_diag"}
    q0 = robot.q0
    for leg in at.LEGS:
        assert q0[robot.idx_q(f"{leg}_q1")] == pytest.approx(-math.pi / 6, abs=1e-15)
        assert q0[robot.idx_q(f"{leg}_q2")] == pytest.approx(math.pi / 2, abs=1e-15)
    m = robot.frame_placement(q0, "platform")
    assert np.allclose(m.rotation, np.eye(3), atol=1e-15)
    assert np.allclose(m.translation, [-0.05, 0, 0], atol=1e-15)  # L = d at alpha = pi/3


@pytest.mark.parametrize("alpha", [math.pi / 3, math.pi / 2, 2.5])
def test_srdf_poses_close_loops_and_match_orientation(alpha):
    robot = legkin.load("tripod") if alpha == math.pi / 3 else legkin.load("tripod", alpha=alpha, d=0.08)
    geo = at.Geometry.from_params(robot.params)
    assert geo.alpha == alpha
    theta = 2 * math.asin(0.6 * math.cos(alpha / 2))
    phis = {"home": None, "tilt_y": -math.pi / 2, "tilt_z": 0.0, "tilt_diag": 3 * math.pi / 4}
    for name, phi in phis.items():
        q = robot.poses[name]
        assert np.linalg.norm(robot.constraint_residual(q)) < 1e-12, name
        assert robot.mobility(q) == 2
        ay, az = (0.0, 0.0) if phi is None else _tilt_u(theta, phi)
        rot = robot.frame_placement(q, "platform").rotation
        assert np.abs(rot - at.platform_rotation(ay, az)).max() < 1e-12, name
        assert np.abs(q - at.ik_joints(_u(ay, az), geometry=geo)).max() < 1e-12, name


def test_point_closures_would_not_suffice(robot):
    """Documented design choice: with 3-D point cuts the platform copies could spin (mobility 8, not 2)."""
    import pinocchio as pin

    from legkin.loops import LoopSet, LoopSpec

    ls = LoopSet(robot.model, [LoopSpec("B", "point", "A_ee", "B_ee"), LoopSpec("C", "point", "A_ee", "C_ee")])
    assert ls.mobility(robot.q0, np.ones(12, bool), 1e-9) == 8
    assert robot.mobility(robot.q0) == 2
    assert robot.mobility(robot.q0, locked=["A_q1", "B_q1"]) == 0
    assert pin.__version__.startswith("4.")


def test_solve_loops_from_home_reaches_tilted_pose(robot):
    qt = robot.poses["tilt_diag"]
    fixed = {"A_q1": qt[0], "B_q1": qt[4]}
    q, info = robot.solve_loops(robot.q0, fixed, return_info=True)
    assert info.residual <= 1e-12 and info.iterations < 20
    assert np.abs(q - qt).max() < 1e-10


# ------------------------------------------------------------------------------------------ properties
@settings(max_examples=60, deadline=None)
@given(st.floats(-math.pi, math.pi), st.floats(-10, -3), st.sampled_from(ALPHAS), st.integers(0, 2))
def test_round_trip_near_boundary(phi, log_gap, alpha, k):
    """Tilts where leg k has 1 - |cos q_k2| = 10**log_gap (just inside the workspace: the boundary formula of
    docs/tripod.md); fk reports alpha_y in [-pi/2, pi/2]."""
    s = abs(math.sin(phi - at.ETA[k]))
    arg = (1 - 10**log_gap) * math.cos(alpha / 2) / max(s, 1e-300)
    if arg >= 1 or arg < 0.05:
        return
    ay, az = _tilt_u(2 * math.asin(arg), phi)
    geo = _geo(alpha)
    q, ok = at.ik_joints(_u([ay], [az]), geometry=geo, return_mask=True)
    if not ok[0] or 1 + math.cos(ay) * math.cos(az) < 1e-2:
        return
    assert 1 - abs(math.cos(q[0, 4 * k + 1])) == pytest.approx(10**log_gap, rel=1e-3)
    y, z = at.fk(q[0, MOTORS], geometry=geo, max_inconsistency=1e-8)
    assert np.abs(at.platform_rotation(y, z) - at.platform_rotation(ay, az)).max() < 1e-9
    assert -math.pi / 2 <= y <= math.pi / 2


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-math.pi, math.pi), min_size=4, max_size=4), st.sampled_from(at.LEGS))
def test_leg_transform_is_eq10_on_cv_branch_and_general_position(q, leg):
    q = np.array(q)
    t = at.leg_transform(q, leg)
    cv = at.leg_transform_cv(q[:2], leg)
    assert np.allclose(t[:3, :3] @ t[:3, :3].T, np.eye(3), atol=1e-14)
    assert np.allclose(t[:3, 3], cv[:3, 3], atol=1e-16)
    qcv = np.array([q[0], q[1], q[1], q[0]])
    assert np.abs(at.leg_transform(qcv, leg) - cv).max() < 1e-15


def test_seed_t33_sign_and_eq15_atan_are_wrong():
    """The corrections are needed: the printed forms disagree with the mechanism."""
    q1, q2, eta = 0.3, 1.1, at.ETA[1]
    t = at.leg_transform_cv(np.array([q1, q2]), "B")
    c1, s1, c2, s2 = math.cos(q1), math.sin(q1), math.cos(q2), math.sin(q2)
    ca, sa, ce, se = math.cos(at.ALPHA), math.sin(at.ALPHA), math.cos(eta), math.sin(eta)
    g4 = c2 * (c1 * sa + s1 * s2 * (1 + ca))
    printed = t[2, 2] - 4 * ce * se * g4  # T33 with -2 c s g4 instead of +2 c s g4
    assert abs(printed - t[2, 2]) > 0.1
    ay, az = 1.2, 2.0  # c_y + c_z < 0: one-argument atan lands on the wrong branch
    wrong = math.atan(math.sin(ay) * math.sin(az) / (math.cos(ay) + math.cos(az)))
    assert abs(wrong - float(at.alpha_x(ay, az))) == pytest.approx(math.pi, abs=1e-12)
    q = at.ik_joints(np.array([ay, az]))
    robot = legkin.load("tripod")
    rot = robot.frame_placement(q, "platform").rotation
    assert np.abs(rot - at.platform_rotation(ay, az)).max() < 1e-13


def test_workspace_matches_ik():
    for alpha in ALPHAS:
        ws = at.workspace(geometry=_geo(alpha), n=61)
        gy, gz = np.meshgrid(ws.alpha_y, ws.alpha_z, indexing="ij")
        _, ok = at.ik(_u(gy, gz), geometry=_geo(alpha), return_mask=True)
        assert np.array_equal(ok, ws.reachable)
        b = ws.boundary[np.all(np.isfinite(ws.boundary), axis=1)]
        if len(b):
            c2 = _ik_aux(b[:, 0], b[:, 1], alpha)[1][:, :3]
            c2 = c2[np.all(np.isfinite(c2), axis=-1)]  # points at the flip (tilt pi) have no E
            assert len(c2) > 100 and np.allclose(np.abs(c2).max(axis=-1), 1.0, atol=1e-9)
    small, large = at.workspace(geometry=_geo(math.pi / 2)), at.workspace(geometry=_geo(math.pi / 4))
    assert small.reachable.mean() < large.reachable.mean()


# ------------------------------------------------------------------------------------------ error paths
@pytest.mark.parametrize("params", [{"d": 0.0}, {"d": -0.1}, {"alpha": 0.0}, {"alpha": math.pi}, {"alpha": 4.0},
                                    {"alpha": float("nan")}, {"foo": 1.0}])
def test_bad_params_refused_before_writing(params, tmp_path, monkeypatch):
    monkeypatch.setenv("LEGKIN_CACHE", str(tmp_path))
    with pytest.raises(InvalidParameterError):
        legkin.load("tripod", **params)
    assert list(tmp_path.iterdir()) == []


def test_xacro_refuses_bad_alpha_directly():
    from legkin._generate import render
    from legkin._registry import get_spec

    spec = get_spec("tripod")
    args = {k: p.default for k, p in spec.params.items()}
    with pytest.raises(Exception, match="alpha"):
        render(spec, {**args, "alpha": 4.0})
    with pytest.raises(Exception, match="d="):
        render(spec, {**args, "d": -1.0})


def test_unreachable_and_singular_name_the_leg():
    geo = _geo(math.pi / 2)  # workspace: tilt <= 2 asin(cos(pi/4) / max |sin(phi - eta)|)
    u = _u(*_tilt_u(2.6, 0.0))  # tilt 2.6 rad towards +y: beyond legs B and C
    with pytest.raises(UnreachableError, match="leg B would need cos q_B2"):
        at.ik(u, geometry=geo)
    with pytest.raises(UnreachableError, match="leg B"):
        at.jacobian(u, geometry=geo)
    with pytest.raises(SingularityError, match="1 \\+ cos"):
        at.ik(np.array([0.0, math.pi]))
    # exactly on the boundary of leg A: sin q_A2 = 0
    u = _u(*_tilt_u(2 * math.asin(math.cos(math.pi / 4)), math.pi / 2))
    with pytest.raises(SingularityError, match="leg A has sin q_A2 = 0"):
        at.ik(u, geometry=geo)
    a, m = at.jacobian(u[None], geometry=geo, return_mask=True)
    assert not m[0] and np.isnan(a).all()


def test_fk_reports_inconsistent_motors():
    q = at.ik(np.array([0.3, -0.4]))
    bad = q + np.array([0.0, 0.0, 1e-3])
    with pytest.raises(UnreachableError, match="inconsistent") as exc:
        at.fk(bad)
    assert exc.value.closest is not None
    _, info = at.fk(bad, max_inconsistency=np.inf, return_info=True)
    assert 1e-5 < info.inconsistency < 1e-3
    u, ok, info = at.fk(np.stack([q, bad]), return_mask=True, return_info=True)
    assert ok.tolist() == [True, False] and np.isnan(u[1]).all() and info.inconsistency[0] < 1e-12


# ------------------------------------------------------------------------------------------ fk internals (closed forms)
def _exact_lstsq(a: np.ndarray, r: np.ndarray) -> np.ndarray:
    """-pinv(A) r in exact rational arithmetic (A is 3 x 2 of full rank): the reference for the closed form."""
    from fractions import Fraction

    m = [[Fraction(float(x)) for x in row] for row in a]
    v = [Fraction(float(x)) for x in r]
    g11, g22 = (sum(m[i][j] ** 2 for i in range(3)) for j in (0, 1))
    g12 = sum(m[i][0] * m[i][1] for i in range(3))
    b1, b2 = (sum(m[i][j] * v[i] for i in range(3)) for j in (0, 1))
    det = g11 * g22 - g12 * g12
    return np.array([-float((g22 * b1 - g12 * b2) / det), -float((g11 * b2 - g12 * b1) / det)])


def _random_a(rng, cond: float) -> np.ndarray:
    u, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    v, _ = np.linalg.qr(rng.normal(size=(2, 2)))
    return (u[:, :2] * np.array([1.0, 1.0 / cond])) @ v.T


def _step(a: np.ndarray, r: np.ndarray) -> np.ndarray:
    return np.array(_k_gn_step(np.ascontiguousarray(a[:, 0]), np.ascontiguousarray(a[:, 1]), np.ascontiguousarray(r)))


@pytest.mark.parametrize("cond", [1.0, 1e4, 1e8])
def test_gauss_newton_step_error_grows_like_cond_not_cond_squared(cond):
    """Consistent r = A x: the closed-form step errs ~1e-16 cond (naive normal equations: ~1e-16 cond^2)."""
    rng = np.random.default_rng(int(math.log10(cond)))
    worst = 0.0
    for _ in range(100):
        a = _random_a(rng, cond)
        r = a @ rng.normal(size=2)
        ref = _exact_lstsq(a, r)
        worst = max(worst, np.abs(_step(a, r) - ref).max() / np.abs(ref).max())
    assert worst <= 1e-15 * cond + 1e-15


def test_gauss_newton_step_matches_pinv_including_rank_deficient():
    rng = np.random.default_rng(7)
    for _ in range(200):  # inconsistent r (both differ from the exact step by ~1e-16 cond^2 here): same as pinv
        a, r = _random_a(rng, 10.0 ** rng.uniform(0, 1)), rng.normal(size=3)
        ref = -np.linalg.pinv(a, rcond=STEP_RCOND) @ r
        assert np.abs(_step(a, r) - ref).max() <= 1e-13 * np.abs(ref).max()
    a1 = rng.normal(size=3)
    for a2 in (np.zeros(3), 1e-14 * rng.normal(size=3), 3.0 * a1):  # sigma_2 <= 1e-12 sigma_1: rank-1 pinv
        a, r = np.stack([a1, a2], axis=-1), rng.normal(size=3)
        ref = -np.linalg.pinv(a, rcond=STEP_RCOND) @ r
        assert np.abs(_step(a, r) - ref).max() <= 1e-12 * np.abs(ref).max()
    assert np.array_equal(_step(np.zeros((3, 2)), rng.normal(size=3)), [0.0, 0.0])


def _planes_lstsq_u(q):
    """The motor planes' least-squares intersection -> (alpha_y, alpha_z), with the SVD pseudo-inverse (oracle)."""
    s, c = np.sin(q), np.cos(q)
    m = np.stack([s, -c * np.cos(at.ETA), -c * np.sin(at.ETA)], axis=-1)
    e = np.linalg.pinv(m, rcond=1e-10) @ np.full(3, at.D * (1 - math.cos(at.ALPHA)))
    e = e / np.linalg.norm(e) if np.linalg.norm(e) > 0 else np.array([-1.0, 0.0, 0.0])
    return at.orientation_from_axis(2 * e[0] * e - np.array([1.0, 0.0, 0.0]))


def test_initial_guess_is_the_planes_intersection():
    G = at.Geometry()._vector
    h = math.pi / 2
    for q in [(0.3, -1.0, 2.0), (-2.5, 0.4, 1.1), (0.2, 1.4, -0.7)]:  # regular planes (|det M| >> DET_GUARD)
        ay, az, det = _k_initial_guess(*q, G)
        assert abs(det) > 1e-3
        ry, rz = _planes_lstsq_u(np.array(q))
        assert np.abs(at.platform_rotation(ay, az) - at.platform_rotation(ry, rz)).max() < 1e-12, q
    for q in [(h, h, h), (h, -h, h), (0.0, 0.0, 0.0)]:  # parallel planes: det M = 0, fk refuses them
        assert abs(_k_initial_guess(*q, G)[2]) < 1e-12
        with pytest.raises(SingularityError, match="actuation singularity"):
            at.fk(np.array(q))
    u = np.array([[0.4, -2.0], [-1.2, 0.7], [1.5, 3.0]])  # consistent motors: the start is already the pose
    for row, q in zip(u, at.ik(u)):
        ay, az, _ = _k_initial_guess(*q, G)
        assert np.abs(at.platform_rotation(ay, az) - at.platform_rotation(*row)).max() < 1e-13


def test_fk_rank_one_step():
    """alpha_y = pi/2 makes A_u's second column vanish (rank-1 Gauss-Newton step): fk still reproduces the pose."""
    for ay, az in [(0.3, -0.4), (math.pi / 2, 0.3), (-1.2, 2.9)]:
        y, z = at.fk(at.ik(np.array([ay, az])))
        assert np.abs(at.platform_rotation(y, z) - at.platform_rotation(ay, az)).max() < 1e-13


# ------------------------------------------------------------------------------------------ parameter validation
@pytest.mark.parametrize(
    "kw, match",
    [
        ({"d": float("nan")}, r"d=nan is out of range: must be in \(0, inf\)"),
        ({"d": float("inf")}, r"d=inf is out of range"),
        ({"d": -0.1}, r"d=-0.1 is out of range"),
        ({"d": 0}, r"d=0(\.0)? is out of range"),
        ({"d": True}, r"d must be a real number, got True"),
        ({"d": "0.05"}, r"d must be a real number, got '0.05'; valid range \(0, inf\)"),
        ({"d": 0.05 + 0j}, r"d must be a real number"),
        ({"d": [0.05]}, r"d must be a real number"),
        ({"alpha": 0.0}, r"alpha=0.0 is out of range: must be in \(0, 3.14159\)"),
        ({"alpha": -1}, r"alpha=-1(\.0)? is out of range"),
        ({"alpha": math.pi}, r"alpha=3.14159\d* is out of range"),
        ({"alpha": float("nan")}, r"alpha=nan is out of range"),
        ({"alpha": "pi"}, r"alpha must be a real number"),
        ({"eta": "abc"}, r"eta must be three finite real angles"),
        ({"eta": (0.0, 1.0)}, r"eta must be three finite real angles"),
        ({"eta": [0.0, 1.0, 2.0j]}, r"eta_C must be a real number"),
        ({"eta": [0.0, float("nan"), 1.0]}, r"eta_B=nan is out of range"),
        ({"eta": [[0.0, 1.0, 2.0]]}, r"eta must be three finite real angles"),
        ({"eta": [0.0, [1.0], 2.0]}, r"eta_B must be a real number"),
    ],
)
def test_geometry_is_validated(kw, match):
    with pytest.raises(InvalidParameterError, match=match):
        at.Geometry(**kw)


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"mode": "-+"}, r"mode must be one of '-\+\+\+', "),
        ({"mode": None}, r"mode must be one of .*got None"),
        ({"return_mask": "yes"}, r"return_mask must be True or False"),
        ({"return_mask": 1}, r"return_mask must be True or False"),
        ({"geometry": {"d": 0.05}}, r"geometry must be a legkin.tripod.Geometry or None"),
    ],
)
def test_keyword_parameters_are_validated(kw, match):
    u = np.array([0.1, 0.2])
    q = at.ik(u)
    calls = [lambda: at.ik(u, **kw), lambda: at.ik_joints(u, **kw), lambda: at.jacobian(u, **kw),
             lambda: at.fk(q, **kw)]
    if "mode" not in kw:
        calls.append(lambda: at.ik_all(u, **kw))
    for call in calls:
        with pytest.raises(InvalidParameterError, match=match):
            call()


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"tol": float("nan")}, r"tol=nan is out of range: must be a finite number in \[0, 0.1\]"),
        ({"tol": -1e-13}, r"tol=-1e-13 is out of range"),
        ({"tol": 1.0}, r"tol=1.0 is out of range"),
        ({"tol": "1e-13"}, r"tol must be a real number"),
        ({"max_iter": 2.5}, r"max_iter must be an integer in \[1, 10000\], got 2.5"),
        ({"max_iter": 0}, r"max_iter=0 is out of range: must be an integer in \[1, 10000\]"),
        ({"max_iter": -1}, r"max_iter=-1 is out of range"),
        ({"max_iter": True}, r"max_iter must be an integer"),
        ({"max_iter": 10**6}, r"max_iter=1000000 is out of range"),
        ({"max_inconsistency": float("nan")},
         r"max_inconsistency=nan is out of range: must be a finite number in \[0, inf\)"),
        ({"max_inconsistency": -1.0}, r"max_inconsistency=-1.0 is out of range"),
        ({"max_inconsistency": None}, r"max_inconsistency must be a real number"),
        ({"mode": "all!"}, r"mode must be one of"),
        ({"return_info": "no"}, r"return_info must be True or False"),
    ],
)
def test_fk_options_are_validated(kw, match):
    q = at.ik(np.array([0.1, 0.2]))
    with pytest.raises(InvalidParameterError, match=match):
        at.fk(q, **kw)


@pytest.mark.parametrize(
    "call",
    [
        lambda: at.workspace(n=1),
        lambda: at.workspace(n=2.5),
        lambda: at.workspace(n=10**6),
        lambda: at.workspace(m="10"),
        lambda: at.workspace(geometry=(0.05, 1.0)),
        lambda: at.leg_transform(np.zeros(4), "D"),
        lambda: at.leg_transform(np.zeros(4), "a"),
        lambda: at.leg_transform_cv(np.zeros(2), "AB"),
        lambda: at.platform_position(0.1, 0.2, geometry="default"),
        lambda: at.jacobian(np.array([0.1, 0.2]), mode="all"),
    ],
)
def test_other_parameters_are_validated(call):
    with pytest.raises(InvalidParameterError):
        call()


@pytest.mark.parametrize(
    "call",
    [
        lambda: at.leg_transform(np.zeros(3), "A"),
        lambda: at.leg_transform(np.zeros(4) + 0j, "A"),
        lambda: at.leg_transform_cv(np.array([0.1, np.nan]), "B"),
        lambda: at.platform_rotation("a", 1.0),
        lambda: at.platform_position(np.inf, 0.0),
        lambda: at.orientation_from_axis(np.zeros(3)),
        lambda: at.orientation_from_axis([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]),
        lambda: at.orientation_from_axis([1.0, 0.0, 0.0, 0.0]),
        lambda: at.platform_axis(np.nan, 0.0),
    ],
)
def test_bad_arrays_raise_invalid_input(call):
    """The functions outside the contract (fk / ik / jacobian are tests/test_contract.py's)."""
    with pytest.raises(InvalidInputError):
        call()


# ------------------------------------------------------------------------------------------ assembly modes
def test_modes_and_home_mode(robot):
    assert len(at.MODES) == 16 and len(set(at.MODES)) == 16 and at.MODES[0] == at.HOME_MODE == "-+++"
    # the reference pose is in the home mode: E_x < 0 (E = (-L, 0, 0)) and sin q_K2 > 0 on every leg
    q0 = robot.q0
    assert np.all(np.sin(q0[[1, 5, 9]]) > 0)
    assert robot.frame_placement(q0, "platform").translation[0] < 0
    np.testing.assert_allclose(at.ik_joints(np.zeros(2)), q0, atol=1e-15)


@pytest.mark.parametrize("alpha", ALPHAS)
def test_every_mode_closes_the_loops_with_the_same_rotation(alpha):
    robot = legkin.load("tripod") if alpha == math.pi / 3 else legkin.load("tripod", alpha=alpha)
    geo = _geo(alpha)
    u = np.array([0.4, -0.7])
    q_all, ok = at.ik_joints(u, geometry=geo, mode="all", return_mask=True)
    assert q_all.shape == (16, 12) and ok.all()
    m_all, ok_all = at.ik_all(u, geometry=geo, return_mask=True)
    assert np.array_equal(m_all, q_all[:, MOTORS]) and np.array_equal(ok_all, ok)
    rot = at.platform_rotation(*u)
    for m, q in zip(at.MODES, q_all):
        assert np.linalg.norm(robot.constraint_residual(q)) < 1e-12, m
        placement = robot.frame_placement(q, "platform")
        assert np.abs(placement.rotation - rot).max() < 1e-12, m
        assert np.sign(placement.translation[0]) == (-1 if m[0] == "-" else 1), m
        assert [np.sign(np.sin(q[4 * k + 1])) for k in range(3)] == [(-1 if c == "-" else 1) for c in m[1:]], m
        np.testing.assert_array_equal(at.ik_joints(u, geometry=geo, mode=m), q)
        np.testing.assert_array_equal(at.ik(u, geometry=geo, mode=m), q[MOTORS])


def test_ik_all_is_ik_in_every_mode_bit_for_bit():
    """ik_all's shared kernel (each leg solved once per side of E and sign of sin q_K2) gives every mode's ik
    exactly, guards included: random orientations in and around the workspace, near the flip and on the
    actuation-singular curves; the single call is the batch row."""
    rng = np.random.default_rng(11)
    for alpha in ALPHAS:
        geo = _geo(alpha)
        box = _u(rng.uniform(-2.0, 2.0, 1500), rng.uniform(-3.5, 3.5, 1500))
        flip = _u(*_tilt_u(np.arccos(10.0 ** rng.uniform(-13, -2, 300) - 1.0), rng.uniform(-3, 3, 300)))
        det = np.array(det_curves(alpha)[:200]) + 10.0 ** rng.uniform(-9, -5, (min(200, len(det_curves(alpha))), 2))
        u = np.concatenate([box, flip, det])
        q_all, ok_all = at.ik_all(u, geometry=geo, return_mask=True)
        j_all, jok_all = at.ik_joints(u, geometry=geo, mode="all", return_mask=True)
        assert np.array_equal(j_all[..., MOTORS], q_all, equal_nan=True) and np.array_equal(jok_all, ok_all)
        assert 0 < ok_all.mean() < 1
        for j, m in enumerate(at.MODES):
            q, ok = at.ik(u, geometry=geo, mode=m, return_mask=True)
            assert np.array_equal(ok, ok_all[:, j]), m
            assert np.array_equal(q, q_all[:, j], equal_nan=True), m
        for i in np.flatnonzero(ok_all.any(axis=-1))[::50]:
            single, mask = at.ik_all(u[i], geometry=geo, return_mask=True)
            assert np.array_equal(single, q_all[i], equal_nan=True) and np.array_equal(mask, ok_all[i])
    with pytest.raises(UnreachableError, match="leg B"):
        at.ik_all(_u(*_tilt_u(2.6, 0.0)), geometry=_geo(math.pi / 2))
    with pytest.raises(InvalidInputError):
        at.ik_all(np.array([np.nan, 0.0]))


def test_fk_mode_is_explicit():
    """fk solves motors in the mode asked for; motors of another mode: AssemblyModeError naming it (single),
    mask False (batch); mode="all" finds it."""
    u = np.array([0.3, -0.4])
    for m in at.MODES[1:]:
        q = at.ik(u, mode=m)
        y, z = at.fk(q, mode=m)
        assert np.abs(at.platform_rotation(y, z) - at.platform_rotation(*u)).max() < 1e-12
        pattern = f"mode\\(s\\) {re.escape(m)}, not in mode -\\+\\+\\+"
        with pytest.raises(legkin.AssemblyModeError, match=pattern) as exc:
            at.fk(q)
        assert exc.value.modes == [{"mode": m}]
        assert isinstance(exc.value, UnreachableError)
        _, ok = at.fk(q[None], return_mask=True)
        assert not ok[0]
        us, oks = at.fk(q, mode="all", return_mask=True)
        assert us.shape == (16, 2) and oks.tolist() == [mm == m for mm in at.MODES]
        assert np.isnan(us[~oks]).all() and np.isfinite(us[oks]).all()


# ------------------------------------------------------------------------------------------ the guards
def test_fk_reproduces_ik_next_to_the_flip():
    """With 1 + c_y c_z computed without cancellation and the inconsistency measured off the range of A_u,
    fk(ik(u)) reproduces u down to the singular tolerance (before: default fk failed below ~1e-6)."""
    geo = _geo(math.pi / 4)
    phi = np.linspace(-3, 3, 200)
    for nb in (1e-11, 1e-9, 1e-7, 1e-5):
        ay, az = _tilt_u(np.full_like(phi, np.arccos(nb - 1.0)), phi)
        q, ok = at.ik(_u(ay, az), geometry=geo, return_mask=True)
        assert ok.sum() > 20
        ay, az, q = ay[ok], az[ok], q[ok]
        u, m, info = at.fk(q, geometry=geo, return_mask=True, return_info=True)
        assert m.all(), nb
        assert np.abs(u[:, 0] - ay).max() < 1e-12 and np.abs(wrap(u[:, 1] - az)).max() < 1e-12
        assert info.inconsistency.max() < 1e-12


def _home_det(alpha, ay, az):
    """det M of the home mode's motor planes at (ay, az) (arrays), NaN outside the workspace; no guard."""
    q, aux = _ik_aux(ay, az, alpha)
    inside = (aux[..., 3] > 1e-12) & np.all(1.0 - np.abs(aux[..., :3]) > 1e-12, axis=-1)
    with np.errstate(all="ignore"):
        q1 = _ik_eval_q1(ay, az, alpha)
    return q1, np.where(inside, aux[..., 4], np.nan)


def _ik_eval_q1(ay, az, alpha):
    """q_K1 (..., 3) of eq (102) in the home mode without ik's guards (NaN outside the workspace)."""
    from legkin.tripod.closure import _k_centre, _k_leg

    G = at.Geometry(alpha=alpha)._vector
    ay, az = np.broadcast_arrays(np.asarray(ay, dtype=float), np.asarray(az, dtype=float))
    out = np.full(ay.shape + (3,), np.nan)
    for idx in np.ndindex(ay.shape):
        y, z = ay[idx], az[idx]
        x, yy, zz, _ = _k_centre(np.cos(y), np.sin(y), np.cos(z), np.sin(z), G, True, -1.0)
        out[idx] = [_k_leg(k, x, yy, zz, G, True, 1.0)[0] for k in range(3)]
    return out


def det_zero_points(alpha, az, n=601):
    """alpha_y where det M = 0 along alpha_z = az (bisection between sign changes on a grid)."""
    return _det_zeros(alpha, np.linspace(-np.pi / 2, np.pi / 2, n), az, along_y=True)


def _det_zeros(alpha, grid, fixed, along_y):
    """Zeros of det M along a line of u (alpha_y varying at alpha_z = fixed, or the other way round)."""
    def det(v):
        w = np.full(len(v), fixed)
        return _home_det(alpha, v, w)[1] if along_y else _home_det(alpha, w, v)[1]

    d = det(grid)
    i = np.nonzero(np.sign(d[1:]) * np.sign(d[:-1]) < 0)[0]
    lo, hi = grid[i], grid[i + 1]
    flo = det(lo)
    for _ in range(70):
        mid = 0.5 * (lo + hi)
        fm = det(mid)
        left = np.sign(fm) == np.sign(flo)
        lo, flo, hi = np.where(left, mid, lo), np.where(left, fm, flo), np.where(left, hi, mid)
    return 0.5 * (lo + hi)


def test_actuation_singularity_guard():
    """On det M = 0 the motors fit two poses: ik and fk refuse them (SingularityError) instead of fk returning
    the other pose (before: fk failed or returned the other pose); away from the guard fk(ik(u)) reproduces u."""
    alpha, az = math.pi / 3, -2.5
    geo = _geo(alpha)
    y0 = det_zero_points(alpha, az)[0]
    with pytest.raises(SingularityError, match="actuation singularity"):
        at.ik(_u(y0, az), geometry=geo)
    _, ok = at.ik(_u([y0, y0 + 0.01], az), geometry=geo, return_mask=True)
    assert ok.tolist() == [False, True]
    qm = _home_det(alpha, y0, az)[0]  # the motors, from an unguarded evaluation
    with pytest.raises(SingularityError, match="actuation singularity"):
        at.fk(qm, geometry=geo)
    _, ok = at.fk(qm[None], geometry=geo, return_mask=True)
    assert not ok[0]
    for off in (1e-3, -1e-4):
        y, z = at.fk(at.ik(_u(y0 + off, az), geometry=geo), geometry=geo)
        assert abs(y - (y0 + off)) < 1e-10 and abs(z - az) < 1e-10


def test_fk_near_boundary_and_near_singular_planes():
    """A start a rounding error outside the workspace (planes nearly dependent, a hair from a leg's boundary)
    is pulled in; before, fk reported "the solver left the workspace"."""
    geo, ay, az = _geo(math.pi / 2), -0.5236046131772432, -1.570796326775148
    u, info = at.fk(at.ik(_u(ay, az), geometry=geo), geometry=geo, return_info=True)
    assert abs(u[0] - ay) < 1e-12 and abs(u[1] - az) < 1e-12 and info.inconsistency < 1e-12


# ------------------------------------------------------------------------------------- the IK contract (property tests)
CONTRACT_TOL = 1e-9


def _mode_of(e_side, s_legs):
    return ("-" if e_side < 0 else "+") + "".join("-" if s < 0 else "+" for s in s_legs)


class _Consts:
    """The constants of a geometry the tests below use (cos / sin of eta, d, k = 1 - cos alpha, -L, ...)."""

    def __init__(self, geo):
        self.d, self.ce, self.se = geo.d, np.cos(np.asarray(geo.eta)), np.sin(np.asarray(geo.eta))
        self.ca, self.sa = math.cos(geo.alpha), math.sin(geo.alpha)
        self.k, self.dsa, self.minus_l = 1.0 - self.ca, geo.d * self.sa, -geo.length


def _configuration_from_motors(qa, qb, branch, s_c, alpha):
    """A closed configuration with motors q_A1 = qa, q_B1 = qb: E on both motor planes and |E| = L (the
    ``branch`` of the two line-sphere points), leg C on the side ``s_c``. Returns (u, mode, q_C1) or None."""
    g = _Consts(at.Geometry(alpha=alpha))
    s, c = np.sin([qa, qb]), np.cos([qa, qb])
    n = np.stack([s, -c * g.ce[:2], -c * g.se[:2]], axis=-1)
    cab, v = float(n[0] @ n[1]), np.cross(n[0], n[1])
    if v @ v < 1e-12:
        return None
    p0 = g.d * g.k * (n[0] + n[1]) / (1.0 + cab)
    t2 = (g.minus_l**2 - p0 @ p0) / (v @ v)
    if t2 < 0:
        return None
    e = p0 + branch * math.sqrt(t2) * v
    h1, h2 = -e[0] / g.d, -(g.ce[:2] * e[1] + g.se[:2] * e[2]) / g.d
    s_ab = c * h1 + s * h2  # sin q_K2 sin(alpha) of legs A and B at E
    if np.any(np.abs(s_ab) < 1e-9) or abs(e[0]) < 1e-12:
        return None
    mode = _mode_of(e[0], [*np.sign(s_ab), s_c])
    ee = e / np.linalg.norm(e)
    u = at.orientation_from_axis(2.0 * ee[0] * ee - np.array([1.0, 0.0, 0.0]))
    # q_C1 straight from E (eqs 98, 102 on the side s_c), not through u: near the flip u -> E is ill-conditioned
    c2 = (g.ce[2] * e[2] - g.se[2] * e[1]) / g.dsa
    if not abs(c2) < 1.0:
        return None
    s2sa = s_c * math.sqrt(1.0 - c2 * c2) * g.sa
    w = -(g.ce[2] * e[1] + g.se[2] * e[2])
    qc = math.atan2(g.k * e[0] + s2sa * w, -s2sa * e[0] + g.k * w)
    return (float(u[0]), float(u[1])), mode, qc


motor = st.one_of(st.floats(-math.pi, math.pi), st.sampled_from([-math.pi, math.pi, 0.0, math.pi / 2, -math.pi / 2]))


@settings(max_examples=200, deadline=None)
@example(qa=0.0, qb=6.103515625e-05, branch=1.0, s_c=-1.0, alpha=math.pi / 3)  # flip and boundary at once
@example(qa=0.0, qb=6.103515625e-05, branch=-1.0, s_c=-1.0, alpha=math.pi / 3)
@example(qa=0.0, qb=0.0, branch=-1.0, s_c=-1.0, alpha=math.pi / 3)  # on the flip (1 + c_y c_z = 1.8e-15)
@example(qa=0.0, qb=1e-05, branch=-1.0, s_c=-1.0, alpha=math.pi / 3)  # leg B on its boundary, next to the flip
@example(qa=1e-06, qb=1e-06, branch=1.0, s_c=-1.0, alpha=math.pi / 3)  # where the boundary meets the flip
@example(qa=0.0, qb=1e-06, branch=1.0, s_c=-1.0, alpha=math.pi / 3)
@example(qa=0.0, qb=-4.5661120220129836e-07, branch=-1.0, s_c=-1.0, alpha=math.pi / 3)
@given(qa=motor, qb=motor, branch=st.sampled_from([-1.0, 1.0]), s_c=st.sampled_from([-1.0, 1.0]),
       alpha=st.sampled_from(ALPHAS))
def test_contract_fk_from_in_limit_motors(qa, qb, branch, s_c, alpha):
    """(b) and (d): fk of the motors of a closed configuration in the joint limits, in its mode, is a pose that ik
    solves in that mode and whose motors it gives back; the default fk refuses motors of another mode with
    AssemblyModeError naming it (mask False in a batch)."""
    made = _configuration_from_motors(qa, qb, branch, s_c, alpha)
    if made is None:
        return
    u, mode, qc = made
    geo, qm = _geo(alpha), np.array([qa, qb, qc])
    try:
        y, z = at.fk(qm, geometry=geo, mode=mode)
    except (SingularityError, UnreachableError) as exc:  # the guards, the flip, a boundary: refused by ik as well
        assert not isinstance(exc, legkin.AssemblyModeError)
        _, ok = at.ik(_u([u[0]], [u[1]]), geometry=geo, mode=mode, return_mask=True)
        assert not ok[0], exc
        return
    assert ct.pose_error(u[0], u[1], y, z) <= CONTRACT_TOL
    q = at.ik(_u(y, z), geometry=geo, mode=mode)  # (b): solved (its motors may differ from qa, qb, qc by more
    # than 1e-9 where a leg is near its boundary: the motors are ill-conditioned functions of the pose there), (a):
    assert ct.pose_error(y, z, *at.fk(q, geometry=geo, mode=mode)) <= CONTRACT_TOL
    _, ok = at.fk(qm[None], geometry=geo, return_mask=True)
    if mode == at.HOME_MODE:
        assert ok[0] and np.array_equal(at.fk(qm, geometry=geo)[0], y)
    else:
        assert not ok[0]
        with pytest.raises(legkin.AssemblyModeError) as exc:
            at.fk(qm, geometry=geo)
        assert {"mode": mode} in exc.value.modes


@functools.cache
def det_curves(alpha):
    """Points on the actuation-singular curves det M = 0 (home motors): zeros along lines of constant alpha_z
    and of constant alpha_y (at alpha = pi/2 det M vanishes on the lines alpha_z = +-pi/2, where two motors sit
    at -pi/2 and their planes coincide)."""
    pts = [(float(y), float(z)) for z in np.linspace(-math.pi, math.pi, 24)
           for y in _det_zeros(alpha, np.linspace(-np.pi / 2, np.pi / 2, 201), z, True)]
    pts += [(float(y), float(z)) for y in np.linspace(-1.5, 1.5, 24)
            for z in _det_zeros(alpha, np.linspace(-np.pi, np.pi, 401), y, False)]
    return pts


def _orientation(kind, alpha, a, b, phi, log_small, sign, index):
    if kind == "box":
        return (math.pi / 2 + 0.3) * a, (math.pi + 0.3) * b
    if kind == "far":
        return 20.0 * a, 20.0 * b
    if kind == "flip":  # 1 + c_y c_z = 10**log_small
        return tuple(float(v) for v in _tilt_u(math.acos(10.0**log_small - 1.0), phi))
    if kind == "boundary":  # some leg a hair inside / outside its boundary: 1 - |cos q_K2| = sign 10**log_small
        k = index % 3
        sk = abs(math.sin(phi - at.ETA[k]))
        arg = (1.0 - sign * 10.0**log_small) * math.cos(alpha / 2) / max(sk, 1e-300)
        return tuple(float(v) for v in _tilt_u(2.0 * math.asin(min(arg, 1.0)), phi))
    pts = det_curves(alpha)
    y, z = pts[index % len(pts)]
    off = 10.0 ** (log_small / 1.4)
    return y + off * a, z + off * b


@settings(max_examples=400, deadline=None)
@given(
    kind=st.sampled_from(["box", "far", "flip", "boundary", "det"]),
    alpha=st.sampled_from(ALPHAS),
    a=st.floats(-1, 1), b=st.floats(-1, 1), phi=st.floats(-math.pi, math.pi),
    log_small=st.floats(-16, -2), sign=st.sampled_from([-1.0, 1.0]), index=st.integers(0, 10**6),
    mode=st.sampled_from([at.HOME_MODE, at.HOME_MODE] + list(at.MODES[1:])),
)
def test_contract_random_orientations(kind, alpha, a, b, phi, log_small, sign, index, mode):
    """(a), (c): whatever the orientation (in and around the workspace, near the flip, a hair from a leg's
    boundary, on and next to the actuation-singular curves), ik either raises a legkin error or returns joints in
    the limits whose motors fk (same mode, default options) maps back to the orientation within 1e-9 rad."""
    ay, az = _orientation(kind, alpha, a, b, phi, log_small, sign, index)
    geo = _geo(alpha)
    try:
        q = at.ik_joints(_u(ay, az), geometry=geo, mode=mode)
    except (UnreachableError, SingularityError):
        return
    assert np.all(np.abs(q) <= math.pi)  # the URDF limits of every joint
    y, z = at.fk(q[MOTORS], geometry=geo, mode=mode)
    assert ct.pose_error(ay, az, y, z) <= CONTRACT_TOL
    at.ik(_u(y, z), geometry=geo, mode=mode)  # and fk's answer is solved by ik (b)


finite = st.floats(allow_nan=False, allow_infinity=False)


@settings(max_examples=100, deadline=None)
@given(u=st.tuples(finite, finite), m=st.tuples(finite, finite, finite), mode=st.sampled_from(at.MODES),
       alpha=st.sampled_from(ALPHAS))
def test_no_foreign_exception_or_warning_on_any_finite_input(u, m, mode, alpha):
    """Huge, tiny or odd finite inputs: only legkin errors, no numpy exception or warning."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        geo = at.Geometry(alpha=alpha)
        calls = [
            lambda: at.ik(np.array(u), geometry=geo, mode=mode),
            lambda: at.ik_all(np.array(u), geometry=geo),
            lambda: at.ik_joints(np.array(u), geometry=geo, mode=mode),
            lambda: at.jacobian(np.array(u), geometry=geo, mode=mode),
            lambda: at.fk(np.array(m), geometry=geo, mode=mode),
            lambda: at.fk(np.array(m), geometry=geo, max_inconsistency=np.inf),
            lambda: at.platform_position(*u, geometry=geo),
            lambda: at.platform_rotation(*u),
            lambda: at.orientation_from_axis(m),
            lambda: at.leg_transform(np.array([*m, u[0]]), "B", geometry=geo),
            lambda: at.leg_transform_cv(np.array(m[:2]), "C", geometry=geo),
        ]
        for call in calls:
            try:
                call()
            except legkin.LegkinError:
                pass
        for call in (
            lambda: at.ik(np.array([u, (0.1, 0.2)]), geometry=geo, mode=mode, return_mask=True),
            lambda: at.fk(np.array([m, (0.1, 0.2, 0.3)]), geometry=geo, mode=mode, return_mask=True),
        ):
            out = call()
            assert out[-1].shape == (2,)


def test_ik_robustness_row_passes():
    import time

    t0 = time.perf_counter()
    row = ct.ik_robustness(10_000, np.random.default_rng(3))
    assert row.passed, row.name
    assert row.counts.made == 5000 and row.counts.wrong == 0 and row.counts.missed == 0
    assert row.counts.exceptions == 0 and row.max_error <= 1e-9
    assert time.perf_counter() - t0 < 10
