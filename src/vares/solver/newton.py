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
from .failure import Failure, describe_cells
from .line_search import LineSearch
from .linear import LinearSolver
from .result import IterationRecord, StepRecord
from .reuse import ETA_MAX, ReusingSolver, forcing_term
from .steps import Damping, plain_step
from .turning import TurningSearch, TurnState, turning_minimum

__all__ = [
    "EXACT_TANGENT_BELOW",
    "ISOTROPIC_EXACT_TANGENT_BELOW",
    "METHODS",
    "ROUND_OFF_REGIME",
    "SOFTNESS_REFERENCE",
    "AssembledDofs",
    "Failure",
    "NewtonContext",
    "absolute_hessians",
    "at_round_off",
    "describe_cells",
    "exact_tangent_below",
    "newton",
]

#: Relative residual below which globalised Newton returns from projected to exact tangents
#: (the default; :func:`exact_tangent_below` gives it per problem).
EXACT_TANGENT_BELOW = 1e-2
#: The same where the energy does not depend on the yarns (an isotropic law without
#: prestress): measured on public scans with slivers (benchmarks/race.py) the face of 51,712
#: triangles takes 8 Newton iterations instead of 11, the camel head 12 instead of 13, the lion
#: 10 either way, the robustness suite's steep saddle 4 instead of 5 and every other isotropic
#: row of benchmarks/robustness.py as many as at 1e-2; at 5e-2 four fabric rows took 1–5 more,
#: so fabrics keep 1e-2 (docs/benchmarks.md).
ISOTROPIC_EXACT_TANGENT_BELOW = 5e-2
#: The softness (:meth:`~vares.materials.Hyperelastic.softness`) of a fabric below which its
#: switch is moved down in proportion: coated fabrics (PES/PVC type II: 0.076; the robustness
#: suite's orthotropic law 0.1) keep 1e-2.
SOFTNESS_REFERENCE = 0.05
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
#: ``"full"``: plain Newton; ``"line-search"``: globalised; ``"damped"``: Levenberg–Marquardt;
#: ``"bounded"``: exact Newton steps shortened to keep every cell admissible.
METHODS = ("full", "line-search", "damped", "bounded")


def exact_tangent_below(softness: float = float("nan"), isotropic: bool = False) -> float:
    """The relative residual below which Newton takes the exact tangent:
    :data:`ISOTROPIC_EXACT_TANGENT_BELOW` for an ``isotropic`` problem, else
    :data:`EXACT_TANGENT_BELOW`, times ``softness / SOFTNESS_REFERENCE`` when that is below 1.

    The relative residual is measured against the stiffest stiffness (the yarns'), while how
    far the pattern is from the minimum along its soft (shear) modes shows in the residual
    scaled by the soft stiffness: the same distance gives a residual smaller by their ratio.
    With yarns 10,000 times stiffer than the shear the exact tangent taken from a relative
    residual of 1e-2 (from a kinematic net's pattern: at once) is a Newton step far from the
    solution along the shear modes, which the line search cuts to 0.01–0.5 for dozens of
    iterations (48 on the 2,400-cell hemisphere, 16 with the switch moved down; docs/locking.md).
    ``softness`` is that of the discrete problem: the law's where the shear modes are free
    (locking-free yarn strains), ``nan`` (not known: no scaling) where linear triangles lock
    them.
    """
    if isotropic:
        return ISOTROPIC_EXACT_TANGENT_BELOW
    if not softness > 0:  # no small-strain stiffness to compare with
        return EXACT_TANGENT_BELOW
    return EXACT_TANGENT_BELOW * min(1.0, softness / SOFTNESS_REFERENCE)


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
class AssembledDofs:
    """The dof map of an objective whose evaluations come assembled: ``gradients`` a vector
    over every entry of its state, ``hessians`` the matrix over the ``free`` ones (seam
    matching's KKT system, whose state is every panel's coordinates and the multipliers)."""

    free: np.ndarray

    @property
    def num_free(self) -> int:
        return int(np.count_nonzero(self.free))

    def vector(self, gradients: np.ndarray) -> np.ndarray:
        return gradients

    def matrix(self, hessians: sp.spmatrix) -> sp.spmatrix:
        return hessians


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
    #: steps (:class:`~vares.solver.line_search.StepPath`); ``None``: steps are straight lines.
    turning_about: int | None = None
    #: The rotation about ``turning_about`` is an explicit unknown of the Newton system, with
    #: its exact coupling (:mod:`vares.solver.turning`), instead of a step's least-squares turn.
    turning: bool = False
    #: Give up a line-search iteration whose least residual has not halved over this many
    #: iterations (``None``: never), so the next attempt goes on from there: an energy with
    #: kinks can keep Newton's steps circling the solution (cells switching state at every
    #: iteration) where damped steps settle it.
    stall_window: int | None = None
    #: What a line search held back by a fold for :data:`SQUEEZED_ITERATIONS` iterations says
    #: (``{cells}``: the cells).
    squeezed: str = SQUEEZED_PATTERN
    #: A further condition of convergence on the state (``None``: none): seam matching's seams
    #: must have equal lengths on both sides to round-off as well.
    accepts: Callable[[np.ndarray], bool] | None = None
    #: The projected tangent of an iteration whose last step was shortened (and of the first)
    #: has the absolute values of the exact one's eigenvalues, point by point, instead of its
    #: negative ones set to zero (:func:`absolute_hessians`): a compressed cell's negative
    #: curvature then stiffens the step instead of leaving it free to fold that cell.
    absolute_after_short_steps: bool = False
    #: Relative residual below which the line-search method takes the exact tangent
    #: (:func:`exact_tangent_below`).
    exact_tangent_below: float = EXACT_TANGENT_BELOW

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
      solution (relative residual at or above ``ctx.exact_tangent_below``) the tangent is the
      quadrature-point-wise positive semi-definite projection of the exact one (projected
      Newton: always a descent direction); below it the exact tangent, so the final convergence
      is quadratic, with the projection as fallback whenever the exact step is no descent.
    - ``"damped"``: each iteration solves ``(K + c I) ΔX = −r`` and accepts the step only if it
      lowers the energy without inverting a cell; ``c`` (starting at ``damping`` × the mean
      tangent diagonal) follows the gain ratio of actual to predicted decrease (Nielsen's rule)
      and is capped in proportion to the residual, so it vanishes as the iteration converges.
    - ``"bounded"``: exact Newton steps, each shortened to 0.9 of the longest that keeps every
      cell admissible; for an objective whose stationary point is a saddle (a Lagrangian).

    Raises :class:`Failure` when it does not converge.
    """
    x = coordinates.copy()
    initial_residual = None
    damping_state = Damping(damping)
    step_length, tangent = 0.0, ""
    residuals: list[float] = []
    step_lengths: list[float] = []
    evaluation = None  # the line search's evaluation of the point it accepted, if it has one
    squeezed = 0  # iterations in a row whose steps a fold held back, each shorter
    turn = TurnState()  # what turning steps carry over (``ctx.turning``)
    floor_from = 0  # the residuals that show the round-off floor start here
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
        converged, floor_from = _converged(
            x, ctx, evaluation, residual_vector, residual, residuals, step_lengths, floor_from
        )
        hessians, projected = _tangent(
            problem, ctx, evaluation, method, converged, residual, step_length
        )
        matrix = None if converged else ctx.assembler.matrix(hessians)
        if method == "damped" and matrix is not None:
            damping_state.cap(matrix, residual, initial_residual)
        record = (strategy, step, tau, iteration, residual, residual / ctx.force_scale)
        c = damping_state.c or 0.0
        ctx.record(IterationRecord(*record, evaluation.energy, c, step_length, tangent))
        if _ends(ctx, x, evaluation.energy, converged, iteration, method, residuals):
            return x
        eta = forcing_term(
            residuals, ctx.residual_tolerance / ctx.force_scale, ctx.loosest_forcing
        )  # relative residuals: the same ratios
        if method != "line-search":
            energy = evaluation.energy
            x, step_length, tangent = plain_step(
                method, problem, x, ctx, matrix, residual_vector, eta, energy, damping_state
            )
            evaluation = None
            continue
        if ctx.turning:
            search = TurningSearch(problem, x, ctx, evaluation, matrix, residual_vector, turn)
        else:
            search = LineSearch(
                problem, x, ctx, evaluation, matrix, residual_vector, projected, eta
            )
        # the search owns the tangent now: it lets go of it before evaluating a trial point
        evaluation = matrix = hessians = None
        x, step_length, tangent, evaluation = search.step()
        squeezed = squeezed + 1 if _held_back(search, step_length, step_lengths) else 0
        if squeezed >= SQUEEZED_ITERATIONS:
            raise Failure(
                ctx.squeezed.format(cells=describe_cells(search.bounded_by)), x, folding=True
            )
    raise AssertionError("unreachable")


def _converged(x, ctx, evaluation, residual_vector, residual, residuals, step_lengths, floor_from):
    """Whether the iteration at ``x`` (its ``residual``; the relative ones so far) has converged,
    and from which residual on the round-off floor is looked for: the tolerance or the floor
    (:func:`at_round_off`), the objective's own condition (``ctx.accepts``), and for a pattern
    free to turn a minimum, not a stationary rotation (where it is not, the residuals so far
    say nothing of the floor)."""
    converged = residual <= ctx.residual_tolerance or at_round_off(
        residuals[floor_from:], step_lengths[floor_from:], ctx.round_off_regime
    )
    if converged and ctx.accepts is not None:
        converged = ctx.accepts(x)
    if converged and ctx.turning:  # a stationary rotation, or a minimum?
        exact = ctx.assembler.matrix(evaluation.hessians)
        converged = turning_minimum(x, ctx, exact, residual_vector)
        if not converged:
            floor_from = len(residuals)
    return converged, floor_from


def _tangent(problem, ctx, evaluation, method, converged, residual, step_length):
    """The per-block Hessians of the next step's tangent and whether they are projected: far
    from the solution (by the relative residual) the projected ones for a line search, with
    the absolute values of the exact eigenvalues after a shortened step where the context asks
    for them; near it, and for the other methods, the exact ones."""
    projected = (
        method == "line-search"
        and not ctx.turning  # the exact tangent first, whatever the residual
        and not converged
        and residual >= ctx.exact_tangent_below * ctx.force_scale
    )
    hessians = problem.projected_hessians(evaluation) if projected else evaluation.hessians
    if projected and ctx.absolute_after_short_steps and step_length < 1.0:
        hessians = absolute_hessians(hessians, evaluation.hessians)
    return hessians, projected


def absolute_hessians(projected: list, exact: list) -> list:
    """Per-block Hessians whose point-wise eigenvalues are the absolute values of the exact
    ones (Chen et al. 2024), from the clamped projection: ``|H| = 2 H₊ − H`` with ``H₊`` the
    negative eigenvalues set to zero (the nodal Hessian is linear in the point-wise one).
    ``projected`` is overwritten. Blocks whose shapes differ, or that are the exact ones
    themselves, are left as they are."""
    for block, full in zip(projected, exact, strict=True):
        if block.shape == full.shape and not np.may_share_memory(block, full):
            block *= 2.0
            block -= full
    return projected


def _ends(ctx, x, energy, converged, iteration, method, residuals) -> bool:
    """True when the iteration converged; raises :class:`Failure` where it must end (a value
    not finite, the iteration limit, a stall)."""
    if not (np.isfinite(residuals[-1]) and np.isfinite(energy)):
        raise Failure("non-finite energy or residual", x)
    if converged:
        return True
    if iteration == ctx.max_iterations:
        raise Failure(f"iteration limit ({ctx.max_iterations}) reached", x)
    if method == "line-search" and _stalled(residuals, ctx.stall_window):
        raise Failure(
            f"the residual stalled at {residuals[-1]:.3g} over {ctx.stall_window} iterations", x
        )
    return False


def _stalled(residuals: list[float], window: int | None) -> bool:
    """Whether the least of the last ``window`` residuals is above half the least before."""
    if window is None or len(residuals) <= window:
        return False
    return min(residuals[-window:]) > 0.5 * min(residuals[:-window])


#: After this many iterations in a row whose steps shrink (each below a tenth, each less than
#: half the one before) because a cell would fold, the line search gives up.
SQUEEZED_ITERATIONS = 6


def _held_back(search: LineSearch, step_length: float, step_lengths: list[float]) -> bool:
    """Whether this step was held back by a fold, and shorter than half the one before."""
    previous = step_lengths[-1] if step_lengths else 1.0
    return (
        search.bounded_by is not None
        and search.bounded_by.size > 0
        and step_length < 0.1
        and step_length < 0.5 * previous
    )
