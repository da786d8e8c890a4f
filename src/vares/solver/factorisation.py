"""What every sparse back end of :mod:`vares.solver.linear` shares: its errors, the check of a
solution, and the sparsity pattern a symbolic analysis depends on."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = [
    "DIAGONAL_PIVOTING_RESIDUAL",
    "IndefiniteMatrixError",
    "SingularMatrixError",
    "finite_solution",
    "same_pattern",
    "sparsity_pattern",
]


class SingularMatrixError(RuntimeError):
    """The tangent matrix is singular (to working precision)."""


class IndefiniteMatrixError(SingularMatrixError):
    """A solver for positive definite matrices was given another and asked not to pass it on
    to its (slower) fallback: the caller has a definite matrix to try instead."""


def finite_solution(x: np.ndarray) -> np.ndarray:
    """``x``, or :class:`SingularMatrixError` where a solve gave values that are not finite."""
    if not np.all(np.isfinite(x)):
        raise SingularMatrixError("the solution of the tangent system is not finite")
    return x


#: Relative residual above which a solve with diagonal pivots is redone with partial pivoting.
DIAGONAL_PIVOTING_RESIDUAL = 1e-9


def sparsity_pattern(matrix: sp.csr_matrix) -> tuple:
    """A CSR matrix's sparsity pattern ``(shape, indptr, indices)``, without its values."""
    return matrix.shape, matrix.indptr, matrix.indices


def same_pattern(a: tuple, b: tuple) -> bool:
    if a[0] == b[0] and a[1] is b[1] and a[2] is b[2]:  # one assembler's arrays: no comparison
        return True
    return (
        a[0] == b[0]
        and a[2].size == b[2].size
        and np.array_equal(a[1], b[1])
        and np.array_equal(a[2], b[2])
    )
