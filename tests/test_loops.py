"""The generic loop machinery on a four-bar fixture (independent of any registered model)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from legkin import LoopClosureError
from legkin.loops import LoopSet, parse_loops

FOURBAR = Path(__file__).parent / "data" / "fourbar.urdf"


@pytest.fixture(scope="module")
def fourbar():
    model = pin.buildModelFromUrdf(str(FOURBAR))
    return model, LoopSet(model, parse_loops(FOURBAR))


def closed_fourbar(qa: float) -> np.ndarray:
    """Analytic closure of the fixture (crank 0.1, coupler 0.3, rocker 0.2, ground 0.3), elbow-up branch."""
    b = np.array([0.1 * math.cos(qa), 0.1 * math.sin(qa)])
    d = np.array([0.3, 0.0])
    bd = d - b
    L = np.linalg.norm(bd)
    ang = math.acos((0.3**2 + L**2 - 0.2**2) / (2 * 0.3 * L))
    phi = math.atan2(bd[1], bd[0]) + ang
    c = b + 0.3 * np.array([math.cos(phi), math.sin(phi)])
    qd = math.atan2(c[1] - d[1], c[0] - d[0])
    return np.array([qa, phi - qa, qd])


def test_parse(fourbar):
    model, loops = fourbar
    assert [(lp.name, lp.type) for lp in loops.loops] == [("D", "point")]
    assert loops.rows == 3


@pytest.mark.parametrize("qa", [0.3, 1.0, 2.0, -1.2])
def test_solver_closes_and_matches_analytic(fourbar, qa):
    model, loops = fourbar
    q_true = closed_fourbar(qa)
    assert np.linalg.norm(loops.residual(q_true)) < 1e-15
    free = np.array([False, True, True])
    start = q_true + np.array([0.0, 0.2, -0.15])
    q, info = loops.solve(start, free, 1e-12, 100)
    assert info.residual <= 1e-12 and info.iterations <= 10
    assert q[0] == qa
    np.testing.assert_allclose(q, q_true, atol=1e-10)


def test_mobility_counts_redundant_rows(fourbar):
    model, loops = fourbar
    q = closed_fourbar(0.7)
    # 3 joints, a planar loop gives 2 independent rows out of 3: one DOF; zero with the crank locked.
    assert loops.mobility(q, np.ones(3, bool), 1e-9) == 1
    assert loops.mobility(q, np.array([False, True, True]), 1e-9) == 0


def test_unclosable_raises_with_residual(fourbar):
    model, loops = fourbar
    q = closed_fourbar(0.5)
    free = np.array([False, True, False])  # only the coupler may move: it cannot reach the held rocker
    q[2] += 0.5
    with pytest.raises(LoopClosureError) as info:
        loops.solve(q, free, 1e-12, 50)
    assert info.value.residual > 1e-3
    assert "residual" in str(info.value)


# ---------------------------------------------------------------- bad inputs
from legkin import InvalidInputError  # noqa: E402

FREE = np.array([False, True, True])


@pytest.mark.parametrize(
    "q, free, kwargs, words",
    [
        (np.zeros(2), FREE, {}, ["q", "(3,)", "(2,)"]),
        (np.array([0.3, np.nan, 0.0]), FREE, {}, ["q", "finite", "nan"]),
        (np.zeros(3) + 0j, FREE, {}, ["q", "real"]),
        (np.zeros(3), np.array([1, 0, 1]), {}, ["free", "boolean"]),
        (np.zeros(3), np.ones(2, bool), {}, ["free", "(3,)"]),
        (np.zeros(3), FREE, {"tol": np.nan}, ["tol", "(0, inf)"]),
        (np.zeros(3), FREE, {"tol": -1.0}, ["tol", "(0, inf)"]),
        (np.zeros(3), FREE, {"max_iter": -1}, ["max_iter", "[0, inf)"]),
        (np.zeros(3), FREE, {"max_iter": 1.5}, ["max_iter", "integer"]),
        (np.zeros(3), FREE, {"damping": 0.0}, ["damping", "(0, inf)"]),
    ],
)
def test_solve_refuses_bad_input(fourbar, q, free, kwargs, words):
    model, loops = fourbar
    args = {"tol": 1e-12, "max_iter": 50, **kwargs}
    with pytest.raises(InvalidInputError) as info:
        loops.solve(q, free, args.pop("tol"), args.pop("max_iter"), **args)
    for word in words:
        assert word in str(info.value)


def test_mobility_refuses_bad_tolerance(fourbar):
    model, loops = fourbar
    for tol in (np.nan, -1e-9, 1.0, "1e-9"):
        with pytest.raises(InvalidInputError, match=r"tol"):
            loops.mobility(closed_fourbar(0.7), np.ones(3, bool), tol)


def test_damping_is_used(fourbar):
    model, loops = fourbar
    q_true = closed_fourbar(1.0)
    start = q_true + np.array([0.0, 0.2, -0.15])
    for damping in (1e-9, 1e-6, 1e-1):
        q, info = loops.solve(start, FREE, 1e-12, 100, damping=damping)
        np.testing.assert_allclose(q, q_true, atol=1e-10)


def test_breakdown_becomes_loop_closure_error(fourbar, monkeypatch):
    # A non-finite Jacobian on the way (overflow) must not escape as numpy's LinAlgError.
    model, loops = fourbar
    q = closed_fourbar(0.5) + np.array([0.0, 0.3, 0.0])
    r, j = loops.residual_and_jacobian(q)
    monkeypatch.setattr(loops, "residual_and_jacobian", lambda q: (r, j * np.nan))
    with pytest.raises(LoopClosureError, match="broke down"):
        loops.solve(q, FREE, 1e-12, 50)


def test_the_option_checkers_take_numpy_scalars_and_refuse_the_rest():
    """legkin._batch.check_number / check_integer: the one option checker of every module (loops, robot, mjcf)."""
    from legkin._batch import check_integer, check_number

    assert check_number(np.float32(0.5), "x", 0.0, 1.0) == 0.5
    assert check_number(np.array(0.25), "x", 0.0, 1.0) == 0.25
    assert check_integer(np.int64(3), "n", 0) == 3
    for bad in (np.nan, np.inf, 2.0, -0.1, True, "0.5", 0.5j, [0.5], np.array([0.5])):
        with pytest.raises(InvalidInputError, match=r"x.* must be .*\[0, 1\]"):
            check_number(bad, "x", 0.0, 1.0)
    for bad in (-1, 2.5, np.nan, True, "3", None):
        with pytest.raises(InvalidInputError, match=r"n.* must be an integer in \[0, inf\)"):
            check_integer(bad, "n", 0)
