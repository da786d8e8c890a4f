"""Erection analysis: build the structure from its patterns and see what it becomes.

The patterns (one per panel) are welded along their seams (seam nodes coinciding in 3D become one
node), stretched onto the supports, and left to settle: :func:`erect` solves the forward problem
of :mod:`vares.mechanics.erection` (the patterns fixed, the 3D positions unknown, the same law and
fibres as the patterning, the tension-field energy where the membrane would be compressed) by the
same globalised Newton as the patterning, from the design shape. It reports the erected shape,
its deviation from the design, and the membrane forces against the intended prestress.

Supports and edge cables: :mod:`vares.analysis.erection_model`.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..geometry.elements import ELEMENTS
from ..geometry.mesh import SurfaceMesh
from ..materials import Hyperelastic
from ..mechanics.erection import Cables, ErectionProblem
from ..mechanics.wrinkling import WrinklingError
from ..options import split_settings, takes_options
from ..solver.linear import get_solver, quiet_blas
from ..solver.newton import NewtonContext, describe_cells
from ..solver.options import SolveOptions
from ..solver.result import IterationRecord, PatternResult, StepRecord
from ..solver.reuse import ETA_MAX, ETA_MAX_KINKED, ReusingSolver
from ..solver.strategies import Attempt, follow_plan
from .erection_fields import erection_statistics, membrane_forces, node_normals
from .erection_model import Pattern, Structure, build_structure, dof_map, patterns_of
from .erection_trials import PRIMED_ITERATIONS
from .options import ErectionOptions

__all__ = ["ErectionResult", "Pattern", "erect", "erection_defaults"]

#: Energy changes below this fraction of stiffness × thickness × area are round-off.
ENERGY_NOISE = 1e-13
#: A Newton stall counts as the round-off floor only below this relative residual: where cells
#: switch between taut, wrinkled and slack, Newton's method may stall well above round-off, and
#: that is no convergence.
ROUND_OFF_REGIME = 1e-11
#: With the tension field, the line search hands over to damped steps when the residual has not
#: halved in this many iterations (Newton's steps circling a solution where cells switch state).
STALL_WINDOW = 10
#: What an erection held back by folding cells says.
SQUEEZED_MEMBRANE = (
    "the erected membrane is being folded over at {cells}: the patterns are far from fitting "
    "their supports there (a pattern much too large or too small for its boundary), or the "
    "start folds them"
)
_ATTEMPTS = (Attempt("erection", None, "line-search"), Attempt("erection, damped", None, "damped"))
_REGULARISED = tuple(Attempt(f"{a.name}, regularised", a.taus, a.method) for a in _ATTEMPTS)


class LazyFields(Mapping[str, np.ndarray]):
    """Per-cell fields computed when first read (an erection's fields on the design shape:
    reports read them, the optimiser's trial erections never do)."""

    def __init__(self, compute: Callable[[], dict[str, np.ndarray]]) -> None:
        self._compute: Callable[[], dict[str, np.ndarray]] | None = compute
        self._fields: dict[str, np.ndarray] = {}

    def _made(self) -> dict[str, np.ndarray]:
        if self._compute is not None:
            self._fields, self._compute = self._compute(), None
        return self._fields

    def __getitem__(self, key: str) -> np.ndarray:
        return self._made()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._made())

    def __len__(self) -> int:
        return len(self._made())

    def __reduce__(self):  # pickled (sent to another process) as the fields themselves
        return dict, (self._made(),)


@dataclass
class ErectionResult:
    """The structure built from its patterns.

    Attributes
    ----------
    mesh
        The welded design surface (seam nodes shared); ``erected_points`` ``(n, 3)`` the
        erected positions of its nodes, ``erected_mesh`` the erected surface.
    converged, reason
        Whether the forward problem converged, and why not.
    displacement, normal_deviation
        Per node: ``erected − design`` ``(n, 3)`` and its component along the design surface's
        normal ``(n,)`` (the signed distance from the design surface's tangent plane).
    fields, design_fields
        Per cell (welded cell order, see :data:`vares.analysis.erection_fields.CELL_FIELDS`):
        after erection, and on the design shape (the patterns forced onto the surface, the law
        as it is: what the patterning reports).
    intended
        The intended warp and fill prestress per cell ``(m, 2)``, force per length.
    held
        Per node: held by a support.
    cables, cable_tension
        The edge cables (or None) and the force in each segment.
    panels, node_maps, cell_ids
        Panel names; per panel, the welded node of each of its nodes and the welded cell of each
        of its cells (its own cell order).
    regularised
        Newton's method on the law itself stalled (where cells wrinkle or hang slack the
        tension field's equilibria are not isolated), and the state is the equilibrium of the
        regularised energy (the film's tension in it, module docs of
        :mod:`vares.mechanics.erection`): the law's residual there is the film's forces.
    problem, structure, context
        The forward problem, the welded structure and the Newton context it was solved with
        (what the sensitivities of :mod:`vares.analysis.erection_optimum` build on).
    """

    mesh: SurfaceMesh
    erected_points: np.ndarray
    converged: bool
    reason: str | None
    history: list[IterationRecord]
    steps: list[StepRecord]
    strategy: list[str]
    linear_solver: str
    elapsed: float
    options: ErectionOptions
    material: Hyperelastic
    thickness: float
    displacement: np.ndarray
    normal_deviation: np.ndarray
    node_areas: np.ndarray
    fields: dict[str, np.ndarray]
    design_fields: Mapping[str, np.ndarray]
    intended: np.ndarray
    held: np.ndarray
    cables: Cables | None = None
    cable_tension: np.ndarray | None = None
    panels: list[str] = field(default_factory=list)
    node_maps: list[np.ndarray] = field(default_factory=list)
    cell_ids: list[np.ndarray] = field(default_factory=list)
    regularised: bool = False
    problem: ErectionProblem | None = field(default=None, repr=False, compare=False)
    structure: Structure | None = field(default=None, repr=False, compare=False)
    context: NewtonContext | None = field(default=None, repr=False, compare=False)

    @property
    def iterations(self) -> int:
        """Newton iterations (linear solves)."""
        return sum(1 for r in self.history if r.iteration > 0)

    @property
    def erected_mesh(self) -> SurfaceMesh:
        return SurfaceMesh(self.erected_points, self.mesh.cells)

    @property
    def surface_area(self) -> float:
        return self.mesh.area

    @property
    def erected_area(self) -> float:
        return float(
            sum(ELEMENTS[t].areas(self.erected_points, c).sum() for t, c in self.mesh.cells.items())
        )

    def deviation(self) -> dict[str, float]:
        """``max`` and (design-area-weighted) ``rms`` normal deviation, length units."""
        d = self.normal_deviation
        rms = np.sqrt(d**2 @ self.node_areas / self.node_areas.sum())
        return {"max": float(np.abs(d).max()), "rms": float(rms)}

    def statistics(self, design: bool = False) -> dict[str, object]:
        """Stress statistics per yarn and wrinkled/slack area fractions, after erection (or on
        the design shape)."""
        fields = self.design_fields if design else self.fields
        return erection_statistics(fields, self.intended, self.fields["surface_area"])

    def to_dict(self, units: str = "m") -> dict[str, object]:
        """The key figures (the contract of ``erect.json``) and more."""
        from .._version import __version__

        after = self.statistics()
        out: dict[str, object] = {
            "vares_version": __version__,
            "converged": self.converged,
            "reason": self.reason,
            "iterations": self.iterations,
            "regularised": self.regularised,
            "units": units,
            "surface_area": self.surface_area,
            "erected_area": self.erected_area,
            "deviation": self.deviation(),
            **after,
            "design_shape": self.statistics(design=True),
            "options": self.options.to_dict(),
            "material": {"law": type(self.material).__name__, **self.material.parameters},
            "thickness": self.thickness,
            "panels": self.panels,
            "nodes": self.mesh.num_points,
            "cells": self.mesh.num_cells,
            "held_nodes": int(self.held.sum()),
            "linear_solver": self.linear_solver,
            "elapsed_seconds": self.elapsed,
        }
        if self.cables is not None:
            out["cables"] = {
                "segments": len(self.cables.segments),
                "stiffness": self.cables.stiffness,
                "force_min": float(self.cable_tension.min()),
                "force_max": float(self.cable_tension.max()),
            }
        out["history"] = [
            {"iteration": r.iteration, "relative_residual": r.relative_residual, "energy": r.energy}
            for r in self.history
        ]
        return out


@takes_options(ErectionOptions)
@quiet_blas()
def erect(
    source: Any,
    material: Hyperelastic | None = None,
    thickness: float | None = None,
    *,
    solver: SolveOptions | None = None,
    options: ErectionOptions | None = None,
    start: np.ndarray | None = None,
    callback: Callable[[IterationRecord], None] | None = None,
    primer: Callable[[np.ndarray], np.ndarray] | None = None,
    **settings: Any,
) -> ErectionResult:
    """Build the structure from its patterns and solve for the shape it settles into.

    Parameters
    ----------
    source
        A :class:`vares.PatternResult`, a structure's result (:func:`vares.solve_structure`),
        a list of results or of :class:`Pattern` (one per panel).
    material, thickness
        The law and thickness (default: those of the first result; required for patterns).
    solver
        Tolerance, iteration limit and linear solver (default: the first result's options).
    start
        Positions ``(n, 3)`` of the welded nodes (numbered as ``ErectionResult.mesh``) to start
        from instead of the design shape; held nodes stay at their design positions.
    callback
        Called with every Newton iteration's record (progress display).
    primer
        A solve with the factorised tangent of a nearby erected state (free dofs, as
        ``ErectionResult.context``'s): Newton's steps are solved by conjugate gradients
        preconditioned by it while that takes a few iterations
        (:meth:`~vares.solver.reuse.ReusingSolver.prime`).
    options, settings
        :class:`ErectionOptions` and any of its fields as keywords (listed below).

    Returns
    -------
    ErectionResult
        Always returned; ``converged`` and ``reason`` tell whether and why not.
    """
    (options,) = split_settings(settings, [options or ErectionOptions()])
    started = time.perf_counter()
    material, thickness, solver = erection_defaults(source, material, thickness, solver)
    structure = build_structure(patterns_of(source), thickness, options)
    mesh, design, held = structure.mesh, structure.mesh.points, structure.held
    problem = ErectionProblem(
        design,
        structure.blocks,
        material,
        thickness,
        wrinkling=options.wrinkling,
        regularisation=options.regularisation,
        cables=structure.cables,
        pressure=options.pressure,
    )
    ctx = _context(problem, held, solver, callback, options.erection_iterations)
    if primer is not None:
        ctx.systems.prime(primer, PRIMED_ITERATIONS)
    x, path, reason = design.copy(), [], None
    if start is not None:
        x[~held] = _checked_start(start, design)[~held]
        inverted = problem.inverted_cells(x)
        if inverted.size:
            reason = f"the start turns {describe_cells(inverted)} over"
    regularised = False
    if reason is None:
        try:
            x, path, reason, regularised = _settle(problem, x, ctx)
        except WrinklingError as exc:
            reason = str(exc)
    problem.film_in_energy = False  # the law's forces, whichever problem was solved
    fields = _fields(problem, x, structure, relaxed=options.wrinkling)
    if reason is None:
        reason = _not_in_equilibrium(
            problem, x, ctx, taut=not fields["state"].any(), film=regularised
        )
    normals, node_areas = node_normals(mesh)
    solver_name = ctx.linear_solver.name
    # the result keeps the dof map and tolerances, not the last tangent's factors (at 1M
    # triangles a factorisation holds gigabytes): a fresh solver of the same kind
    ctx.linear_solver = get_solver(solver_name)
    ctx.systems = ReusingSolver(ctx.linear_solver)
    return ErectionResult(
        mesh=mesh,
        erected_points=x,
        converged=reason is None,
        reason=reason,
        history=ctx.history,
        steps=ctx.steps,
        strategy=path,
        linear_solver=solver_name,
        elapsed=time.perf_counter() - started,
        options=options,
        material=material,
        thickness=float(thickness),
        displacement=x - design,
        normal_deviation=np.einsum("ni,ni->n", x - design, normals),
        node_areas=node_areas,
        fields=fields,
        design_fields=LazyFields(lambda: _fields(problem, design, structure, relaxed=False)),
        intended=structure.intended,
        held=held,
        cables=structure.cables,
        cable_tension=problem.cable_tension(x),
        panels=structure.names,
        node_maps=structure.welded.node_maps,
        cell_ids=structure.panel_cells,
        problem=problem,
        structure=structure,
        context=ctx,
        regularised=regularised,
    )


def _settle(problem: ErectionProblem, x: np.ndarray, ctx: NewtonContext):
    """Newton's method on the law itself (the film in the tangent only); where it stalls (the
    tension field's equilibria are not isolated where cells wrinkle or hang slack: Newton's steps
    circle them), on the regularised energy with the film in it, from where it stopped:
    ``(x, attempts, reason of failure or None, regularised)``."""
    fallback = problem.wrinkling and problem.tension > 0
    first = _ATTEMPTS[:1] if fallback else _ATTEMPTS
    x, path, reason = follow_plan(problem, x, None, first, ctx, damping=1.0)
    if reason is None or not fallback:
        return x, path, reason, False
    problem.film_in_energy = True
    x, more, reason = follow_plan(problem, x, None, _REGULARISED, ctx, damping=1.0)
    return x, path + more, reason, True


def erection_defaults(
    source: Any,
    material: Hyperelastic | None,
    thickness: float | None,
    solver: SolveOptions | None,
) -> tuple[Hyperelastic, float, SolveOptions]:
    """Material, thickness and solver options of an erection of ``source``: as given, or those
    of the first pattern's solve."""
    first = source if isinstance(source, PatternResult) else getattr(source, "results", source)
    first = first[0] if isinstance(first, list | tuple) else first
    solved = isinstance(first, PatternResult)
    if material is None:
        if not solved:
            raise ValueError("erecting patterns needs the material")
        material = first.material
    if thickness is None:
        thickness = first.thickness if solved else 1.0
    if solver is None:
        solver = first.options if solved else SolveOptions()
    return material, thickness, solver


def _context(
    problem: ErectionProblem, held, solver: SolveOptions, callback, max_iterations: int
) -> NewtonContext:
    """The Newton context of an erection: supports held, the solve's tolerance and linear
    solver, the erection's own iteration limit."""
    material = problem.material
    return NewtonContext(
        assembler=dof_map(problem.connectivity, np.repeat(~held, 3)),
        linear_solver=get_solver(solver.linear_solver),
        residual_tolerance=solver.tolerance * problem.force_scale,
        energy_noise=ENERGY_NOISE
        * material.stiffness_scale
        * problem.thickness
        * problem.reference_area,
        force_scale=problem.force_scale,
        max_iterations=max_iterations,
        history=[],
        steps=[],
        callback=callback,
        round_off_regime=ROUND_OFF_REGIME,
        loosest_forcing=ETA_MAX_KINKED if problem.wrinkling else ETA_MAX,
        stall_window=STALL_WINDOW if problem.wrinkling else None,
        squeezed=SQUEEZED_MEMBRANE,
    )


def _not_in_equilibrium(
    problem: ErectionProblem, x, ctx: NewtonContext, taut: bool, film: bool = False
) -> str | None:
    """Why ``x`` is no equilibrium, or None: the residual of the energy solved for (the relaxed
    law's) and, where no cell wrinkles or hangs slack, that of the law as it is (the two agree
    there) must be within the tolerance, or the round-off floor Newton's method stopped at; with
    ``film`` (the regularised energy was solved), within that plus the film's own forces."""
    bound = max(ctx.residual_tolerance, ctx.round_off_regime * ctx.force_scale)
    if film:
        bound += 1.01 * _film_residual(problem, x, ctx)
    laws = [problem.wrinkling] + ([False] if taut and problem.wrinkling else [])
    for relaxed in laws:
        evaluation = problem.evaluate(x, order=1, relaxed=relaxed)
        residual = float(np.linalg.norm(ctx.residual(ctx.assembler.vector(evaluation.gradients))))
        if not residual <= bound:
            law = "tension-field" if relaxed else "elastic"
            return (
                f"the state found is no equilibrium of the {law} law: residual "
                f"{residual / ctx.force_scale:.3g} of the stiffness (at most "
                f"{bound / ctx.force_scale:.3g})"
            )
    return None


def _film_residual(problem: ErectionProblem, x, ctx: NewtonContext) -> float:
    """The norm of the film's nodal forces at ``x`` (free dofs)."""
    forces = []
    for in_energy in (True, False):
        problem.film_in_energy = in_energy
        evaluation = problem.evaluate(x, order=1)
        forces.append(ctx.residual(ctx.assembler.vector(evaluation.gradients)))
    problem.film_in_energy = False
    return float(np.linalg.norm(forces[0] - forces[1]))


def _checked_start(start, design: np.ndarray) -> np.ndarray:
    start = np.asarray(start, dtype=float)
    if start.shape != design.shape or not np.all(np.isfinite(start)):
        raise ValueError(f"start must have shape {design.shape} and be finite; got {start.shape}")
    return start


def _fields(problem, x, structure: Structure, *, relaxed: bool) -> dict[str, np.ndarray]:
    mesh, intended = structure.mesh, structure.intended
    fields = membrane_forces(problem, x, structure.block_cells, mesh.num_cells, relaxed=relaxed)
    fields["warp_stress_difference"] = fields["warp_stress"] - intended[:, 0]
    fields["fill_stress_difference"] = fields["fill_stress"] - intended[:, 1]
    fields["surface_area"] = mesh.cell_areas()
    return fields
