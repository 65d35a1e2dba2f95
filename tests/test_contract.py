"""The kinematic contract, written once and run on every registered mechanism (see legkin._contract).

A model takes part by the contract module of its package, ``<package>.contract`` with ``contract()`` (or
``contract(name)`` for a package that serves several models, such as :mod:`legkin.legs`: one case per leg); a
registered model without one fails ``test_every_model_signs_the_contract``.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest

import legkin
from legkin._contract import Case, Contract
from legkin._registry import get_spec
from legkin.errors import AssemblyModeError, InvalidInputError, JointLimitError, LegkinError, UnreachableError

N = 200  # joint samples per case (the check rows and the 10^6-target robustness rows do the volume)


def _contract(model: str) -> Contract:
    spec = get_spec(model)
    try:
        module = importlib.import_module(f"{spec.package}.contract")
    except ModuleNotFoundError:
        pytest.fail(f"{spec.package} has no contract module ({spec.package}.contract.contract())")
    c = module.contract(model) if spec.shared_package else module.contract()
    assert isinstance(c, Contract) and c.cases and all(isinstance(k, Case) for k in c.cases)
    return c


def _cases() -> list:
    out = []
    for model in legkin.list_models():
        try:
            cases = _contract(model).cases
        except pytest.fail.Exception:
            continue  # no contract module: test_every_model_signs_the_contract fails for it
        except (ImportError, OSError, legkin.LegkinError) as exc:  # example-robot-data not installed
            out.append(pytest.param(model, None, id=f"{model}-missing",
                                    marks=pytest.mark.skip(reason=f"{model}: {exc}")))
            continue
        out += [pytest.param(model, k, id=f"{model}-{k.name}") for k in cases]
    return out


CASES = _cases()


@pytest.mark.parametrize("model", legkin.list_models())
def test_every_model_signs_the_contract(model):
    _contract(model)


def _rng(model: str, case: Case) -> np.random.Generator:
    return np.random.default_rng([ord(c) for c in model + case.name])  # the same samples in every run


@pytest.mark.parametrize(("model", "case"), CASES)
def test_fk_then_ik_round_trip(model, case):
    """Every target the default FK makes from in-limit joints is solved by the default IK, in limits, and
    reproduced by the FK."""
    q = case.sample(_rng(model, case), N)
    assert q.shape == (N, case.nq)
    assert case.within_limits(q).all(), "sample() must give in-limit joint values"
    x, ok = case.fk(q, return_mask=True)
    assert x.shape == (N, case.nx) and ok.all(), f"FK failed on {np.count_nonzero(~ok)} sampled configurations"
    q_ik, solved = case.ik(x, return_mask=True)
    assert q_ik.shape == (N, case.nq)
    assert solved.all(), f"{np.count_nonzero(~solved)} of {N} FK-made targets not solved"
    assert case.within_limits(q_ik).all(), "a default IK answer lies outside the joint limits"
    err = np.abs(case.fk(q_ik) - x).max()
    assert err <= case.round_trip_tol, f"|fk(ik(x)) - x| = {err:.3g} > {case.round_trip_tol:g}"


@pytest.mark.parametrize(("model", "case"), CASES)
def test_jacobian_matches_central_differences(model, case):
    q = case.sample(_rng(model, case), 20)
    points = q if case.jacobian_of == "fk" else case.fk(q)
    h = case.step
    for u in points:
        jac = case.jacobian(u)
        fd = np.stack(
            [(case.of(u + h * e) - case.of(u - h * e)) / (2 * h) for e in np.eye(u.shape[0])], axis=-1
        )
        assert jac.shape == fd.shape
        err = np.abs(jac - fd).max()
        assert err <= case.jacobian_tol, f"Jacobian vs central differences: {err:.3g} at {u}"


@pytest.mark.parametrize(("model", "case"), CASES)
def test_single_call_equals_batch_row(model, case):
    q = case.sample(_rng(model, case), 8)
    x = case.fk(q)
    q_ik = case.ik(x)
    points = q if case.jacobian_of == "fk" else x
    jac = case.jacobian(points)
    for i in range(len(q)):
        np.testing.assert_array_equal(case.fk(q[i]), x[i])
        np.testing.assert_array_equal(case.ik(x[i]), q_ik[i])
        np.testing.assert_array_equal(case.jacobian(points[i]), jac[i])


@pytest.mark.parametrize(("model", "case"), CASES)
def test_unreachable_targets_give_nan_and_mask(model, case):
    x = case.fk(case.sample(_rng(model, case), 3))
    bad = np.asarray(case.unreachable, dtype=float).reshape(-1, case.nx)
    both = np.concatenate([x, bad])
    q, ok = case.ik(both, return_mask=True)
    assert ok[: len(x)].all() and not ok[len(x) :].any()
    assert np.isnan(q[len(x) :]).all() and np.isfinite(q[: len(x)]).all()
    for target in bad:
        with pytest.raises(LegkinError) as info:
            case.ik(target)
        _check_error_data(info.value, target)


def _check_error_data(exc: LegkinError, target: np.ndarray) -> None:
    """The data an IK error carries (legkin.errors): the target asked for, a distance >= 0 (or NaN: unknown), a
    closest point of the target's shape; a joint limit names the joint, its limits, and a value outside them."""
    if isinstance(exc, UnreachableError):
        assert exc.target is not None, f"{type(exc).__name__} without .target: {exc}"
        np.testing.assert_array_equal(np.asarray(exc.target, dtype=float), target)
        assert np.isnan(exc.distance) or exc.distance >= 0.0, exc.distance
        if exc.closest is not None:
            assert np.shape(exc.closest) == target.shape
    if isinstance(exc, JointLimitError):
        assert isinstance(exc.joint, str) and exc.joint, exc
        assert exc.lower <= exc.upper, exc
        assert np.isnan(exc.value) or not exc.lower <= exc.value <= exc.upper, exc
    if isinstance(exc, AssemblyModeError):
        assert isinstance(exc.modes, list)


def _bad_arrays(n: int) -> dict:
    ok = np.full(n, 0.1)
    return {
        "nan": np.where(np.arange(n) == 0, np.nan, ok),
        "inf": np.where(np.arange(n) == 0, np.inf, ok),
        "complex": ok + 1j,
        "too short": ok[:-1],
        "too long": np.append(ok, 0.1),
        "matrix of wrong width": np.zeros((2, n + 1)),
        "string": "0.1",
    }


@pytest.mark.parametrize(("model", "case"), CASES)
@pytest.mark.parametrize("which", ["fk", "ik", "jacobian"])
def test_bad_inputs_raise_invalid_input(model, case, which):
    fn = getattr(case, which)
    n = case.nq if which == "fk" or (which == "jacobian" and case.jacobian_of == "fk") else case.nx
    for label, value in _bad_arrays(n).items():
        with pytest.raises(InvalidInputError) as exc:
            fn(value)
        assert isinstance(exc.value, ValueError), label
        assert str(exc.value), label


@pytest.mark.parametrize("model", legkin.list_models("legkin"))
def test_check_rows_pass_and_include_a_jacobian_against_pinocchio(model):
    checks = importlib.import_module(f"legkin.{model}.checks")
    rows = checks.run(100, np.random.default_rng(0))
    failed = [r.name for r in rows if not r.passed]
    assert not failed, f"check rows failed: {failed}"
    assert any("jacobian" in r.name.lower() for r in rows), [r.name for r in rows]


@pytest.mark.parametrize("model", legkin.list_models("legkin"))
def test_the_package_exports_its_kinematics_and_no_submodule_hides_a_function(model):
    """``legkin.<name>.X`` is the function ``kinematics.X`` for every public X, even after every submodule of
    the package has been imported (a submodule named like a function would replace it on the package)."""
    import pkgutil
    import types

    pkg = importlib.import_module(f"legkin.{model}")
    for info in pkgutil.iter_modules(pkg.__path__):
        importlib.import_module(f"legkin.{model}.{info.name}")
    kinematics = pkg.kinematics
    assert kinematics.__all__
    for name in kinematics.__all__:
        value = getattr(pkg, name)
        assert not isinstance(value, types.ModuleType), f"legkin.{model}.{name} is a module"
        assert value is getattr(kinematics, name), name
    assert pkg.Geometry.from_params(legkin.load(model).params) == pkg.Geometry()


@pytest.mark.parametrize("model", ["tripod", "wheel_leg", "hybrid_leg"])  # quadruped: with its move onto legs.Leg
def test_public_functions_are_typed_and_document_args_and_returns(model):
    """Every public function of the mechanism (its kinematics ``__all__``) has a full signature annotation and a
    Google-style docstring with Args and Returns (docs/api.md)."""
    import inspect

    kinematics = importlib.import_module(f"legkin.{model}.kinematics")
    missing = []
    for name in kinematics.__all__:
        fn = getattr(kinematics, name)
        if not inspect.isfunction(fn):
            continue
        sig = inspect.signature(fn)
        typed = sig.return_annotation is not inspect.Signature.empty and all(
            p.annotation is not inspect.Parameter.empty for p in sig.parameters.values())
        doc = fn.__doc__ or ""
        if not typed or "Args:" not in doc or "Returns:" not in doc:
            missing.append(name)
    assert not missing, f"legkin.{model}: not typed or without Args/Returns: {missing}"
