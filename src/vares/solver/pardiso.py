"""MKL PARDISO through pypardiso: the symmetric indefinite solver of Newton's tangents
(:class:`PardisoSolver`, the fastest back end of :mod:`vares.solver.linear`, which chooses
among them), the handles that keep its symbolic analysis and factors, and its LU for
unsymmetric systems (:class:`PardisoLU`, Tutte's embedding)."""

from __future__ import annotations

import threading
import weakref
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .factorisation import (
    DIAGONAL_PIVOTING_RESIDUAL,
    SingularMatrixError,
    finite_solution,
    same_pattern,
    sparsity_pattern,
)

__all__ = [
    "NESTED_DISSECTION_ABOVE",
    "HandleState",
    "PardisoLU",
    "PardisoSolver",
    "PardisoState",
    "forget_pardiso_analysis",
    "own_pardiso_state",
]


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
            state = own_pardiso_state(self) if own_factors else _pardiso_state()
        self._state = state
        self._solver = self._state.handle
        self._matrix = None
        self._upper = None
        #: whether the last factorisation's first solve is still to be checked (PARDISO
        #: perturbed pivots)
        self._unchecked = False
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
        return (sparsity_pattern(self._matrix), self._settings(self._matrix.shape[0]))

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
        if self._upper is None or not same_pattern(self._upper[0], sparsity_pattern(matrix)):
            # the map of the thread's last pattern is kept: every erection of a mesh (and each
            # state an optimiser linearises) assembles a new matrix of the same pattern
            known = state.upper
            if known is None or not same_pattern(known[0], sparsity_pattern(matrix)):
                index, indptr, indices = _upper_triangle_map(matrix)
                ia, ja = (indptr + 1).astype(np.int32), (indices + 1).astype(np.int32)
                known = state.upper = (sparsity_pattern(matrix), index, indptr, indices, ia, ja)
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
        self._unchecked = self._solver.iparm[13] > 0  # iparm(14): perturbed pivots

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self._matrix is None:
            raise RuntimeError("factorize() must be called before solve()")
        rhs = np.ascontiguousarray(rhs, dtype=float)
        state = self._state
        if state.factors is not self:  # another solver factorised since: factorise again
            if not _analysed(state, self._analysis()):
                self._set(self._matrix.shape[0])
                self._phase(11, np.zeros(self._matrix.shape[0]))
                state.analysed = self._analysis()
            self._numeric()
        x = self._phase(33, rhs)
        if self._unchecked:
            self._unchecked = False
            x = self._checked(x, rhs)
        return finite_solution(x)

    def _checked(self, x: np.ndarray, rhs: np.ndarray) -> np.ndarray:
        """``x``, the first solve with factors whose pivots PARDISO perturbed (a saddle point's
        zero block), if its residual is within :data:`PERTURBED_RESIDUAL` of ``rhs``; else
        :class:`SingularMatrixError`: a badly scaled KKT system (seam matching in millimetres,
        before its rows were scaled) was solved to a relative residual of 2.3 without a word,
        and its Newton steps went astray. (SuperLU in its place took minutes on that system of
        74,873 unknowns: about three in one run, more than ten in another.)"""
        upper = self._matrix
        product = upper @ x + upper.T @ x - upper.diagonal() * x
        relative = np.linalg.norm(product - rhs) / np.linalg.norm(rhs)
        if not relative > PERTURBED_RESIDUAL:
            return x
        raise SingularMatrixError(
            f"PARDISO's solve with {self._solver.iparm[13]} perturbed pivots has a relative "
            f"residual of {relative:.2g}: the matrix is too badly conditioned"
        )


def _analysed(state: HandleState, analysis: tuple) -> bool:
    """Whether ``state``'s handle holds the symbolic analysis ``analysis`` (pattern, settings)."""
    known = state.analysed
    return known is not None and known[1] == analysis[1] and same_pattern(known[0], analysis[0])


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


def own_pardiso_state(owner: PardisoSolver | None) -> HandleState:
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
#: The relative residual above which a solve with perturbed pivots is refused (such solves of
#: the seam-matching KKT systems reach 5e-9 to 3e-8; a failed one was 2.3).
PERTURBED_RESIDUAL = 1e-6
#: PARDISO orders by parallel nested dissection above this many unknowns, else minimum degree.
NESTED_DISSECTION_ABOVE = 600_000


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
            return finite_solution(self._fallback.solve(rhs))
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
        return finite_solution(x)


#: PARDISO's iparm for :class:`PardisoLU` (1-based): own settings, minimum degree, no
#: iterative refinement unless pivots were perturbed, perturbation 1e-13, scaling and matching.
_PARDISO_LU_SETTINGS = {1: 1, 2: 0, 8: 0, 10: 13, 11: 1, 13: 1}
