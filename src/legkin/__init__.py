"""legkin: kinematic models of legged and parallel mechanisms, validated against Pinocchio."""

from ._registry import list_models
from .errors import (
    AssemblyModeError,
    ConvergenceError,
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

__version__ = "0.1.0"

__all__ = [
    "list_models",
    "load",
    "Robot",
    "LegkinError",
    "UnknownModelError",
    "InvalidParameterError",
    "InvalidInputError",
    "UnreachableError",
    "JointLimitError",
    "AssemblyModeError",
    "SingularityError",
    "LoopClosureError",
    "ConvergenceError",
]
