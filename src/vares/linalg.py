"""Sparse linear solvers behind one small interface.

A solver factorises the Newton matrix once per iteration and then solves with it. SciPy's
SuperLU is always present; faster back ends plug in by implementing the same two methods.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = [
    "LinearSolver",
    "SingularMatrixError",
    "SuperLUSolver",
    "available_solvers",
    "get_solver",
]


class SingularMatrixError(RuntimeError):
    """The tangent matrix is singular (to working precision)."""


class LinearSolver(Protocol):
    """Factorise a sparse symmetric matrix, then solve with it."""

    name: str

    def factorize(self, matrix: sp.csr_matrix) -> None: ...

    def solve(self, rhs: np.ndarray) -> np.ndarray: ...


class SuperLUSolver:
    """SciPy's SuperLU with a fill-reducing ordering for symmetric structure."""

    name = "scipy-superlu"

    def __init__(self) -> None:
        self._lu = None

    def factorize(self, matrix: sp.csr_matrix) -> None:
        try:
            self._lu = spla.splu(matrix.tocsc(), permc_spec="MMD_AT_PLUS_A")
        except RuntimeError as exc:  # SuperLU reports exact singularity this way
            raise SingularMatrixError(str(exc)) from exc

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self._lu is None:
            raise RuntimeError("factorize() must be called before solve()")
        x = self._lu.solve(rhs)
        if not np.all(np.isfinite(x)):
            raise SingularMatrixError("the solution of the tangent system is not finite")
        return x


_SOLVERS = {SuperLUSolver.name: SuperLUSolver}


def available_solvers() -> list[str]:
    """Names of the linear solvers usable here, fastest first."""
    return list(_SOLVERS)


def get_solver(name: str | None = None) -> LinearSolver:
    """A new solver by name; ``None`` picks the fastest available one."""
    if name is None:
        name = available_solvers()[0]
    if name not in _SOLVERS:
        raise ValueError(f"unknown linear solver {name!r}; available: {', '.join(_SOLVERS)}")
    return _SOLVERS[name]()
