"""Worker processes for independent solves (a batch's jobs, a laminate's plies, a band's
samples): each worker started fresh (``spawn``) with its numerical libraries held to its share
of the cores; :func:`parallel_map` runs one function over many tasks here, on such workers or on
the workers of a Dask distributed scheduler."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from typing import Any

__all__ = ["parallel_map", "process_pool"]


def _limit_threads(threads: int) -> None:
    """Keep each worker's numerical libraries to its share of the cores."""
    for variable in (
        "MKL_NUM_THREADS",
        "OMP_NUM_THREADS",
        "OPENBLAS_NUM_THREADS",
        "NUMBA_NUM_THREADS",
    ):
        os.environ[variable] = str(threads)


def process_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of ``workers`` processes, each with ``cores // workers`` threads (at least one)."""
    threads = max(1, (os.cpu_count() or 1) // workers)
    return ProcessPoolExecutor(
        max_workers=workers,
        mp_context=get_context("spawn"),
        initializer=_limit_threads,
        initargs=(threads,),
    )


def parallel_map(
    function: Callable[[Any], Any],
    tasks: Sequence[Any],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
) -> tuple[list[Any], int]:
    """``function`` of every task, in their order, and the number of workers that ran them: the
    workers of the Dask distributed scheduler at ``scheduler`` (``tcp://host:port``), else
    ``workers`` local processes (:func:`process_pool`), or this process alone when ``workers``
    is None or 1. ``function`` and the tasks must pickle to run elsewhere."""
    if scheduler is not None:
        from dask.distributed import Client

        with Client(scheduler, timeout="20s") as client:
            outcomes = client.gather(client.map(function, list(tasks), pure=False))
            count = len(client.scheduler_info()["workers"])
        return list(outcomes), count
    if workers is None or workers <= 1:
        return [function(task) for task in tasks], 1
    with process_pool(workers) as pool:
        return list(pool.map(function, tasks)), workers
