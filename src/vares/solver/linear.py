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
import weakref
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Protocol

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

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


class SingularMatrixError(RuntimeError):
    """The tangent matrix is singular (to working precision)."""


class IndefiniteMatrixError(SingularMatrixError):
    """A solver for positive definite matrices was given another and asked not to pass it on
    to its (slower) fallback: the caller has a definite matrix to try instead."""


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
        return _finite(x)


#: Relative residual above which a solve with diagonal pivots is redone with partial pivoting.
DIAGONAL_PIVOTING_RESIDUAL = 1e-9


class PardisoSolver:
    """MKL PARDISO, real symmetric indefinite (upper triangle), via pypardiso.

    The symbolic analysis (phase 11) is redone only when the sparsity pattern changes; each
    factorisation is the numeric phase 22 alone. The instances of one thread share one PARDISO
    handle (its analysis and factors, :class:`PardisoState`); each thread has its own, so solves
    in several threads at once (a Dask worker's threads) do not disturb one another. With
    ``own_factors`` a solver has a handle of its own, given back to MKL when the solver is
    collected: its factors stay while the thread's other solvers factorise (a preconditioner
    beside a Newton iteration's tangent).

    Settings (chosen by measurement, docs/benchmarks.md): minimum-degree ordering below
    :data:`NESTED_DISSECTION_ABOVE` unknowns (its analysis is 3× faster and its fill no larger
    on surface meshes), parallel nested dissection above; for a solver whose factors serve many
    solves each (``many_solves``: an optimiser's adjoint products, a preconditioner) nested
    dissection and the two-level factorisation, whose solves are 25–50 % faster
    (:meth:`_settings`); Bunch–Kaufman pivoting with pivots
    perturbed below 1e-8 (PARDISO refines a solve itself when it perturbed one); no scaling or
    matching (the tangent is symmetric and well scaled).
    """

    name = "pardiso"
    #: a factorisation costs about four solves (0.06 s against 0.015 s) on the 100k hypar: it
    #: stands in for a later one within three conjugate-gradient iterations, and only cautiously
    #: (:data:`vares.solver.reuse.CAUTIOUS_BELOW`)
    reuse_iterations = 3
    cautious_reuse = True

    def __init__(
        self, own_factors: bool = False, many_solves: bool = False, state: HandleState | None = None
    ) -> None:
        if state is None:
            state = _own_pardiso_state(self) if own_factors else _pardiso_state()
        self._state = state
        self._solver = self._state.handle
        self._matrix = None
        self._upper = None
        self._many_solves = many_solves

    def _settings(self, size: int) -> tuple[int, int]:
        """PARDISO's ``iparm(2)`` and ``iparm(24)`` for a matrix of ``size`` unknowns (class
        docs). ``iparm(2)``: 0 minimum degree, 3 parallel nested dissection, 2 METIS' nested
        dissection for ``many_solves`` (0.26 s for either analysis of the 50k erection tangent).
        ``iparm(24)`` 1, the two-level factorisation, for ``many_solves``: with nested
        dissection its solves are 25–50 % faster than minimum degree's, and the same bits from
        one factorisation of a matrix to the next (with the classic factorisation they differed
        in round-off, and an optimisation's steps with them; tests/test_linear.py)."""
        ordering = 3 if size > NESTED_DISSECTION_ABOVE else (2 if self._many_solves else 0)
        return ordering, (1 if self._many_solves else 0)

    def _set(self, size: int) -> None:
        """Set this solver's :meth:`_settings` on its handle (shared with other solvers)."""
        self._solver.iparm[1], self._solver.iparm[23] = self._settings(size)

    def _analysis(self) -> tuple:
        """What a handle's symbolic analysis depends on: the pattern and the settings."""
        return (_pattern(self._matrix), self._settings(self._matrix.shape[0]))

    def _phase(self, phase: int, rhs: np.ndarray) -> np.ndarray:
        """One call of PARDISO on the current upper triangle (its 1-based index arrays are made
        once per pattern, not per call)."""
        import ctypes

        solver = self._solver
        x = np.zeros_like(rhs)
        error = ctypes.c_int32(0)
        int_p, float_p = ctypes.POINTER(ctypes.c_int32), ctypes.POINTER(ctypes.c_double)
        upper = self._matrix
        solver._mkl_pardiso(
            solver.pt.ctypes.data_as(ctypes.POINTER(solver._pt_type[0])),
            ctypes.byref(ctypes.c_int32(1)),  # maxfct
            ctypes.byref(ctypes.c_int32(1)),  # mnum
            ctypes.byref(ctypes.c_int32(solver.mtype)),
            ctypes.byref(ctypes.c_int32(phase)),
            ctypes.byref(ctypes.c_int32(upper.shape[0])),
            upper.data.ctypes.data_as(float_p),
            self._ia.ctypes.data_as(int_p),
            self._ja.ctypes.data_as(int_p),
            solver.perm.ctypes.data_as(int_p),
            ctypes.byref(ctypes.c_int32(1)),  # one right-hand side
            solver.iparm.ctypes.data_as(int_p),
            ctypes.byref(ctypes.c_int32(0)),  # no messages
            rhs.ctypes.data_as(float_p),
            x.ctypes.data_as(float_p),
            ctypes.byref(error),
        )
        if error.value != 0:
            raise SingularMatrixError(f"PARDISO error {error.value}")
        return x

    def factorize(self, matrix: sp.csr_matrix, definite: bool = False) -> None:
        state = self._state
        size = matrix.shape[0]
        if self._upper is None or not _same_pattern(self._upper[0], _pattern(matrix)):
            # the map of the thread's last pattern is kept: every erection of a mesh (and each
            # state an optimiser linearises) assembles a new matrix of the same pattern
            known = state.upper
            if known is None or not _same_pattern(known[0], _pattern(matrix)):
                index, indptr, indices = _upper_triangle_map(matrix)
                ia, ja = (indptr + 1).astype(np.int32), (indices + 1).astype(np.int32)
                known = state.upper = (_pattern(matrix), index, indptr, indices, ia, ja)
            self._upper, self._ia, self._ja = known[:4], known[4], known[5]
        _, index, indptr, indices = self._upper
        # PARDISO needs every diagonal entry stored, even a zero one (a bordered constraint):
        # the map's index -1 is such an added zero
        data = np.append(matrix.data, 0.0)[index]
        self._matrix = sp.csr_matrix((data, indices, indptr), shape=matrix.shape)
        if not _analysed(state, self._analysis()):
            state.analysed = None
            self._set(size)
            self._phase(11, np.zeros(size))
            state.analysed = self._analysis()
        self._numeric()

    def _numeric(self) -> None:
        """The numeric factorisation of this solver's matrix into its handle."""
        empty = np.zeros(self._matrix.shape[0])
        self._set(len(empty))  # (the handle's other solvers may have other settings)
        self._phase(22, empty)
        self._state.factors = self
        if self._solver.iparm[29] != 0:  # iparm(30): a zero pivot
            raise SingularMatrixError("PARDISO found a zero pivot")

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self._matrix is None:
            raise RuntimeError("factorize() must be called before solve()")
        state = self._state
        if state.factors is not self:  # another solver factorised since: factorise again
            if not _analysed(state, self._analysis()):
                self._set(self._matrix.shape[0])
                self._phase(11, np.zeros(self._matrix.shape[0]))
                state.analysed = self._analysis()
            self._numeric()
        return _finite(self._phase(33, np.ascontiguousarray(rhs, dtype=float)))


def _analysed(state: HandleState, analysis: tuple) -> bool:
    """Whether ``state``'s handle holds the symbolic analysis ``analysis`` (pattern, settings)."""
    known = state.analysed
    return known is not None and known[1] == analysis[1] and _same_pattern(known[0], analysis[0])


class HandleState:
    """A PARDISO handle (made when first needed; MKL itself is loaded once per process), the
    sparsity pattern and ordering it has analysed (see :func:`_pattern`), the solver whose
    numeric factors it holds (a solver whose matrix was factorised by another since factorises
    it again before it solves), the upper-triangle map of the last sparsity pattern factorised
    (:func:`_upper_triangle_map`), and for a solver's own handle, what gives its memory back."""

    handle = None
    analysed: tuple | None = None
    factors: PardisoSolver | None = None
    upper: tuple | None = None
    release: weakref.finalize | None = None


class PardisoState(HandleState, threading.local):
    """A thread's :class:`HandleState`, shared by the thread's solvers."""


_PARDISO_STATE = PardisoState()


def _pardiso_state() -> PardisoState:
    state = _PARDISO_STATE
    if state.handle is None:
        state.handle = _pardiso_handle()
    return state


def _own_pardiso_state(owner: PardisoSolver | None) -> HandleState:
    """A PARDISO handle for ``owner`` alone (its factors stay while the thread's handle
    factorises other matrices), its memory given back to MKL when ``owner`` is collected
    (``None``: when the state itself is, its solvers keeping it)."""
    state = HandleState()
    state.handle = _pardiso_handle()
    keeper = state if owner is None else owner
    state.release = weakref.finalize(keeper, state.handle.free_memory, everything=True)
    return state


def _pardiso_handle():
    _point_pypardiso_at_mkl()
    import pypardiso

    handle = pypardiso.PyPardisoSolver(mtype=-2)
    handle.set_statistical_info_off()
    for index, value in _PARDISO_SETTINGS.items():
        handle.iparm[index - 1] = value
    return handle


def forget_pardiso_analysis() -> None:
    """Forget the symbolic analysis this thread's PARDISO handle keeps (the next
    factorisation analyses its matrix afresh, as in a new process)."""
    _PARDISO_STATE.analysed = None


def _point_pypardiso_at_mkl() -> None:
    """Tell pypardiso where MKL's runtime library is when it lies where MKL's wheel puts it.
    Left to itself, pypardiso searches the whole environment for it, twice (0.6 s each with a
    few hundred packages installed: most of a small roof's run)."""
    import os
    import site
    import sys

    if os.environ.get("PYPARDISO_MKL_RT"):
        return
    for base in (sys.prefix, site.USER_BASE):
        for folder, pattern in (("lib", "libmkl_rt.so*"), ("Library/bin", "mkl_rt*.dll")):
            found = sorted(Path(base, folder).glob(pattern), key=lambda path: len(path.name))
            if found:
                os.environ["PYPARDISO_MKL_RT"] = str(found[0])
                return


def _upper_triangle_map(matrix: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The upper triangle of a CSR matrix with every diagonal entry stored, its columns sorted
    in every row: ``(index, indptr, indices)`` where ``upper.data = append(matrix.data,
    0)[index]``."""
    n = matrix.shape[0]
    rows = np.repeat(np.arange(n), np.diff(matrix.indptr))
    keep = np.flatnonzero(matrix.indices >= rows)
    has_diagonal = np.zeros(n, dtype=bool)
    has_diagonal[rows[keep][matrix.indices[keep] == rows[keep]]] = True
    missing = np.flatnonzero(~has_diagonal)
    indptr = np.zeros(n + 1, dtype=np.int64)
    if not missing.size and matrix.has_sorted_indices:  # the kept entries in order already
        np.cumsum(np.bincount(rows[keep], minlength=n), out=indptr[1:])
        return keep, indptr, matrix.indices[keep]
    all_rows = np.concatenate([rows[keep], missing])
    all_cols = np.concatenate([matrix.indices[keep], missing])
    source = np.concatenate([keep, np.full(missing.size, -1)])
    order = np.lexsort((all_cols, all_rows))
    np.cumsum(np.bincount(all_rows, minlength=n), out=indptr[1:])
    return source[order], indptr, all_cols[order]


#: PARDISO's iparm (1-based as in its manual): own settings, minimum-degree ordering (changed
#: per matrix), no iterative refinement unless pivots were perturbed, perturbation 1e-8, no
#: scaling, no matching, Bunch–Kaufman pivoting.
_PARDISO_SETTINGS = {1: 1, 2: 0, 8: 0, 10: 8, 11: 0, 13: 0, 21: 1}
#: PARDISO orders by parallel nested dissection above this many unknowns, else minimum degree.
NESTED_DISSECTION_ABOVE = 600_000


def _pattern(matrix: sp.csr_matrix) -> tuple:
    """A CSR matrix's sparsity pattern ``(shape, indptr, indices)``, without its values."""
    return matrix.shape, matrix.indptr, matrix.indices


def _same_pattern(a: tuple, b: tuple) -> bool:
    if a[0] == b[0] and a[1] is b[1] and a[2] is b[2]:  # one assembler's arrays: no comparison
        return True
    return (
        a[0] == b[0]
        and a[2].size == b[2].size
        and np.array_equal(a[1], b[1])
        and np.array_equal(a[2], b[2])
    )


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
        pattern = _pattern(csc)  # the analysis holds for this sparsity pattern only
        self._use_fallback = False
        try:
            if self._factor is None or not _same_pattern(self._pattern, pattern):
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
        return _finite(self._factor(rhs))


class PardisoLU:
    """MKL PARDISO's LU of a real unsymmetric matrix (``mtype`` 11) with a handle of its own,
    given back to MKL when the object is collected: for the one-off systems of the flattenings
    that are not symmetric (Tutte's mean-value weights). Minimum-degree ordering, MKL's
    scaling and matching for unsymmetric matrices, pivots perturbed below 1e-13. A first solve
    whose residual exceeds :data:`DIAGONAL_PIVOTING_RESIDUAL` of the right-hand side is redone
    by SuperLU with partial pivoting (as every later one then is). On the face and camel-head
    scans' Tutte systems (26k and 11k unknowns) factorisation and solve took 0.04 and 0.02 s
    against SuperLU's 0.22–0.31 and 0.09 s (docs/benchmarks.md)."""

    def __init__(self, matrix: sp.spmatrix) -> None:
        _point_pypardiso_at_mkl()
        import pypardiso

        self._matrix = sp.csr_matrix(matrix)
        self._matrix.sort_indices()
        handle = pypardiso.PyPardisoSolver(mtype=11)
        handle.set_statistical_info_off()
        for index, value in _PARDISO_LU_SETTINGS.items():
            handle.set_iparm(index, value)
        self._handle = handle
        self._release = weakref.finalize(self, handle.free_memory, everything=True)
        self._fallback = None
        self._checked = False
        handle.factorize(self._matrix)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        rhs = np.ascontiguousarray(rhs, dtype=float)
        if self._fallback is not None:
            return _finite(self._fallback.solve(rhs))
        x = self._handle.solve(self._matrix, rhs)
        if not self._checked:
            self._checked = True
            residual = np.linalg.norm(self._matrix @ x - rhs)
            if not residual <= DIAGONAL_PIVOTING_RESIDUAL * np.linalg.norm(rhs):
                self._release()
                try:
                    self._fallback = spla.splu(self._matrix.tocsc(), permc_spec="MMD_AT_PLUS_A")
                except RuntimeError as exc:
                    raise SingularMatrixError(str(exc)) from exc
                x = self._fallback.solve(rhs)
        return _finite(x)


#: PARDISO's iparm for :class:`PardisoLU` (1-based): own settings, minimum degree, no
#: iterative refinement unless pivots were perturbed, perturbation 1e-13, scaling and matching.
_PARDISO_LU_SETTINGS = {1: 1, 2: 0, 8: 0, 10: 13, 11: 1, 13: 1}


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
    state = _own_pardiso_state(None)  # given back when the maker and its solvers are gone
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
