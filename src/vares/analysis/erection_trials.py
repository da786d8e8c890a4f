"""The erections of an optimiser's trial patterns, started where the last erection leaves off.

A trial of :mod:`vares.analysis.erection_optimum` changes the patterns by a step whose
linearised effect on the erected state is known (``dx* = −K⁻¹ (∂R/∂X) ΔX``, one solve with the
tangent ``K`` of the accepted state, factorised for the step's adjoint anyway). Its erection
starts from that prediction and solves its Newton steps by conjugate gradients preconditioned by
that same factorisation (:class:`PrimedSolver`: inexact Newton, :mod:`vares.solver.reuse`), as
long as conjugate gradients reach the forcing term within a few iterations; where they do not,
the trial's own tangent is factorised as in any erection.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from ..solver.reuse import ReusingSolver, preconditioned_cg

__all__ = ["ACCEPTANCE_ACCURACY", "TRIAL_TOLERANCE", "PrimedSolver", "predicted_positions"]

#: A trial's erection is solved only as accurately as the test of its objective needs: to a
#: residual ``R`` whose effect on the objective, at most ``2 |g| |R|`` to first order
#: (:meth:`~vares.analysis.erection_residuals.ResidualModel.equilibrium_sensitivity`), is at
#: most this fraction of the step's predicted decrease; at most to the relative residual
#: TRIAL_TOLERANCE (the bound is first order), at least to the solver's tolerance. The optimum
#: is erected again to the solver's tolerance at the end. On the 1.5k and 10k hypars the bound
#: was 10–100 × the objective's actual error from erections stopped at 1e-7 … 1e-4.
ACCEPTANCE_ACCURACY = 0.05
TRIAL_TOLERANCE = 1e-6

#: Conjugate-gradient iterations preconditioned by the accepted state's factorisation that may
#: stand in for a factorisation of a trial's tangent: PARDISO factorises the erection tangent of
#: the 1.5k, 10k and 50k hypars in the CPU time of 37, 14 and 11 of its solves (docs/erection.md).
PRIMED_ITERATIONS = 6


class PrimedSolver:
    """The Newton systems of one erection (what :class:`~vares.solver.reuse.ReusingSolver`
    does, which it wraps), solved first by conjugate gradients preconditioned by ``primer`` (a
    solve with the factorisation of a nearby tangent over the same free dofs) within ``budget``
    iterations; the first system that needs more gives it up, and from then on ``systems``
    solves as in any erection. Counts its work as ``systems`` does (``factorisations``,
    ``cg_iterations``)."""

    def __init__(
        self,
        systems: ReusingSolver,
        primer: Callable[[np.ndarray], np.ndarray] | None,
        budget: int | None = None,
    ) -> None:
        self.budget = PRIMED_ITERATIONS if budget is None else budget
        self.systems, self.primer = systems, primer if self.budget > 0 else None
        self.solver = systems.solver
        self.primed_iterations = 0

    @property
    def factorisations(self) -> int:
        return self.systems.factorisations

    @property
    def cg_iterations(self) -> int:
        return self.systems.cg_iterations + self.primed_iterations

    def solve(
        self,
        matrix: sp.spmatrix,
        rhs: np.ndarray,
        rtol: float = 0.0,
        definite: bool = False,
        constraint: np.ndarray | None = None,
    ) -> np.ndarray:
        """``matrix⁻¹ rhs`` to relative residual ``rtol`` (:meth:`ReusingSolver.solve`)."""
        if self.primer is not None and rtol > 0 and constraint is None:
            x, iterations = preconditioned_cg(matrix, rhs, self.primer, rtol, self.budget)
            self.primed_iterations += iterations
            if x is not None:
                return x
            self.primer = None  # the trial has moved too far from the accepted state
        return self.systems.solve(matrix, rhs, rtol, definite, constraint)

    def exact(self, matrix: sp.spmatrix, rhs: np.ndarray, definite: bool = False) -> np.ndarray:
        self.primer = None
        return self.systems.exact(matrix, rhs, definite)


def predicted_positions(points: np.ndarray, free: np.ndarray, dx: np.ndarray) -> np.ndarray:
    """Erected positions ``points`` ``(n, 3)`` moved by the linearised change ``dx`` of their
    ``free`` dofs (indices into ``points.reshape(-1)``)."""
    x = np.array(points, dtype=float)
    x.reshape(-1)[free] += dx
    return x
