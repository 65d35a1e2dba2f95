"""The registry of mechanisms: one frozen entry per model."""

from __future__ import annotations

import importlib
import math
import pkgutil
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from ._batch import interval_text, outside
from .errors import InvalidParameterError, UnknownModelError

__all__ = ["Param", "ModelSpec", "MODELS", "get_spec", "list_models"]


@dataclass(frozen=True)
class Param:
    """One xacro argument of a model, with its default and valid range.

    Attributes:
        default: value used for the committed URDF.
        doc: one line: what the argument is, with its unit.
        low, high: bounds of the valid range (None: unbounded).
        low_open, high_open: whether the bound itself is excluded.
        choices: for string arguments, the allowed values.
    """

    default: float | str
    doc: str
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple[str, ...] = ()

    def range_text(self) -> str:
        """The valid values as text: ``one of 'a', 'b'`` or an interval such as ``(0, inf)``."""
        if self.choices:
            return "one of " + ", ".join(repr(c) for c in self.choices)
        return interval_text(self.low, self.high, self.low_open, self.high_open)

    def check(self, name: str, value: object) -> float | str:
        """Return the value converted to the argument's type, or raise.

        Args:
            name: the argument's name (for the message).
            value: a string of :attr:`choices`, or a real number (not a bool, complex or array) in the range.

        Returns:
            the value (a float for a numeric argument).

        Raises:
            InvalidParameterError: a value of the wrong kind or out of range; the message names it and the range.
        """
        if self.choices:
            if not isinstance(value, str) or value not in self.choices:
                raise InvalidParameterError(f"{name}={value!r} is not valid: must be {self.range_text()}")
            return value
        wrong_kind = isinstance(value, (bool, np.bool_, complex, np.complexfloating)) or (
            isinstance(value, np.ndarray) and value.ndim > 0)
        try:
            x = math.nan if wrong_kind else float(value)  # type: ignore[arg-type]
        except (TypeError, ValueError, OverflowError):
            wrong_kind = True
        if wrong_kind:
            raise InvalidParameterError(f"{name}={value!r} is not a number; valid range {self.range_text()}")
        if outside(x, self.low, self.high, self.low_open, self.high_open):
            raise InvalidParameterError(f"{name}={value!r} is out of range: must be in {self.range_text()}")
        return x


@dataclass(frozen=True)
class ModelSpec:
    """A mechanism: its xacro source, arguments, actuation and analytic module.

    Attributes:
        name: registry key; also the xacro/URDF/SRDF file stem.
        title: one line shown by ``legkin list``.
        seed: the seed document(s) the model is taken from.
        params: xacro arguments (name -> :class:`Param`).
        actuated_joints: names of the actuated joints.
        floating: whether ``load(..., floating=True)`` makes sense (a walking robot).
        reference_pose: the SRDF pose used as ``Robot.q0``.
        actuated_joints: names of the actuated joints; None: every one-coordinate joint (an open tree).
        source: ``"legkin"`` (the model is generated from ``xacro/``) or the distribution whose installed URDF
            it is (``"example-robot-data"``: the robots whose leg kinematics :mod:`legkin.legs` measures).
        package: the package of its kinematics, checks, bench and clips (default ``legkin.<name>``).
        locate: for a model legkin does not generate, ``locate(name) -> (urdf, srdf or None, package dirs)``.
        default_pose: ``default_pose(model, name)``, the reference configuration when the SRDF has none (or None).
        geometry: ``geometry(robot)``, what :attr:`legkin.Robot.geometry` returns (default:
            ``<package>.Geometry.from_params(robot.params)``).
        yardstick_frame: the frame of the bench's Pinocchio yardstick calls, or ``yardstick_frame(robot)``
            ("": the model's last frame).
        mjcf: whether ``legkin check`` runs the MuJoCo export's rows on it.

    The mechanism itself is the package ``legkin.<name>`` (:attr:`package`), found by one rule: every
    sub-package of :mod:`legkin` with a ``spec`` module defining ``SPEC``. Its modules are found by name:
    ``spec`` (this entry; an optional ``assets(args) -> {relative path: bytes}`` making generated files
    other than URDF/SRDF, e.g. meshes), ``kinematics`` (re-exported by the package, with ``Geometry``),
    ``checks`` (``run(samples, rng)``), ``bench`` (``build``, ``single_calls``), ``figures`` and ``clips``.
    """

    name: str
    title: str
    seed: str
    params: Mapping[str, Param] = field(default_factory=dict)
    actuated_joints: tuple[str, ...] | None = ()
    floating: bool = False
    reference_pose: str = "standing"
    source: str = "legkin"
    package: str = ""
    locate: Callable[[str], tuple[Path, Path | None, list[str]]] | None = None
    default_pose: Callable[[Any, str], Any] | None = None
    geometry: Callable[[Any], Any] | None = None
    yardstick_frame: str | Callable[[Any], str] = ""
    mjcf: bool = True

    def __post_init__(self) -> None:
        if not self.package:
            object.__setattr__(self, "package", f"legkin.{self.name}")

    @property
    def generated(self) -> bool:
        """Whether legkin generates the model's URDF from its xacro (else :attr:`locate` finds a distribution's)."""
        return self.locate is None

    @property
    def shared_package(self) -> bool:
        """Whether :attr:`package` serves several models (``legkin.legs``: the robots it measures). Its
        ``checks.run``, ``bench.build`` and ``bench.single_calls`` then take the model's name first."""
        return self.package != f"legkin.{self.name}"

    @property
    def xacro_file(self) -> str:
        return f"{self.name}.urdf.xacro"

    def resolve_params(self, params: Mapping[str, object]) -> dict[str, float | str]:
        """Validate user parameters; return the full argument set (defaults filled in)."""
        unknown = sorted(set(params) - set(self.params))
        if unknown:
            known = ", ".join(self.params) or "none"
            raise InvalidParameterError(
                f"unknown parameter(s) {', '.join(unknown)} for model {self.name!r}; known: {known}"
            )
        out = {k: p.default for k, p in self.params.items()}
        for k, v in params.items():
            out[k] = self.params[k].check(k, v)
        return out


def _discover() -> dict[str, ModelSpec]:
    """Collect the registry entries of every mechanism package: each sub-package ``legkin.<name>`` with a
    ``spec`` module (the one rule by which the framework finds a mechanism), defining ``SPEC`` (the package's own
    model, named ``<name>``) or ``SPECS`` (the models a shared package serves, e.g. :mod:`legkin.legs`)."""
    found: dict[str, ModelSpec] = {}
    for info in sorted(pkgutil.iter_modules([str(Path(__file__).parent)]), key=lambda m: m.name):
        if not info.ispkg or info.name.startswith("_"):
            continue
        if not (Path(info.module_finder.path) / info.name / "spec.py").is_file():  # type: ignore[union-attr]
            continue  # a package that is not a mechanism (read from disk: nothing else is imported)
        module = importlib.import_module(f"legkin.{info.name}.spec")
        specs = [module.SPEC] if hasattr(module, "SPEC") else list(module.SPECS)
        for spec in specs:
            if spec.package != f"legkin.{info.name}" or (hasattr(module, "SPEC") and spec.name != info.name):
                raise RuntimeError(f"legkin.{info.name}.spec declares {spec.name!r} of package {spec.package!r}")
            found[spec.name] = spec
    return found


MODELS: Mapping[str, ModelSpec] = _discover()


def get_spec(name: object) -> ModelSpec:
    """Return the registry entry of ``name``.

    Args:
        name: a registered model's name (anything else is refused with the known names).

    Returns:
        Its registry entry.

    Raises:
        UnknownModelError: the name is not registered (the message lists the known names).
    """
    try:
        return MODELS[name]  # type: ignore[index]  # a non-str key is a KeyError or TypeError, refused below
    except (KeyError, TypeError):
        raise UnknownModelError(
            f"unknown model {name!r}; known models: {', '.join(sorted(MODELS))}", name=name, known=sorted(MODELS)
        ) from None


def list_models(source: str | None = None) -> list[str]:
    """Names of the registered models, sorted.

    Args:
        source: only the models of this source: ``"legkin"`` (the mechanisms generated from legkin's xacro,
            with their analytic kinematics) or ``"example-robot-data"`` (the robots whose leg kinematics
            :mod:`legkin.legs` measures from their URDF); None (default): all.

    Returns:
        The names, sorted.

    Raises:
        InvalidParameterError: an unknown ``source`` (the message lists the valid ones).
    """
    if source is None:
        return sorted(MODELS)
    sources = sorted({s.source for s in MODELS.values()})
    if source not in sources:
        raise InvalidParameterError(f"source={source!r} is not valid: must be one of {', '.join(map(repr, sources))}")
    return sorted(n for n, s in MODELS.items() if s.source == source)
