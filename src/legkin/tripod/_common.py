"""Constants, assembly modes, kernel status codes and argument checks shared by the tripod's kinematics files."""

from __future__ import annotations

import numpy as np

from .._batch import check_choice, check_flag
from ..errors import InvalidParameterError
from .geometry import DEFAULT, Geometry

LEGS = ("A", "B", "C")
#: Below this, ``1 + c_y c_z`` counts as zero: the platform axis is turned back onto -x (E undefined).
SINGULAR_TOL = 1e-12
#: Below this, ``1 - |cos q_K2|`` counts as zero: leg K is on the workspace boundary, sin q_K2 = 0.
BOUNDARY_TOL = 1e-12
#: Assembly modes on the constant-velocity branch (q_K3 = q_K2, q_K4 = q_K1): a string of four signs, the side of
#: the platform centre E along x (``-``: E_x < 0) then the signs of sin q_A2, sin q_B2, sin q_C2. Every
#: orientation has one configuration per mode (E = -+L b/|b|, q_K2 = +-acos(cos q_K2)), all realising the
#: same platform rotation; the motors differ. See docs/tripod.md, "IK contract".
MODES = tuple(c + a + b + k for c in "-+" for a in "+-" for b in "+-" for k in "+-")
#: The mode the mechanism is built in: that of its SRDF reference pose ``home`` (E = (-L, 0, 0), q_K2 = pi/2).
HOME_MODE = "-+++"
#: Actuation-singularity guard: :func:`ik` and :func:`fk` refuse motor angles whose planes (see
#: :func:`legkin.tripod.fk_solver._k_initial_guess`) have ``|det M| < DET_GUARD`` (unit normals). There the motors
#: fix the pose only to ~2e-16 / |det M| rad, and on det M = 0 they fit two poses (the planes share a line that
#: cuts the sphere |E| = L twice; at tangency the two merge and A_u loses rank): fk could not reproduce ik's
#: answers to 1e-9.
DET_GUARD = 1e-6
#: Motor-gain guard: :func:`ik` and :func:`fk` refuse poses where ``|A_u|_F > GAIN_GUARD``. The motors are then so
#: sensitive to the orientation that its float representation fixes them only to ~ulp |A_u| > 1e-8 rad and the
#: Gauss-Newton of fk stalls on that noise. |A_u|_F <= sqrt(3/2) / (min_K |sin q_K2| sqrt(1 + c_y c_z)) (measured),
#: so this happens only where a leg is within ~1e-5 of its boundary next to the flip: near the points where the
#: workspace boundary meets the flip (alpha <= pi/3, e.g. six directions at the default alpha). Away from them
#: |A_u|_F stays below ~1e8 down to the singular tolerances (measured max 8e7 at alpha = pi/4).
GAIN_GUARD = 1e8

#: Kernel status codes (0 = :data:`legkin._kernels.OK`): fk's failures, a NaN / inf input, a closed form's failure.
ST_SINGULAR_PLANES, ST_LEFT, ST_NOT_CONVERGED, ST_INCONSISTENT, ST_OUTSIDE, ST_GAIN = 1, 2, 3, 4, 5, 6
ST_NONFINITE = 7  # an input is NaN or inf (the wrapper raises InvalidInputError with as_input's message)
ST_FAIL = 8  # closed forms: the pose is outside / singular (the wrapper diagnoses it)

#: Per assembly mode (:data:`MODES` order): home flag, side of E, signs of sin q_K2 (the kernels' mode arguments).
MODE_HOME = np.array([m == HOME_MODE for m in MODES])
MODE_E = np.array([-1.0 if m[0] == "-" else 1.0 for m in MODES])
MODE_S = np.array([[-1.0 if c == "-" else 1.0 for c in m[1:]] for m in MODES])
MODE_INDEX = {m: i for i, m in enumerate(MODES)}
MODE_ARGS = {m: (bool(MODE_HOME[i]), float(MODE_E[i]), MODE_S[i]) for i, m in enumerate(MODES)}


def modes_sel(mode: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The kernels' mode arrays (homes, es, ss) for one mode or ``"all"``."""
    if mode == "all":
        return MODE_HOME, MODE_E, MODE_S
    j = MODE_INDEX[mode]
    return MODE_HOME[j:j + 1], MODE_E[j:j + 1], MODE_S[j:j + 1]


# ------------------------------------------------------------------------------------------ arguments
def geometry_of(geometry: object) -> Geometry:
    """The call's :class:`Geometry`: ``geometry``, or the default for None.

    Raises:
        InvalidParameterError: ``geometry`` is neither None nor a :class:`Geometry`.
    """
    if geometry is None:
        return DEFAULT
    if type(geometry) is not Geometry:
        raise InvalidParameterError(f"geometry must be a legkin.tripod.Geometry or None, got {geometry!r}")
    return geometry


def checked_mode(mode: object, allow_all: bool = False) -> str:
    """``mode`` if it is one of :data:`MODES` (or ``"all"`` where allowed), else InvalidParameterError."""
    if type(mode) is str and mode == HOME_MODE:
        return mode
    return str(check_choice(mode, "mode", MODES + (("all",) if allow_all else ())))


def flag(value: object, name: str) -> bool:
    """A bool keyword (fast path for True / False)."""
    if value is False or value is True:
        return value  # type: ignore[return-value]
    return check_flag(value, name)
