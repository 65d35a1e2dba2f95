"""A dask ``LocalCluster`` whose workers each use one core: one worker process = one task thread, and a study task
runs its batches on that thread alone (:func:`legkin.study.run.run_chunk`, ``threads=1``).

What a dask process runs beside its tasks, measured on a 2-CPU machine (process CPU time over 5-10 s, idle and
while a task ran): with dask's defaults a worker process spends 2.3-2.8 % of a core beyond its task's thread (its
statistical profiler samples the task's stack every 10 ms, its event loop ticks every 20 ms, its memory monitor
runs every 100 ms) and the client's process (scheduler and nannies) 3 %: on 2 cores with 2 workers, ~8 % of a core
taken from the workers. With :data:`QUIET`: 0.3 % a worker, 0.6-0.8 % in the client's process.
"""

from __future__ import annotations

import contextlib
from typing import Any, Iterator

from ..errors import InvalidArgumentError

__all__ = ["QUIET", "local_cluster"]

#: dask settings of the clusters :func:`local_cluster` starts (the statistical profiler off; the event-loop tick,
#: the memory and system monitors and the GIL monitor slowed or off). Nothing a study needs depends on them.
QUIET: dict[str, Any] = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.system-monitor.gil.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
}


@contextlib.contextmanager
def local_cluster(workers: int = 2) -> Iterator[Any]:
    """A ``LocalCluster`` of ``workers`` processes on this machine and a client connected to it, closed on exit.

    Each worker process runs one task at a time (``threads_per_worker=1``), a study task on one numba thread (on
    any cluster), with dask's background work reduced (:data:`QUIET`), so k workers use k cores. The dashboard
    takes a free port. (``legkin study --scheduler local:K`` uses it.)

    Args:
        workers: the number of worker processes (>= 1).

    Yields:
        A ``distributed.Client`` whose workers have all started.

    Raises:
        InvalidArgumentError: workers is not an integer >= 1.
    """
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InvalidArgumentError(f"local_cluster(workers={workers!r}): must be an integer >= 1")
    import dask
    from distributed import Client, LocalCluster

    with dask.config.set(QUIET):  # read by the scheduler, the nannies and (passed on) the worker processes
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0")
    with cluster, Client(cluster) as client:
        client.wait_for_workers(workers)
        yield client
