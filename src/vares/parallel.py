"""Worker processes for independent solves (a batch's jobs, a laminate's plies): each worker
started fresh (``spawn``) with its numerical libraries held to its share of the cores."""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

__all__ = ["process_pool"]


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
