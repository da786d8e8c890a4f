"""The erections of an optimiser's trial patterns, started where the last erection leaves off.

A trial of :mod:`vares.analysis.erection_optimum` changes the patterns by a step whose
linearised effect on the erected state is known (``dx* = −K⁻¹ (∂R/∂X) ΔX``, one solve with the
tangent ``K`` of the accepted state, factorised for the step's adjoint anyway). Its erection
starts from that prediction and solves its Newton steps by conjugate gradients preconditioned by
that same factorisation (:meth:`vares.solver.reuse.ReusingSolver.prime`: inexact Newton), as
long as conjugate gradients reach the forcing term within a few iterations; where they do not,
the trial's own tangent is factorised as in any erection.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ACCEPTANCE_ACCURACY", "PRIMED_ITERATIONS", "TRIAL_TOLERANCE", "predicted_positions"]

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


def predicted_positions(points: np.ndarray, free: np.ndarray, dx: np.ndarray) -> np.ndarray:
    """Erected positions ``points`` ``(n, 3)`` moved by the linearised change ``dx`` of their
    ``free`` dofs (indices into ``points.reshape(-1)``)."""
    x = np.array(points, dtype=float)
    x.reshape(-1)[free] += dx
    return x
