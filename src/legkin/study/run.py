"""``study()``: the metrics of a mechanism over a grid of its geometry parameters, in-process or on dask.

The work is a grid of parameter points x blocks of ``block_size`` samples. Block b of point i draws its samples
from ``numpy.random.default_rng(SeedSequence(seed, spawn_key=(i, b)))`` and reduces them to integer counts
(:mod:`legkin.study.stats`); a chunk (one dask task) is a run of consecutive blocks of one point. The blocks and
their seeds do not depend on the chunking, and the merge of counts is exact, so the table is the same bit for bit
in-process, on one worker or on many, whatever ``chunk_blocks``.
"""

from __future__ import annotations

import contextlib
import itertools
import uuid
from dataclasses import dataclass
from typing import Any, Iterator, Mapping, Sequence

import numpy as np

from .._progress import progress_bar
from ..errors import InvalidArgumentError, InvalidParameterError
from .stats import block_stats, merge, metrics_row
from .targets import StudyTarget, get_target

__all__ = ["study", "BLOCK_SIZE", "CHUNK_BLOCKS", "DEFAULT_METRICS", "plan", "Plan", "run_chunk"]

#: Samples per block (the unit of seeding and of reduction): large enough that the compiled batches run at full
#: speed on every numba thread (> 0.2 ms a thread), small enough that a block's arrays stay in cache-sized MBs.
BLOCK_SIZE = 1 << 16
#: Blocks per dask task by default: ~10^6 samples, 0.5-1.3 s of one worker's work for the cheapest target (the
#: quadruped), against dask's 4-7 ms a task measured (docs/study.md, "Chunk size"); fewer when a point has fewer.
CHUNK_BLOCKS = 16
DEFAULT_METRICS = ("reach", "conditioning", "singularity")


@dataclass(frozen=True)
class Plan:
    """The work of a study.

    Attributes:
        target: the :class:`~legkin.study.targets.StudyTarget`.
        names: the swept parameters' names. values: one tuple of their values per point.
        resolved: per point, the full, validated parameter set (defaults filled in).
        sizes: the sample count of each block (the same for every point).
        chunks: (point, first block, end block) of each task.
        metrics: the metric groups. threshold: the singularity threshold on 1/kappa. seed: the root seed.
    """

    target: StudyTarget
    names: tuple[str, ...]
    values: tuple[tuple[Any, ...], ...]
    resolved: tuple[dict[str, Any], ...]
    sizes: tuple[int, ...]
    chunks: tuple[tuple[int, int, int], ...]
    metrics: tuple[str, ...]
    threshold: float
    seed: int


def _grid(params: Mapping[str, Any]) -> tuple[tuple[str, ...], list[tuple[Any, ...]]]:
    names = tuple(params)
    axes = []
    for name in names:
        axis = np.atleast_1d(np.asarray(params[name], dtype=object if isinstance(params[name], str) else None))
        if axis.ndim != 1 or axis.size == 0:
            raise InvalidParameterError(f"study parameter {name!r}: give 1-D values, got {params[name]!r}")
        axes.append([v.item() if hasattr(v, "item") else v for v in axis])
    return names, list(itertools.product(*axes))


def _int_arg(value: Any, name: str, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise InvalidArgumentError(f"{name}={value!r}: must be an integer >= {low}")
    return int(value)


def plan(model: str, params: Mapping[str, Any], samples: int, metrics: Sequence[str] = DEFAULT_METRICS,
         seed: int = 0, *, block_size: int = BLOCK_SIZE, chunk_blocks: int | None = None,
         singular_threshold: float = 0.01) -> Plan:
    """Validate a study and split it into blocks and chunks; nothing is computed.

    Args:
        model: a study target (:data:`legkin.study.TARGETS`). params: name -> 1-D values (the grid is their
            product; the other parameters keep their defaults). samples: samples per point. metrics: metric
            groups. seed: root seed. block_size, chunk_blocks: see :func:`study`. singular_threshold: eps.

    Returns:
        The :class:`Plan`.

    Raises:
        UnknownModelError: no such target. InvalidParameterError: a parameter unknown or out of its registry
            range (every point checked before any work). InvalidArgumentError: bad samples, seed, metric, sizes.
    """
    target = get_target(model)
    names, values = _grid(params)
    resolved = tuple(target.spec.resolve_params(dict(zip(names, v))) for v in values)
    samples = _int_arg(samples, "samples", 1)
    block_size = _int_arg(block_size, "block_size", 1)
    seed = _int_arg(seed, "seed", 0)
    known = DEFAULT_METRICS + target.extras
    bad = [m for m in metrics if m not in known]
    if bad or not metrics:
        raise InvalidArgumentError(f"metrics {bad or list(metrics)!r} not available for {model}; known: {known}")
    if not (isinstance(singular_threshold, (int, float)) and 0 < singular_threshold < 1):
        raise InvalidArgumentError(f"singular_threshold={singular_threshold!r}: must be a number in (0, 1)")
    nb = -(-samples // block_size)
    sizes = tuple(min(block_size, samples - b * block_size) for b in range(nb))
    per = min(nb, CHUNK_BLOCKS if chunk_blocks is None else _int_arg(chunk_blocks, "chunk_blocks", 1))
    chunks = tuple((i, b, min(b + per, nb)) for i in range(len(values)) for b in range(0, nb, per))
    return Plan(target, names, tuple(values), resolved, sizes, chunks, tuple(metrics), float(singular_threshold),
                seed)


@contextlib.contextmanager
def _numba_threads(k: int | None) -> Iterator[None]:
    """The batches called inside run on at most k numba threads (numba's setting is per calling thread); None: as
    set."""
    if k is None:
        yield
        return
    import numba

    before = numba.get_num_threads()
    numba.set_num_threads(max(1, min(k, before)))
    try:
        yield
    finally:
        numba.set_num_threads(before)


def run_chunk(model: str, params: Mapping[str, Any], point: int, sizes: Sequence[int], first: int, seed: int,
              metrics: tuple[str, ...], threshold: float, threads: int | None = None) -> list[dict[str, Any]]:
    """The statistics of blocks ``first, first + 1, ...`` (sizes ``sizes``) of one point: one dask task.

    Args:
        model: the target's name. params: the point's resolved parameters. point: its index (seeding).
        sizes: the blocks' sample counts. first: the first block's index. seed: the root seed.
        metrics: the metric groups. threshold: the singularity threshold eps.
        threads: numba threads of the batches (None: numba's setting; a dask task: 1, its worker thread's core).

    Returns:
        One :func:`~legkin.study.stats.block_stats` dict per block.
    """
    target = get_target(model)
    extras = tuple(m for m in metrics if m in target.extras)
    out = []
    with _numba_threads(threads):
        for j, n in enumerate(sizes):
            rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(point, first + j)))
            solved = target.solve(target.sample(rng, n, params), params, extras)
            out.append(block_stats(solved, n, threshold, extras))
    return out


def _args(p: Plan, chunk: tuple[int, int, int]) -> tuple[Any, ...]:
    i, b, e = chunk
    return (p.target.name, p.resolved[i], i, p.sizes[b:e], b, p.seed, p.metrics, p.threshold)


def _run_local(p: Plan, show: bool) -> list[list[dict[str, Any]]]:
    out = []
    with progress_bar(len(p.chunks), f"study {p.target.name}", show) as bar:
        for chunk in p.chunks:
            out.append(run_chunk(*_args(p, chunk)))
            bar.update()
    return out


def _run_dask(p: Plan, client: Any, show: bool) -> list[list[dict[str, Any]]]:
    """One task per chunk (keys unique to this run), on one numba thread: the parallelism is dask's workers and
    their threads, one core each (a worker's ``NUMBA_NUM_THREADS`` is the machine's CPU count whenever its process
    imported numba before dask applied its environment). dask re-runs a task whose worker is lost."""
    from distributed import progress

    run = uuid.uuid4().hex[:12]
    futures = [client.submit(run_chunk, *_args(p, c), threads=1, key=f"legkin-study-{run}-{k}", retries=2)
               for k, c in enumerate(p.chunks)]
    if show:
        progress(futures)
    return list(client.gather(futures))


def study(model: str, params: Mapping[str, Any], samples: int = 10**6, metrics: Sequence[str] = DEFAULT_METRICS,
          seed: int = 0, client: Any = None, *, block_size: int = BLOCK_SIZE, chunk_blocks: int | None = None,
          singular_threshold: float = 0.01, progress: bool = False) -> Any:
    """The metrics of ``model`` at every point of a parameter grid: one row per point (docs/study.md).

    Args:
        model: a study target: "tripod", "quadruped", "wheel_leg" or "planar_2link" (:data:`legkin.study.TARGETS`).
        params: parameter name -> 1-D values, e.g. ``{"alpha": np.linspace(0.5, 1.2, 36)}``; several names sweep
            their product. Units: the registry's (``legkin list``; m, rad).
        samples: Monte-Carlo samples per point.
        metrics: any of "reach" (reachable fraction, workspace volume), "conditioning" (kappa percentiles),
            "singularity" (fraction with 1/kappa <= eps) and the target's own ("cv_error" for the tripod,
            "rim_contact" for the wheel-leg).
        seed: root seed; block (point i, block b) uses ``SeedSequence(seed, spawn_key=(i, b))``.
        client: None: in-process (the compiled batches on every numba thread); a ``dask.distributed.Client``: one
            task per chunk on its workers, each on one numba thread (one core a worker thread;
            :func:`~legkin.study.cluster.local_cluster` starts such a cluster here). The table is identical bit for
            bit either way.
        block_size: samples per block (the unit of seeding: changing it changes the samples).
        chunk_blocks: blocks per dask task (default :data:`CHUNK_BLOCKS`); does not change the result.
        singular_threshold: eps, dimensionless, in (0, 1).
        progress: show a progress bar (tqdm in-process, dask's with a client).

    Returns:
        A pandas DataFrame, one row per point: the swept parameters, ``samples``, ``reached`` and the metric
        columns with their 95 % bounds (``*_lo``, ``*_hi``).

    Raises:
        UnknownModelError, InvalidParameterError, InvalidArgumentError: see :func:`plan` (before any work).
    """
    import pandas as pd

    p = plan(model, params, samples, metrics, seed, block_size=block_size, chunk_blocks=chunk_blocks,
             singular_threshold=singular_threshold)
    results = _run_local(p, progress) if client is None else _run_dask(p, client, progress)
    per_point: list[list[dict[str, Any]]] = [[] for _ in p.values]
    for chunk, blocks in zip(p.chunks, results):
        per_point[chunk[0]].extend(blocks)
    rows = []
    for values, resolved, blocks in zip(p.values, p.resolved, per_point):
        row: dict[str, Any] = dict(zip(p.names, values))
        row.update(metrics_row(merge(blocks), p.target.measure(resolved), p.metrics))
        rows.append(row)
    frame = pd.DataFrame(rows)
    frame.attrs.update(model=model, unit=p.target.unit, seed=p.seed, block_size=block_size,
                       singular_threshold=p.threshold, measure=[p.target.measure(r) for r in p.resolved])
    return frame
