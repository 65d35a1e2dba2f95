"""Options, number formatting and the MuJoCo import shared by the MJCF modules."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING, Any, Iterable, Mapping

import numpy as np
import pinocchio as pin

from .._batch import check_integer, check_number
from ..errors import InvalidInputError, InvalidParameterError, LegkinError

if TYPE_CHECKING:  # pragma: no cover

    from ..robot import Robot



#: The exporter's options and their defaults (see :func:`to_mjcf`).
DEFAULTS: dict[str, Any] = {
    "timestep": 2e-4,
    "integrator": "implicitfast",
    "iterations": 100,
    "tolerance": 1e-10,
    "eq_solref": None,  # (2 timestep, 0.7)
    "eq_solimp": (0.9999, 0.9999, 0.001, 0.5, 2.0),
    "actuator_frequency": 10.0,
    "damping_ratio": 1.0,
    "kp": None,
    "kv": None,
    "force_limits": False,
    "min_mass": 1e-6,
    "min_radius": 0.005,
    "floor": True,
    "gravity": (0.0, 0.0, -9.81),
}

_INTEGRATORS = ("Euler", "implicit", "implicitfast", "RK4")
_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
_MESH_EXTENSIONS = (".stl", ".obj", ".msh")
#: Tolerances of the rows of :func:`check_rows`.


# ------------------------------------------------------------------------------------------ helpers
def unavailable_reason() -> str | None:
    """Why the MuJoCo features cannot run here (``None`` when ``import mujoco`` works)."""
    try:
        import mujoco  # noqa: F401
    except ImportError as exc:
        return f"mujoco is not installed ({exc}): pip install \"legkin[mujoco]\""
    return None


def _mujoco():
    try:
        import mujoco
    except ImportError as exc:
        raise LegkinError(f"this needs MuJoCo, which is not installed ({exc}): pip install mujoco") from None
    return mujoco


def _num(x: float) -> str:
    """Shortest text that reads back as the same double (``repr``), ``0`` for zeros."""
    x = float(x)
    if x == 0.0:
        return "0"
    s = repr(x)
    return s[:-2] if s.endswith(".0") else s


def _vec(xs: Iterable[float]) -> str:
    return " ".join(_num(x) for x in xs)


def _quat(rotation: np.ndarray) -> np.ndarray:
    """MuJoCo quaternion (w, x, y, z) of a rotation matrix."""
    x, y, z, w = pin.Quaternion(np.asarray(rotation)).normalized().coeffs()
    return np.array([w, x, y, z])


def _set_pose(el: ET.Element, placement: pin.SE3) -> None:
    p = placement.translation
    if np.any(p != 0.0):
        el.set("pos", _vec(p))
    if not np.array_equal(placement.rotation, np.eye(3)):
        el.set("quat", _vec(_quat(placement.rotation)))


def _robot(robot_or_name, params: Mapping[str, Any]) -> "Robot":
    from ..robot import Robot, load

    if isinstance(robot_or_name, Robot):
        if params:
            raise InvalidParameterError(
                f"unknown MJCF option(s) {', '.join(params)}; options: {', '.join(DEFAULTS)} (xacro arguments "
                f"go with a model name: {robot_or_name.name!r} is already loaded)"
            )
        return robot_or_name
    if not isinstance(robot_or_name, str):
        raise InvalidInputError(f"expected a legkin.Robot or a model name, got {robot_or_name!r}")
    return load(robot_or_name, **params)


def _options(options: Mapping[str, Any]) -> dict[str, Any]:
    try:
        return _checked_options(options)
    except InvalidInputError as exc:
        raise InvalidParameterError(str(exc)) from None


def _checked_options(options: Mapping[str, Any]) -> dict[str, Any]:
    unknown = sorted(set(options) - set(DEFAULTS))
    if unknown:
        raise InvalidParameterError(
            f"unknown MJCF option(s) {', '.join(unknown)}; options: {', '.join(DEFAULTS)}"
        )
    o = {**DEFAULTS, **options}
    o["timestep"] = check_number(o["timestep"], "timestep", 0.0, 0.1, low_open=True)
    if o["integrator"] not in _INTEGRATORS:
        raise InvalidParameterError(f"integrator must be one of {', '.join(_INTEGRATORS)}, got {o['integrator']!r}")
    o["iterations"] = check_integer(o["iterations"], "iterations", 1)
    o["tolerance"] = check_number(o["tolerance"], "tolerance", 0.0)
    if o["eq_solref"] is None:
        o["eq_solref"] = (2.0 * o["timestep"], 0.7)
    o["eq_solref"] = tuple(check_number(v, f"eq_solref[{i}]") for i, v in enumerate(o["eq_solref"]))
    o["eq_solimp"] = tuple(check_number(v, f"eq_solimp[{i}]") for i, v in enumerate(o["eq_solimp"]))
    if len(o["eq_solref"]) != 2 or len(o["eq_solimp"]) not in (3, 5):
        raise InvalidParameterError("eq_solref takes 2 numbers and eq_solimp 3 or 5")
    o["actuator_frequency"] = check_number(o["actuator_frequency"], "actuator_frequency", 0.0, low_open=True)
    o["damping_ratio"] = check_number(o["damping_ratio"], "damping_ratio", 0.0)
    o["min_mass"] = check_number(o["min_mass"], "min_mass", 0.0, low_open=True)
    o["min_radius"] = check_number(o["min_radius"], "min_radius", 0.0, low_open=True)
    o["gravity"] = tuple(check_number(v, f"gravity[{i}]") for i, v in enumerate(o["gravity"]))
    for flag in ("force_limits", "floor"):
        if not isinstance(o[flag], (bool, np.bool_)):
            raise InvalidParameterError(f"{flag} must be True or False, got {o[flag]!r}")
    return o
