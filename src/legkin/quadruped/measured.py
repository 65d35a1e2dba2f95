"""POPI's four legs as generic :class:`legkin.legs.Leg` objects, measured from the quadruped's URDF.

The quadruped's kinematics (:mod:`legkin.quadruped.kinematics`) are :class:`~legkin.legs.Leg`'s closed form
(:mod:`legkin.legs`: the product of exponentials with the measured joint axes, its closed-form IK polished on
the exact forward map): :func:`legs` builds the four legs once per geometry with
:func:`legkin.legs.from_urdf`, from ``urdf/quadruped.urdf`` for the default geometry and from the model
``legkin.load("quadruped", foot_z=...)`` generates otherwise (:func:`legkin._generate.model_files`: xacro into
the user cache, once). The first call of a geometry imports Pinocchio and measures (about 0.3 s, more for a
geometry xacro has not generated yet); later calls are a dict look-up.

The branch order: :class:`~legkin.legs.Leg` numbers its branches ``(s_a, s_k)`` in its abduction frame
(``s_a`` the sign of the foot along ``a1 x a2``, ``s_k`` the sign of the knee's triangle angle), which for POPI
is mirrored between the left and the right legs. The quadruped keeps seed 004's order
:data:`~legkin.quadruped.BRANCHES` ``(s_u, k)`` on every leg (``s_u = -1``: foot below the hip plane; ``k``: the
sign of ``acos K`` in ``q3``): :data:`SEED_ORDER` gives, per leg, the :class:`Leg` row of each seed branch
(``tests/test_quadruped.py`` checks both signs on every row).
"""

from __future__ import annotations

import threading

from ..legs.kinematics import Leg
from ._common import foot_z_of
from .constants import LEGS
from .geometry import Geometry

__all__ = ["legs", "SEED_ORDER"]

#: Per leg, the :class:`~legkin.legs.Leg` branch (row of ``Leg.ik_all``) of each branch of
#: :data:`~legkin.quadruped.BRANCHES`, in that order: on the left legs ``e3 = a1 x a2`` points down and the knee
#: axis is opposite to the hip pitch axis (``s_a = -s_u``, ``s_k = -k``), on the right legs ``e3`` points up
#: (``s_a = s_u``, ``s_k = -k``).
SEED_ORDER = {"LF": (3, 2, 1, 0), "LH": (3, 2, 1, 0), "RF": (1, 0, 3, 2), "RH": (1, 0, 3, 2)}
#: At most this many geometries' legs are kept (the oldest measured is dropped first).
CACHE_SIZE = 16

_LEGS: dict[float, dict[str, Leg]] = {}
_LOCK = threading.Lock()


def legs(geometry: Geometry | None = None) -> dict[str, Leg]:
    """POPI's legs ``{"LF": Leg, "LH": Leg, "RF": Leg, "RH": Leg}`` for ``geometry`` (None: the default).

    Args:
        geometry: the :class:`~legkin.quadruped.Geometry` (its ``foot_z``, m, sets the URDF measured).

    Returns:
        The four measured legs (root frame: the quadruped's base link; joints in the order of ``q``).

    Raises:
        InvalidParameterError: ``geometry`` not a Geometry or None.
    """
    fz = foot_z_of(geometry)
    found = _LEGS.get(fz)
    return found if found is not None else _measure(fz)


def _measure(foot_z: float) -> dict[str, Leg]:
    """Measure the four legs of the URDF of ``foot_z`` (m) and keep them (thread-safe, once per value)."""
    from .._generate import model_files
    from ..legs.extract import from_urdf
    from .spec import SPEC

    with _LOCK:
        found = _LEGS.get(foot_z)
        if found is None:
            urdf, _ = model_files(SPEC, SPEC.resolve_params({"foot_z": foot_z}))
            measured = from_urdf(urdf)
            found = {leg: measured[leg] for leg in LEGS}
            if len(_LEGS) >= CACHE_SIZE:
                del _LEGS[next(iter(_LEGS))]
            _LEGS[foot_z] = found
    return found
