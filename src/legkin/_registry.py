"""The registry of mechanisms: one frozen entry per model."""

from __future__ import annotations

import importlib
import math
import pkgutil
from dataclasses import dataclass, field
from pathlib import Path
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
        left = "(" if self.low_open or self.low is None else "["
        right = ")" if self.high_open or self.high is None else "]"
        return f"{left}{lo}, {hi}{right}"

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
        reference_pose: the SRDF pose used as ``Robot.q0``.
        source: ``"legkin"`` (the model is generated from ``xacro/``) or the distribution whose installed URDF
            it is (``"example-robot-data"``: the nine quadrupeds whose leg IK :mod:`legkin.legs` derives).

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
    actuated_joints: tuple[str, ...] = ()
    floating: bool = False
    reference_pose: str = "standing"
    source: str = "legkin"

    @property
    def external(self) -> bool:
        """A robot whose URDF comes from another distribution (example-robot-data), not from legkin's xacro."""
        return self.source != "legkin"

    @property
    def package(self) -> str:
        """Dotted name of the mechanism's package (``legkin.legs`` for the external quadrupeds)."""
        return "legkin.legs" if self.external else f"legkin.{self.name}"

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
    """Collect ``SPEC`` from every mechanism package: each sub-package ``legkin.<name>`` with a ``spec``
    module (the one rule by which the framework finds a mechanism)."""
    import legkin

    found: dict[str, ModelSpec] = {}
    for info in sorted(pkgutil.iter_modules(legkin.__path__), key=lambda m: m.name):
        if not info.ispkg or info.name.startswith("_"):
            continue
        if not (Path(info.module_finder.path) / info.name / "spec.py").is_file():  # type: ignore[union-attr]
            continue  # a package that is not a mechanism (read from disk: nothing else is imported)
        spec = importlib.import_module(f"legkin.{info.name}.spec").SPEC
        if spec.name != info.name:
            raise RuntimeError(f"legkin.{info.name}.spec.SPEC is named {spec.name!r}: it must be {info.name!r}")
        found[spec.name] = spec
    return found


def _external() -> dict[str, ModelSpec]:
    """The legged robots of example-robot-data (:data:`legkin.legs.ERD_ALL`; their files are found when loaded)."""
    from .legs.erd import ERD_ALL

    return {
        r.name: ModelSpec(
            name=r.name,
            title=f"{r.title}: leg kinematics measured from its URDF (legkin.legs)",
            seed="",
            floating=True,
            reference_pose=r.reference_pose or "",
            source="example-robot-data",
        )
        for r in ERD_ALL.values()
    }


MODELS: Mapping[str, ModelSpec] = {**_discover(), **_external()}


def get_spec(name: str) -> ModelSpec:
    """Return the registry entry of ``name``.

    Raises:
        UnknownModelError: the name is not registered (the message lists the known names).
    """
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        raise UnknownModelError(
            f"unknown model {name!r}; known models: {', '.join(sorted(MODELS))}", name=name, known=sorted(MODELS)
        ) from None


def list_models(source: str | None = None) -> list[str]:
    """Names of the registered models, sorted.

    Args:
        source: only the models of this source: ``"legkin"`` (the mechanisms generated from legkin's xacro,
            with their analytic kinematics) or ``"example-robot-data"`` (the external quadrupeds of
            :mod:`legkin.legs`); None (default): all.
    """
    if source is None:
        return sorted(MODELS)
    sources = sorted({s.source for s in MODELS.values()})
    if source not in sources:
        raise InvalidParameterError(f"source={source!r} is not valid: must be one of {', '.join(map(repr, sources))}")
    return sorted(n for n, s in MODELS.items() if s.source == source)
