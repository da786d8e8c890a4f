"""Forward drape of a given blank onto a mould.

A blank (a rectangle off the roll, or any outline: :mod:`vares.geometry.blank`) is pressed onto
the mould from a seed point outward. The mould is a frictionless contact surface
(:mod:`vares.mechanics.contact`): every node of the blank lies on it and slides on it freely.
The unknowns are the blank's node positions on the mould, the energy is the fabric's membrane
energy with the flat blank as reference (:class:`vares.mechanics.erection.ErectionProblem`: the
erection's kernels, the law as it is), and the solution is the blank's equilibrium on the mould:
no tangential force at any node. Pressed onto the mould the fabric cannot buckle out of it, so
compression costs the law's energy; cells with a compressed direction (a principal membrane
force ≤ 0) are where it would wrinkle once released. The seed node is held at the seed point,
and the node next to it along the warp moves only in the plane of the warp and the normal
there: that fixes the blank's slide and turn, which cost no energy on a surface of
revolution.

**Start.** The kinematic net (:func:`vares.geometry.drape_net.kinematic_net`, the yarn spacing
the blank's) from the seed along the warp: every blank node goes to the net position of its
material point (bilinear in the net's cells). Nodes the net does not reach (beyond a cell
sheared to 90°) go out from the nearest node it does reach along the net's yarns there, and
are smoothed on the mould until no cell faces away from it.

**Newton's method on the mould.** Each iteration solves ``(Tᵀ K T) Δu = −Tᵀ g`` for the nodes'
tangential moves, then puts the moved nodes back onto the mould and halves the step until no
cell faces away from the mould and the residual decreases (the exact tangent, used below a
relative residual of :data:`EXACT_TANGENT_BELOW`: the iteration goes to the equilibrium nearest
the start) or the energy does (Armijo; the point-wise positive semi-definite part of the
tangent, used above it or where the exact step finds nothing). The residual, not the energy,
rules near the start: a fabric with stiff yarns and weak shear pressed onto a doubly curved
mould has lower-energy states than its drape, in which compressed yarns kink in the plane
(Rosen's micro-buckling, at a yarn stress of about G12); a membrane without bending stiffness
has nothing to stop them, and a line search on the energy walks into them.

**Facets.** A triangulated mould is flat in each face and kinked across its edges. A node near
an edge sees a different tangent plane on either side, and the residual stalls at a floor set
by the facets' angles and by how many blank nodes lie on each facet. Where the unbalanced
tangential force is below ``facet_tolerance`` of the forces the cells exert on their nodes (the
root sum of squares over cells), a stall (the residual not halved over :data:`STALL_WINDOW`
iterations, or no step found) ends the iteration as ``facet_limited``; the summary gives the
residual and the unbalanced force reached.

**Trim line and excess.** The mould is extended by a flange beyond its edge
(:func:`vares.geometry.mould.mould_surface`) on which the blank's excess lies. The trim line is
where the blank crosses the mould's edge, found on the flat blank as the zero level of the
mould's outwardness (:mod:`vares.analysis.blank_trim`); the **net** part of the blank lies on
the mould, the **excess** beyond its edge.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..geometry.blank import Blank
from ..geometry.drape_net import kinematic_net, yarn_shear
from ..geometry.elements import ELEMENTS
from ..geometry.mesh import SurfaceMesh
from ..geometry.mould import Mould, mould_surface
from ..materials import Fibres, Hyperelastic, InadmissibleState
from ..mechanics.assembly import Assembler
from ..mechanics.contact import SlidingNodes, turned_over
from ..mechanics.erection import ErectionProblem, membrane_block
from ..mechanics.forward import deformation_gradients
from ..solver.linear import SingularMatrixError, get_solver, quiet_blas
from .blank_start import kinematic_start
from .blank_trim import trim_blank
from .erection_fields import membrane_forces

__all__ = ["BlankDrapeResult", "drape_blank"]

#: Below this relative residual the exact tangent (quadratic convergence), above it its
#: point-wise positive semi-definite part (a descent direction however far from the solution).
EXACT_TANGENT_BELOW = 1e-2
#: Energy changes below this × stiffness × thickness × blank area are round-off.
ENERGY_NOISE = 1e-13
#: Halvings of a step before the line search gives up.
HALVINGS = 30
#: Iterations without halving the residual after which, below the facet tolerance, the state
#: is the equilibrium the mould's facets allow (module docs).
STALL_WINDOW = 4


@dataclass(frozen=True)
class BlankDrapeResult:
    """A blank draped onto a mould.

    ``positions`` ``(n, 3)``: the blank's nodes on the mould (blank node order), ``faces``
    ``(n,)`` the extended mould's faces they lie in, ``start`` ``(n, 3)`` the kinematic start.
    Per blank cell ``(m,)``: ``shear_angle`` (degrees, the decrease of the angle between the
    +warp and +fill yarns from 90°), ``warp_strain`` and ``fill_strain`` (yarn stretch − 1),
    ``warp`` and ``fill`` ``(m, 3)`` (unit yarn directions), ``state`` (0 taut, 1 one principal
    membrane force ≤ 0: compressed one way, 2 both or stress-free:
    :func:`vares.analysis.erection_fields.membrane_forces`), ``stress_min``, and
    ``on_part`` (the cell's centroid lies on the mould, not on the flange). Per node
    ``outwardness`` ``(n,)`` (< 0 on the mould). ``trim_lines``: polylines ``(k, 2)`` on the flat
    blank where it crosses the mould's edge; ``net_area`` and ``excess_area``: the blank's area
    on the mould and beyond its edge. ``history``: per iteration the relative residual, the
    unbalanced tangential force (a share of the cells' forces), the energy and the step length.
    ``converged``: an equilibrium to ``tolerance``, or (``facet_limited``) stopped by the mould's
    facets below ``facet_tolerance`` (module docs).
    """

    blank: Blank
    mould: Mould
    positions: np.ndarray
    faces: np.ndarray
    start: np.ndarray
    converged: bool
    reason: str | None
    facet_limited: bool
    history: list[dict[str, float]]
    elapsed: float
    material: Hyperelastic
    thickness: float
    shear_angle: np.ndarray
    warp_strain: np.ndarray
    fill_strain: np.ndarray
    warp: np.ndarray
    fill: np.ndarray
    state: np.ndarray
    stress_min: np.ndarray
    on_part: np.ndarray
    outwardness: np.ndarray
    trim_lines: list[np.ndarray]
    net_area: float
    excess_area: float
    problem: ErectionProblem | None = field(default=None, repr=False, compare=False)

    @property
    def iterations(self) -> int:
        return max(0, len(self.history) - 1)

    @property
    def draped_mesh(self) -> SurfaceMesh:
        """The blank as it lies on the mould."""
        return SurfaceMesh(self.positions, {"triangle": self.blank.triangles})

    def summary(self) -> dict[str, object]:
        """The key figures (the contract of ``blank.json``)."""
        areas = self.draped_mesh.cell_areas()
        part = self.on_part

        def share(mask: np.ndarray) -> float:
            return float(areas[mask & part].sum() / max(areas[part].sum(), 1e-300))

        shear = np.abs(self.shear_angle[part]) if part.any() else np.zeros(1)
        return {
            "converged": self.converged,
            "reason": self.reason,
            "facet_limited": self.facet_limited,
            "iterations": self.iterations,
            "relative_residual": self.history[-1]["relative_residual"],
            "unbalanced_force": self.history[-1]["unbalanced"],
            "elapsed_seconds": self.elapsed,
            "blank_nodes": len(self.positions),
            "blank_cells": len(self.blank.triangles),
            "blank_area": self.blank.area,
            "net_area": self.net_area,
            "excess_area": self.excess_area,
            "trim_lines": len(self.trim_lines),
            "max_shear_on_part": float(shear.max()),
            "mean_shear_on_part": float(np.average(shear, weights=areas[part]))
            if part.any()
            else 0.0,
            "max_shear": float(np.abs(self.shear_angle).max()),
            "compressed_fraction_on_part": share(self.state != 0),
            "max_yarn_strain": float(max(self.warp_strain.max(), self.fill_strain.max())),
            "min_yarn_strain": float(min(self.warp_strain.min(), self.fill_strain.min())),
            "material": {"law": type(self.material).__name__, **self.material.parameters},
            "thickness": self.thickness,
            "flange_width": self.mould.flange_width,
        }


@quiet_blas()
def drape_blank(
    mould: SurfaceMesh,
    blank: Blank,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    seed: np.ndarray,
    warp_direction: np.ndarray,
    flange_width: float | None = None,
    tolerance: float = 1e-8,
    facet_tolerance: float = 1e-2,
    max_iterations: int = 100,
    regularisation: float = 1e-6,
) -> BlankDrapeResult:
    """Drape ``blank`` onto ``mould`` from ``seed`` ``(3,)`` (a point on the mould, where the
    blank's seed node goes) with the blank's warp (+x) along ``warp_direction`` ``(3,)`` there
    (projected onto the tangent plane). ``material``: the fabric's law (warp along the blank's x,
    fill along y), ``thickness`` its thickness; ``flange_width``: how far the mould is extended
    beyond its edge for the excess (default: the blank's largest distance from its seed node);
    ``tolerance``: the relative residual (of the stiffness × thickness × √area) that counts as
    equilibrium; ``facet_tolerance``: the unbalanced tangential force, as a share of the forces
    the cells exert on their nodes, that does where the mould's facets stop Newton's method
    (module docs).

    Returns a :class:`BlankDrapeResult` (``converged`` and ``reason`` tell whether and why not).
    Raises ``ValueError`` for a seed off the mould or a start that cannot be made.
    """
    started = time.perf_counter()
    if flange_width is None:
        flange_width = float(
            np.linalg.norm(blank.coordinates - blank.coordinates[blank.seed], axis=1).max()
        )
    surface = mould_surface(mould, flange_width)
    net = kinematic_net(surface.mesh, seed, warp_direction, blank.spacing)
    start, held, guided = kinematic_start(surface, blank, net)
    nodes = SlidingNodes.placed(surface, start, held, guided)
    fibres = Fibres(np.array([1.0, 0.0]), np.array([0.0, 1.0]))
    element = ELEMENTS["triangle"]
    block = membrane_block(
        element,
        blank.triangles,
        blank.coordinates[blank.triangles],
        nodes.positions,
        thickness,
        fibres if material.needs_fibres else None,
    )
    problem = ErectionProblem(
        nodes.positions,
        [block],
        material,
        thickness,
        wrinkling=False,
        regularisation=regularisation,
    )
    nodes, history, reason, facet_limited = _settle(
        problem, nodes, tolerance, facet_tolerance, max_iterations
    )
    fields = _fields(problem, nodes, blank, fibres)
    _, bary, _ = surface.project(nodes.positions)
    outwardness = surface.outward(nodes.faces, bary)
    lines, net_area = trim_blank(blank, outwardness)
    centroid_out = outwardness[blank.triangles].mean(axis=1)
    return BlankDrapeResult(
        blank=blank,
        mould=surface,
        positions=nodes.positions,
        faces=nodes.faces,
        start=start,
        converged=reason is None,
        reason=reason,
        facet_limited=facet_limited,
        history=history,
        elapsed=time.perf_counter() - started,
        material=material,
        thickness=float(thickness),
        on_part=centroid_out < 0,
        outwardness=outwardness,
        trim_lines=lines,
        net_area=net_area,
        excess_area=blank.area - net_area,
        problem=problem,
        **fields,
    )


def _settle(
    problem: ErectionProblem, nodes: SlidingNodes, tolerance: float, facets: float, limit: int
):
    """Newton's method on the mould (module docs): ``(nodes, history, reason or None, whether
    the facets stopped it)``."""
    n = len(nodes.positions)
    assembler = Assembler(problem.connectivity, np.ones(3 * n, dtype=bool), dofs_per_node=3)
    solver = get_solver()
    scale = problem.force_scale
    noise = ENERGY_NOISE * problem.material.stiffness_scale * problem.thickness
    noise *= problem.reference_area
    history: list[dict[str, float]] = []
    for _ in range(limit + 1):
        evaluation = problem.evaluate(nodes.positions, order=2)
        basis = nodes.basis()
        gradient = assembler.vector(evaluation.gradients).ravel()
        residual = basis.T @ gradient
        relative = float(np.linalg.norm(residual)) / scale
        cell_forces = np.sqrt(sum(float(np.sum(g**2)) for g in evaluation.gradients))
        unbalanced = float(np.linalg.norm(residual)) / max(cell_forces, 1e-300)
        history.append(
            {
                "relative_residual": relative,
                "unbalanced": unbalanced,
                "energy": evaluation.energy,
                "step": _last(history),
            }
        )
        residuals = [h["relative_residual"] for h in history]
        if relative <= tolerance:
            return nodes, history, None, False
        if unbalanced <= facets and _stalled(residuals):
            return nodes, history, None, True
        exact = relative < EXACT_TANGENT_BELOW
        try:
            step, exact = _direction(problem, evaluation, assembler, basis, residual, solver, exact)
        except SingularMatrixError as exc:
            return nodes, history, f"singular tangent ({exc})", False
        moved = _line_search(problem, assembler, nodes, basis, step, residual, exact, noise)
        if moved is None and exact:  # the positive semi-definite step may still get on
            step, exact = _direction(problem, evaluation, assembler, basis, residual, solver, False)
            moved = _line_search(problem, assembler, nodes, basis, step, residual, exact, noise)
        if moved is None:
            if unbalanced <= facets:
                return nodes, history, None, True
            return nodes, history, _stuck(unbalanced), False
        nodes, history[-1]["step"] = moved
    return nodes, history, f"iteration limit ({limit}) reached", False


def _stuck(unbalanced: float) -> str:
    return (
        f"no step reduces the residual further; the unbalanced tangential force is "
        f"{unbalanced:.3g} of the cells' forces"
    )


def _stalled(residuals: list[float]) -> bool:
    """The least of the last :data:`STALL_WINDOW` residuals is above half the least before."""
    if len(residuals) <= STALL_WINDOW:
        return False
    return min(residuals[-STALL_WINDOW:]) > 0.5 * min(residuals[:-STALL_WINDOW])


def _last(history: list[dict[str, float]]) -> float:
    return history[-1]["step"] if history else 0.0


def _direction(problem, evaluation, assembler, basis, residual, solver, exact: bool):
    """The Newton step ``(n, 3)`` and whether it is the exact tangent's (else the positive
    semi-definite one's, a descent direction of the energy)."""
    if exact:
        matrix = (basis.T @ assembler.matrix(evaluation.hessians) @ basis).tocsr()
        try:
            solver.factorize(matrix)
            return (basis @ solver.solve(-residual)).reshape(-1, 3), True
        except SingularMatrixError:
            pass
    hessians = problem.projected_hessians(evaluation)
    matrix = (basis.T @ assembler.matrix(hessians) @ basis).tocsr()
    solver.factorize(matrix, definite=True)
    return (basis @ solver.solve(-residual)).reshape(-1, 3), False


def _line_search(
    problem, assembler, nodes: SlidingNodes, basis, step, residual, exact: bool, noise
):
    """Halve the step until no cell turns over and the energy decreases enough (Armijo; a
    step of the positive semi-definite tangent) or the residual does (a step of the exact
    tangent, module docs): ``(nodes, step length)`` or None. ``basis``: ``nodes.basis()``."""
    energy = _energy(problem, nodes)
    slope = residual @ (basis.T @ step.ravel())
    norm = float(np.linalg.norm(residual))
    alpha = 1.0
    for _ in range(HALVINGS):
        trial = nodes.moved(alpha * step)
        value = _energy(problem, trial)
        if np.isfinite(value):
            if exact:
                if _residual_norm(problem, assembler, trial) <= (1.0 - 1e-4 * alpha) * norm:
                    return trial, alpha
            elif value <= energy + 1e-4 * alpha * slope or (
                abs(value - energy) <= noise and alpha == 1.0
            ):
                return trial, alpha
        alpha *= 0.5
    return None


def _residual_norm(problem, assembler, nodes: SlidingNodes) -> float:
    evaluation = problem.evaluate(nodes.positions, order=1)
    gradient = assembler.vector(evaluation.gradients).ravel()
    return float(np.linalg.norm(nodes.basis().T @ gradient))


def _energy(problem: ErectionProblem, nodes: SlidingNodes) -> float:
    triangles = problem.blocks[0].cells
    if turned_over(nodes.positions, nodes.faces, triangles, nodes.mould.normals).size:
        return float("inf")
    try:
        return problem.evaluate(nodes.positions, order=0).energy
    except InadmissibleState:
        return float("inf")


def _fields(problem, nodes: SlidingNodes, blank: Blank, fibres: Fibres):
    """Per blank cell: yarn directions, strains and shear, and the membrane state."""
    block = problem.blocks[0]
    F = deformation_gradients(
        np.ascontiguousarray(nodes.positions[block.cells]), block.reference.gradients
    ).mean(axis=1)  # (m, 3, 2)
    warp, fill = F @ fibres.warp, F @ fibres.fill
    m = len(blank.triangles)
    forces = membrane_forces(problem, nodes.positions, [np.arange(m)], m, relaxed=False)
    warp_length, fill_length = np.linalg.norm(warp, axis=1), np.linalg.norm(fill, axis=1)
    return {
        "shear_angle": yarn_shear(warp, fill),
        "warp_strain": warp_length - 1.0,
        "fill_strain": fill_length - 1.0,
        "warp": warp / warp_length[:, None],
        "fill": fill / fill_length[:, None],
        "state": forces["state"].astype(int),
        "stress_min": forces["stress_min"],
    }
