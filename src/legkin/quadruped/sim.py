"""The quadruped's ground model: the one of :mod:`legkin.legs` (its legs measured from the URDF), found by
:func:`legkin.mjcf.ground.ground_model`."""

from __future__ import annotations

from ..legs.sim import ground_model

__all__ = ["ground_model"]
