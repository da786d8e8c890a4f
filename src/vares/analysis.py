"""Results per cell for any pattern: area ratio, stretches, stresses, energy.

Values at quadrature points are averaged over each cell with pattern-area weights, so that
``det_F`` of a cell is exactly its 3D area divided by its pattern area.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .elements import ELEMENTS
from .kernels import determinant, inverse
from .materials import Fibres, Hyperelastic
from .mesh import SurfaceMesh
from .problem import Problem

__all__ = ["FIELD_DESCRIPTIONS", "PatternEvaluation", "cell_fields", "evaluate"]

#: Name → (description, unit kind) of every per-cell field.
FIELD_DESCRIPTIONS: dict[str, tuple[str, str]] = {
    "det_F": ("area ratio erected/pattern (det F)", "1"),
    "stretch_max": ("larger principal stretch", "1"),
    "stretch_min": ("smaller principal stretch", "1"),
    "stress_max": ("larger principal Cauchy stress", "stress"),
    "stress_min": ("smaller principal Cauchy stress", "stress"),
    "energy": ("strain energy of the cell (thickness × ∫Ψ̃ dA)", "energy"),
    "energy_density": ("strain energy density Ψ per reference volume", "stress"),
    "pattern_area": ("area of the cell in the pattern", "area"),
    "surface_area": ("area of the cell on the 3D surface", "area"),
}


def _symmetric_eigenvalues(trace: np.ndarray, det: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues of 2×2 matrices with real spectrum from trace and determinant."""
    half = 0.5 * trace
    root = np.sqrt(np.maximum(half**2 - det, 0.0))
    return half + root, half - root


def cell_fields(
    mesh: SurfaceMesh,
    coordinates: np.ndarray,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    fibres: Fibres | None = None,
    prestress: np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """Per-cell fields of a pattern ``(n, 2)`` erected onto ``mesh`` (global cell order).

    See :data:`FIELD_DESCRIPTIONS` for the names. Stresses are Cauchy stresses of the
    material (the prestress is the target, not part of the stress).
    """
    problem = Problem(mesh, material, thickness, fibres=fibres, prestress=prestress)
    cell_energy = problem.evaluate(coordinates, order=0).cell_energy
    per_block: dict[str, list[np.ndarray]] = {name: [] for name in FIELD_DESCRIPTIONS}
    for (cell_type, cells), energy in zip(mesh.cells.items(), cell_energy, strict=True):
        element = ELEMENTS[cell_type]
        J = element.jacobians(coordinates, cells)
        det_j = determinant(J)
        K = inverse(J, det_j)
        G = element.metrics(mesh.points, cells)
        C = np.einsum("mqup,mquv,mqvs->mqps", K, G, K)
        response = material.response(C, fibres, tangent=False)
        det_c = determinant(C)
        det_f = np.sqrt(np.maximum(det_c, 0.0))
        stretch_sq = _symmetric_eigenvalues(C[..., 0, 0] + C[..., 1, 1], det_c)
        SC = response.stress @ C
        stress = _symmetric_eigenvalues(SC[..., 0, 0] + SC[..., 1, 1], determinant(SC))
        weight = det_j * element.quadrature_weights  # pattern area per quadrature point
        area = weight.sum(axis=1)

        def mean(values: np.ndarray, weight=weight, area=area) -> np.ndarray:
            return (values * weight).sum(axis=1) / area

        per_block["det_F"].append(mean(det_f))
        per_block["stretch_max"].append(mean(np.sqrt(stretch_sq[0])))
        per_block["stretch_min"].append(mean(np.sqrt(np.maximum(stretch_sq[1], 0.0))))
        per_block["stress_max"].append(mean(stress[0] / det_f))
        per_block["stress_min"].append(mean(stress[1] / det_f))
        per_block["energy"].append(energy)
        per_block["energy_density"].append(mean(response.psi))
        per_block["pattern_area"].append(area)
        per_block["surface_area"].append(element.areas(mesh.points, cells))
    return {name: np.concatenate(values) for name, values in per_block.items()}


@dataclass(frozen=True)
class PatternEvaluation:
    """Energy and per-cell fields of a given pattern."""

    energy: float
    fields: dict[str, np.ndarray]
    inverted_cells: np.ndarray


def evaluate(
    mesh: SurfaceMesh,
    coordinates: np.ndarray,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    fibres: Fibres | None = None,
    prestress: np.ndarray | None = None,
) -> PatternEvaluation:
    """Evaluate any pattern ``(n, 2)`` (optimised or not) with a material and fibre directions."""
    coordinates = np.asarray(coordinates, dtype=float)
    if coordinates.shape != (mesh.num_points, 2):
        raise ValueError(
            f"coordinates must have shape ({mesh.num_points}, 2); got {coordinates.shape}"
        )
    problem = Problem(mesh, material, thickness, fibres=fibres, prestress=prestress)
    inverted = problem.inverted_cells(coordinates)
    energy = problem.energy(coordinates)
    with np.errstate(invalid="ignore", divide="ignore"):
        fields = cell_fields(
            mesh, coordinates, material, thickness, fibres=fibres, prestress=prestress
        )
    return PatternEvaluation(energy, fields, inverted)
