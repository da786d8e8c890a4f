"""Results per cell for any pattern: area ratio, stretches, stresses, energy.

Values at quadrature points are averaged over each cell with pattern-area weights, so that
``det_F`` of a cell is exactly its 3D area divided by its pattern area.
"""

from __future__ import annotations

import numpy as np

from ..geometry.elements import ELEMENTS, determinant, inverse
from ..geometry.mesh import SurfaceMesh
from ..geometry.orientation import warp_deviation
from ..materials import Fibres, Hyperelastic
from .problem import Problem

__all__ = [
    "COMPRESSION_TOLERANCE",
    "FIELD_DESCRIPTIONS",
    "KEY_FIELDS",
    "cell_fields",
    "principal_values",
    "stress_along",
]

#: Name → (description, unit kind) of every per-cell field.
FIELD_DESCRIPTIONS: dict[str, tuple[str, str]] = {
    "det_F": ("area ratio erected/pattern (det F)", "1"),
    "stretch_max": ("larger principal stretch", "1"),
    "stretch_min": ("smaller principal stretch", "1"),
    "stress_max": ("larger principal Cauchy stress", "stress"),
    "stress_min": ("smaller principal Cauchy stress", "stress"),
    "warp_stretch": ("stretch along the warp, √I4", "1"),
    "fill_stretch": ("stretch along the fill, √I6", "1"),
    "shear_angle": ("yarn shear angle: decrease of the angle between the yarns", "degree"),
    "warp_compensation": ("compensation along the warp: 1 − pattern/erected length", "%"),
    "fill_compensation": ("compensation along the fill: 1 − pattern/erected length", "%"),
    "warp_stress": ("Cauchy stress along the erected warp", "stress"),
    "fill_stress": ("Cauchy stress along the erected fill", "stress"),
    "warp_stress_pk2": ("2nd Piola–Kirchhoff stress Φ₁·SΦ₁ along the warp", "stress"),
    "fill_stress_pk2": ("2nd Piola–Kirchhoff stress Φ₂·SΦ₂ along the fill", "stress"),
    "compressed_yarns": ("1 where the warp or the fill is in compression", "1"),
    "wrinkling": ("1 where a principal stress is compressive (wrinkling risk)", "1"),
    "energy": ("strain energy of the cell (thickness × ∫Ψ̃ dA)", "energy"),
    "energy_density": ("strain energy density Ψ per reference volume", "stress"),
    "pattern_area": ("area of the cell in the pattern", "area"),
    "surface_area": ("area of the cell on the 3D surface", "area"),
    "warp_deviation": ("angle from the prescribed 3D warp direction to the erected warp", "degree"),
}

#: The fields a summary table shows first.
KEY_FIELDS = (
    "det_F",
    "warp_stretch",
    "fill_stretch",
    "shear_angle",
    "warp_stress",
    "fill_stress",
    "stress_min",
    "stress_max",
)

#: Compressive stresses below this fraction of the material's stiffness are round-off.
COMPRESSION_TOLERANCE = 1e-8


def principal_values(matrices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The larger and the smaller eigenvalue of 2×2 matrices ``(..., 2, 2)`` with a real
    spectrum (``C``, or ``S C``, similar to the symmetric ``C½ S C½``); from the half
    difference of the diagonal, not from √(half trace² − det), which loses half the digits
    where the two are close."""
    half = 0.5 * (matrices[..., 0, 0] + matrices[..., 1, 1])
    difference = 0.5 * (matrices[..., 0, 0] - matrices[..., 1, 1])
    root = np.sqrt(np.maximum(difference**2 + matrices[..., 0, 1] * matrices[..., 1, 0], 0.0))
    return half + root, half - root


def stress_along(CSC: np.ndarray, C: np.ndarray, direction) -> np.ndarray:
    """``Φ·CSCΦ / Φ·CΦ``: the Cauchy stress along the erected yarn ``FΦ``, times ``det F``
    (``Φ`` a reference direction, ``S`` the 2nd Piola–Kirchhoff stress)."""
    phi = np.asarray(direction, dtype=float)
    return np.einsum("a,...ab,b->...", phi, CSC, phi) / np.einsum("a,...ab,b->...", phi, C, phi)


def cell_fields(
    mesh: SurfaceMesh,
    coordinates: np.ndarray,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    fibres: Fibres | None = None,
    prestress: np.ndarray | None = None,
    warp_direction: np.ndarray | None = None,
    compression_threshold: float = 0.0,
) -> dict[str, np.ndarray]:
    """Per-cell fields of a pattern ``(n, 2)`` erected onto ``mesh`` (global cell order).

    See :data:`FIELD_DESCRIPTIONS` for the names. Stresses are Cauchy stresses of the
    material (the prestress is the target, not part of the stress). Yarn fields need
    ``fibres`` (default: warp along x, fill along y); ``warp_deviation`` needs
    ``warp_direction``. A yarn or principal stress counts as compressive below
    ``−compression_threshold`` (stress units; round-off is never counted).
    """
    if fibres is None:
        fibres = Fibres.from_angles(0.0)
    compressive = -max(compression_threshold, COMPRESSION_TOLERANCE * material.stiffness_scale)
    reference_angle = np.degrees(np.arccos(np.clip(fibres.warp @ fibres.fill, -1.0, 1.0)))
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
        stretch_sq = principal_values(C)
        stress = principal_values(response.stress @ C)
        weight = det_j * element.quadrature_weights  # pattern area per quadrature point
        area = weight.sum(axis=1)

        def mean(values: np.ndarray, weight=weight, area=area) -> np.ndarray:
            return (values * weight).sum(axis=1) / area

        per_block["det_F"].append(mean(det_f))
        per_block["stretch_max"].append(mean(np.sqrt(stretch_sq[0])))
        per_block["stretch_min"].append(mean(np.sqrt(np.maximum(stretch_sq[1], 0.0))))
        per_block["stress_max"].append(mean(stress[0] / det_f))
        per_block["stress_min"].append(mean(stress[1] / det_f))
        i4 = np.einsum("a,mqab,b->mq", fibres.warp, C, fibres.warp)
        i6 = np.einsum("a,mqab,b->mq", fibres.fill, C, fibres.fill)
        i8 = np.einsum("a,mqab,b->mq", fibres.warp, C, fibres.fill)
        yarn_angle = np.degrees(np.arccos(np.clip(i8 / np.sqrt(i4 * i6), -1.0, 1.0)))
        CSC = C @ response.stress @ C
        warp_cauchy = mean(stress_along(CSC, C, fibres.warp) / det_f)
        fill_cauchy = mean(stress_along(CSC, C, fibres.fill) / det_f)
        per_block["warp_stretch"].append(mean(np.sqrt(i4)))
        per_block["fill_stretch"].append(mean(np.sqrt(i6)))
        per_block["warp_compensation"].append(mean(100.0 * (1.0 - 1.0 / np.sqrt(i4))))
        per_block["fill_compensation"].append(mean(100.0 * (1.0 - 1.0 / np.sqrt(i6))))
        per_block["shear_angle"].append(mean(reference_angle - yarn_angle))
        per_block["warp_stress"].append(warp_cauchy)
        per_block["fill_stress"].append(fill_cauchy)
        per_block["warp_stress_pk2"].append(
            mean(np.einsum("a,mqab,b->mq", fibres.warp, response.stress, fibres.warp))
        )
        per_block["fill_stress_pk2"].append(
            mean(np.einsum("a,mqab,b->mq", fibres.fill, response.stress, fibres.fill))
        )
        per_block["compressed_yarns"].append(
            ((warp_cauchy < compressive) | (fill_cauchy < compressive)).astype(float)
        )
        per_block["wrinkling"].append((per_block["stress_min"][-1] < compressive).astype(float))
        per_block["energy"].append(energy)
        per_block["energy_density"].append(mean(response.psi))
        per_block["pattern_area"].append(area)
        per_block["surface_area"].append(element.areas(mesh.points, cells))
    if warp_direction is not None:
        _, deviation = warp_deviation(mesh, coordinates, fibres.warp, warp_direction)
        per_block["warp_deviation"] = [np.degrees(deviation)]
    else:
        del per_block["warp_deviation"]
    return {name: np.concatenate(values) for name, values in per_block.items()}
