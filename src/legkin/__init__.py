"""legkin: kinematic models of legged and parallel mechanisms, validated against Pinocchio."""

from typing import TYPE_CHECKING, Any

from ._registry import list_models
from .errors import *  # noqa: F403 - every error class (errors.__all__) at the top level
from .errors import __all__ as _errors

if TYPE_CHECKING:
    from .robot import Robot, load

# isort: split
# The mechanisms, one package each, after the registry (which finds them); their kinematics load on first use.
from . import hybrid_leg, quadruped, tripod, wheel_leg

__version__ = "0.2.0"


def __getattr__(name: str) -> Any:
    """``Robot`` and ``load`` on first use: they import Pinocchio (about 0.1 s), which the analytic kinematics
    never need."""
    if name in ("Robot", "load"):
        from . import robot

        return getattr(robot, name)
    raise AttributeError(f"module 'legkin' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | {"Robot", "load"})

__all__ = [
    "quadruped",
    "tripod",
    "wheel_leg",
    "hybrid_leg",
    "list_models",
    "load",
    "Robot",
    *_errors,
]
