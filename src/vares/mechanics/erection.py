"""The forward (erection) problem: the patterns fixed, the erected 3D positions unknown.

``ErectionProblem`` is an *objective* of :func:`vares.solver.newton.newton`, like
:class:`vares.mechanics.Problem` with the roles swapped: every cell keeps its own panel's pattern
as its stress-free reference, the unknowns are the positions ``x`` ``(n, 3)`` of the nodes of the
welded structure (seam nodes shared), and the energy is

    Π(x) = Σ_cells t ∫ Ψ_rel(C) dA_pattern + Σ_cables E_cable − p V(x)

(:mod:`vares.mechanics.forward`, :mod:`vares.mechanics.wrinkling`, :mod:`vares.mechanics.loads`).
Slack regions carry no stiffness and have no determinate shape (any shape shorter than the
fabric stores no energy), wrinkled ones none across their wrinkles, and where cells switch between
taut, wrinkled and slack the energy has kinks. Newton's tangent is therefore *stabilised*: the
Hessian of a fictitious soap film ``τ (tr C − 2)/2`` of tension ``τ = ε k`` (``k`` the law's
stiffness, ``ε`` = ``regularisation``) is added to it, ``τ Σ_q w ∇_X N_a·∇_X N_b δ_ik``: a
constant matrix (the pattern's Laplacian in each coordinate), positive definite with the supports
held. The film is in the tangent only, never in the energy or the residual: the iteration
converges to an equilibrium of the law itself (a stress-free structure stays on its design), and
near a taut solution the tangent is exact to ``ε``, so Newton's method keeps converging at its
quadratic rate until the residual is far below any tolerance.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.elements import ReferenceElement
from ..materials import Fibres, Hyperelastic, InadmissibleState, MaterialError
from .assembly import Connectivity
from .forward import ReferenceBlock, forward_block, forward_projected_hessian, reference_block
from .loads import cable_terms, pressure_terms
from .problem import first_positive_root
from .wrinkling import relaxed_response

__all__ = ["Cables", "ErectionEvaluation", "ErectionProblem", "MembraneBlock", "membrane_block"]


@dataclass(frozen=True)
class MembraneBlock:
    """Cells of one panel and one cell type: ``cells`` ``(m, nen)`` (welded node numbers), their
    fixed ``reference`` (the panel's pattern), the panel's ``fibres`` and ``frames``
    ``(m, c, 2, 3)``: orthonormal tangent vectors of the design surface at the element's check
    points, against which an erected cell's orientation is measured."""

    element: ReferenceElement
    cells: np.ndarray
    reference: ReferenceBlock
    fibres: Fibres | None
    frames: np.ndarray


def membrane_block(
    element: ReferenceElement,
    cells: np.ndarray,
    pattern_nodes: np.ndarray,
    design_points: np.ndarray,
    thickness: float,
    fibres: Fibres | None,
) -> MembraneBlock:
    """A membrane block from its cells, their pattern coordinates ``(m, nen, 2)`` and the
    design positions ``(n, 3)`` of the welded nodes."""
    j = element.jacobians(design_points, cells, at="check")
    first = j[..., 0] / np.linalg.norm(j[..., 0], axis=-1, keepdims=True)
    normal = np.cross(j[..., 0], j[..., 1])
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    frames = np.stack([first, np.cross(normal, first)], axis=-2)
    reference = reference_block(element, pattern_nodes, thickness)
    if not (reference.weights > 0).all():
        raise ValueError("a pattern cell is inverted or collapsed (det J ≤ 0)")
    return MembraneBlock(element, np.asarray(cells), reference, fibres, frames)


@dataclass(frozen=True)
class Cables:
    """Tension-only edge cable segments: end nodes ``(k, 2)``, unstressed lengths ``(k,)`` and
    the axial stiffness ``EA`` (force)."""

    segments: np.ndarray
    rest_length: np.ndarray
    stiffness: float


@dataclass(frozen=True)
class ErectionEvaluation:
    """Energy and per-block derivatives (membrane blocks, then the cables if any);
    ``jacobian_hessians`` holds ``∂²W/∂F²`` per membrane block, ``cable_tension`` the force in
    every cable segment."""

    energy: float
    cell_energy: list[np.ndarray]
    gradients: list[np.ndarray] | None
    hessians: list[np.ndarray] | None
    jacobian_hessians: list[np.ndarray] | None
    cable_hessian: np.ndarray | None
    cable_tension: np.ndarray | None


class ErectionProblem:
    """Energy of the welded structure erected from its patterns (module docs).

    Parameters
    ----------
    design_points
        Design positions ``(n, 3)`` of the welded nodes (the start, and where supports hold).
    blocks
        The membrane blocks (:func:`membrane_block`).
    material, thickness
        The law (energy per reference volume) and the thickness.
    wrinkling
        Use the tension-field energy (no compression); else the law as it is.
    regularisation
        ``ε``: the tension of the film that stabilises the tangent, relative to the law's
        stiffness (module docs).
    cables
        Edge cables, or None.
    pressure
        Uniform pressure along the cells' normal (force per area); needs every boundary node held.
    """

    def __init__(
        self,
        design_points: np.ndarray,
        blocks: list[MembraneBlock],
        material: Hyperelastic,
        thickness: float = 1.0,
        *,
        wrinkling: bool = True,
        regularisation: float = 1e-6,
        cables: Cables | None = None,
        pressure: float = 0.0,
    ) -> None:
        if material.needs_fibres and any(b.fibres is None for b in blocks):
            raise MaterialError(f"{type(material).__name__} needs fibre directions")
        self.design_points = np.asarray(design_points, dtype=float)
        self.blocks = blocks
        self.material = material
        self.thickness = float(thickness)
        self.wrinkling = wrinkling
        self.tension = float(regularisation) * material.stiffness_scale
        self.cables = cables
        self.pressure = float(pressure)
        cells = {f"membrane-{k}": b.cells for k, b in enumerate(blocks)}
        if cables is not None and len(cables.segments):
            cells["cables"] = cables.segments
        self.connectivity = Connectivity(len(self.design_points), cells)
        self.reference_area = float(sum(b.reference.weights.sum() for b in blocks)) / thickness
        self._wrinkles: dict[int, np.ndarray] = {}  # per block: the wrinkles last found
        self._film = [self._film_hessian(b) for b in blocks] if self.tension > 0 else None
        #: the film in the energy too (a regularised problem, whose slack regions hang taut at
        #: the film's tension), or in the tangent only (module docs)
        self.film_in_energy = False

    def _film_hessian(self, block: MembraneBlock) -> np.ndarray:
        """The film's Hessian ``(m, nen, 3, nen, 3)``: the same for every ``x``."""
        points = block.reference.weights.shape
        unit = np.broadcast_to(self.tension * np.eye(6), (*points, 6, 6))
        return forward_projected_hessian(block.reference, np.ascontiguousarray(unit))

    # ------------------------------------------------------------------ the energy
    def response(
        self, fibres: Fibres | None, relaxed: bool | None = None, block: int | None = None
    ):
        """The response function of :func:`vares.mechanics.forward.forward_block`: the relaxed
        (or plain) law. With ``block``, the wrinkles found at the block's last evaluation are
        the start of the next (Newton's iterates move little)."""
        relaxed = self.wrinkling if relaxed is None else relaxed

        def respond(C, tangent):
            if relaxed and np.isrealobj(C):
                guess = self._wrinkles.get(block)
                if guess is not None and guess.shape != C.shape[:-1]:
                    guess = None
                r = relaxed_response(self.material, C, fibres, tangent=tangent, guess=guess)
                if block is not None:
                    self._wrinkles[block] = r.wrinkle
            else:
                r = self.material.response(C, fibres, tangent=tangent)
            if not self.film_in_energy:
                return r.psi, r.stress, r.tangent
            psi = r.psi + 0.5 * self.tension * (C[..., 0, 0] + C[..., 1, 1] - 2.0)
            return psi, r.stress + self.tension * np.eye(2), r.tangent

        return respond

    def evaluate(
        self,
        x: np.ndarray,
        order: int = 2,
        relaxed: bool | None = None,
        stabilised: bool = True,
    ) -> ErectionEvaluation:
        """Energy (and per-block gradients for ``order ≥ 1``, Hessians for ``order = 2``) at the
        positions ``x`` ``(n, 3)``; ``relaxed``: the tension-field or the plain law (default
        :attr:`wrinkling`); ``stabilised``: the film's stiffness in the Hessians (module docs),
        else the exact ones."""
        energies, gradients, hessians, jacobian_hessians = [], [], [], []
        total = 0.0
        for index, block in enumerate(self.blocks):
            nodes = x[block.cells]
            respond = self.response(block.fibres, relaxed, block=index)
            result = forward_block(block.reference, nodes, respond, order)
            energies.append(result.energy)
            total += np.sum(result.energy).real
            gradient, hessian = result.gradient, result.hessian
            if (
                hessian is not None
                and self._film is not None
                and stabilised
                and not self.film_in_energy
            ):
                hessian += self._film[index]  # (the block's own new array: added in place)
            if self.pressure:
                load = pressure_terms(nodes, self.pressure, order)
                total += np.sum(load[0]).real
                gradient = None if order == 0 else gradient + load[1]
                if order >= 2:
                    hessian += load[2]
            gradients.append(gradient)
            hessians.append(hessian)
            jacobian_hessians.append(result.jacobian_hessian)
        cable_hessian = tension = None
        if "cables" in self.connectivity.cells:
            c = self.cables
            energy, gradient, cable_hessian, tension = cable_terms(
                x[c.segments], c.rest_length, c.stiffness, order
            )
            total += float(energy.sum())
            gradients.append(gradient)
            hessians.append(cable_hessian)
        return ErectionEvaluation(
            float(total),
            energies,
            gradients if order >= 1 else None,
            hessians if order >= 2 else None,
            jacobian_hessians if order >= 2 else None,
            cable_hessian,
            tension,
        )

    def cable_tension(self, x: np.ndarray) -> np.ndarray | None:
        """The force in each cable segment at ``x`` (None without cables)."""
        if "cables" not in self.connectivity.cells:
            return None
        c = self.cables
        return cable_terms(x[c.segments], c.rest_length, c.stiffness, 0)[3]

    def projected_hessians(self, evaluation: ErectionEvaluation) -> list[np.ndarray]:
        """The membrane Hessians made positive semi-definite point by point (with the film's,
        module docs) and the cables' (positive semi-definite already); the pressure's load
        stiffness is left out."""
        out = [
            forward_projected_hessian(b.reference, h)
            for b, h in zip(self.blocks, evaluation.jacobian_hessians, strict=True)
        ]
        if self._film is not None and not self.film_in_energy:
            for h, film in zip(out, self._film, strict=True):
                h += film  # (new arrays: added in place)
        if evaluation.cable_hessian is not None:
            out.append(evaluation.cable_hessian)
        return out

    def energy(self, x: np.ndarray) -> float:
        """Energy at ``x``; ``inf`` where a cell turns over (or a wrinkled state is not found)."""
        if self.inverted_cells(x).size:
            return float("inf")
        try:
            return self.evaluate(x, order=0).energy
        except InadmissibleState:
            return float("inf")

    # ------------------------------------------------------------------ admissibility
    def _tangent_jacobians(self, block: MembraneBlock, x: np.ndarray) -> np.ndarray:
        """``P j`` ``(m, c, 2, 2)``: the erected cell's Jacobian in the design tangent frame at
        the check points; its determinant is positive while the cell keeps its orientation."""
        j = block.element.jacobians(x, block.cells, at="check")
        return block.frames @ j

    def inverted_cells(self, x: np.ndarray) -> np.ndarray:
        """Global (welded) ids of the cells that turned over against the design surface."""
        out, offset = [], 0
        for block in self.blocks:
            pj = self._tangent_jacobians(block, x)
            det = pj[..., 0, 0] * pj[..., 1, 1] - pj[..., 0, 1] * pj[..., 1, 0]
            out.append(offset + np.flatnonzero(~(det > 0).all(axis=1)))
            offset += len(block.cells)
        return np.concatenate(out)

    def admissible_step(self, x: np.ndarray, delta: np.ndarray) -> float:
        """Largest ``α`` keeping every cell of ``x + α delta`` turned as on the design."""
        bound = np.inf
        for block in self.blocks:
            bound = min(
                bound,
                first_positive_root(
                    self._tangent_jacobians(block, x), self._tangent_jacobians(block, delta)
                ),
            )
        return bound

    @property
    def force_scale(self) -> float:
        """Reference force: stiffness × thickness × √(pattern area)."""
        return self.material.stiffness_scale * self.thickness * np.sqrt(self.reference_area)
