"""Patterns optimised for the structure they build.

VaReS minimises the energy of erecting the pattern *onto the design shape*. The structure the
patterns make settles elsewhere (:func:`vares.erect`): its forces differ from the intended
prestress and its shape from the design. Here the patterns ``X`` are changed so that the erected
equilibrium ``x*(X)`` (``R(x*, X) = 0``) carries the intended prestress and keeps the design's
shape, by least squares (:mod:`vares.analysis.erection_residuals`):

    J(X) = Σ_cells A_e Σ_yarn (n(x*, X) − n_intended)² / (A s₀²)
           + 30 Σ_yarn (mean n − mean n_intended)² / s₀²
           + 3 Σ_cells A_e min(0, m_e − 0.1 min n_intended)² / (A s₀²)
           + w Σ_nodes a_i d_i(x*)² / (A d₀²) + 100 Σ_{|d_i| > b} a_i (|d_i| − b)² / (A d₀²)

``n`` the membrane forces along warp and fill, ``m_e`` the cell's smaller principal force of the
plain law (negative where the erected membrane wrinkles or hangs slack: an optimum does not buy
its forces with wrinkles), ``d`` the normal deviation from the design, ``A_e``
and ``a_i`` the cells' and nodes' design areas, ``s₀`` and ``d₀`` the RMS force deviation and RMS
shape deviation of the starting patterns' erection (``shape_weight`` ``w`` weighs a relative gain
in shape against one in force), ``b`` the bound on the shape deviation (``shape_bound`` × the
start's largest). Seams are constraints: every seam edge equally long in the two patterns it
joins, each step projected onto them and the patterns matched again to round-off after it.

The minimisation is Levenberg–Marquardt (a Gauss–Newton model of ``J``, damped by ``μ``; a step
is taken only if ``J`` falls, ``μ`` follows the ratio of the actual to the predicted decrease)
in a trust region on the patterns' edge lengths: no step changes one by more than a strain that
starts at 10 %, doubles after a good step that reached it and halves after a poor one; a refused
step is tried again half as long along the same direction. Its Jacobian is never formed:
products with it and its transpose take one solve each with the erection's tangent ``K``
(factorised once per accepted state), ``dx* = −K⁻¹ (∂R/∂X) dX`` and the adjoint
``Jᵀu = ∂r/∂Xᵀ u − (∂R/∂X)ᵀ K⁻¹ ∂r/∂xᵀ u`` (:mod:`vares.analysis.erection_sensitivity`), and
LSQR solves each step's least-squares problem, preconditioned by the inverse of the starting
patterns' stiffness (:func:`~vares.analysis.erection_residuals.stiffness_preconditioner`: 15
iterations make the step 30 plain ones made). A trial step's erection starts from the erected
state moved by its linearised change ``dx*`` (Newton's method then needs fewer iterations than
from the last state), is solved by conjugate gradients preconditioned by the accepted state's
factorised tangent, and only as accurately as the test of its objective needs
(:mod:`vares.analysis.erection_trials`); only an accepted state is linearised, and the optimum
is erected to the full tolerance at the end. It stops when a step lowers ``J`` (or the
Gauss–Newton model promises to lower it) by less than ``tolerance`` of it, when nothing is left
above round-off, or after ``optimise_iterations`` steps. Patterns stay one-to-one (a step that
inverts a pattern cell is refused like one that raises ``J``). The shape bound is held, not
only penalised (:mod:`vares.analysis.erection_bound`): nodes at the bound that a step would move
outwards are held there (the step solved again on the null space of their linearised
constraints), each step is cut where its linearised deviations reach the bound, and a trial
beyond it is refused.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from ..materials import Hyperelastic
from ..options import split_settings, takes_options
from ..solver.linear import quiet_blas, solver_family
from ..solver.options import SolveOptions
from .erection import erect
from .erection_bound import ShapeBound
from .erection_model import Pattern, patterns_of
from .erection_optimum_result import OptimisedPatterns, OptimumRecord, optimised_results
from .erection_residuals import (
    ResidualModel,
    edge_strain,
    erected_rms,
    pattern_edges,
    stiffness_preconditioner,
)
from .erection_trials import ACCEPTANCE_ACCURACY, TRIAL_TOLERANCE, predicted_positions
from .optimum_steps import norm_squared, step_direction
from .options import ErectionOptions
from .pattern_seams import PatternLayout, matched, moved, seam_edges

__all__ = ["OptimisedPatterns", "OptimumRecord", "optimise_for_erection", "optimised_results"]

#: The first damping ``μ``, relative to ``|J|²`` on a mesh of DAMPING_NODES nodes or fewer; it
#: follows the gain ratio (Nielsen's rule). ``|J|²`` is the curvature of the objective's
#: roughest change of the patterns, the same on every mesh of a surface, while a smooth change's
#: (what a step mostly is) falls as one over the nodes (its Euclidean norm grows with their
#: number, its effect on the forces does not): so on finer meshes ``μ`` starts smaller by the
#: ratio of their nodes, and damps the smooth changes as much as on a mesh of DAMPING_NODES. On
#: the 50k hypar of ``benchmarks/erection_optimum.py`` the unscaled damping took 7 steps to the
#: optimum, the scaled 4 (docs/erection.md).
INITIAL_DAMPING = 1e-3
DAMPING_NODES = 1000
#: The trust region of a step: the largest change of a pattern edge's length it may make (a
#: strain), at first, at most, and below which a refused step's direction is given up.
INITIAL_STEP_STRAIN = 0.1
MAX_STEP_STRAIN = 0.2
MIN_STEP_STRAIN = 1e-4
#: A step whose Gauss–Newton model promises to lower ``J`` by less than this fraction of the
#: tolerance (of ``J``) ends the optimisation before its trial is erected: its actual gain
#: would not pass the tolerance either (the gains of the last steps are 0.25–0.95).
PROMISED_GAIN = 1.0
#: A step the bound cuts to less than this fraction of itself neither ends the optimisation by
#: its small gain nor by its model's small promise (the promise of the step before the cut is
#: what counts): the nodes that cut it are at the bound at the next step, and held there. On the
#: isotropic 1,568-triangle hypar, patterns solved to the solver's tolerance from starts 1e-8
#: apart ended at J = 0.661 … 0.830 when a cut step's promise ended the optimisation.
BOUND_CUT = 0.5
#: Deviations are measured against the start's, but at least against a force of this strain
#: times the stiffness and a length of this fraction of the size; deviations below these are
#: round-off, nothing is left to gain (the erections are solved to 1e-10 of the stiffness: an
#: RMS force deviation of 1e-9 of it still leaves each cell's within a few 1e-9).
FORCE_FLOOR = 1e-9
SHAPE_FLOOR = 1e-11


def _erect(patterns, material, thickness, solver, options, start, primer=None):
    return erect(
        patterns, material, thickness, solver=solver, options=options, start=start, primer=primer
    )


@takes_options(ErectionOptions)
def optimise_for_erection(
    source: Any,
    material: Hyperelastic | None = None,
    thickness: float | None = None,
    *,
    solver: SolveOptions | None = None,
    options: ErectionOptions | None = None,
    tolerance: float = 0.01,
    callback: Callable[[OptimumRecord], None] | None = None,
    **settings: Any,
) -> OptimisedPatterns:
    """Change the patterns so that the structure they build carries the intended prestress
    and keeps the design's shape (module docs).

    Parameters
    ----------
    source
        What :func:`vares.erect` takes: a solve, a structure's result, or a list of them or of
        :class:`Pattern` (the starting patterns: usually VaReS').
    material, thickness, solver
        As for :func:`vares.erect`.
    options
        The erection's options (supports, cables, pressure, wrinkling) and the optimiser's:
        ``shape_weight`` ``w`` (a relative gain in the RMS shape deviation against the same in
        the RMS force deviation; 0: forces only), ``shape_bound`` (the largest shape deviation
        allowed, relative to the starting patterns'; None: no bound; a node further from the
        design adds its excess, heavily weighted) and ``optimise_iterations``.
    tolerance
        Stop when a step lowers ``J`` by less than this fraction of it.
    callback
        Called with every iteration's record.
    settings
        Any field of :class:`ErectionOptions` as a keyword (listed below).
    """
    (options,) = split_settings(settings, [options or ErectionOptions()])
    with quiet_blas():  # LSQR's vector operations beside PARDISO's solves (quiet_blas docs)
        return _optimise(source, material, thickness, solver, options, tolerance, callback)


def _optimise(source, material, thickness, solver, options, tolerance, callback):
    started = time.perf_counter()
    shape_weight, shape_bound = options.shape_weight, options.shape_bound
    iterations = options.optimise_iterations
    patterns = patterns_of(source)
    if material is None or thickness is None or solver is None:
        from .erection import erection_defaults

        material, thickness, solver = erection_defaults(source, material, thickness, solver)
    first = _erect(patterns, material, thickness, solver, options, None)
    if not first.converged:
        return OptimisedPatterns(
            patterns,
            first,
            first,
            [],
            False,
            f"the starting patterns: {first.reason}",
            shape_weight,
            shape_bound,
        )
    layout = PatternLayout(patterns, first)
    seams = seam_edges(patterns, first, layout)
    # the start's deviations, but never below the floors (a pattern at the round-off of its
    # solve is left as it is)
    size = float(np.ptp(first.mesh.points, axis=0).max())
    floors = (FORCE_FLOOR * material.stiffness_scale * thickness, SHAPE_FLOOR * size)
    scales = (max(erected_rms(first), floors[0]), max(first.deviation()["rms"], floors[1]))
    negligible = ((floors[0] / scales[0]) ** 2, shape_weight * (floors[1] / scales[1]) ** 2)
    held = None if shape_bound is None else ShapeBound(shape_bound * first.deviation()["max"])
    bound = None if held is None else held.bound

    # the states' tangents factorised by solvers of one family: one symbolic analysis for all,
    # apart from the trial erections' own factorisations
    tangents = solver_family(solver.linear_solver, many_solves=True)

    def model_of(p, e):
        return ResidualModel(p, e, layout, seams, scales, shape_weight, bound, tangents)

    current, erected = patterns, first
    model = model_of(current, erected)
    objective = float(model.residual @ model.residual)
    history = [_record(0, objective, model, erected, current, seams, 0.0, 0, True)]
    if callback is not None:
        callback(history[-1])
    edges = pattern_edges(patterns, layout)
    preconditioner = None  # made for the first step (none where the start is at round-off)
    mu, reason, converged = None, None, False
    radius, step, step_strain = INITIAL_STEP_STRAIN, None, 0.0
    for iteration in range(1, iterations + 1):
        if model.parts[0] <= negligible[0] and model.parts[1] <= negligible[1]:  # round-off
            converged = True
            break
        lsqr_its = 0
        if step is None:  # a new Levenberg–Marquardt step (after a refused one: shorter)
            if mu is None:
                nodes = layout.num_variables // 2
                coarse = min(1.0, DAMPING_NODES / nodes)
                mu = INITIAL_DAMPING * coarse * norm_squared(model.operator())
                preconditioner = stiffness_preconditioner(
                    patterns, material, thickness, solver.linear_solver
                )

            def strain_of(v, at=current):
                return edge_strain(at, v, edges, layout)

            step, step_strain, lsqr_its = step_direction(
                model, mu, preconditioner, strain_of, held, radius
            )
        scale = min(1.0, radius / step_strain) if step_strain > 0 else 1.0
        change, dx = model.response(scale * step)
        # what the model promises along the step before the bound cuts it: a step the bound
        # cuts short promises little because nodes meet the bound (they are held at the next
        # step), not because the optimum is near
        promised = objective - float(np.sum((model.residual + change) ** 2))
        cut = 1.0
        if held is not None:  # cut where its linearised deviations reach the bound
            moved_to = model.deviation_change(dx)
            cut = held.largest_step(model.erected.normal_deviation, moved_to)
            scale, change, dx = cut * scale, cut * change, cut * dx
        predicted = objective - float(np.sum((model.residual + change) ** 2))
        if promised < PROMISED_GAIN * tolerance * objective or not predicted > 0:
            converged = True  # the model promises less than a step must gain
            break
        trial = matched(moved(current, layout.split(scale * step)), seams, layout)
        loose = _trial_solver(solver, model, erected, predicted)
        attempt, newton = _trial_erection(
            trial, material, thickness, loose, options, erected, model, dx
        )
        accepted, decrease, gain = False, 0.0, -1.0
        if attempt is not None and held is not None:
            if not held.admits(attempt.deviation()["max"], erected.deviation()["max"]):
                attempt, held.refused = None, held.refused + 1  # beyond the bound: refused
        if attempt is not None:
            trial_model = model_of(trial, attempt)
            value = float(trial_model.residual @ trial_model.residual)
            gain = (objective - value) / predicted
            if value < objective:
                accepted, decrease = True, (objective - value) / objective
                current, erected, model, objective = trial, attempt, trial_model, value
        taken = scale * step_strain
        if accepted:
            mu *= max(1.0 / 3.0, 1.0 - (2.0 * gain - 1.0) ** 3)
            if gain > 0.75 and scale < 1.0:
                radius = min(2.0 * radius, MAX_STEP_STRAIN)
            elif gain < 0.25:
                radius = 0.5 * taken
            step = None
        else:  # the same direction, half as long; the next direction damped more
            mu *= 2.0
            radius = 0.5 * taken
        record = _record(
            iteration, objective, model, erected, current, seams, mu, lsqr_its, accepted, newton
        )
        record = replace(record, gain=gain, step_strain=taken)
        history.append(record)
        if callback is not None:
            callback(record)
        if accepted and decrease < tolerance and cut >= BOUND_CUT:
            converged = True  # (a step the bound cut short says nothing of the optimum)
            break
        if not accepted and taken < MIN_STEP_STRAIN:
            break  # no step along the model's direction lowers the objective
    else:
        converged = True  # every step taken lowered the objective: the patterns are usable
    if not converged:
        reason = "no step lowers the objective"
    tightening = None
    if erected is not first and not _tight(erected, solver):  # trials erected loosely
        primer = model.tangent_solve if model.linearised else None
        tight = _tightened(current, material, thickness, solver, options, erected, primer)
        tightening, erected = (tight.iterations if tight is not erected else None), tight
    overlap = _overlapping(current)
    if overlap is not None:  # a pattern that laps over itself is no cutting pattern
        current, erected, converged, reason = patterns, first, False, overlap
    return OptimisedPatterns(
        current,
        first,
        erected,
        history,
        converged,
        None if converged else reason,
        shape_weight,
        shape_bound,
        elapsed=time.perf_counter() - started,
        tightening=None if current is patterns else tightening,
    )


def _overlapping(patterns: list[Pattern]) -> str | None:
    """Why an optimised pattern is not one-to-one (it laps over itself), or None."""
    from ..geometry.injectivity import pattern_overlap

    for pattern in patterns:
        overlap = pattern_overlap(pattern.mesh, pattern.material_coordinates)
        if overlap is not None:
            where = overlap.describe(pattern.mesh)
            return f"{pattern.name}: the optimised pattern is not one-to-one: {where}"
    return None


def _trial_erection(trial, material, thickness, solver, options, erected, model, dx):
    """The erection of trial patterns from the linearised prediction of their erected state
    (from the last erected state where that fails), its Newton steps preconditioned by the
    accepted state's factorised tangent (:mod:`vares.analysis.erection_trials`), and its Newton
    iterations, or ``(None, n)`` where a pattern cell turned over or the erection did not
    converge."""
    newton = 0
    predicted = predicted_positions(erected.erected_points, erected.context.assembler.free, dx)
    for start in (predicted, erected.erected_points):
        try:
            attempt = _erect(
                trial, material, thickness, solver, options, start, model.tangent_solve
            )
        except ValueError:  # a pattern cell turned over
            return None, newton
        newton += attempt.iterations
        if attempt.converged:
            return attempt, newton
    return None, newton


def _trial_solver(solver, model, erected, predicted):
    """The solver options of a trial's erection: its residual tolerance as loose as keeps the
    objective's error (at most ``2 |g| |R|``, :meth:`ResidualModel.equilibrium_sensitivity`)
    within :data:`ACCEPTANCE_ACCURACY` of the step's predicted decrease, between the solver's
    own tolerance and :data:`TRIAL_TOLERANCE`."""
    if TRIAL_TOLERANCE <= solver.tolerance:
        return solver
    bound = ACCEPTANCE_ACCURACY * predicted / (2.0 * model.equilibrium_sensitivity())
    tolerance = min(TRIAL_TOLERANCE, bound / erected.problem.force_scale)
    return replace(solver, tolerance=max(solver.tolerance, tolerance))


def _tight(erected, solver) -> bool:
    """Whether an erection's last iterate meets the solver's own tolerance (a trial's erection,
    asked for less, may have met it anyway: then it is the optimum's final erection)."""
    return bool(erected.history) and erected.history[-1].relative_residual <= solver.tolerance


def _tightened(patterns, material, thickness, solver, options, erected, primer=None):
    """The erection of the optimised patterns to the solver's tolerance, from their loosely
    erected state (one or two Newton iterations, preconditioned by ``primer``, a solve with the
    factorised tangent of that state where the optimiser made one); that state where this one
    fails."""
    tight = _erect(patterns, material, thickness, solver, options, erected.erected_points, primer)
    return tight if tight.converged else erected


def _record(
    iteration, objective, model, erected, patterns, seams, mu, lsqr_its, accepted, newton=0
):
    deviation = erected.deviation()
    mismatch = 0.0
    if len(seams):
        X = np.concatenate([p.material_coordinates for p in patterns])
        ends = X[seams]
        lengths = np.linalg.norm(ends[:, :, 1] - ends[:, :, 0], axis=-1)
        mismatch = float(np.abs(lengths[:, 0] - lengths[:, 1]).max())
    return OptimumRecord(
        iteration,
        objective,
        model.parts[0],
        model.parts[1],
        erected_rms(erected),
        deviation["max"],
        deviation["rms"],
        mismatch,
        mu,
        int(lsqr_its or 0),
        accepted,
        newton,
    )
