"""What a study samples and solves, per mechanism: :class:`StudyTarget` and the registry :data:`TARGETS`.

A target declares a set of outputs of known measure (a box of foot positions, the sphere of platform axes), draws
uniform samples from it, and solves them with the mechanism's own compiled batches (``ik``/``jacobian`` with
``geometry=`` and ``return_mask=True``). The mechanisms are imported by name on first use (the framework never
imports a mechanism package statically: see the layers in CONTRIBUTING.md).
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np

from .._registry import ModelSpec, Param, get_spec
from ..errors import UnknownModelError
from ._kernels import PLANAR, TWIST

__all__ = ["Solved", "StudyTarget", "TARGETS", "get_target", "PLANAR_SPEC"]


@dataclass(frozen=True)
class Solved:
    """One block of samples, solved.

    Attributes:
        ok: (n,) bool, the targets the default IK solved (inside the joint limits).
        jac: (n, m * k) Jacobians, row-major, NaN rows where not solved.
        shape: (m, k) of one Jacobian.
        extras: per-sample values of the target's own metrics whose maximum is reported (name -> (n,) array, NaN
            where undefined).
        counts: the target's own proportions: name -> (successes, trials) in this block.
    """

    ok: np.ndarray
    jac: np.ndarray
    shape: tuple[int, int]
    extras: Mapping[str, np.ndarray] = field(default_factory=dict)
    counts: Mapping[str, tuple[int, int]] = field(default_factory=dict)


@dataclass(frozen=True)
class StudyTarget:
    """A mechanism as a study sees it.

    Attributes:
        name: the model's registry name (or ``"planar_2link"``).
        spec: its registry entry (the parameters and their ranges).
        measure: ``measure(params)``, the measure of the declared target set (box volume in m^3, m^2, or the
            sphere's 4 pi sr): the workspace estimate is ``measure x reachable fraction``.
        unit: the unit of :attr:`measure`.
        sample: ``sample(rng, n, params)`` -> (n, d) targets uniform in the declared set.
        solve: ``solve(targets, params, extras)`` -> :class:`Solved` (``extras``: the names of its own metrics
            to compute).
        jacobian: what the Jacobian is (the docs' metric table), e.g. "d(foot position)/dq (m/rad)".
        extras: the names of the target's own metrics (see docs/study.md).
    """

    name: str
    spec: ModelSpec
    measure: Callable[[Mapping[str, Any]], float]
    unit: str
    sample: Callable[[np.random.Generator, int, Mapping[str, Any]], np.ndarray]
    solve: Callable[[np.ndarray, Mapping[str, Any], tuple[str, ...]], Solved]
    jacobian: str
    extras: tuple[str, ...] = ()


def _geometry(name: str, params: Mapping[str, Any]) -> Any:
    """The mechanism's ``Geometry`` for resolved parameters (no URDF, no Pinocchio)."""
    return importlib.import_module(f"legkin.{name}").Geometry.from_params(dict(params))


def _rows(a: np.ndarray, n: int) -> np.ndarray:
    return np.ascontiguousarray(a.reshape(n, -1), dtype=np.float64)


# ------------------------------------------------------------------ planar 2-link leg (known answers)
#: The known-answer mechanism: a planar 2-link leg, joints unlimited, lengths l1, l2 (m). Its reachable set is
#: the annulus |l1 - l2| <= r <= l1 + l2, of area 4 pi l1 l2.
PLANAR_SPEC = ModelSpec(
    name="planar_2link",
    title="planar 2-link leg (the study's known-answer case)",
    seed="",
    params={
        "l1": Param(0.3, "thigh length (m)", 0.0, 10.0, low_open=True),
        "l2": Param(0.2, "shank length (m)", 0.0, 10.0, low_open=True),
    },
)


def _planar_half(params: Mapping[str, Any]) -> float:
    return float(params["l1"]) + float(params["l2"])


def _planar_sample(rng: np.random.Generator, n: int, params: Mapping[str, Any]) -> np.ndarray:
    h = _planar_half(params)
    return rng.uniform(-h, h, (n, 2))


def _planar_solve(target: np.ndarray, params: Mapping[str, Any], extras: tuple[str, ...]) -> Solved:
    n = target.shape[0]
    q, jac, ok = np.empty((n, 2)), np.empty((n, 4)), np.empty(n, dtype=np.bool_)
    PLANAR(np.ascontiguousarray(target), float(params["l1"]), float(params["l2"]), q, jac, ok)
    return Solved(ok, jac, (2, 2))


# ------------------------------------------------------------------ the tripod (seed 000)
def _tripod_sample(rng: np.random.Generator, n: int, params: Mapping[str, Any]) -> np.ndarray:
    """Platform axes uniform on the unit sphere (isotropic Gaussians), as (alpha_y, alpha_z) (rad):
    :func:`legkin.tripod.orientation_from_axis`."""
    ay, az = importlib.import_module("legkin.tripod").orientation_from_axis(rng.standard_normal((n, 3)))
    return np.stack([ay, az], -1)


def _tripod_cv_error(tp: Any, target: np.ndarray, ok: np.ndarray, g: Any) -> np.ndarray:
    """Per sample: the largest twist (rad) of the three legs' output rotations, each computed along its own chain
    (``leg_transform`` of the joints of ``ik_joints``); NaN where not solved."""
    n = target.shape[0]
    out = np.full(n, np.nan)
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return out
    joints = tp.ik_joints(target[idx], geometry=g, return_mask=True)[0]
    worst = np.zeros(idx.size)
    tw = np.empty(idx.size)
    for k, leg in enumerate(tp.LEGS):
        T = tp.leg_transform(joints[:, 4 * k:4 * k + 4], leg, geometry=g)
        TWIST(np.ascontiguousarray(T[:, :3, :3].reshape(idx.size, 9)), tw)
        worst = np.maximum(worst, tw)
    out[idx] = worst
    return out


def _tripod_solve(target: np.ndarray, params: Mapping[str, Any], extras: tuple[str, ...]) -> Solved:
    tp = importlib.import_module("legkin.tripod")
    g = _geometry("tripod", params)
    n = target.shape[0]
    _, ok = tp.ik(target, geometry=g, return_mask=True)
    jac, _ = tp.jacobian(target, geometry=g, return_mask=True)
    jac = np.where(ok[:, None, None], jac, np.nan)
    more = {"cv_error": _tripod_cv_error(tp, target, ok, g)} if "cv_error" in extras else {}
    return Solved(ok, _rows(jac, n), (3, 2), more)


# ------------------------------------------------------------------ the quadruped's LF leg (seeds 004 + 002)
#: Foot positions of the LF leg in the base frame (m): the bounding box of fk over the joint limits for foot_z in
#: {-0.1, 0, 0.1} (2 x 10^5 samples: x [-0.216, 0.948], y [0.035, 0.511], z [-0.677, 0.318]), rounded outward
#: to 0.05 m. The same box for every foot_z, so that volumes compare.
QUADRUPED_BOX = np.array([[-0.25, 0.95], [0.0, 0.55], [-0.70, 0.35]])


def _box_measure(box: np.ndarray) -> Callable[[Mapping[str, Any]], float]:
    return lambda params: float(np.prod(box[:, 1] - box[:, 0]))


def _box_sample(box: np.ndarray) -> Callable[[np.random.Generator, int, Mapping[str, Any]], np.ndarray]:
    return lambda rng, n, params: rng.uniform(box[:, 0], box[:, 1], (n, box.shape[0]))


def _quadruped_solve(target: np.ndarray, params: Mapping[str, Any], extras: tuple[str, ...]) -> Solved:
    qd = importlib.import_module("legkin.quadruped")
    g = _geometry("quadruped", params)
    n = target.shape[0]
    q, ok = qd.ik(target, "LF", geometry=g, return_mask=True)
    jac = np.full((n, 3, 3), np.nan)
    if ok.any():
        jac[ok] = qd.jacobian(q[ok], "LF", geometry=g)
    return Solved(ok, _rows(jac, n), (3, 3))


# ------------------------------------------------------------------ the wheel-leg's FL leg (seed 001)
#: The rim links of :func:`legkin.wheel_leg.rim_segment`, in its order (rim parameter alpha < -50 deg, [-50, 0),
#: [0, 50], > 50 deg).
RIM_LINKS = ("upper_L", "lower_L", "lower_R", "upper_R")


def _wheel_box(params: Mapping[str, Any]) -> np.ndarray:
    """A cube about the FL module origin (+L_body/2, +W_body/2, d_abad), half-width 3.5 R + d_wheel + T/2 (m): every
    rim point of the leg lies inside (measured: 3.4 R from the origin in x at R = 0.1, 2 x 10^5 joint samples)."""
    h = 3.5 * float(params["R"]) + float(params["d_wheel"]) + 0.5 * float(params["T"])
    o = np.array([0.5 * float(params["L_body"]), 0.5 * float(params["W_body"]), float(params["d_abad"])])
    return np.stack([o - h, o + h], -1)


def _wheel_sample(rng: np.random.Generator, n: int, params: Mapping[str, Any]) -> np.ndarray:
    """(n, 4): a target uniform in :func:`_wheel_box` and the rim parameter alpha uniform in [-pi, pi] (rad)."""
    box = _wheel_box(params)
    return np.concatenate([rng.uniform(box[:, 0], box[:, 1], (n, 3)), rng.uniform(-math.pi, math.pi, (n, 1))], 1)


def _wheel_solve(sample: np.ndarray, params: Mapping[str, Any], extras: tuple[str, ...]) -> Solved:
    wl = importlib.import_module("legkin.wheel_leg")
    g = _geometry("wheel_leg", params)
    n = sample.shape[0]
    target, alpha = np.ascontiguousarray(sample[:, :3]), np.ascontiguousarray(sample[:, 3])
    q, ok = wl.ik(target, "FL", alpha=alpha, geometry=g, return_mask=True)
    jac = np.full((n, 3, 3), np.nan)
    if ok.any():
        jac[ok] = wl.jacobian(q[ok], "FL", alpha=alpha[ok], geometry=g, return_mask=True)[0]
    counts = {}
    if "rim_contact" in extras:
        link = wl.rim_segment(alpha, geometry=g)
        for k, name in enumerate(RIM_LINKS):
            on = link == k
            counts[f"rim_contact_{name}"] = (int(np.count_nonzero(ok & on)), int(np.count_nonzero(on)))
    return Solved(ok, _rows(jac, n), (3, 3), counts=counts)


TARGETS: Mapping[str, StudyTarget] = {
    "planar_2link": StudyTarget(
        "planar_2link", PLANAR_SPEC, lambda p: (2.0 * _planar_half(p)) ** 2, "m^2", _planar_sample, _planar_solve,
        "d(x, y)/d(q1, q2) (m/rad)",
    ),
    "tripod": StudyTarget(
        "tripod", get_spec("tripod"), lambda p: 4.0 * math.pi, "sr", _tripod_sample, _tripod_solve,
        "A_u = d(q_A1, q_B1, q_C1)/d(alpha_y, alpha_z) (rad/rad), the IK Jacobian", ("cv_error",),
    ),
    "quadruped": StudyTarget(
        "quadruped", get_spec("quadruped"), _box_measure(QUADRUPED_BOX), "m^3", _box_sample(QUADRUPED_BOX),
        _quadruped_solve, "d(LF foot position)/d(HAA, HFE, KFE) (m/rad)",
    ),
    "wheel_leg": StudyTarget(
        "wheel_leg", get_spec("wheel_leg"), lambda p: float(np.prod(np.diff(_wheel_box(p), axis=1))), "m^3",
        _wheel_sample, _wheel_solve, "d(FL rim point)/d(theta, beta, gamma) (m/rad)", ("rim_contact",),
    ),
}


def get_target(name: str) -> StudyTarget:
    """The study target of a model.

    Args:
        name: a key of :data:`TARGETS`.

    Returns:
        Its :class:`StudyTarget`.

    Raises:
        UnknownModelError: no study target of that name (the message lists them).
    """
    if name not in TARGETS:
        raise UnknownModelError(
            f"no study target {name!r}; known: {', '.join(sorted(TARGETS))}", name=name, known=sorted(TARGETS)
        )
    return TARGETS[name]
