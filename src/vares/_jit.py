"""Compiled kernels: numba's ``njit``, applied when a kernel is first called, and the size of
work below which a kernel runs as numpy instead.

Importing numba (0.2 s), loading its first cached function (0.2 s more) and, on the first run
after an install, compiling the kernels (several seconds) cost more than a small job's whole
solve. So a kernel module decorates its loops with :func:`njit` from here — numba is imported,
and the kernel compiled or loaded from numba's cache, only when the compiled kernel is first
called — and asks :func:`compiled` whether a call of a given size takes it. Below
:data:`COMPILED_FROM` cells the numpy form runs: where the kernel's loop body is elementwise
arithmetic, the very same Python function (``kernel.py_func``) over arrays with the cells on
the last axis (:func:`lanes`), so the mechanics have one source. The path depends on the size
of the call alone, never on what the process ran before: the same input gives the same numbers
in every process (a worker's as the caller's).
"""

from __future__ import annotations

import functools
import importlib
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any

import numpy as np

__all__ = ["COMPILED_FROM", "Kernel", "compiled", "lanes", "njit", "prange", "sized_for"]

#: Cells (or items) from which a kernel runs compiled; below, its numpy form runs.
COMPILED_FROM = 2000

#: The loop over the cells of a kernel compiled with ``parallel=True``: numba's ``prange`` once
#: the kernel is compiled (its cells shared among the cores, each cell's results written by one
#: thread alone: the same numbers on any number of threads), the builtin ``range`` before (the
#: numpy form runs one block).
prange = range

#: Held while a parallel kernel runs: calls from several Python threads at once take turns (each
#: uses every core anyway), as numba's own thread pool (``workqueue``, where neither TBB nor
#: OpenMP is installed) ends the process when two threads launch parallel kernels at once.
_PARALLEL = threading.Lock()

_FORCED: ContextVar[bool | None] = ContextVar("vares_compiled", default=None)


def compiled(size: int) -> bool:
    """Whether a kernel over ``size`` cells runs compiled: from :data:`COMPILED_FROM` cells;
    inside :func:`sized_for`, as that says."""
    forced = _FORCED.get()
    return size >= COMPILED_FROM if forced is None else forced


@contextmanager
def sized_for(size: int | bool) -> Iterator[None]:
    """Within, every kernel takes the path of a job of ``size`` cells whatever its own size
    (``True``: compiled, ``False``: numpy): loading a large mesh's kernels by solving one of
    its cells loads the compiled ones; tests and benchmarks run either path."""
    token = _FORCED.set(bool(size) if isinstance(size, bool) else size >= COMPILED_FROM)
    try:
        yield
    finally:
        _FORCED.reset(token)


class Kernel:
    """A function compiled by numba (``njit`` with ``options``) when it is first called;
    ``py_func`` is the function itself."""

    def __init__(self, function: Callable[..., Any], options: dict[str, Any]) -> None:
        functools.update_wrapper(self, function)
        self.py_func = function
        self.options = options
        self.dispatcher: Any = None

    def __call__(self, *args: Any) -> Any:
        if self.dispatcher is None:
            numba = importlib.import_module("numba")
            if self.options.get("parallel"):  # the kernel's module's prange (module docs)
                self.py_func.__globals__["prange"] = numba.prange
            self.dispatcher = numba.njit(**self.options)(self.py_func)
        if self.options.get("parallel"):
            with _PARALLEL:
                return self.dispatcher(*args)
        return self.dispatcher(*args)


def njit(**options: Any) -> Callable[[Callable[..., Any]], Kernel]:
    """``numba.njit(**options)``, applied at the kernel's first call (numba imported then)."""

    def decorate(function: Callable[..., Any]) -> Kernel:
        return Kernel(function, options)

    return decorate


def lanes(array: np.ndarray) -> np.ndarray:
    """A view of ``array`` ``(m, ...)`` as one block ``(1, ..., m)``: a kernel written for one
    cell at a time (its loop over the leading axis) then does every cell at once, each scalar
    of its body an array over the cells; writes go to ``array``."""
    return np.moveaxis(array, 0, -1)[None]
