"""The globalised Newton step: exact tangent first (projected where that gives no descent),
bounded to keep every cell admissible, backtracked until the energy falls enough (Armijo); for a
pattern free to turn, along a true rotation (:class:`StepPath`)."""

from __future__ import annotations

import numpy as np

from ..materials import InadmissibleState
from .failure import Failure
from .linear import SingularMatrixError

__all__ = ["MAX_TURN_SCALE", "LineSearch", "StepPath", "backtrack"]


#: The largest multiple of a projected step's turn that :meth:`_LineSearch._turn_further` tries.
MAX_TURN_SCALE = 1024.0


class StepPath:
    """The points ``x + α d`` of a step, or, for a pattern free to turn about its held node
    ``pivot``, the step's rigid-rotation part (least squares) made a true rotation: a turn
    applied linearly stretches the pattern by a factor ``√(1 + φ²)``, an energy that holds a
    line search back to short steps when the energy turns the pattern far (an anisotropic
    fabric with ``orientation="free"``: hundreds of iterations). Both paths leave ``x`` along
    ``d``; ``rest`` is ``d`` less its turn (``det J`` of a turned point is that of the unturned
    one)."""

    def __init__(self, x: np.ndarray, direction: np.ndarray, pivot: int | None) -> None:
        self.x, self.rest, self.turn = x, direction, 0.0
        if pivot is None:  # no turn: a straight step
            return
        self.centre = x[pivot]
        self.arm = x - self.centre
        across = np.column_stack([-self.arm[:, 1], self.arm[:, 0]])  # d(turned x)/dφ at φ = 0
        norm = float(np.sum(across * across))
        if norm > 0:
            self.turn = float(np.sum(direction * across)) / norm
            self.rest = direction - self.turn * across

    @classmethod
    def turning(cls, x: np.ndarray, rest: np.ndarray, pivot: int, turn: float) -> StepPath:
        """The path ``p + R(α turn)(x + α rest − p)`` about node ``pivot`` (``p``), its turn
        given (radians per unit step) rather than taken from a step by least squares."""
        path = cls(x, rest, None)
        path.centre = x[pivot]
        path.arm = x - path.centre
        path.turn = float(turn)
        return path

    def at(self, alpha: float, turned: float | None = None) -> np.ndarray:
        """The point ``α`` along the step, its turn ``turned`` times the step's (default α)."""
        if self.turn == 0.0:
            return self.x + alpha * self.rest
        angle = (alpha if turned is None else turned) * self.turn
        c, s = np.cos(angle), np.sin(angle)
        return self.centre + (self.arm + alpha * self.rest) @ np.array([[c, s], [-s, c]])


def backtrack(problem, path, alpha: float, energy: float, slope: float, noise: float):
    """Armijo backtracking along ``path`` (a :class:`StepPath`) from the step length
    ``alpha``, halved up to 40 times, until the energy falls below ``energy + 1e-4 α slope``
    (within ``noise``): ``(point, α, its evaluation or None, its energy)``, or ``None``. The
    first trial, usually accepted near the solution, is evaluated with its derivatives (the
    next iteration needs them); one that folds a cell or cannot be evaluated counts as
    infinite energy, so shorter steps are tried."""
    for tries in range(40):
        trial = path.at(alpha)
        at_trial = None
        if tries > 0:
            value = problem.energy(trial)
        elif problem.inverted_cells(trial).size:
            value = np.inf
        else:
            try:
                at_trial = problem.evaluate(trial, order=2)
                value = at_trial.energy
            except InadmissibleState:  # like a fold: shorter steps are tried
                value = np.inf
        if value <= energy + 1e-4 * alpha * slope + noise:
            return trial, alpha, at_trial, value
        alpha *= 0.5
    return None


class LineSearch:
    """A globalised step: exact tangent first (projected where that gives no descent), bounded
    to keep every cell admissible, backtracked until the energy falls enough (Armijo).

    The first trial, usually accepted near the solution, is evaluated with its derivatives: the
    next iteration needs them. The element derivatives at ``x`` and the tangent are dropped once
    a descent direction is found, before that trial is evaluated (two sets of element blocks
    would be alive at once; at 1M triangles each is about 0.5 GB); they are computed again in
    the rare case that the exact tangent's direction finds no decrease and the projected one
    must be tried.
    """

    def __init__(
        self, problem, x, ctx, evaluation, matrix, residual_vector, projected, eta
    ) -> None:
        self.problem, self.x, self.ctx, self.eta = problem, x, ctx, eta
        self.evaluation, self.matrix = evaluation, matrix
        self.energy = evaluation.energy
        self.residual_vector, self.projected = residual_vector, projected
        #: the cells that would fold just beyond the step, when they bounded it
        self.bounded_by: np.ndarray | None = None

    def step(self):
        """``(new point, step length, tangent used, evaluation at the new point or None)``."""
        problem, x, ctx = self.problem, self.x, self.ctx
        for attempt in ("projected",) if self.projected else ("exact", "projected"):
            if attempt == "projected" and not self.projected:
                self.projected = True
                if self.evaluation is None:
                    self.evaluation = problem.evaluate(x, order=2)
                self.matrix = ctx.assembler.matrix(problem.projected_hessians(self.evaluation))
            try:
                delta = ctx.step(
                    self.matrix, -self.residual_vector, self.eta, definite=attempt == "exact"
                )
            except SingularMatrixError:
                continue
            slope = float(self.residual_vector @ delta)
            if not slope < 0:
                continue
            self.evaluation = self.matrix = None
            full = np.zeros_like(x)
            full.ravel()[ctx.assembler.free] = delta
            path = StepPath(x, full, ctx.turning_about)
            bound = problem.admissible_step(x, path.rest)  # a rotation inverts no cell
            alpha = min(1.0, 0.9 * bound)
            self.bounded_by = (
                problem.inverted_cells(path.at(min(1.0, 1.01 * bound))) if bound < 1 else None
            )
            found = backtrack(problem, path, alpha, self.energy, slope, ctx.energy_noise)
            if found is not None:
                trial, alpha, at_trial, energy = found
                tangent = "projected" if self.projected else "exact"
                if self.projected and alpha == 1.0 and path.turn != 0.0:
                    turned = self._turn_further(path, energy)
                    if turned is not None:
                        return turned, alpha, "projected, turned", None
                return trial, alpha, tangent, at_trial
        raise Failure("the line search found no decrease of the energy", x)

    def _turn_further(self, path: StepPath, energy: float) -> np.ndarray | None:
        """The step's turn doubled while the energy keeps falling, or ``None`` if doubling it
        once does not lower it. A projected tangent (the exact one gave no descent: the energy
        is concave in the pattern's rotation there) is stiffer against turning than the energy
        is, so its turn falls short: each iteration turns the pattern a little and lowers the
        energy a little, for dozens of iterations (a non-crimp fabric on a flat hypar whose
        energy turns it 25°: 283 iterations). The evaluation at the step's own end is not used
        then: the next iteration evaluates the turned point."""
        best, scale = None, 2.0
        while scale <= MAX_TURN_SCALE:
            trial = path.at(1.0, turned=scale)  # turning inverts no cell the step did not
            value = self.problem.energy(trial)
            if not value < energy - self.ctx.energy_noise:
                break
            best, energy, scale = trial, value, 2.0 * scale
        return best
