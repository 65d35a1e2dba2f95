"""Design studies: workspace, dexterity and singularity metrics over a mechanism's geometry parameters, in-process
or on a dask cluster (docs/study.md).

The names load on first use (``legkin study --help`` and ``legkin list`` do not import numba)."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .cluster import local_cluster
    from .run import BLOCK_SIZE, CHUNK_BLOCKS, DEFAULT_METRICS, Plan, plan, study
    from .targets import TARGETS, StudyTarget, get_target

#: Public name -> the submodule defining it.
_WHERE = {
    "study": "run", "plan": "run", "Plan": "run", "BLOCK_SIZE": "run", "CHUNK_BLOCKS": "run", "DEFAULT_METRICS": "run",
    "local_cluster": "cluster", "TARGETS": "targets", "StudyTarget": "targets", "get_target": "targets",
}

__all__ = ["study", "plan", "Plan", "local_cluster", "TARGETS", "StudyTarget", "get_target", "BLOCK_SIZE",
           "CHUNK_BLOCKS", "DEFAULT_METRICS"]


def __getattr__(name: str) -> Any:
    """A public name, from its submodule on first use (then kept in the package's namespace)."""
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_WHERE[name]}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
