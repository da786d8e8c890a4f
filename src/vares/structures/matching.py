"""Patterns of a whole structure whose seams match.

A membrane is welded from panels (strips of roll width), a composite part laid up from several
plies. Neighbouring panels share a seam; welded together, its two sides must have the same
length. :func:`solve_structure` patterns every panel and, with seam matching, solves all panels as
one problem in which every seam segment (the edge between two consecutive seam nodes) has the
same length in both patterns:

    minimise Σ_panels Π_p(X_p)   subject to   |ΔX_a|² − |ΔX_b|² = 0 for every seam segment,

by Newton's method on the Lagrangian (the KKT system, with the exact Hessians of the energies and
of the constraints, :mod:`vares.structures.coupled`), started from the independently solved
panels: the one Newton driver (:func:`vares.solver.newton.newton`) with exact steps shortened to
keep every cell admissible, as the patterns and the erection use it. It has converged when the
Lagrangian's gradient meets the solve tolerance (relative to the panels' reference force), or
has stalled at its round-off floor (:func:`vares.solver.newton.at_round_off`), and every
segment's two lengths agree to round-off: their difference is at most
:data:`ROUND_OFF` × machine epsilon × the largest pattern coordinate. That is the accuracy the
lengths can be computed to, whatever the cut: a test on the squared lengths relative to the
shortest segment cannot be met on seams with short segments (seams through cells).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..geometry.injectivity import pattern_area_misfit, pattern_overlap
from ..materials import Hyperelastic
from ..options import split_settings, takes_options
from ..solver import IterationRecord, PatternResult, SolveOptions, solve
from ..solver.linear import get_solver, quiet_blas
from ..solver.newton import AssembledDofs, Failure, NewtonContext, newton
from .coupled import KKT, CoupledProblem, SeamMatching
from .options import StructureOptions
from .panels import Panel, width_across_warp
from .seams import Seam, SeamReport, find_seams, seam_lengths, seam_reports

__all__ = [
    "KKT",
    "ROUND_OFF",
    "CoupledProblem",
    "MatchingRecord",
    "SeamMatching",
    "StructureResult",
    "solve_structure",
]

#: Seam segments match when their lengths differ by at most this many machine epsilons times
#: the largest pattern coordinate (the round-off of computing a length from coordinates).
ROUND_OFF = 64


@dataclass(frozen=True)
class MatchingRecord:
    """One iteration of seam matching: the Lagrangian's relative gradient, the largest length
    difference of a seam segment (pattern length units), what round-off allows of it, and the
    step length that led here."""

    iteration: int
    residual: float
    violation: float
    round_off: float
    step_length: float


@dataclass
class StructureResult:
    """Patterns of all panels, the seams and what matching them cost.

    ``converged`` is true only when every panel converged and, with matching, the matching did;
    a panel's result says the same (``converged`` false and the structure's ``reason`` when the
    matching failed). ``too_wide`` lists ``(panel, width)`` of the patterns wider across the warp
    than the roll width (when one is given).
    """

    panels: list[Panel]
    results: list[PatternResult]
    seams: list[Seam]
    seam_reports: list[SeamReport]
    matched: bool
    converged: bool
    reason: str | None
    energy_independent: float
    energy: float
    iterations: int
    history: list[MatchingRecord] = field(default_factory=list)
    elapsed: float = 0.0
    options: SolveOptions = field(default_factory=SolveOptions)
    structure_options: StructureOptions = field(default_factory=StructureOptions)
    too_wide: list[tuple[str, float]] = field(default_factory=list)

    @property
    def energy_price(self) -> float:
        """Energy of matching the seams: matched minus independent total energy."""
        return self.energy - self.energy_independent


@takes_options(SolveOptions, StructureOptions)
@quiet_blas()
def solve_structure(
    panels: Sequence[Panel],
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    seams: list[Seam] | None = None,
    prestress: float | Sequence[float] | None = None,
    panel_prestress: Sequence[Any] | None = None,
    panel_settings: Sequence[Mapping[str, Any]] | None = None,
    options: SolveOptions | None = None,
    structure: StructureOptions | None = None,
    callback: Callable[[IterationRecord], None] | None = None,
    **settings: Any,
) -> StructureResult:
    """Pattern every panel; with ``match_seams``, make every seam segment equally long in both
    patterns (module docs).

    Every panel is solved by :func:`vares.solve` with the same options (fibres, strategy,
    tolerance, iteration limit …); the seam matching uses the same tolerance and iteration limit,
    and holds each panel's rigid modes as its solve did. ``seams`` default to
    :func:`find_seams`; ``prestress`` is uniform (a number or warp, fill[, shear]);
    ``panel_prestress`` gives one prestress per panel instead (each what :func:`vares.solve`
    takes, e.g. one row per cell of the panel: a form-found design's membrane forces).
    ``panel_settings`` change solve options per panel (one mapping per panel, e.g.
    ``{"warp_direction": (0, 1, 0)}`` to give every strip its own warp); each panel's result
    keeps the options it was solved with.
    """
    options, structure = split_settings(
        settings, [options or SolveOptions(), structure or StructureOptions()]
    )
    started = time.perf_counter()
    panels = list(panels)
    seams = find_seams(panels) if seams is None else seams
    if panel_settings is not None and len(panel_settings) != len(panels):
        raise ValueError(
            f"panel_settings needs one mapping per panel ({len(panels)}); got {len(panel_settings)}"
        )
    own = (
        [options.replace(**s) for s in panel_settings]
        if panel_settings
        else [options] * len(panels)
    )
    if panel_prestress is not None and len(panel_prestress) != len(panels):
        raise ValueError(
            f"panel_prestress needs one prestress per panel ({len(panels)}); "
            f"got {len(panel_prestress)}"
        )
    stresses = [prestress] * len(panels) if panel_prestress is None else list(panel_prestress)
    results = [
        solve(p.mesh, material, thickness, prestress=s, options=o, callback=callback)
        for p, o, s in zip(panels, own, stresses, strict=True)
    ]
    independent = float(sum(r.energy for r in results))
    before = [seam_lengths([r.material_coordinates for r in results], s) for s in seams]
    failed = [(p.name, r.reason) for p, r in zip(panels, results, strict=True) if not r.converged]
    out = StructureResult(
        panels,
        results,
        seams,
        seam_reports(panels, seams, before, before),
        False,
        not failed,
        None if not failed else f"panel {failed[0][0]}: {failed[0][1]}",
        independent,
        independent,
        0,
        options=options,
        structure_options=structure,
    )
    if not failed and structure.match_seams and seams:
        out = _match(out, material, thickness, before)
    out.too_wide = _too_wide(out, structure.roll_width)
    out.elapsed = time.perf_counter() - started
    return out


def _too_wide(out: StructureResult, roll_width: float | None) -> list[tuple[str, float]]:
    if roll_width is None:
        return []
    widths = [
        (p.name, width_across_warp(r.material_coordinates, r.fibres.warp))
        for p, r in zip(out.panels, out.results, strict=True)
    ]
    return [(name, width) for name, width in widths if width > roll_width]


def _match(
    out: StructureResult,
    material: Hyperelastic,
    thickness: float,
    before: list[tuple[np.ndarray, np.ndarray]],
) -> StructureResult:
    """Newton on the KKT system from the independent patterns (module docs), by the one
    Newton driver (:func:`vares.solver.newton.newton`, exact steps bounded to keep every cell
    admissible)."""
    options = out.options
    coupled = CoupledProblem.build(out.results, material, thickness, out.seams)
    objective = SeamMatching(coupled, [r.material_coordinates for r in out.results], ROUND_OFF)
    ctx = NewtonContext(
        assembler=AssembledDofs(objective.free),
        linear_solver=get_solver(options.linear_solver),
        residual_tolerance=options.tolerance * coupled.force_scale,
        energy_noise=0.0,
        force_scale=coupled.force_scale,
        max_iterations=options.max_iterations,
        history=[],
        steps=[],
        callback=None,
        accepts=lambda state: objective.matched,
    )
    reason = None
    try:
        state = newton(
            objective,
            objective.start,
            ctx,
            strategy="seam matching",
            step=1,
            tau=1.0,
            method="bounded",
        )
    except Failure as failure:
        reason, state = f"seam matching: {failure.reason}", failure.coordinates
    converged = reason is None
    coordinates, _ = objective.split(state)
    history = [
        MatchingRecord(r.iteration, r.relative_residual, *checked, r.step_length)
        for r, checked in zip(ctx.history, objective.checked, strict=True)
    ]
    after = [seam_lengths(coordinates, s) for s in out.seams]
    results = []
    for panel, result, x, problem in zip(
        out.panels, out.results, coordinates, coupled.problems, strict=True
    ):
        # a matched pattern is checked again: it must still be cuttable in one piece
        overlap = pattern_overlap(result.mesh, x) if converged else None
        misfit = pattern_area_misfit(result.mesh, x) if converged and overlap is None else None
        own_reason = reason if not converged else None
        if overlap is not None:
            own_reason = overlap.describe(result.mesh)
        if misfit is not None:
            own_reason = misfit.describe()
        matched = replace(
            result,
            material_coordinates=x,
            energy=problem.energy(x),
            converged=own_reason is None,
            reason=own_reason,
            overlap=overlap,
            area_misfit=misfit,
            _fields=None,
        )
        results.append(matched)
        if (overlap is not None or misfit is not None) and reason is None:
            reason = f"panel {panel.name}: {own_reason}"
    converged = reason is None
    return replace(
        out,
        results=results,
        seam_reports=seam_reports(out.panels, out.seams, before, after),
        matched=True,
        converged=converged,
        reason=reason,
        energy=float(sum(r.energy for r in results)),
        iterations=len(history) - 1,
        history=history,
    )
