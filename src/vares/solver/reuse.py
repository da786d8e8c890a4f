"""Newton systems solved to the accuracy Newton's method needs, reusing a factorisation.

Far from the solution a Newton step need not be exact: inexact Newton solves ``K Δx = −r`` only
until the linear residual is a fraction ``η`` (the *forcing term*, :func:`forcing_term`) of
``‖r‖``, and keeps a quadratic end when ``η`` shrinks with ``‖r‖`` (Eisenstat & Walker 1996).
The tangents of successive iterations differ little (the strains of a pattern are small), so
the factorisation of an earlier one is an excellent preconditioner for conjugate gradients on
the next: on the 100k-triangle hypar each CG iteration cuts the error tenfold, and a Newton
step needs two to four of them instead of a new factorisation. For back ends whose
factorisation costs many solves (CHOLMOD, SuperLU: 15–30 solves) that replaces all but the
first factorisation; PARDISO factorises in about four solves' time and reuses its
factorisation only cautiously (:data:`CAUTIOUS_BELOW`), at Newton's fast end
(docs/benchmarks.md).

Conjugate gradients are written out here rather than taken from SciPy: the iteration must stop
as soon as it meets a direction of non-positive curvature (an indefinite tangent must be
factorised, not iterated on) or its rate shows it would overrun the budget.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from .linear import LinearSolver

__all__ = [
    "CAUTIOUS_BELOW",
    "ETA_MAX",
    "ETA_MAX_KINKED",
    "ReusingSolver",
    "forcing_term",
    "preconditioned_cg",
]

#: The loosest relative accuracy a Newton step is solved to (a smooth energy's).
ETA_MAX = 0.1
#: … of an energy with kinks (the erection's tension field): where cells switch between taut,
#: wrinkled and slack the residual barely falls for many iterations and the forcing term sits
#: at its cap; steps solved to 0.1 then took 1.3–2× the iterations (and 1.4–1.6× the time) of
#: steps solved to 1e-3 with SuperLU (docs/erection.md), which cost a few CG iterations more.
ETA_MAX_KINKED = 1e-3
#: A back end whose factorisation costs few solves (``cautious_reuse``: PARDISO) reuses it only
#: for steps asked to better than this (Newton's fast end, where the tangents barely move), only
#: for a tangent of the kind it factorised (exact or projected), and never again in a sequence
#: once conjugate gradients failed. The 100k hypar's last two Newton steps then take 3 and 1
#: conjugate-gradient iterations instead of two factorisations (docs/benchmarks.md).
CAUTIOUS_BELOW = 0.05


def forcing_term(residuals: list[float], tolerance: float, loosest: float = ETA_MAX) -> float:
    """How accurately (relative linear residual) to solve the next Newton step, from the
    residual norms of this Newton iteration so far (the last is the current one).

    Eisenstat and Walker's second choice, ``η = 0.9 (‖r_k‖ / ‖r_{k−1}‖)²``, at most
    ``loosest`` (:data:`ETA_MAX`, which makes their safeguard against a sudden drop, active
    above ``η_{k−1} = 1/3``, moot; :data:`ETA_MAX_KINKED` for an energy with kinks), and never
    tighter than half the ``tolerance`` (an absolute residual) asks of the next iterate;
    ``loosest`` at the first iteration.
    """
    current = residuals[-1]
    if len(residuals) < 2 or residuals[-2] <= 0:
        eta = loosest
    else:
        eta = 0.9 * (current / residuals[-2]) ** 2
    if current > 0:
        eta = max(eta, 0.5 * tolerance / current)
    return min(eta, loosest)


def preconditioned_cg(
    matrix: sp.spmatrix,
    rhs: np.ndarray,
    preconditioner,
    rtol: float,
    budget: int,
    constraint: np.ndarray | None = None,
) -> tuple[np.ndarray | None, int]:
    """Conjugate gradients from zero on ``matrix x = rhs`` preconditioned by ``preconditioner``
    (a function applying an approximate inverse) until ``‖rhs − matrix x‖ ≤ rtol ‖rhs‖``.

    With a unit ``constraint`` ``c`` the solution is sought where ``cᵀx = 0``: the
    preconditioner must return such vectors (a factorisation of the matrix bordered by ``c``
    does), and the residual is kept less its component along ``c`` (the constraint's free
    reaction): constraint-preconditioned CG with the residual projected at every iteration, as
    Gould, Hribar & Nocedal (2001) advise against round-off.

    Returns ``(x, iterations)``, or ``(None, iterations)`` when it gives up: a direction of
    non-positive curvature (the matrix or the preconditioner is not positive definite), more
    than ``budget`` iterations, or a rate of convergence that would need more than that.
    """

    def projected(r: np.ndarray) -> np.ndarray:  # less the constraint's (free) reaction
        return r if constraint is None else r - constraint * (constraint @ r)

    r = projected(rhs)
    norm = float(np.linalg.norm(r))
    if norm == 0.0:
        return np.zeros_like(rhs), 0
    x = np.zeros_like(rhs)
    z = preconditioner(r)
    p = z.copy()
    rz = float(r @ z)
    if not rz > 0:
        return None, 0
    first = None
    for iteration in range(1, budget + 1):
        q = matrix @ p
        curvature = float(p @ q)
        if not curvature > 0:
            return None, iteration
        alpha = rz / curvature
        x += alpha * p
        r = projected(r - alpha * q)  # projected every time: no round-off along c builds up
        relative = float(np.linalg.norm(r)) / norm
        if relative <= rtol:
            return x, iteration
        first = relative if first is None else first
        if iteration >= 3:  # from the mean rate so far, the iterations still needed
            rate = (relative / first) ** (1.0 / (iteration - 1))
            if rate >= 1.0 or iteration + math.log(rtol / relative) / math.log(rate) > budget:
                return None, iteration
        z = preconditioner(r)
        rz_next = float(r @ z)
        if not rz_next > 0:
            return None, iteration
        p = z + (rz_next / rz) * p
        rz = rz_next
    return None, budget


class ReusingSolver:
    """A :class:`~vares.solver.linear.LinearSolver` used for a sequence of Newton systems of one
    size: :meth:`solve` with a tolerance first tries conjugate gradients preconditioned by the
    last factorisation, within the back end's ``reuse_iterations`` (0: never); it factorises
    the matrix when that fails or when an exact solution is asked for. Counts its work.

    :meth:`prime` gives it, before its first factorisation, a preconditioner from elsewhere (a
    solve with the factorisation of a nearby matrix of the same size): the first systems are
    tried with that one, until one needs more than its budget or a factorisation is made."""

    def __init__(self, solver: LinearSolver) -> None:
        self.solver = solver
        self.budget = solver.reuse_iterations
        self._size: int | None = None
        self._primer: Callable[[np.ndarray], np.ndarray] | None = None
        self._primer_budget = 0
        self._definite = False  # of the matrix factorised last (Newton's exact tangents: True)
        #: numeric factorisations and conjugate-gradient iterations so far (failed ones too)
        self.factorisations = 0
        self.cg_iterations = 0

    def prime(self, preconditioner: Callable[[np.ndarray], np.ndarray], budget: int) -> None:
        """Precondition the systems before the first factorisation by ``preconditioner``, at
        most ``budget`` conjugate-gradient iterations each (0: not at all)."""
        self._primer, self._primer_budget = (preconditioner if budget > 0 else None), budget

    def solve(
        self,
        matrix: sp.spmatrix,
        rhs: np.ndarray,
        rtol: float = 0.0,
        definite: bool = False,
        constraint: np.ndarray | None = None,
    ) -> np.ndarray:
        """``matrix⁻¹ rhs``, to relative residual ``rtol`` (0: as exactly as the factorisation
        solves it). ``definite``: rather :class:`~vares.solver.linear.IndefiniteMatrixError`
        than a slow fallback when the back end factorises definite matrices only. With a unit
        ``constraint`` ``c``: the solution with ``cᵀx = 0``, from the matrix bordered by ``c``
        (a saddle point, factorised as it is; its factorisation preconditions later ones)."""
        size = matrix.shape[0] + (constraint is not None)

        def solve(r: np.ndarray) -> np.ndarray:  # the last factorisation, as a preconditioner
            if constraint is None:
                return self.solver.solve(r)
            return self.solver.solve(np.append(r, 0.0))[:-1]

        if rtol > 0 and self._primer is not None and constraint is None:
            x, iterations = preconditioned_cg(matrix, rhs, self._primer, rtol, self._primer_budget)
            self.cg_iterations += iterations
            if x is not None:
                return x
            self._primer = None  # the systems have moved too far from the primer's matrix
        cautious = getattr(self.solver, "cautious_reuse", False)
        reusable = not cautious or (rtol <= CAUTIOUS_BELOW and definite == self._definite)
        if rtol > 0 and reusable and self.budget > 0 and self._size == size:
            x, iterations = preconditioned_cg(matrix, rhs, solve, rtol, self.budget, constraint)
            self.cg_iterations += iterations
            if x is not None:
                return x
            if cautious:
                self.budget = 0  # the tangents move too much: factorise from now on
        if constraint is None:
            return self.exact(matrix, rhs, definite)
        column = sp.csr_matrix(constraint[:, None])
        bordered = sp.bmat([[matrix, column], [column.T, None]], format="csr")
        return self.exact(bordered, np.append(rhs, 0.0))[:-1]

    def exact(self, matrix: sp.spmatrix, rhs: np.ndarray, definite: bool = False) -> np.ndarray:
        """Factorise ``matrix`` (it becomes the preconditioner of later solves) and solve."""
        self._size, self._primer = None, None
        self.factorisations += 1
        self.solver.factorize(matrix, definite=definite)
        self._size, self._definite = matrix.shape[0], definite
        return self.solver.solve(rhs)
