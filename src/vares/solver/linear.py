"""Sparse linear solvers behind one small interface.

A solver factorises the Newton matrix once per iteration and then solves with it. The matrices
of one mesh share their sparsity pattern, so a back end that separates the symbolic analysis
(fill-reducing ordering) from the numeric factorisation does the analysis once. Back ends,
fastest first (measured in docs/benchmarks.md):

``pardiso``
    Intel MKL PARDISO (pypardiso), symmetric indefinite mode: installed with vares on x86-64
    Linux and Windows, where MKL has wheels.
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

import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Protocol

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .factorisation import (
    DIAGONAL_PIVOTING_RESIDUAL,
    IndefiniteMatrixError,
    SingularMatrixError,
    finite_solution,
    same_pattern,
    sparsity_pattern,
)
from .pardiso import (
    PardisoLU,
    PardisoSolver,
    forget_pardiso_analysis,
    own_pardiso_state,
)

__all__ = [
    "SOLVER_NAMES",
    "IndefiniteMatrixError",
    "LinearSolver",
    "SingularMatrixError",
    "available_solvers",
    "forget_pardiso_analysis",
    "get_solver",
    "quiet_blas",
    "solver_choice",
    "solver_family",
    "unsymmetric_factorizer",
]


class LinearSolver(Protocol):
    """Factorise a sparse symmetric matrix, then solve with it. ``reuse_iterations``: how
    many conjugate-gradient iterations preconditioned by the last factorisation may stand in
    for a new one (:mod:`vares.solver.reuse`; about what a factorisation costs in solves);
    a back end may set ``cautious_reuse`` (PARDISO) to reuse only at Newton's fast end
    (:data:`vares.solver.reuse.CAUTIOUS_BELOW`).
    ``factorize(matrix, definite=True)``: the caller would rather have
    :class:`IndefiniteMatrixError` than a slow factorisation of an indefinite matrix (a
    solver that handles indefinite matrices as fast may ignore it)."""

    name: str
    reuse_iterations: int

    def factorize(self, matrix: sp.csr_matrix, definite: bool = False) -> None: ...

    def solve(self, rhs: np.ndarray) -> np.ndarray: ...


_QUIET_LOCK = threading.Lock()
_quiet: dict = {"depth": 0, "limiter": None}


@contextmanager
def quiet_blas() -> Iterator[None]:
    """A context (or a decorator: ``@quiet_blas()``) in which OpenBLAS (NumPy's and SciPy's)
    runs on one thread; MKL, which runs PARDISO, keeps its threads. vares' own BLAS calls are
    on vectors; left multi-threaded, OpenBLAS's worker keeps spinning after each call and takes
    a core from PARDISO, which then factorises at single-thread speed, and a vector norm beside
    PARDISO's threads takes milliseconds (docs/benchmarks.md). Nested contexts cost nothing:
    only the outermost limits the threads (about 2 ms) and gives them back."""
    with _QUIET_LOCK:
        if _quiet["depth"] == 0:
            from threadpoolctl import ThreadpoolController

            controller = ThreadpoolController().select(internal_api="openblas")
            _quiet["limiter"] = controller.limit(limits=1)
        _quiet["depth"] += 1
    try:
        yield
    finally:
        with _QUIET_LOCK:
            _quiet["depth"] -= 1
            if _quiet["depth"] == 0:
                _quiet["limiter"].restore_original_limits()
                _quiet["limiter"] = None


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
    #: a factorisation costs about 30 solves (100k-triangle hypar: 0.54 s against 0.018 s)
    reuse_iterations = 20

    def __init__(self) -> None:
        self._lu = None
        self._matrix = None
        self._pivoted_on_diagonal = False
        self._checked = False  # the diagonal pivots' accuracy, checked on the first solve

    def factorize(self, matrix: sp.csr_matrix, definite: bool = False) -> None:
        self._matrix = matrix
        self._checked = False
        self._lu = None  # the last factors freed before the next are made: at 1M triangles
        # the two together were the peak (4.7 GiB instead of 3.4 GiB)
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
        self._lu = None
        try:
            self._lu = spla.splu(self._matrix.tocsc(), permc_spec="MMD_AT_PLUS_A")
        except RuntimeError as exc:  # SuperLU reports exact singularity this way
            raise SingularMatrixError(str(exc)) from exc
        self._pivoted_on_diagonal = False

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self._lu is None:
            raise RuntimeError("factorize() must be called before solve()")
        x = self._lu.solve(rhs)
        if self._pivoted_on_diagonal and not self._checked:
            # small pivots spoil every solve with these factors alike: checking the first is
            # enough (CG with these factors as preconditioner solves with them many times)
            self._checked = True
            residual = np.linalg.norm(self._matrix @ x - rhs)
            if not residual <= DIAGONAL_PIVOTING_RESIDUAL * np.linalg.norm(rhs):
                self._partial_pivoting()
                x = self._lu.solve(rhs)
        return finite_solution(x)


class CholmodSolver:
    """CHOLMOD supernodal Cholesky; indefinite matrices go to ``fallback`` (SuperLU), unless
    the caller asks for a definite factorisation only (``definite=True``: it has a definite
    matrix to try instead, as globalised Newton has the projected tangent), when they raise
    :class:`IndefiniteMatrixError`. Ordering: approximate minimum degree (its analysis costs
    0.05 s on the 100k-triangle hypar against nested dissection's 0.25 s, for a factorisation
    0.31 s instead of 0.24 s: with factorisations reused, the analysis weighs more)."""

    name = "cholmod"
    #: a factorisation costs about 15 solves (0.24–0.31 s against 0.017 s)
    reuse_iterations = 12

    def __init__(self, fallback: LinearSolver | None = None) -> None:
        from sksparse import cholmod

        self._cholmod = cholmod
        self._factor = None
        self._pattern: tuple | None = None
        self._fallback = fallback or SuperLUSolver()
        self._use_fallback = False

    def factorize(self, matrix: sp.csr_matrix, definite: bool = False) -> None:
        csc = matrix.tocsc()
        pattern = sparsity_pattern(csc)  # the analysis holds for this sparsity pattern only
        self._use_fallback = False
        try:
            if self._factor is None or not same_pattern(self._pattern, pattern):
                self._factor = self._cholmod.analyze(
                    csc, mode="supernodal", ordering_method=CHOLMOD_ORDERING
                )
                self._pattern = pattern
            self._factor.cholesky_inplace(csc)
        except self._cholmod.CholmodNotPositiveDefiniteError as exc:
            if definite:
                raise IndefiniteMatrixError(str(exc)) from exc
            self._use_fallback = True
            self._fallback.factorize(matrix)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self._use_fallback:
            return self._fallback.solve(rhs)
        if self._factor is None:
            raise RuntimeError("factorize() must be called before solve()")
        return finite_solution(self._factor(rhs))


def unsymmetric_factorizer(
    name: str | None = None,
) -> Callable[[sp.spmatrix], Callable[[np.ndarray], np.ndarray]] | None:
    """A function from a sparse unsymmetric matrix to its solver ``rhs ↦ x`` on the back end
    ``name`` (``None``: the fastest available): PARDISO's LU (:class:`PardisoLU`); ``None``
    for back ends without an unsymmetric factorisation (the caller keeps its SuperLU)."""
    name = available_solvers()[0] if name is None else name
    if name != PardisoSolver.name or name not in available_solvers():
        return None
    return lambda matrix: PardisoLU(matrix).solve


def _importable(module: str) -> bool:
    from importlib.util import find_spec

    return find_spec(module) is not None


#: CHOLMOD's fill-reducing ordering (see :class:`CholmodSolver`).
CHOLMOD_ORDERING = "amd"

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


def get_solver(
    name: str | None = None, own_factors: bool = False, many_solves: bool = False
) -> LinearSolver:
    """A new solver by name; ``None`` picks the fastest available one. ``own_factors``: its
    factors are its own while other solvers factorise (PARDISO's solvers of one thread share a
    handle, and one factorises again after another did; this one has a handle of its own).
    ``many_solves``: each factorisation will serve many solves (PARDISO then orders by nested
    dissection, :class:`PardisoSolver`)."""
    name = _installed(name)
    if name == PardisoSolver.name and (own_factors or many_solves):
        return PardisoSolver(own_factors=own_factors, many_solves=many_solves)
    return _SOLVERS[name]()


def solver_family(name: str | None = None, many_solves: bool = False) -> Callable[[], LinearSolver]:
    """A maker of solvers (by ``name``, as :func:`get_solver`) that share one handle of their
    own, apart from every other solver's: each keeps its matrix and factorises it again where
    another of the family has factorised since, and the family's symbolic analysis of a
    sparsity pattern serves all its members (the states an optimiser linearises, one after
    another, while erections factorise their own tangents between them)."""
    name = _installed(name)
    if name != PardisoSolver.name:
        return _SOLVERS[name]
    state = own_pardiso_state(None)  # given back when the maker and its solvers are gone
    return lambda: PardisoSolver(many_solves=many_solves, state=state)


def _installed(name: str | None) -> str:
    """``name`` if it is an installed solver's (None: the fastest installed), else ValueError."""
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
    return name


def solver_choice(requested: str | None, used: str) -> str:
    """Why ``used`` solved: the words a summary or report gives."""
    if requested is not None:
        return f"{used}, as asked"
    others = [name for name in available_solvers() if name != used]
    rest = f"; also installed: {', '.join(others)}" if others else ""
    return f"{used}, the fastest installed{rest}"
