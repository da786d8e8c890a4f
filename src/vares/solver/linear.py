"""Sparse linear solvers behind one small interface.

A solver factorises the Newton matrix once per iteration and then solves with it. The matrices
of one mesh share their sparsity pattern, so a back end that separates the symbolic analysis
(fill-reducing ordering) from the numeric factorisation does the analysis once. Back ends,
fastest first (measured in docs/benchmarks.md):

``pardiso``
    Intel MKL PARDISO (pypardiso, optional extra ``vares[pardiso]``), symmetric indefinite mode.
``cholmod``
    CHOLMOD's Cholesky (scikit-sparse, optional extra ``vares[cholmod]``): nested-dissection
    analysis once per pattern, numeric factorisation per iteration. For positive definite
    matrices only; an indefinite matrix (a tangent far from the solution, or one bordered by
    a constraint) is passed on to SuperLU.
``scipy-superlu``
    SciPy's SuperLU, always present.

:func:`get_solver` without a name picks the first available of these, in this order.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = [
    "SOLVER_NAMES",
    "LinearSolver",
    "SingularMatrixError",
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


def _finite(x: np.ndarray) -> np.ndarray:
    if not np.all(np.isfinite(x)):
        raise SingularMatrixError("the solution of the tangent system is not finite")
    return x


class SuperLUSolver:
    """SciPy's SuperLU told that the matrix is symmetric: a symmetric fill-reducing ordering
    (minimum degree on AᵀA + A) and pivots on the diagonal, which keep the fill of a symmetric
    factorisation (for a positive definite matrix as stable as Cholesky). Told nothing, SuperLU
    pivots for a general matrix and can fill in catastrophically: minutes instead of seconds on
    a 50k-triangle scan, and a near-complete fill of the erection's tangent, whose out-of-plane
    diagonal is far smaller than its in-plane couplings (docs/benchmarks.md). A factorisation
    that meets a zero pivot, or a solve whose residual exceeds
    :data:`DIAGONAL_PIVOTING_RESIDUAL` of the right-hand side (an indefinite matrix with small
    pivots, a bordered system), is redone with partial pivoting.
    """

    name = "scipy-superlu"

    def __init__(self) -> None:
        self._lu = None
        self._matrix = None
        self._pivoted_on_diagonal = False

    def factorize(self, matrix: sp.csr_matrix) -> None:
        self._matrix = matrix
        try:
            self._lu = spla.splu(
                matrix.tocsc(),
                permc_spec="MMD_AT_PLUS_A",
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
            self._pivoted_on_diagonal = True
        except RuntimeError:  # a zero pivot on the diagonal: pivot by rows instead
            self._partial_pivoting()

    def _partial_pivoting(self) -> None:
        try:
            self._lu = spla.splu(self._matrix.tocsc(), permc_spec="MMD_AT_PLUS_A")
        except RuntimeError as exc:  # SuperLU reports exact singularity this way
            raise SingularMatrixError(str(exc)) from exc
        self._pivoted_on_diagonal = False

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self._lu is None:
            raise RuntimeError("factorize() must be called before solve()")
        x = self._lu.solve(rhs)
        if self._pivoted_on_diagonal:
            residual = np.linalg.norm(self._matrix @ x - rhs)
            if not residual <= DIAGONAL_PIVOTING_RESIDUAL * np.linalg.norm(rhs):
                self._partial_pivoting()
                x = self._lu.solve(rhs)
        return _finite(x)


#: Relative residual above which a solve with diagonal pivots is redone with partial pivoting.
DIAGONAL_PIVOTING_RESIDUAL = 1e-9


_PARDISO = None


class PardisoSolver:
    """MKL PARDISO, real symmetric indefinite (upper triangle), via pypardiso.

    The symbolic analysis (phase 11) is redone only when the sparsity pattern changes; each
    factorisation is the numeric phase 22 alone. All instances share one PARDISO handle (MKL is
    loaded once per process), so solvers must not be used from several threads at once.
    """

    name = "pardiso"

    def __init__(self) -> None:
        global _PARDISO
        if _PARDISO is None:  # loading MKL takes a while: one handle per process
            import pypardiso

            _PARDISO = pypardiso.PyPardisoSolver(mtype=-2)
            _PARDISO.set_statistical_info_off()
        self._solver = _PARDISO
        self._matrix = None

    def _phase(self, phase: int, rhs: np.ndarray) -> np.ndarray:
        from pypardiso.pardiso_wrapper import PyPardisoError

        self._solver.set_phase(phase)
        try:
            return self._solver._call_pardiso(self._matrix, rhs)
        except PyPardisoError as exc:
            raise SingularMatrixError(f"PARDISO: {exc}") from exc

    def factorize(self, matrix: sp.csr_matrix) -> None:
        # PARDISO needs every diagonal entry stored, even a zero one (a bordered constraint)
        upper = sp.triu(matrix, format="coo")
        size = matrix.shape[0]
        diagonal = np.arange(size)
        upper = sp.csr_matrix(
            (
                np.concatenate([upper.data, np.zeros(size)]),
                (np.concatenate([upper.row, diagonal]), np.concatenate([upper.col, diagonal])),
            ),
            shape=matrix.shape,
        )
        upper.sort_indices()
        global _PARDISO_ANALYSED
        self._matrix = upper
        self._solver._check_A(upper)
        empty = np.zeros(size)
        if _PARDISO_ANALYSED is None or not _same_pattern(_PARDISO_ANALYSED, upper):
            _PARDISO_ANALYSED = None
            self._phase(11, empty)
            _PARDISO_ANALYSED = upper
        self._phase(22, empty)
        if self._solver.get_iparm(30) != 0:
            raise SingularMatrixError("PARDISO found a zero pivot")

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self._matrix is None:
            raise RuntimeError("factorize() must be called before solve()")
        return _finite(self._phase(33, np.ascontiguousarray(rhs, dtype=float)))


#: The matrix whose pattern the shared PARDISO handle has analysed.
_PARDISO_ANALYSED: sp.csr_matrix | None = None


def _same_pattern(a: sp.csr_matrix, b: sp.csr_matrix) -> bool:
    return (
        a.shape == b.shape
        and a.nnz == b.nnz
        and np.array_equal(a.indptr, b.indptr)
        and np.array_equal(a.indices, b.indices)
    )


class CholmodSolver:
    """CHOLMOD supernodal Cholesky; indefinite matrices go to ``fallback``."""

    name = "cholmod"

    def __init__(self, fallback: LinearSolver | None = None) -> None:
        from sksparse import cholmod

        self._cholmod = cholmod
        self._factor = None
        self._pattern: tuple[int, int] | None = None
        self._fallback = fallback or SuperLUSolver()
        self._use_fallback = False

    def factorize(self, matrix: sp.csr_matrix) -> None:
        csc = matrix.tocsc()
        pattern = (csc.shape[0], csc.nnz)
        self._use_fallback = False
        try:
            if self._factor is None or pattern != self._pattern:
                self._factor = self._cholmod.analyze(
                    csc, mode="simplicial", ordering_method="nesdis"
                )
                self._pattern = pattern
            self._factor.cholesky_inplace(csc)
        except self._cholmod.CholmodNotPositiveDefiniteError:
            self._use_fallback = True
            self._fallback.factorize(matrix)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self._use_fallback:
            return self._fallback.solve(rhs)
        if self._factor is None:
            raise RuntimeError("factorize() must be called before solve()")
        return _finite(self._factor(rhs))


def _importable(module: str) -> bool:
    from importlib.util import find_spec

    return find_spec(module) is not None


_SOLVERS: dict[str, type] = {
    PardisoSolver.name: PardisoSolver,
    CholmodSolver.name: CholmodSolver,
    SuperLUSolver.name: SuperLUSolver,
}
_MODULES = {"cholmod": "sksparse", "pardiso": "pypardiso"}
#: Every linear solver's name, installed or not (fastest first).
SOLVER_NAMES = tuple(_SOLVERS)


def available_solvers() -> list[str]:
    """Names of the linear solvers usable here, fastest first."""
    return [name for name in _SOLVERS if name not in _MODULES or _importable(_MODULES[name])]


def get_solver(name: str | None = None) -> LinearSolver:
    """A new solver by name; ``None`` picks the fastest available one."""
    available = available_solvers()
    if name is None:
        name = available[0]
    if name not in _SOLVERS:
        raise ValueError(f"unknown linear solver {name!r}; available: {', '.join(available)}")
    if name not in available:
        raise ValueError(
            f"linear solver {name!r} is not installed (pip install 'vares[{name}]'); "
            f"available: {', '.join(available)}"
        )
    return _SOLVERS[name]()
