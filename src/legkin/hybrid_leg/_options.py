"""Option checks, fast-path tests, status codes and the geometry resolution shared by the hybrid leg's modules.

Every option error is an :class:`~legkin.errors.InvalidArgumentError` (both an InvalidParameterError and an
InvalidInputError, hence a ValueError) naming the option and the value given.
"""

from __future__ import annotations

from typing import Final, Sequence

import numpy as np

from .._batch import check_flag
from ..errors import InvalidArgumentError, UnreachableError
from .geometry import DEFAULT, K_TOL, MOTOR_BRANCHES, Geometry

# Status codes of the kernels (OK = legkin._kernels.OK = 0).
ST_INPUT: Final = 1  # a non-finite input (or not a rotation): the wrapper's checks raise the InvalidInputError
ST_REACH: Final = 2  # a chain out of the motors' reach (|k| > 1 + tol)
ST_ASSEMBLE: Final = 3  # the closed sub-chain does not assemble in the mode asked for
ST_BAND: Final = 4  # the forward-singularity band (foot gain >= FK_GAIN_MAX)
ST_SINGULAR: Final = 5  # N singular / reach boundary

#: A motor branch pair (b1, b2), each +1 or -1 (:func:`check_branch`).
Branch = Sequence[int]

#: Scalar types a single-call fast path passes straight to a kernel (anything else takes the checked path).
SCALARS = (float, np.float64)


def flat(a: np.ndarray) -> np.ndarray:
    """A checked input as a fresh, writeable, C-contiguous float64 vector (for a kernel)."""
    return np.array(a, dtype=np.float64).reshape(-1)


def _is_real(value: object) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def check_branch(branch: object) -> np.ndarray:
    """Motor branch pair (b1, b2), each +1 or -1, as a float array."""
    b = None
    if not isinstance(branch, (str, bytes)):
        try:
            raw = np.asarray(branch)
        except (TypeError, ValueError):
            raw = None
        if raw is not None and raw.dtype.kind in "iuf" and raw.shape == (2,) and np.all(np.abs(raw) == 1):
            b = raw.astype(float)
    if b is None:
        raise InvalidArgumentError(
            f"branch must be one of {', '.join(map(str, MOTOR_BRANCHES))} (b1, b2: the motor branch of each chain), "
            f"got {branch!r}"
        )
    return b


def check_sign(value: object, name: str, allow_none: bool = False) -> float | None:
    """+1 or -1 (as float), or None if allowed."""
    if value is None and allow_none:
        return None
    if _is_real(value) and value in (1, -1):
        return float(value)  # type: ignore[arg-type]
    valid = "+1 or -1" + (" (or None: try both, see FOOT_IK_ORDER)" if allow_none else "")
    raise InvalidArgumentError(f"{name} must be {valid}, got {value!r}")


def check_assembly(value: object) -> float:
    if _is_real(value) and value in (1, -1):
        return float(value)  # type: ignore[arg-type]
    raise InvalidArgumentError(
        f"assembly must be +1 (the assembly mode of the neutral pose, R_P = I, on the given branch) or -1 (the other "
        f"sign of det(dtheta/d(roll, pitch))), got {value!r}"
    )


def fast_branch(branch: object) -> tuple[float, float] | None:
    """(b1, b2) as floats for a plain tuple of two ints +-1, else None (the checked path then)."""
    if type(branch) is tuple and len(branch) == 2:
        b1, b2 = branch
        if type(b1) is int and type(b2) is int and (b1 == 1 or b1 == -1) and (b2 == 1 or b2 == -1):
            return float(b1), float(b2)
    return None


def fast_sign(value: object) -> float | None:
    """+-1.0 for a plain int +-1, else None."""
    if type(value) is int and (value == 1 or value == -1):
        return float(value)
    return None


def fast_geometry(geometry: object) -> Geometry | None:
    """The geometry for a fast path: the default for None, a Geometry as is, else None (the checked path)."""
    if geometry is None:
        return DEFAULT
    if type(geometry) is Geometry:
        return geometry
    return None


def resolve(geometry: object, *, universal: str = "") -> Geometry:
    """The checked geometry of a call (None: the default).

    ``universal``: the function's name when it needs the universal centre (refuses ``center="spherical"``).
    """
    if geometry is None:
        g = DEFAULT
    elif isinstance(geometry, Geometry):
        g = geometry
    else:
        raise InvalidArgumentError(f"geometry must be a legkin.hybrid_leg.Geometry or None, got {geometry!r}")
    if universal and g.center != "universal":
        raise InvalidArgumentError(
            f"{universal} needs the universal centre (geometry.center='universal'), got center={g.center!r}: with the "
            "spherical centre one platform rotation is free with the motors locked (spherical_free_axis), so the "
            "motors do not fix the platform"
        )
    return g


def mode_args(branch: object, assembly: object, geometry: object, return_mask: object,
             what: str) -> tuple[float, float, float, float, bool]:
    """(starting_value, b1, b2, assembly, return_mask) of a call of ``fk``, ``jacobian`` or ``ik`` (``what``: its
    name), checked (straight through for the common values)."""
    fb, fs, g = fast_branch(branch), fast_sign(assembly), fast_geometry(geometry)
    if fb is None or fs is None or g is None or g.center != "universal":
        g = resolve(geometry, universal=what)
        b = check_branch(branch)
        fb, fs = (float(b[0]), float(b[1])), check_assembly(assembly)
    if return_mask is not False and return_mask is not True:
        return_mask = check_flag(return_mask, "return_mask")
    return g.starting_value, fb[0], fb[1], fs, return_mask  # type: ignore[return-value]


def unreachable(what: str, k: np.ndarray) -> UnreachableError:
    """The error of a rotation or pose out of the motors' reach, naming the chain(s) and their |k|."""
    bad = [f"chain {i + 1} (|k| = {abs(float(k[i])):.15g})" for i in range(2) if not abs(float(k[i])) <= 1.0 + K_TOL]
    return UnreachableError(
        f"{what} is out of the motors' reach: the rod-length equation A cos(theta) + B sin(theta) = C has no "
        f"solution for {', '.join(bad) or 'a chain (|k| not finite)'}; it needs |k| = |C| / sqrt(A^2 + B^2) <= 1 "
        f"(+ {K_TOL:g} for rounding)",
        target=None,
    )


def fmt(p: np.ndarray) -> str:
    return "[" + ", ".join(f"{float(v):.17g}" for v in np.ravel(p)) + "]"


def mode_text(b: np.ndarray, s: float) -> str:
    return f"branch=({int(b[0])}, {int(b[1])}), assembly={int(s):+d}"

