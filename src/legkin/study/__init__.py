"""Design studies: workspace, dexterity and singularity metrics over a mechanism's geometry parameters, in-process
or on a dask cluster (docs/study.md)."""

from .run import BLOCK_SIZE, CHUNK_BLOCKS, DEFAULT_METRICS, Plan, plan, study
from .targets import TARGETS, StudyTarget, get_target

__all__ = ["study", "plan", "Plan", "TARGETS", "StudyTarget", "get_target", "BLOCK_SIZE", "CHUNK_BLOCKS",
           "DEFAULT_METRICS"]
