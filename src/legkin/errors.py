"""Exception classes raised by legkin."""

from __future__ import annotations

__all__ = [
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


class LegkinError(Exception):
    """Base class of every error legkin raises on purpose."""


class UnknownModelError(LegkinError, KeyError):
    """A model name that is not in the registry."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class InvalidParameterError(LegkinError, ValueError):
    """A model parameter (xacro argument) that is unknown or out of range."""


class InvalidInputError(LegkinError, ValueError):
    """An input array with the wrong shape, or with NaN or infinite entries."""


class InvalidArgumentError(InvalidParameterError, InvalidInputError):
    """A keyword argument (an option such as a branch or a tolerance) of the wrong kind or out of range.

    Both an :class:`InvalidParameterError` and an :class:`InvalidInputError` (hence a ``ValueError``): an
    option is a parameter of the call and an input of the function alike.
    """


class UnreachableError(LegkinError):
    """An inverse-kinematics target that no configuration of the mechanism reaches.

    Attributes:
        target: the target that was asked for.
        closest: the closest point reached, when the solver knows one.
    """

    def __init__(self, message: str, target=None, closest=None):
        super().__init__(message)
        self.target = target
        self.closest = closest


class JointLimitError(UnreachableError):
    """A target that is geometrically reachable, but only outside the joint limits."""


class AssemblyModeError(UnreachableError):
    """A target that is reachable, but only in another assembly mode (or branch) than the one asked for.

    Attributes:
        modes: the mode arguments under which the target is reachable, e.g. ``[{"ll_branch": 1}]``.
    """

    def __init__(self, message: str, target=None, closest=None, modes=None):
        super().__init__(message, target=target, closest=closest)
        self.modes = modes or []


class SingularityError(LegkinError):
    """A configuration on a singular set, where the asked quantity is undefined."""


class LoopClosureError(LegkinError):
    """The loop solver could not close the kinematic loops.

    Attributes:
        residual: norm of the stacked constraint residual reached.
        iterations: iterations performed.
    """

    def __init__(self, message: str, residual: float = float("nan"), iterations: int = 0, q=None):
        super().__init__(message)
        self.residual = residual
        self.iterations = iterations
        self.q = q


class ConvergenceError(LegkinError):
    """An iterative analytic solver (forward kinematics of a parallel mechanism) did not converge."""
