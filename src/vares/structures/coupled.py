"""The coupled problem of seam matching: every panel's energy and the seams' equal lengths as
one KKT system (:class:`CoupledProblem`), and that system as an objective of the one Newton
driver, :func:`vares.solver.newton.newton` (:class:`SeamMatching`); see
:mod:`vares.structures.matching`."""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ..materials import Hyperelastic
from ..mechanics.assembly import Assembler
from ..mechanics.problem import Problem
from ..mechanics.rigid import rigid_modes
from ..solver import PatternResult
from .seams import Seam, seam_lengths

__all__ = ["KKT", "CoupledProblem", "SeamMatching"]


class SeamMatching:
    """The coupled problem as an objective of :func:`vares.solver.newton.newton`: its state is
    one vector of every panel's coordinates (``(n_p, 2)`` each, raveled in turn) and the
    constraints' multipliers; an evaluation is the KKT residual (the Lagrangian's gradient,
    then the constraint values) and matrix, and records the largest seam length difference
    with what round-off allows of it (:attr:`checked`: ``round_off`` machine epsilons times
    the largest pattern coordinate)."""

    def __init__(
        self, coupled: CoupledProblem, coordinates: list[np.ndarray], round_off: float
    ) -> None:
        self.coupled = coupled
        self.round_off = round_off
        self.shapes = [x.shape for x in coordinates]
        self.bounds = np.cumsum([0] + [x.size for x in coordinates])
        multipliers = np.zeros(coupled.num_constraints)
        self.start = np.concatenate([x.ravel() for x in coordinates] + [multipliers])
        self.free = np.concatenate(
            [a.free for a in coupled.assemblers] + [np.ones(coupled.num_constraints, bool)]
        )
        #: per evaluation: the largest seam length difference and the round-off allowed
        self.checked: list[tuple[float, float]] = []

    def split(self, state: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
        """Per-panel coordinates and the multipliers of a state vector."""
        bounds = self.bounds
        coordinates = [
            state[a:b].reshape(shape)
            for a, b, shape in zip(bounds[:-1], bounds[1:], self.shapes, strict=True)
        ]
        return coordinates, state[bounds[-1] :]

    def evaluate(self, state: np.ndarray, order: int = 2) -> KKT:
        coordinates, multipliers = self.split(state)
        kkt = self.coupled.kkt(coordinates, multipliers)
        gradients = np.zeros(state.size)
        gradients[self.free] = np.concatenate([kkt.gradient, kkt.constraint])
        violation = self.coupled.violation(coordinates)
        largest = max(np.abs(x).max() for x in coordinates)
        round_off = self.round_off * np.finfo(float).eps * largest
        self.checked.append((violation, round_off))
        return KKT(gradients, kkt.constraint, kkt.matrix, kkt.energy)

    @property
    def matched(self) -> bool:
        """Whether the seams' lengths agreed to round-off at the last evaluation."""
        violation, round_off = self.checked[-1]
        return violation <= round_off

    def admissible_step(self, state: np.ndarray, delta: np.ndarray) -> float:
        coordinates, _ = self.split(state)
        changes, _ = self.split(delta)
        return min(
            p.admissible_step(x, d)
            for p, x, d in zip(self.coupled.problems, coordinates, changes, strict=True)
        )

    def energy(self, state: np.ndarray) -> float:
        coordinates, _ = self.split(state)
        problems = self.coupled.problems
        return float(sum(p.energy(x) for p, x in zip(problems, coordinates, strict=True)))


class KKT(NamedTuple):
    """The coupled problem at one point: the Lagrangian's gradient over the free dofs, the
    constraint values (rotation rows first, then every seam segment), the KKT matrix
    ``[[∇²L, Bᵀ], [B, 0]]`` and the total energy. As :class:`SeamMatching` evaluates it for
    the Newton driver, ``gradients`` and ``hessians`` name the residual and the matrix."""

    gradient: np.ndarray
    constraint: np.ndarray
    matrix: sp.csr_matrix
    energy: float

    @property
    def gradients(self) -> np.ndarray:
        return self.gradient

    @property
    def hessians(self) -> sp.csr_matrix:
        return self.matrix


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

    def _segment_lengths(self, seam: Seam) -> np.ndarray:
        """The 3D lengths of a seam's segments (on its first panel's surface)."""
        points = self.problems[seam.first].mesh.points[seam.nodes_first]
        return np.linalg.norm(np.diff(points, axis=0), axis=1)

    def kkt(self, coordinates: list[np.ndarray], multipliers: np.ndarray) -> KKT:
        """The coupled problem at ``coordinates`` (one ``(n, 2)`` per panel) and
        ``multipliers``. A seam segment's constraint is the difference of its two sides'
        squared lengths over twice its 3D length: about the difference of the lengths, so that
        its row of the Jacobian is about a unit vector whatever the length unit, as the rotation
        rows are (with the squared lengths alone, a pattern in millimetres had rows a thousand
        times longer than in metres, and PARDISO solved the KKT system to a relative residual of
        2: its seam matching did not converge)."""
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
            weight = 0.5 / self._segment_lengths(seam)  # c = (|Δ_P|² − |Δ_Q|²) / (2 ℓ_3D)
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
                    sign * weight,
                    lam,
                )
            constraint.append(weight * (squared[0] - squared[1]))
            row += k
        n, m = self.num_free, row
        jacobian = _csr(b_rows, b_cols, b_values, (m, n))
        lagrangian_hessian = _csr(rows, cols, values, (n, n))
        gradient = gradient + jacobian.T @ multipliers
        matrix = sp.bmat([[lagrangian_hessian, jacobian.T], [jacobian, None]], format="csr")
        return KKT(gradient, np.concatenate(constraint), matrix, energy)


def _constraint_terms(jacobian, hessian, segment_rows, ends, delta, sign, lam) -> None:
    """Add one side of a seam's segments: ``c = ±w|Δ|²`` (``sign``: ``±w``, per segment) has
    the gradient ``±2wΔ`` at the end node and ``∓2wΔ`` at the start node, and ``λ ∇²c =
    ±2wλ [[I, −I], [−I, I]]`` per axis."""
    (b_rows, b_cols, b_values), (rows, cols, values) = jacobian, hessian
    sign = np.broadcast_to(sign, len(delta))
    for end, direction in zip(ends, (-1.0, 1.0), strict=True):
        for axis in range(2):
            dof = end[:, axis]
            kept = dof >= 0
            b_rows.append(segment_rows[kept])
            b_cols.append(dof[kept])
            b_values.append(2.0 * sign[kept] * direction * delta[kept, axis])
    for (e1, s1), (e2, s2) in itertools.product(zip(ends, (-1.0, 1.0), strict=True), repeat=2):
        for axis in range(2):
            kept = (e1[:, axis] >= 0) & (e2[:, axis] >= 0)
            rows.append(e1[kept, axis])
            cols.append(e2[kept, axis])
            values.append(2.0 * sign[kept] * s1 * s2 * lam[kept])


def _csr(rows, cols, values, shape) -> sp.csr_matrix:
    return sp.csr_matrix(
        (np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))), shape=shape
    )
