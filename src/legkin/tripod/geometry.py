"""The tripod's geometry: the xacro arguments that matter to its kinematics, as one frozen value."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from .._batch import real_number
from ..errors import InvalidParameterError
from .spec import SPEC

__all__ = ["Geometry", "D", "ALPHA", "ETA"]

#: The registry defaults: |OD| = |DE| (m), the angle between the axes of joints 2 and 3 (rad), the legs'
#: placement angles about x (rad).
D = float(SPEC.params["d"].default)
ALPHA = float(SPEC.params["alpha"].default)
ETA = (float(SPEC.params["eta_A"].default), float(SPEC.params["eta_B"].default), float(SPEC.params["eta_C"].default))
_ETA_KEYS = ("eta_A", "eta_B", "eta_C")


def _checked(name: str, value: object) -> float:
    param = SPEC.params[name]
    return float(param.check(name, real_number(value, name, param.range_text)))


@dataclass(frozen=True)
class Geometry:
    """The tripod's kinematic parameters (defaults = the xacro defaults, ranges = :data:`legkin.tripod.spec.SPEC`).

    Attributes:
        d: ``|OD| = |DE|`` (m), in (0, inf).
        alpha: angle between the axes of joints 2 and 3 of each leg (rad), in (0, pi).
        eta: the legs' placement angles ``(eta_A, eta_B, eta_C)`` about the x axis (rad), finite.

    Raises:
        InvalidParameterError: a value that is not a real number or is out of its range (the message names
            the value and the range).
    """

    d: float = D
    alpha: float = ALPHA
    eta: tuple[float, float, float] = ETA
    _vector: np.ndarray = field(init=False, repr=False, compare=False, hash=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "d", _checked("d", self.d))
        object.__setattr__(self, "alpha", _checked("alpha", self.alpha))
        eta = self.eta
        if isinstance(eta, (str, bytes)) or not hasattr(eta, "__len__") or len(eta) != 3:
            raise InvalidParameterError(f"eta must be three finite real angles (eta_A, eta_B, eta_C), got {eta!r}")
        object.__setattr__(self, "eta", tuple(_checked(k, v) for k, v in zip(_ETA_KEYS, eta)))
        object.__setattr__(self, "_vector", _kernel_vector(self.d, self.alpha, self.eta))

    @classmethod
    def from_params(cls, params: Mapping[str, object] | None) -> Geometry:
        """The geometry of a model's xacro arguments (e.g. ``robot.params``); keys that are not kinematic are
        ignored, missing ones take their defaults."""
        p = dict(params or {})
        kw: dict[str, object] = {k: p[k] for k in ("d", "alpha") if k in p}
        if any(k in p for k in _ETA_KEYS):
            kw["eta"] = tuple(p.get(k, ETA[i]) for i, k in enumerate(_ETA_KEYS))
        return cls(**kw)  # type: ignore[arg-type]

    @property
    def length(self) -> float:
        """``L = |OE| = d sqrt(2 (1 - cos alpha))`` (eq 18): the distance of the platform centre from the base
        centre."""
        return self.d * math.sqrt(2.0 * (1.0 - math.cos(self.alpha)))


#: Indices into the kernels' geometry vector (:func:`_kernel_vector`).
G_D, G_CA, G_SA, G_K, G_K2, G_OPC, G_DSA, G_ML, G_TH, G_CE, G_SE, G_W = 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 12, 15


def _kernel_vector(d: float, alpha: float, eta: tuple[float, float, float]) -> np.ndarray:
    """The kernels' geometry (18,): d, c_alpha, s_alpha, k = 1 - c_alpha, k^2, 1 + c_alpha, d s_alpha, -L,
    tan(alpha / 2), c_eta (3), s_eta (3), sin(eta_{K+2} - eta_{K+1}) (3) (legs cyclic A -> B -> C -> A)."""
    ca, sa = math.cos(alpha), math.sin(alpha)
    e = np.asarray(eta, dtype=np.float64)
    nxt, prv = np.array([1, 2, 0]), np.array([2, 0, 1])
    head = [d, ca, sa, 1 - ca, (1 - ca) ** 2, 1 + ca, d * sa, -d * math.sqrt(2.0 * (1.0 - ca)), math.tan(alpha / 2.0)]
    return np.ascontiguousarray(np.concatenate([head, np.cos(e), np.sin(e), np.sin(e[prv] - e[nxt])]), dtype=np.float64)


DEFAULT = Geometry()
