"""Patterns of a whole structure whose seams match.

A membrane is welded from panels (strips of roll width), a composite part laid up from several
plies. Neighbouring panels share a seam; welded together, its two sides must have the same
length. :func:`solve_structure` patterns every panel and, with seam matching, solves all panels as
one problem in which every seam segment (the edge between two consecutive seam nodes) has the
same length in both patterns:

    minimise Σ_panels Π_p(X_p)   subject to   |ΔX_a|² − |ΔX_b|² = 0 for every seam segment,

by Newton's method on the Lagrangian (the KKT system, with the exact Hessians of the energies and
of the constraints), started from the independently solved panels. It has converged when the
Lagrangian's gradient meets the solve tolerance (relative to the panels' reference force), or
has stalled at its round-off floor (:func:`vares.solver.newton.at_round_off`), and every
segment's two lengths agree to round-off: their difference is at most
:data:`ROUND_OFF` × machine epsilon × the largest pattern coordinate. That is the accuracy the
lengths can be computed to, whatever the cut: a test on the squared lengths relative to the
shortest segment cannot be met on seams with short segments (seams through cells).
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp

from ..geometry.injectivity import pattern_area_misfit, pattern_overlap
from ..materials import Hyperelastic
from ..mechanics.assembly import Assembler
from ..mechanics.problem import Problem
from ..mechanics.rigid import rigid_modes
from ..options import split_settings, takes_options
from ..solver import IterationRecord, PatternResult, SolveOptions, solve
from ..solver.linear import SingularMatrixError, get_solver
from ..solver.newton import at_round_off
from .options import StructureOptions
from .panels import Panel, width_across_warp
from .seams import Seam, SeamReport, find_seams, seam_lengths, seam_reports

__all__ = [
    "KKT",
    "ROUND_OFF",
    "CoupledProblem",
    "MatchingRecord",
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
    """Newton on the KKT system from the independent patterns (module docs)."""
    options = out.options
    coupled = CoupledProblem.build(out.results, material, thickness, out.seams)
    coordinates = [r.material_coordinates.copy() for r in out.results]
    multipliers = np.zeros(coupled.num_constraints)
    solver = get_solver(options.linear_solver)
    history: list[MatchingRecord] = []
    reason, converged, alpha = None, False, 0.0
    for iteration in range(options.max_iterations + 1):
        gradient, constraint, matrix, _ = coupled.kkt(coordinates, multipliers)
        residual = float(np.linalg.norm(gradient)) / coupled.force_scale
        violation = coupled.violation(coordinates)
        round_off = ROUND_OFF * np.finfo(float).eps * max(np.abs(x).max() for x in coordinates)
        history.append(MatchingRecord(iteration, residual, violation, round_off, alpha))
        stalled = at_round_off([h.residual for h in history], [h.step_length for h in history])
        if (residual <= options.tolerance or stalled) and violation <= round_off:
            converged = True
            break
        if iteration == options.max_iterations:
            reason = f"seam matching: iteration limit ({options.max_iterations}) reached"
            break
        try:
            solver.factorize(matrix)
            step = solver.solve(-np.concatenate([gradient, constraint]))
        except SingularMatrixError as exc:
            reason = f"seam matching: singular KKT matrix ({exc})"
            break
        dx, dlam = step[: coupled.num_free], step[coupled.num_free :]
        deltas = coupled.full(dx)
        alpha = min(
            [1.0]
            + [
                0.9 * p.admissible_step(x, d)
                for p, x, d in zip(coupled.problems, coordinates, deltas, strict=True)
            ]
        )
        coordinates = [x + alpha * d for x, d in zip(coordinates, deltas, strict=True)]
        multipliers = multipliers + alpha * dlam
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


class KKT(NamedTuple):
    """The coupled problem at one point: the Lagrangian's gradient over the free dofs, the
    constraint values (rotation rows first, then every seam segment), the KKT matrix
    ``[[∇²L, Bᵀ], [B, 0]]`` and the total energy."""

    gradient: np.ndarray
    constraint: np.ndarray
    matrix: sp.csr_matrix
    energy: float


@dataclass
class CoupledProblem:
    """The coupled problem: each panel's energy and free dofs, and one constraint row per
    rotation-held panel and per seam segment."""

    problems: list[Problem]
    assemblers: list[Assembler]
    rotation: list[np.ndarray | None]
    offsets: np.ndarray  # free-dof offset of each panel
    seams: list[Seam]
    free_index: list[np.ndarray]  # per panel (n, 2): global free dof of each node coordinate, −1

    @classmethod
    def build(
        cls, results: list[PatternResult], material: Hyperelastic, thickness: float, seams
    ) -> CoupledProblem:
        problems, assemblers, rotations = [], [], []
        for result in results:
            problem = Problem(
                result.mesh, material, thickness, fibres=result.fibres, prestress=result.prestress
            )
            mode = result.orientation if problem.orientation_matters else "fixed"
            free, rotation = rigid_modes(
                result.material_coordinates, "held" if mode == "direction" else mode
            )
            problems.append(problem)
            assemblers.append(Assembler(result.mesh, free))
            rotations.append(rotation)
        offsets = np.concatenate([[0], np.cumsum([a.num_free for a in assemblers])])
        free_index = []
        for assembler, offset in zip(assemblers, offsets, strict=False):
            index = np.full(assembler.free.size, -1)
            index[assembler.free] = offset + np.arange(assembler.num_free)
            free_index.append(index.reshape(-1, 2))
        return cls(problems, assemblers, rotations, offsets, seams, free_index)

    @property
    def num_free(self) -> int:
        return int(self.offsets[-1])

    @property
    def num_rotations(self) -> int:
        return sum(r is not None for r in self.rotation)

    @property
    def num_constraints(self) -> int:
        return self.num_rotations + sum(s.segments for s in self.seams)

    @property
    def force_scale(self) -> float:
        return float(sum(p.force_scale for p in self.problems))

    def full(self, dx: np.ndarray) -> list[np.ndarray]:
        """Per-panel coordinate changes ``(n, 2)`` from a step over the free dofs."""
        out = []
        for p, assembler in enumerate(self.assemblers):
            delta = np.zeros(assembler.free.size)
            delta[assembler.free] = dx[self.offsets[p] : self.offsets[p + 1]]
            out.append(delta.reshape(-1, 2))
        return out

    def violation(self, coordinates: list[np.ndarray]) -> float:
        """Largest length difference of a seam segment's two sides."""
        worst = 0.0
        for seam in self.seams:
            a, b = seam_lengths(coordinates, seam)
            worst = max(worst, float(np.abs(a - b).max()))
        return worst

    def kkt(self, coordinates: list[np.ndarray], multipliers: np.ndarray) -> KKT:
        """The coupled problem at ``coordinates`` (one ``(n, 2)`` per panel) and
        ``multipliers``."""
        blocks, gradient, energy = [], np.zeros(self.num_free), 0.0
        for p, (problem, assembler) in enumerate(zip(self.problems, self.assemblers, strict=True)):
            evaluation = problem.evaluate(coordinates[p], order=2)
            energy += evaluation.energy
            g = assembler.vector(evaluation.gradients).ravel()[assembler.free]
            gradient[self.offsets[p] : self.offsets[p + 1]] = g
            blocks.append(assembler.matrix(evaluation.hessians))
        hessian = sp.block_diag(blocks, format="coo")
        rows, cols, values = [hessian.row], [hessian.col], [hessian.data]
        b_rows, b_cols, b_values, constraint = [], [], [], []
        row = 0
        for p, rotation in enumerate(self.rotation):  # linear rows: no curvature
            if rotation is None:
                continue
            b_rows.append(np.full(rotation.size, row))
            b_cols.append(np.arange(self.offsets[p], self.offsets[p + 1]))
            b_values.append(rotation)
            constraint.append(np.zeros(1))
            row += 1
        for seam in self.seams:
            k = seam.segments
            segment_rows = row + np.arange(k)
            lam = multipliers[segment_rows] if multipliers.size else np.zeros(k)
            squared = []
            for panel, nodes, sign in (
                (seam.first, seam.nodes_first, 1.0),
                (seam.second, seam.nodes_second, -1.0),
            ):
                delta = np.diff(coordinates[panel][nodes], axis=0)  # (k, 2)
                ends = (self.free_index[panel][nodes[:-1]], self.free_index[panel][nodes[1:]])
                squared.append(np.sum(delta**2, axis=1))
                _constraint_terms(
                    (b_rows, b_cols, b_values),
                    (rows, cols, values),
                    segment_rows,
                    ends,
                    delta,
                    sign,
                    lam,
                )
            constraint.append(squared[0] - squared[1])
            row += k
        n, m = self.num_free, row
        jacobian = _csr(b_rows, b_cols, b_values, (m, n))
        lagrangian_hessian = _csr(rows, cols, values, (n, n))
        gradient = gradient + jacobian.T @ multipliers
        matrix = sp.bmat([[lagrangian_hessian, jacobian.T], [jacobian, None]], format="csr")
        return KKT(gradient, np.concatenate(constraint), matrix, energy)


def _constraint_terms(jacobian, hessian, segment_rows, ends, delta, sign, lam) -> None:
    """Add one side of a seam's segments: ``c = ±|Δ|²`` has the gradient ``±2Δ`` at the end
    node and ``∓2Δ`` at the start node, and ``λ ∇²c = ±2λ [[I, −I], [−I, I]]`` per axis."""
    (b_rows, b_cols, b_values), (rows, cols, values) = jacobian, hessian
    for end, direction in zip(ends, (-1.0, 1.0), strict=True):
        for axis in range(2):
            dof = end[:, axis]
            kept = dof >= 0
            b_rows.append(segment_rows[kept])
            b_cols.append(dof[kept])
            b_values.append(2.0 * sign * direction * delta[kept, axis])
    for (e1, s1), (e2, s2) in itertools.product(zip(ends, (-1.0, 1.0), strict=True), repeat=2):
        for axis in range(2):
            kept = (e1[:, axis] >= 0) & (e2[:, axis] >= 0)
            rows.append(e1[kept, axis])
            cols.append(e2[kept, axis])
            values.append(2.0 * sign * s1 * s2 * lam[kept])


def _csr(rows, cols, values, shape) -> sp.csr_matrix:
    return sp.csr_matrix(
        (np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))), shape=shape
    )
