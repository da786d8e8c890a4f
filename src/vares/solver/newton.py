"""Newton–Raphson on one energy, with the globalisations every strategy is built from.

The iteration works on any *objective*: an object with the methods of
:class:`vares.mechanics.Problem` that it uses,

- ``evaluate(x, order=2)``: energy, per-block gradients and Hessians (and ``∂²W/∂J²``);
- ``projected_hessians(evaluation)``: the Hessians made positive semi-definite point by point;
- ``energy(x)``: the energy, ``inf`` where ``x`` is not admissible;
- ``inverted_cells(x)``: the cells that make ``x`` inadmissible;
- ``admissible_step(x, delta)``: the largest ``α`` keeping ``x + α delta`` admissible,

so the forward (erection) problem can be solved by the same code as the pattern. The unknowns
are ``x.ravel()[assembler.free]``, optionally subject to one linear constraint ``cᵀΔx = 0``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp

from ..materials import InadmissibleState
from ..mechanics.assembly import Assembler
from .linear import LinearSolver, SingularMatrixError
from .result import IterationRecord, StepRecord
from .reuse import ETA_MAX, ReusingSolver, forcing_term

__all__ = [
    "EXACT_TANGENT_BELOW",
    "METHODS",
    "ROUND_OFF_REGIME",
    "Failure",
    "NewtonContext",
    "at_round_off",
    "describe_cells",
    "newton",
]

#: Relative residual below which globalised Newton returns from projected to exact tangents.
EXACT_TANGENT_BELOW = 1e-2
#: Below this relative residual, full Newton steps that twice in a row fail to halve the residual
#: mean it has reached the round-off floor of the mesh (ill-shaped cells make the floor higher
#: than a tight tolerance): the iteration stops there (see :func:`at_round_off`).
ROUND_OFF_REGIME = 1e-6
#: A pattern squeezed flat (:class:`NewtonContext`'s ``squeezed``).
SQUEEZED_PATTERN = (
    "the pattern is being squeezed flat at {cells}: the energy's minimum would fold them (the "
    "pattern would lap over itself there); cut the surface there (split it into panels) or add "
    "a dart"
)
#: ``"full"``: plain Newton; ``"line-search"``: globalised; ``"damped"``: Levenberg–Marquardt.
METHODS = ("full", "line-search", "damped")


class Failure(Exception):
    """A Newton iteration (or a strategy) did not converge; ``coordinates`` is where it stopped
    (never inverted)."""

    def __init__(self, reason: str, coordinates: np.ndarray, folding: bool = False) -> None:
        super().__init__(reason)
        self.reason = reason
        self.coordinates = coordinates
        self.folding = folding  # the energy's minimum lies beyond a fold: no strategy helps


def describe_cells(ids: np.ndarray, limit: int = 5) -> str:
    """``"3 cell(s) (4, 7, 9)"`` for messages."""
    shown = ", ".join(str(int(i)) for i in ids[:limit])
    return f"{ids.size} cell(s) ({shown}{', …' if ids.size > limit else ''})"


def at_round_off(
    residuals: list[float], step_lengths: list[float], regime: float = ROUND_OFF_REGIME
) -> bool:
    """True when the last two full Newton steps (step length 1) both left the relative residual
    above half the least one before them, below ``regime``: near the solution Newton's method
    converges quadratically, so such a stall is the floor that round-off sets, not slowness."""
    if len(residuals) < 3 or residuals[-1] > regime:
        return False
    best = min(residuals[:-2])
    stalled = residuals[-1] > 0.5 * best and residuals[-2] > 0.5 * best
    return stalled and step_lengths[-1] == 1.0 and step_lengths[-2] == 1.0


@dataclass
class NewtonContext:
    """What every Newton iteration of one solve shares: the dof map, the linear solver, the
    convergence test, and the records of the iterations and steps."""

    assembler: Assembler
    linear_solver: LinearSolver
    residual_tolerance: float
    energy_noise: float
    force_scale: float
    max_iterations: int
    history: list[IterationRecord]
    steps: list[StepRecord]
    callback: Callable[[IterationRecord], None] | None
    constraint: np.ndarray | None = None
    #: Below this relative residual a stall counts as the round-off floor (:func:`at_round_off`);
    #: an objective whose energy has kinks (the erection's tension field) stalls above its
    #: round-off floor where states switch, and sets it lower.
    round_off_regime: float = ROUND_OFF_REGIME
    #: The loosest relative accuracy of a Newton step (:func:`~vares.solver.reuse.forcing_term`);
    #: an objective with kinks sets it tighter.
    loosest_forcing: float = ETA_MAX
    #: The node a pattern free to turn (``orientation="free"``) turns about in a line search's
    #: steps (:class:`_Path`); ``None``: steps are straight lines.
    turning_about: int | None = None
    #: Give up a line-search iteration whose least residual has not halved over this many
    #: iterations (``None``: never), so the next attempt goes on from there: an energy with
    #: kinks can keep Newton's steps circling the solution (cells switching state at every
    #: iteration) where damped steps settle it.
    stall_window: int | None = None
    #: What a line search held back by a fold for :data:`SQUEEZED_ITERATIONS` iterations says
    #: (``{cells}``: the cells).
    squeezed: str = SQUEEZED_PATTERN

    def __post_init__(self) -> None:
        #: the linear solver, reusing its factorisations where that is cheaper (inexact Newton)
        self.systems = ReusingSolver(self.linear_solver)
        self._counted = (0, 0)

    def residual(self, gradient: np.ndarray) -> np.ndarray:
        """The residual over the free dofs, less its component along the linear constraint."""
        r = gradient.ravel()[self.assembler.free]
        if self.constraint is not None:
            r = r - self.constraint * (self.constraint @ r)
        return r

    def step(
        self, matrix: sp.csr_matrix, rhs: np.ndarray, rtol: float = 0.0, definite: bool = False
    ) -> np.ndarray:
        """Solve the Newton system to relative residual ``rtol`` (0: exactly), subject to the
        linear constraint when there is one. ``definite``: the caller has a definite matrix to
        try should this one be indefinite (:class:`~vares.solver.linear.IndefiniteMatrixError`
        instead of a slow fallback; a constrained system is a saddle point, never refused)."""
        return self.systems.solve(matrix, rhs, rtol, definite, constraint=self.constraint)

    def record(self, record: IterationRecord) -> None:
        """Keep ``record``, with the linear work done since the record before it."""
        counted = (self.systems.factorisations, self.systems.cg_iterations)
        record = replace(
            record,
            factorisations=counted[0] - self._counted[0],
            cg_iterations=counted[1] - self._counted[1],
        )
        self._counted = counted
        self.history.append(record)
        if self.callback is not None:
            self.callback(record)

    def attempt(
        self, name: str, step: int, tau: float, run: Callable[[], np.ndarray]
    ) -> np.ndarray:
        """Run one Newton solve and record it as a step (failed ones too, then re-raised)."""
        before = len(self.history)
        try:
            x = run()
        except Failure as failure:
            iterations = len(self.history) - before - 1
            self.steps.append(StepRecord(name, step, tau, iterations, False, failure.reason))
            raise
        self.steps.append(
            StepRecord(name, step, tau, len(self.history) - before - 1, True, None, x)
        )
        return x


@dataclass
class _Damping:
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


def newton(
    problem,
    coordinates: np.ndarray,
    ctx: NewtonContext,
    *,
    strategy: str,
    step: int,
    tau: float,
    method: str = "line-search",
    damping: float = 1.0,
) -> np.ndarray:
    """Newton–Raphson on one surface from ``coordinates``; returns the converged pattern.

    ``method`` is

    - ``"full"``: plain Newton, full steps; a step that inverts a cell ends it.
    - ``"line-search"``: globalised Newton. The step is bounded so that every ``det J`` stays
      positive and backtracked until the energy decreases enough (Armijo). Far from the
      solution (relative residual at or above :data:`EXACT_TANGENT_BELOW`) the tangent is the
      quadrature-point-wise positive semi-definite projection of the exact one (projected
      Newton: always a descent direction); below it the exact tangent, so the final convergence
      is quadratic, with the projection as fallback whenever the exact step is no descent.
    - ``"damped"``: each iteration solves ``(K + c I) ΔX = −r`` and accepts the step only if it
      lowers the energy without inverting a cell; ``c`` (starting at ``damping`` × the mean
      tangent diagonal) follows the gain ratio of actual to predicted decrease (Nielsen's rule)
      and is capped in proportion to the residual, so it vanishes as the iteration converges.

    Raises :class:`Failure` when it does not converge.
    """
    x = coordinates.copy()
    initial_residual = None
    state = _Damping(damping)
    step_length, tangent = 0.0, ""
    residuals: list[float] = []
    step_lengths: list[float] = []
    evaluation = None  # the line search's evaluation of the point it accepted, if it has one
    squeezed = 0  # iterations in a row whose steps a fold held back, each shorter
    for iteration in range(ctx.max_iterations + 1):
        if evaluation is None:
            try:
                evaluation = problem.evaluate(x, order=2)
            except InadmissibleState as exc:  # the next strategy may still get on from x
                raise Failure(str(exc), x) from exc
        residual_vector = ctx.residual(ctx.assembler.vector(evaluation.gradients))
        residual = float(np.linalg.norm(residual_vector))
        initial_residual = residual if initial_residual is None else initial_residual
        residuals.append(residual / ctx.force_scale)
        step_lengths.append(step_length)
        converged = residual <= ctx.residual_tolerance or at_round_off(
            residuals, step_lengths, ctx.round_off_regime
        )
        # far from the solution (by the residual) the projected tangent, near it the exact one
        projected = (
            method == "line-search"
            and not converged
            and residual >= EXACT_TANGENT_BELOW * ctx.force_scale
        )
        hessians = problem.projected_hessians(evaluation) if projected else evaluation.hessians
        matrix = None if converged else ctx.assembler.matrix(hessians)
        if method == "damped" and matrix is not None:
            state.cap(matrix, residual, initial_residual)
        ctx.record(
            IterationRecord(
                strategy,
                step,
                tau,
                iteration,
                residual,
                residual / ctx.force_scale,
                evaluation.energy,
                state.c or 0.0,
                step_length,
                tangent,
            )
        )
        if not (np.isfinite(residual) and np.isfinite(evaluation.energy)):
            raise Failure("non-finite energy or residual", x)
        if converged:
            return x
        if iteration == ctx.max_iterations:
            raise Failure(f"iteration limit ({ctx.max_iterations}) reached", x)
        if method == "line-search" and _stalled(residuals, ctx.stall_window):
            raise Failure(
                f"the residual stalled at {residuals[-1]:.3g} over {ctx.stall_window} iterations",
                x,
            )
        eta = forcing_term(
            residuals, ctx.residual_tolerance / ctx.force_scale, ctx.loosest_forcing
        )  # relative residuals: the same ratios
        if method == "full":
            x, step_length, tangent = _full_step(problem, x, ctx, matrix, residual_vector, eta)
            evaluation = None
        elif method == "damped":
            x, step_length, tangent = _damped_step(
                problem, x, ctx, matrix, residual_vector, evaluation.energy, state
            )
            evaluation = None
        else:
            search = _LineSearch(
                problem, x, ctx, evaluation, matrix, residual_vector, projected, eta
            )
            # the search owns the tangent now: it lets go of it before evaluating a trial point
            del evaluation, matrix, hessians
            x, step_length, tangent, evaluation = search.step()
            squeezed = squeezed + 1 if _held_back(search, step_length, step_lengths) else 0
            if squeezed >= SQUEEZED_ITERATIONS:
                raise Failure(
                    ctx.squeezed.format(cells=describe_cells(search.bounded_by)), x, folding=True
                )
    raise AssertionError("unreachable")


def _stalled(residuals: list[float], window: int | None) -> bool:
    """Whether the least of the last ``window`` residuals is above half the least before."""
    if window is None or len(residuals) <= window:
        return False
    return min(residuals[-window:]) > 0.5 * min(residuals[:-window])


def _full_step(problem, x, ctx, matrix, residual_vector, eta):
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


def _damped_step(problem, x, ctx, matrix, residual_vector, energy, state: _Damping):
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


#: After this many iterations in a row whose steps shrink (each below a tenth, each less than
#: half the one before) because a cell would fold, the line search gives up.
SQUEEZED_ITERATIONS = 6


def _held_back(search: _LineSearch, step_length: float, step_lengths: list[float]) -> bool:
    """Whether this step was held back by a fold, and shorter than half the one before."""
    previous = step_lengths[-1] if step_lengths else 1.0
    return (
        search.bounded_by is not None
        and search.bounded_by.size > 0
        and step_length < 0.1
        and step_length < 0.5 * previous
    )


#: The largest multiple of a projected step's turn that :meth:`_LineSearch._turn_further` tries.
MAX_TURN_SCALE = 1024.0


class _Path:
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

    def at(self, alpha: float, turned: float | None = None) -> np.ndarray:
        """The point ``α`` along the step, its turn ``turned`` times the step's (default α)."""
        if self.turn == 0.0:
            return self.x + alpha * self.rest
        angle = (alpha if turned is None else turned) * self.turn
        c, s = np.cos(angle), np.sin(angle)
        return self.centre + (self.arm + alpha * self.rest) @ np.array([[c, s], [-s, c]])


class _LineSearch:
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
            path = _Path(x, full, ctx.turning_about)
            bound = problem.admissible_step(x, path.rest)  # a rotation inverts no cell
            alpha = min(1.0, 0.9 * bound)
            self.bounded_by = (
                problem.inverted_cells(path.at(min(1.0, 1.01 * bound))) if bound < 1 else None
            )
            for backtrack in range(40):
                trial = path.at(alpha)
                at_trial = None
                if backtrack > 0:
                    energy = problem.energy(trial)
                elif problem.inverted_cells(trial).size:
                    energy = np.inf
                else:
                    try:
                        at_trial = problem.evaluate(trial, order=2)
                        energy = at_trial.energy
                    except InadmissibleState:  # like a fold: shorter steps are tried
                        energy = np.inf
                if energy <= self.energy + 1e-4 * alpha * slope + ctx.energy_noise:
                    tangent = "projected" if self.projected else "exact"
                    if self.projected and alpha == 1.0 and path.turn != 0.0:
                        turned = self._turn_further(path, energy)
                        if turned is not None:
                            return turned, alpha, "projected, turned", None
                    return trial, alpha, tangent, at_trial
                alpha *= 0.5
        raise Failure("the line search found no decrease of the energy", x)

    def _turn_further(self, path: _Path, energy: float) -> np.ndarray | None:
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
