"""A dask ``LocalCluster`` whose workers each use one core: one worker process = one task thread = one numba thread.

What else a dask process runs beside its tasks, measured on a 2-CPU machine (scripts/bench_study.py): with dask's
defaults an idle worker process spends 2.3 % of a core (its event loop ticks every 20 ms, its memory monitor every
100 ms) and, while a task runs, 8-10 % more CPU than the task's own thread (the statistical profiler samples the
task thread's stack every 10 ms); the scheduler and nannies in the client's process spend 3 % of a core. On 2 cores
with 2 workers that is ~8 % of a core taken from the workers. :data:`QUIET` turns the profiler off and slows the
periodic callbacks (+1 % a worker, 0.6 % of a core in the client's process).
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

    Each worker process runs one task at a time (``threads_per_worker=1``) with one numba thread
    (:data:`WORKER_ENV`) and dask's background work reduced (:data:`QUIET`), so k workers use k cores. The
    dashboard takes a free port. (``legkin study --scheduler local:K`` uses it.)

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
