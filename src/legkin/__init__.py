"""legkin: kinematic models of legged and parallel mechanisms, validated against Pinocchio."""

from ._registry import list_models
from .errors import (
    AssemblyModeError,
    ConvergenceError,
    InvalidArgumentError,
    InvalidInputError,
    InvalidParameterError,
    JointLimitError,
    LegkinError,
    LoopClosureError,
    SingularityError,
    UnknownModelError,
    UnreachableError,
)
from .robot import Robot, load

# The mechanisms, one package each (found by the registry; listed here so that `from legkin import tripod` works).
from . import hybrid_leg, quadruped, tripod, wheel_leg  # noqa: E402

__version__ = "0.1.0"

__all__ = [
    "quadruped",
    "tripod",
    "wheel_leg",
    "hybrid_leg",
    "list_models",
    "load",
    "Robot",
    "LegkinError",
    "UnknownModelError",
    "InvalidParameterError",
    "InvalidInputError",
    "InvalidArgumentError",
    "UnreachableError",
    "JointLimitError",
    "AssemblyModeError",
    "SingularityError",
    "LoopClosureError",
    "ConvergenceError",
]
