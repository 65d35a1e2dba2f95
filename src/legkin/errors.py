"""Exception classes raised by legkin."""

from __future__ import annotations

from typing import Any, Sequence

__all__ = [
    "LegkinError",
    "UnknownModelError",
    "InvalidParameterError",
    "InvalidInputError",
    "InvalidArgumentError",
    "UnreachableError",
    "JointLimitError",
    "LegStructureError",
    "AssemblyModeError",
    "SingularityError",
    "LoopClosureError",
    "ConvergenceError",
    "CacheWarning",
]


class LegkinError(Exception):
    """Base class of every error legkin raises on purpose."""


class UnknownModelError(LegkinError, KeyError):
    """A model name that is not in the registry.

    Attributes:
        name: the name that was asked for.
        known: the valid names, sorted.
    """

    def __init__(self, message: str, name: object = None, known: Sequence[str] = ()) -> None:
        super().__init__(message)
        self.name = name
        self.known = list(known)

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
        closest: the closest point reached, when the solver knows one (else None).
        distance: how far the target lies from ``closest`` or from the reachable set (m, or rad for an
            orientation), when known (else NaN).
    """

    def __init__(self, message: str, target: Any = None, closest: Any = None, distance: float = float("nan")) -> None:
        super().__init__(message)
        self.target = target
        self.closest = closest
        self.distance = distance


class JointLimitError(UnreachableError):
    """A target that is geometrically reachable, but only outside the joint limits.

    Attributes:
        joint: the name of the (first) joint whose limit the solutions violate, when known.
        value: that joint's value in the closest solution (rad or m).
        lower: the joint's lower limit (rad or m).
        upper: the joint's upper limit (rad or m).
    """

    def __init__(
        self,
        message: str,
        target: Any = None,
        closest: Any = None,
        distance: float = float("nan"),
        *,
        joint: str | None = None,
        value: float = float("nan"),
        lower: float = float("nan"),
        upper: float = float("nan"),
    ) -> None:
        super().__init__(message, target=target, closest=closest, distance=distance)
        self.joint = joint
        self.value = value
        self.lower = lower
        self.upper = upper


class AssemblyModeError(UnreachableError):
    """A target that is reachable, but only in another assembly mode (or branch) than the one asked for.

    Attributes:
        modes: the mode arguments under which the target is reachable, e.g. ``[{"ll_branch": 1}]``.
    """

    def __init__(
        self, message: str, target: Any = None, closest: Any = None, modes: Sequence[Any] | None = None
    ) -> None:
        super().__init__(message, target=target, closest=closest)
        self.modes = list(modes or [])


class LegStructureError(LegkinError, ValueError):
    """A robot description whose chains match no leg structure that legkin supports.

    Attributes:
        found: what was found, e.g. ``{"LF": "HAA-HFE (2 joints)"}`` or a list of chain descriptions.
        expected: the structures legkin supports, e.g. ``["HAA-HFE-KFE", "6-DOF"]``.
    """

    def __init__(self, message: str, found: Any = None, expected: Sequence[str] = ()) -> None:
        super().__init__(message)
        self.found = found
        self.expected = list(expected)


class SingularityError(LegkinError):
    """A configuration on a singular set, where the asked quantity is undefined."""


class LoopClosureError(LegkinError):
    """The loop solver could not close the kinematic loops.

    Attributes:
        residual: norm of the stacked constraint residual reached.
        iterations: iterations performed.
        q: the configuration reached (the closest found), when known.
        open_loops: per loop, how far it stays open (``legkin.closing.LoopError``: name, distance m,
            angle rad), when known (else empty).
    """

    def __init__(
        self,
        message: str,
        residual: float = float("nan"),
        iterations: int = 0,
        q: Any = None,
        open_loops: Sequence[Any] = (),
    ) -> None:
        super().__init__(message)
        self.residual = residual
        self.iterations = iterations
        self.q = q
        self.open_loops = list(open_loops)


class ConvergenceError(LegkinError):
    """An iterative analytic solver (forward kinematics of a parallel mechanism) did not converge."""


class CacheWarning(UserWarning):
    """numba's on-disk cache of legkin's kernels could not be used as is: a damaged cache file (discarded; the
    kernel is compiled again), or no writable cache directory (kernels load from a readable cache or compile in
    memory). Results are unaffected; only the first-call time is. See docs/robustness.md, "The kernel cache"."""
