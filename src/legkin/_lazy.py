"""The lazy re-export of a mechanism package (``import legkin`` must not import numba).

A mechanism's ``__init__`` writes::

    __getattr__, __dir__ = lazy_exports(__name__, globals(), SUBMODULES, light={"Geometry": "geometry"})

``legkin.<name>.X`` then imports ``legkin.<name>.kinematics`` on first use and returns its ``X`` (any name of
``kinematics.__all__``); names in ``light`` come from their own (numba-free) module; a submodule name returns
the submodule. A name found once is kept in the package's namespace, so later look-ups are plain attribute
reads (a trip through ``__getattr__`` costs about 5 us, more than a compiled kernel call).
"""

from __future__ import annotations

import importlib
from typing import Any, Callable, Mapping, MutableMapping


def lazy_exports(
    package: str,
    namespace: MutableMapping[str, Any],
    submodules: tuple[str, ...],
    light: Mapping[str, str] | None = None,
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The module-level ``__getattr__`` and ``__dir__`` of the mechanism package ``package``."""
    light = dict(light or {})

    def kinematics_all() -> list[str]:
        return list(importlib.import_module(f"{package}.kinematics").__all__)

    def __getattr__(name: str) -> Any:
        if name in submodules:
            return importlib.import_module(f"{package}.{name}")
        if name in light:
            value = getattr(importlib.import_module(f"{package}.{light[name]}"), name)
        elif name == "__all__":
            value = ["SPEC", *kinematics_all()]
        elif name in kinematics_all():
            value = getattr(importlib.import_module(f"{package}.kinematics"), name)
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(submodules) | set(light) | set(kinematics_all()))

    return __getattr__, __dir__
