"""Whole structures: several panels, the seams between them, and patterns whose seams match.

A membrane is welded from panels (strips of roll width), a composite part laid up from several
plies. Neighbouring panels share a seam; welded together, its two sides must have the same
length. Here a structure is a list of :class:`Panel`. Seams are found from boundary nodes that
coincide in 3D (:func:`find_seams`); :func:`solve_structure` patterns every panel and, with seam
matching, solves all panels as one problem in which every seam segment (the edge between two
consecutive seam nodes) has the same length in both patterns:

    minimise Σ_panels Π_p(X_p)   subject to   |ΔX_a|² − |ΔX_b|² = 0 for every seam segment,

by Newton's method on the Lagrangian (the KKT system, with the exact Hessians of the energies
and of the constraints), started from the independently solved panels.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .assembly import Assembler
from .linalg import SingularMatrixError, get_solver
from .materials import Fibres, Hyperelastic
from .mesh import MeshError, SurfaceMesh
from .problem import Problem
from .solver import PatternResult, _rigid_modes, _step_bound, solve

__all__ = [
    "Panel",
    "Seam",
    "SeamReport",
    "StructureResult",
    "find_seams",
    "roll_width_check",
    "solve_structure",
    "split_panels",
]


@dataclass(frozen=True)
class Panel:
    """A named panel of a structure."""

    name: str
    mesh: SurfaceMesh


@dataclass(frozen=True)
class Seam:
    """A seam between panels ``first`` and ``second``: matching node chains ``(k + 1,)`` in
    each panel's own numbering, in the same order along the seam (``k`` segments)."""

    first: int
    second: int
    nodes_first: np.ndarray
    nodes_second: np.ndarray

    @property
    def segments(self) -> int:
        return len(self.nodes_first) - 1


@dataclass(frozen=True)
class SeamReport:
    """Length of a seam on each side before and after matching (pattern units)."""

    first: str
    second: str
    segments: int
    length_first_before: float
    length_second_before: float
    length_first_after: float
    length_second_after: float
    max_segment_mismatch_after: float

    @property
    def mismatch_before(self) -> float:
        """Relative length difference of the two sides before matching."""
        return abs(self.length_first_before - self.length_second_before) / self.length_first_before

    @property
    def mismatch_after(self) -> float:
        return abs(self.length_first_after - self.length_second_after) / self.length_first_after


@dataclass
class StructureResult:
    """Patterns of all panels, the seams and what matching them cost."""

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
    history: list[tuple[int, float, float]] = field(default_factory=list)
    elapsed: float = 0.0

    @property
    def energy_price(self) -> float:
        """Energy of matching the seams: matched minus independent total energy."""
        return self.energy - self.energy_independent


def split_panels(
    mesh: SurfaceMesh, panel_ids: np.ndarray, names: dict[int, str] | None = None
) -> list[Panel]:
    """Split a mesh into panels by a per-cell id (global cell order); each panel is validated
    as a surface of its own and keeps its nodes' coordinates (shared nodes are duplicated)."""
    panel_ids = np.asarray(panel_ids).ravel()
    if panel_ids.shape != (mesh.num_cells,):
        raise MeshError(
            f"panel ids must have one value per cell ({mesh.num_cells}); got {panel_ids.size}"
        )
    if not np.all(np.equal(np.mod(panel_ids, 1), 0)):
        raise MeshError("panel ids must be integers")
    panels = []
    bounds = np.cumsum([0] + [len(c) for c in mesh.cells.values()])
    for value in np.unique(panel_ids):
        cells = {}
        for (cell_type, block), a, b in zip(
            mesh.cells.items(), bounds[:-1], bounds[1:], strict=True
        ):
            chosen = block[panel_ids[a:b] == value]
            if len(chosen):
                cells[cell_type] = chosen
        used = np.unique(np.concatenate([c.ravel() for c in cells.values()]))
        renumber = np.full(mesh.num_points, -1)
        renumber[used] = np.arange(used.size)
        name = (names or {}).get(int(value), f"panel-{int(value)}")
        try:
            panel_mesh = SurfaceMesh(mesh.points[used], {t: renumber[c] for t, c in cells.items()})
        except MeshError as exc:
            raise MeshError(f"panel {name}: {exc}") from exc
        panels.append(Panel(name, panel_mesh))
    return panels


def find_seams(panels: list[Panel], tolerance: float | None = None) -> list[Seam]:
    """Seams between panels: chains of boundary edges whose end nodes coincide in 3D (within
    ``tolerance``; default 1e-6 × the structure's size) with a boundary edge of another panel."""
    from scipy.spatial import cKDTree

    all_points = np.vstack([p.mesh.points for p in panels])
    size = float(np.ptp(all_points, axis=0).max()) or 1.0
    tolerance = 1e-6 * size if tolerance is None else tolerance
    boundary = [p.mesh.boundary_edges() for p in panels]
    seams = []
    for i, j in itertools.combinations(range(len(panels)), 2):
        nodes_i = np.unique(boundary[i])
        nodes_j = np.unique(boundary[j])
        tree = cKDTree(panels[j].mesh.points[nodes_j])
        distance, index = tree.query(panels[i].mesh.points[nodes_i], distance_upper_bound=tolerance)
        match = {
            int(a): int(nodes_j[k])
            for a, d, k in zip(nodes_i, distance, index, strict=True)
            if np.isfinite(d)
        }
        if len(match) < 2:
            continue
        edges_j = {(int(a), int(b)) for a, b in boundary[j]}
        following = {}
        for a, b in boundary[i]:
            a, b = int(a), int(b)
            if a in match and b in match and (match[b], match[a]) in edges_j:
                following[a] = b  # opposite orientation on the neighbour: a shared edge
        starts = set(following) - set(following.values())
        visited = set()
        chains = []
        for start in sorted(starts) + sorted(set(following) - starts):
            if start in visited:
                continue
            chain = [start]
            visited.add(start)
            node = following[start]
            while True:
                chain.append(node)
                if node not in following or node in visited:
                    break
                visited.add(node)
                node = following[node]
            chains.append(chain)
        for chain in chains:
            nodes = np.array(chain)
            seams.append(Seam(i, j, nodes, np.array([match[n] for n in chain])))
    return seams


def _seam_lengths(coordinates: list[np.ndarray], seam: Seam) -> tuple[np.ndarray, np.ndarray]:
    a = np.linalg.norm(np.diff(coordinates[seam.first][seam.nodes_first], axis=0), axis=1)
    b = np.linalg.norm(np.diff(coordinates[seam.second][seam.nodes_second], axis=0), axis=1)
    return a, b


@dataclass
class _Coupled:
    """Index book-keeping of the coupled problem: dof offsets and constraint rows."""

    problems: list[Problem]
    assemblers: list[Assembler]
    rotation: list[np.ndarray | None]
    offsets: np.ndarray  # free-dof offset of each panel
    seams: list[Seam]

    @property
    def num_free(self) -> int:
        return int(self.offsets[-1])

    def free_index(self, panel: int) -> np.ndarray:
        """Global free-dof index of each dof of a panel (−1 where held)."""
        free = self.assemblers[panel].free
        out = np.full(free.size, -1)
        out[free] = self.offsets[panel] + np.arange(free.sum())
        return out


def _kkt(coupled: _Coupled, coordinates: list[np.ndarray], multipliers: np.ndarray):
    """Gradient of the Lagrangian over the free dofs, constraint values, KKT matrix, energy."""
    blocks, gradient, energy = [], np.zeros(coupled.num_free), 0.0
    for p, (problem, assembler) in enumerate(
        zip(coupled.problems, coupled.assemblers, strict=True)
    ):
        evaluation = problem.evaluate(coordinates[p], order=2)
        energy += evaluation.energy
        g = assembler.vector(evaluation.gradients).ravel()[assembler.free]
        gradient[coupled.offsets[p] : coupled.offsets[p + 1]] = g
        blocks.append(assembler.matrix(evaluation.hessians))
    hessian = sp.block_diag(blocks, format="coo")
    rows, cols, values = [hessian.row], [hessian.col], [hessian.data]
    b_rows, b_cols, b_values, constraint = [], [], [], []
    row = 0
    # rotation rows of anisotropic panels (linear, no curvature)
    for p, rotation in enumerate(coupled.rotation):
        if rotation is None:
            continue
        index = np.arange(coupled.offsets[p], coupled.offsets[p + 1])
        b_rows.append(np.full(index.size, row))
        b_cols.append(index)
        b_values.append(rotation)
        constraint.append(0.0)
        row += 1
    # seam segments: c = |a|² − |b|²
    for seam in coupled.seams:
        sides = []
        for panel, nodes, sign in (
            (seam.first, seam.nodes_first, 1.0),
            (seam.second, seam.nodes_second, -1.0),
        ):
            delta = np.diff(coordinates[panel][nodes], axis=0)  # (k, 2)
            dofs = coupled.free_index(panel).reshape(-1, 2)[nodes]  # (k + 1, 2)
            sides.append((delta, dofs, sign))
        k = seam.segments
        constraint.extend(np.sum(sides[0][0] ** 2, axis=1) - np.sum(sides[1][0] ** 2, axis=1))
        for segment in range(k):
            lam = multipliers[row + segment] if multipliers.size else 0.0
            for delta, dofs, sign in sides:
                d = delta[segment]
                ends = (dofs[segment], dofs[segment + 1])
                for end, direction in zip(ends, (-1.0, 1.0), strict=True):
                    for axis in range(2):
                        if end[axis] >= 0:
                            b_rows.append(np.array([row + segment]))
                            b_cols.append(np.array([end[axis]]))
                            b_values.append(np.array([2.0 * sign * direction * d[axis]]))
                # λ ∇²c: ±2λ [[I, −I], [−I, I]] on the two end nodes
                for (e1, s1), (e2, s2) in itertools.product(
                    zip(ends, (-1.0, 1.0), strict=True), repeat=2
                ):
                    for axis in range(2):
                        if e1[axis] >= 0 and e2[axis] >= 0:
                            rows.append(np.array([e1[axis]]))
                            cols.append(np.array([e2[axis]]))
                            values.append(np.array([2.0 * lam * sign * s1 * s2]))
        row += k
    n, m = coupled.num_free, row
    constraint_matrix = sp.csr_matrix(
        (np.concatenate(b_values), (np.concatenate(b_rows), np.concatenate(b_cols))),
        shape=(m, n),
    )
    lagrangian_hessian = sp.csr_matrix(
        (np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    )
    gradient = gradient + constraint_matrix.T @ multipliers
    matrix = sp.bmat(
        [[lagrangian_hessian, constraint_matrix.T], [constraint_matrix, None]], format="csr"
    )
    return gradient, np.asarray(constraint), matrix, energy, constraint_matrix


def solve_structure(
    panels: list[Panel],
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    match_seams: bool = True,
    seams: list[Seam] | None = None,
    tolerance: float = 1e-10,
    max_iterations: int = 30,
    linear_solver: str | None = None,
    **solve_options,
) -> StructureResult:
    """Pattern every panel; with ``match_seams``, make every seam segment equally long in both
    patterns (module docs). ``solve_options`` go to :func:`vares.solve` for each panel (fibres,
    prestress, strategy …); the panels' rigid modes are held as there."""
    started = time.perf_counter()
    seams = find_seams(panels) if seams is None else seams
    results = [
        solve(p.mesh, material, thickness, linear_solver=linear_solver, **solve_options)
        for p in panels
    ]
    failed = [(p.name, r.reason) for p, r in zip(panels, results, strict=True) if not r.converged]
    independent = float(sum(r.energy for r in results))
    before = [r.material_coordinates for r in results]
    report_lengths = [_seam_lengths(before, s) for s in seams]
    if failed or not match_seams or not seams:
        reason = None if not failed else f"panel {failed[0][0]}: {failed[0][1]}"
        return StructureResult(
            panels,
            results,
            seams,
            _reports(panels, seams, report_lengths, report_lengths),
            False,
            not failed,
            reason,
            independent,
            independent,
            0,
            elapsed=time.perf_counter() - started,
        )

    problems, assemblers, rotations = [], [], []
    for result in results:
        problem = Problem(
            result.mesh, material, thickness, fibres=result.fibres, prestress=result.prestress
        )
        mode = result.orientation if problem.orientation_matters else "fixed"
        mode = "held" if mode == "direction" else mode
        free, rotation = _rigid_modes(result.material_coordinates, mode)
        problems.append(problem)
        assemblers.append(Assembler(result.mesh, free))
        rotations.append(rotation)
    offsets = np.concatenate([[0], np.cumsum([a.num_free for a in assemblers])])
    coupled = _Coupled(problems, assemblers, rotations, offsets, seams)
    coordinates = [x.copy() for x in before]
    count = sum(r is not None for r in rotations) + sum(s.segments for s in seams)
    multipliers = np.zeros(count)
    force_scale = sum(p.force_scale for p in problems)
    lengths = np.concatenate([a for a, _ in report_lengths])
    solver = get_solver(linear_solver)
    history, reason, converged, iteration = [], None, False, 0
    for iteration in range(max_iterations + 1):
        gradient, constraint, matrix, _, _ = _kkt(coupled, coordinates, multipliers)
        residual = float(np.linalg.norm(gradient)) / force_scale
        violation = float(np.abs(constraint[count - lengths.size :]).max() / lengths.min() ** 2)
        history.append((iteration, residual, violation))
        if residual <= tolerance and violation <= 1e-13:
            converged = True
            break
        if iteration == max_iterations:
            reason = f"seam matching: iteration limit ({max_iterations}) reached"
            break
        try:
            solver.factorize(matrix)
            step = solver.solve(-np.concatenate([gradient, constraint]))
        except SingularMatrixError as exc:
            reason = f"seam matching: singular KKT matrix ({exc})"
            break
        dx, dlam = step[: coupled.num_free], step[coupled.num_free :]
        full = []
        alpha = 1.0
        for p, assembler in enumerate(assemblers):
            delta = np.zeros_like(coordinates[p])
            delta.ravel()[assembler.free] = dx[offsets[p] : offsets[p + 1]]
            full.append(delta)
            alpha = min(alpha, 0.9 * _step_bound(problems[p], coordinates[p], delta))
        coordinates = [x + alpha * d for x, d in zip(coordinates, full, strict=True)]
        multipliers = multipliers + alpha * dlam
    after = [_seam_lengths(coordinates, s) for s in seams]
    matched_results = []
    for result, x, problem in zip(results, coordinates, problems, strict=True):
        matched = PatternResult(
            **{
                **result.__dict__,
                "material_coordinates": x,
                "energy": problem.energy(x),
                "_fields": None,
            }
        )
        matched_results.append(matched)
    return StructureResult(
        panels,
        matched_results,
        seams,
        _reports(panels, seams, report_lengths, after),
        True,
        converged,
        reason,
        independent,
        float(sum(r.energy for r in matched_results)),
        iteration,
        history,
        time.perf_counter() - started,
    )


def _reports(panels, seams, before, after) -> list[SeamReport]:
    out = []
    for seam, (a0, b0), (a1, b1) in zip(seams, before, after, strict=True):
        out.append(
            SeamReport(
                panels[seam.first].name,
                panels[seam.second].name,
                seam.segments,
                float(a0.sum()),
                float(b0.sum()),
                float(a1.sum()),
                float(b1.sum()),
                float(np.max(np.abs(a1 - b1) / a1)),
            )
        )
    return out


def roll_width_check(
    results: list[PatternResult], names: list[str], roll_width: float
) -> list[tuple[str, float]]:
    """Panels wider than the usable roll width across the warp: ``(name, width)`` pairs."""
    out = []
    for name, result in zip(names, results, strict=True):
        warp = result.fibres.warp if result.fibres is not None else Fibres.from_angles(0.0).warp
        across = np.array([-warp[1], warp[0]])
        width = float(np.ptp(result.material_coordinates @ across))
        if width > roll_width:
            out.append((name, width))
    return out
