"""Helpers shared by the wheel-leg kinematics files: input range checks and small float kernels."""

from __future__ import annotations

import math
from typing import Literal, Union

import numpy as np

from .._batch import check_choice
from .._kernels import kernel
from ..errors import InvalidInputError
from .geometry import THETA_MAX, THETA_MIN, Geometry


def _check_theta(theta: np.ndarray, name: str = "theta") -> None:
    bad = (theta < THETA_MIN - 1e-12) | (theta > THETA_MAX + 1e-12)
    if np.any(bad):
        v = float(np.asarray(theta)[bad].ravel()[0])
        raise InvalidInputError(
            f"{name}={v!r} rad ({math.degrees(v):.4g} deg) is out of range: must be in "
            f"[{THETA_MIN:.6f}, {THETA_MAX:.6f}] rad (17 deg to 160 deg)"
        )


def _check_alpha(alpha: np.ndarray) -> None:
    bad = np.abs(alpha) > math.pi + 1e-12
    if np.any(bad):
        v = float(alpha[bad].ravel()[0])
        raise InvalidInputError(f"alpha={v!r} rad is out of range: must be in [-pi, pi]")


def _check_w(w: np.ndarray, geo: Geometry) -> None:
    bad = np.abs(w) > geo.T / 2 + 1e-15
    if np.any(bad):
        v = float(w[bad].ravel()[0])
        raise InvalidInputError(f"w={v!r} m is out of range: must be in [-T/2, T/2] = [{-geo.T / 2:g}, {geo.T / 2:g}]")


@kernel
def _k_clip(x, lo, hi):
    """``np.clip`` for one float (NaN passes through)."""
    if x < lo:
        return lo
    if x > hi:
        return hi
    return x


@kernel
def _k_max(a, b):
    """``np.maximum`` for floats (NaN propagates)."""
    if a != a or b != b:
        return math.nan
    return a if a >= b else b


@kernel(inline=True)
def _k_min(a, b):
    """``np.minimum`` for floats (NaN propagates)."""
    if a != a or b != b:
        return math.nan
    return a if a <= b else b


@kernel
def _k_phase(z):
    return math.atan2(z.imag, z.real)


_SCALARS = (float, int)


#: Outcome of an IK target: solved, out of reach, reachable only outside the ABAD limits.
_SOLVED, _UNREACHABLE, _LIMITS = 0, 1, 2


#: A leg: its name or its index 0-3.
Leg = Union[Literal["FL", "FR", "RR", "RL"], str, int]
#: The rim models: the four rim links (continuous in alpha) or the seed's three-arc formula (seed 1.1).
Rim = Literal["continuous", "three_arc"]
RIMS = ("continuous", "three_arc")


def rim_name(rim: object) -> str:
    """``rim`` checked: one of :data:`RIMS`.

    Raises:
        InvalidArgumentError: any other value.
    """
    if type(rim) is str and rim == "continuous":
        return "continuous"
    return str(check_choice(rim, "rim", RIMS))
