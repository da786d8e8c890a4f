"""The Newton steps other than the line search's (:mod:`.line_search`): a plain step, an exact
step shortened to keep every cell admissible, and a Levenberg–Marquardt step, each from the
tangent ``matrix`` and the residual of one iteration of :func:`vares.solver.newton.newton`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .failure import Failure, describe_cells
from .linear import SingularMatrixError

__all__ = ["Damping", "bounded_step", "damped_step", "full_step", "plain_step"]


@dataclass
class Damping:
    """State of the damped iteration: the coefficient ``c`` and how fast it grows on rejection."""

    factor: float
    c: float | None = None
    growth: float = 2.0

    def cap(self, matrix: sp.csr_matrix, residual: float, initial_residual: float) -> None:
        scale = self.factor * float(np.mean(np.abs(matrix.diagonal())))
        cap = scale * min(1.0, residual / initial_residual) if initial_residual > 0 else scale
        self.c = cap if self.c is None else min(self.c, cap)

    def reject(self) -> None:
        self.c, self.growth = self.c * self.growth, 2.0 * self.growth


def plain_step(method: str, problem, x, ctx, matrix, residual_vector, eta, energy, damping):
    """The step of ``method`` (``"full"``, ``"bounded"`` or ``"damped"``): ``(new point, step
    length, tangent used)``."""
    if method == "full":
        return full_step(problem, x, ctx, matrix, residual_vector, eta)
    if method == "bounded":
        return bounded_step(problem, x, ctx, matrix, residual_vector)
    return damped_step(problem, x, ctx, matrix, residual_vector, energy, damping)


def full_step(problem, x, ctx, matrix, residual_vector, eta):
    """A plain (inexact) Newton step; one that inverts a cell ends the iteration."""
    try:
        delta = ctx.step(matrix, -residual_vector, eta)
    except SingularMatrixError as exc:
        raise Failure(f"singular tangent ({exc})", x) from exc
    trial = x.copy()
    trial.ravel()[ctx.assembler.free] += delta
    inverted = problem.inverted_cells(trial)
    if inverted.size:
        raise Failure(f"inverted elements: {describe_cells(inverted)}", x)
    return trial, 1.0, "exact"


def bounded_step(problem, x, ctx, matrix, residual_vector):
    """An exact Newton step, shortened to 0.9 of the longest that keeps every cell admissible
    (no line search: the objective's value need not fall, as a Lagrangian's at a saddle)."""
    try:
        delta = ctx.step(matrix, -residual_vector)
    except SingularMatrixError as exc:
        raise Failure(f"singular tangent ({exc})", x) from exc
    full = np.zeros_like(x)
    full.ravel()[ctx.assembler.free] = delta
    alpha = min(1.0, 0.9 * problem.admissible_step(x, full))
    return x + alpha * full, alpha, "exact"


def damped_step(problem, x, ctx, matrix, residual_vector, energy, state: Damping):
    """A Levenberg–Marquardt step: ``c`` grows until the step lowers the energy."""
    identity = sp.identity(ctx.assembler.num_free, format="csr")
    for _attempt in range(60):
        try:
            delta = ctx.step(matrix + state.c * identity, -residual_vector)
        except SingularMatrixError:
            state.reject()
            continue
        trial = x.copy()
        trial.ravel()[ctx.assembler.free] += delta
        predicted = -(residual_vector @ delta + 0.5 * delta @ (matrix @ delta))
        actual = energy - problem.energy(trial)
        if predicted > 0 and actual >= -ctx.energy_noise:
            gain = actual / predicted
            state.c *= max(1.0 / 3.0, 1.0 - (2.0 * gain - 1.0) ** 3)
            state.growth = 2.0
            return trial, 1.0, "damped"
        state.reject()
    raise Failure("damping could not find an admissible step", x)
