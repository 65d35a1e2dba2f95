"""Animation clips for ``legkin view MODEL --animate NAME``.

A model's clips live in ``legkin.<model>.clips`` (the external quadrupeds': ``legkin.legs.clips``) as
``ANIMATIONS = {name: function(robot) -> list of q}``.
"""

from __future__ import annotations

import importlib

from .errors import LegkinError

__all__ = ["available", "frames"]


def available(model: str) -> dict:
    """The clips of ``model`` (name -> function(robot) -> configurations)."""
    from ._registry import MODELS

    spec = MODELS.get(model)
    package = spec.package if spec is not None else f"legkin.{model}"  # legkin.legs for the external robots
    try:
        mod = importlib.import_module(f"{package}.clips")
    except ModuleNotFoundError:
        return {}
    return dict(mod.ANIMATIONS)


def frames(robot, name: str) -> list:
    """The configurations of clip ``name`` for ``robot``."""
    clips = available(robot.name)
    if name not in clips:
        raise LegkinError(
            f"model {robot.name!r} has no animation {name!r}; animations: {', '.join(sorted(clips)) or 'none'}"
        )
    return clips[name](robot)
