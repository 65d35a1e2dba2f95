"""The registry of mechanisms: one frozen entry per model."""

from __future__ import annotations

import importlib
import math
import pkgutil
from dataclasses import dataclass, field
from typing import Mapping

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
        if self.choices:
            return "one of " + ", ".join(repr(c) for c in self.choices)
        lo = "-inf" if self.low is None else f"{self.low:g}"
        hi = "inf" if self.high is None else f"{self.high:g}"
        return f"{'(' if self.low_open or self.low is None else '['}{lo}, {hi}{')' if self.high_open or self.high is None else ']'}"

    def check(self, name: str, value) -> float | str:
        """Return the value converted to the argument's type, or raise."""
        if self.choices:
            if value not in self.choices:
                raise InvalidParameterError(f"{name}={value!r} is not valid: must be {self.range_text()}")
            return value
        try:
            x = float(value)
        except (TypeError, ValueError):
            raise InvalidParameterError(f"{name}={value!r} is not a number; valid range {self.range_text()}") from None
        bad = not math.isfinite(x)
        if self.low is not None:
            bad |= x < self.low or (self.low_open and x == self.low)
        if self.high is not None:
            bad |= x > self.high or (self.high_open and x == self.high)
        if bad:
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
        analytic: dotted path of the analytic module.
        checks: dotted path of the module whose ``run(samples, rng)`` validates it.
        assets: dotted path of a function ``(args) -> {relative path: bytes}`` making
            generated files other than URDF/SRDF (meshes), written beside the URDF.
        reference_pose: the SRDF pose used as ``Robot.q0``.
    """

    name: str
    title: str
    seed: str
    params: Mapping[str, Param] = field(default_factory=dict)
    actuated_joints: tuple[str, ...] = ()
    floating: bool = False
    analytic: str = ""
    checks: str = ""
    assets: str = ""
    reference_pose: str = "standing"

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
    """Collect ``SPEC`` from every module of :mod:`legkin.models` (one module per mechanism)."""
    from . import models

    found: dict[str, ModelSpec] = {}
    for info in sorted(pkgutil.iter_modules(models.__path__), key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        spec = importlib.import_module(f"{models.__name__}.{info.name}").SPEC
        found[spec.name] = spec
    return found


MODELS: Mapping[str, ModelSpec] = _discover()


def get_spec(name: str) -> ModelSpec:
    """Return the registry entry of ``name``.

    Raises:
        UnknownModelError: the name is not registered (the message lists the known names).
    """
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        raise UnknownModelError(
            f"unknown model {name!r}; known models: {', '.join(sorted(MODELS))}"
        ) from None


def list_models() -> list[str]:
    """Names of the registered models, sorted."""
    return sorted(MODELS)
