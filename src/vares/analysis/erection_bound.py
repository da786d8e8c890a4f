"""The bound on the erected shape's deviation from the design, held by the optimiser of
:mod:`vares.analysis.erection_optimum` rather than only penalised.

The bound ``b`` is on every node's **normal deviation** ``d_i`` (its displacement along the
design surface's normal there, :attr:`~vares.analysis.erection.ErectionResult.normal_deviation`:
the quantity whose largest value :meth:`~vares.analysis.erection.ErectionResult.deviation`
reports as ``max``). The objective's penalty on the excess ``|d_i| − b`` alone does not hold it:
the least of the penalised objective lies beyond the bound wherever the forces gain by moving the
shape (on the panels of docs/erection.md 1.53–1.58 × the VaReS erection's largest deviation for a
bound of 1.5 ×). Three rules of the step hold it:

- *Nodes at the bound held there* (an active set). A node within :data:`AT_BOUND` of the bound
  that a Levenberg–Marquardt step would move outwards, by the linearised deviations of the step
  (``d + n·dx*``, ``dx*`` the erected positions' predicted change), is held where it is: the
  step is solved again on the null space of the constraints ``∂d_i/∂X ΔX = 0`` (``∂d_i/∂X =
  −(∂R/∂X)ᵀ K⁻¹ n_i``, one solve with the erection tangent per node; :class:`HeldNodes`), so
  the step slides along the bound instead of being stopped by it.
- *Steps cut at the bound.* The step (already cut to the trust region) is cut further to the
  largest fraction of it whose linearised deviations stay within ``b``.
- *Step acceptance.* A trial whose erected largest deviation exceeds ``b`` by more than
  :data:`BOUND_TOLERANCE` of it (the linearisation's error) is refused whatever its objective,
  and tried again half as long; a start beyond the bound is never moved further beyond it. So
  every accepted state, the optimum included, lies within the bound to that tolerance.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse.linalg as spla

__all__ = ["AT_BOUND", "BOUND_TOLERANCE", "HeldNodes", "ShapeBound"]

#: The bound holds to this fraction of it: an accepted state's largest normal deviation is at
#: most ``b (1 + BOUND_TOLERANCE)``.
BOUND_TOLERANCE = 5e-3
#: A node whose normal deviation is within this fraction of the bound from it is at the bound.
AT_BOUND = 1e-2


class ShapeBound:
    """The bound ``b`` (length units) on the nodes' normal deviation, and the trials refused
    for breaking it."""

    def __init__(self, bound: float) -> None:
        self.bound = float(bound)
        self.limit = self.bound * (1.0 + BOUND_TOLERANCE)
        self.refused = 0

    def admits(self, trial_max: float, current_max: float) -> bool:
        """Whether a trial whose largest normal deviation is ``trial_max`` may be accepted from
        a state whose largest is ``current_max``: within the bound, or (from a start beyond
        it) no further beyond it."""
        return trial_max <= max(self.limit, current_max)

    def largest_step(self, deviation: np.ndarray, predicted: np.ndarray) -> float:
        """The largest fraction ``s ∈ [0, 1]`` of a step that takes the nodes' normal deviations
        from ``deviation`` to ``predicted`` (linearly) keeping every node within the bound that
        is within it now (a node beyond it, of a start beyond the bound, is not counted)."""
        inside = np.abs(deviation) <= self.bound
        d, change = deviation[inside], (predicted - deviation)[inside]
        room = np.where(change > 0, self.bound - d, self.bound + d)
        moving = np.abs(change) > 0
        if not moving.any():
            return 1.0
        return float(np.clip((room[moving] / np.abs(change[moving])).min(), 0.0, 1.0))


class HeldNodes:
    """The linearised constraints that hold nodes at the bound where they are, ``∂d_i/∂X ΔX =
    0``, in the variables ``y`` of the preconditioned least-squares step ``Δ = P_C M y`` (``M``
    the preconditioner, ``P_C`` the projection onto the seams' constraints): the projection of
    ``y`` onto their null space, ``y − Aᵀ (A Aᵀ)⁺ A y`` with the rows ``A = M P_C ∂d_i/∂X``."""

    def __init__(
        self,
        gradients: np.ndarray,
        project: Callable[[np.ndarray], np.ndarray],
        preconditioner: spla.LinearOperator | None,
    ) -> None:
        def metric(v):
            return v if preconditioner is None else preconditioner.matvec(v)

        self.A = np.array([metric(project(g)) for g in gradients])
        self._gram = np.linalg.pinv(self.A @ self.A.T, rcond=1e-10, hermitian=True)

    def project(self, y: np.ndarray) -> np.ndarray:
        """``y`` projected onto the null space of the constraints."""
        return y - self.A.T @ (self._gram @ (self.A @ y))
