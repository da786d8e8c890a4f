"""Results of an erection: per cell the membrane forces and the wrinkling state, per node the
displacement from the design and its normal component, and their statistics.

Membrane forces are force per length: thickness × the Cauchy stress of the relaxed (or plain)
law. A cell is **taut** when both principal forces are
positive, **wrinkled** when one is ≤ 0 < the other (uniaxial tension), **slack** when neither is
positive (round-off of a stress-free state counts as zero). Means, RMS values and area fractions
are weighted by the cells' areas on the design surface.
"""

from __future__ import annotations

import numpy as np

from ..geometry.elements import determinant
from ..geometry.mesh import SurfaceMesh
from ..mechanics.erection import ErectionProblem
from ..mechanics.fields import COMPRESSION_TOLERANCE, principal_values, stress_along
from ..mechanics.forward import forward_block
from .statistics import stress_statistics

__all__ = [
    "CELL_FIELDS",
    "erection_statistics",
    "membrane_forces",
    "node_normals",
]

#: Per-cell results of an erection: name → (description, unit kind).
CELL_FIELDS: dict[str, tuple[str, str]] = {
    "warp_stress": ("membrane force along the erected warp", "force/length"),
    "fill_stress": ("membrane force along the erected fill", "force/length"),
    "stress_max": ("larger principal membrane force", "force/length"),
    "stress_min": ("smaller principal membrane force", "force/length"),
    "warp_stress_difference": ("warp force minus the intended prestress", "force/length"),
    "fill_stress_difference": ("fill force minus the intended prestress", "force/length"),
    "state": ("0 taut, 1 wrinkled (uniaxial tension), 2 slack", "1"),
    "det_F": ("area ratio erected/pattern", "1"),
    "surface_area": ("area of the cell on the design surface", "area"),
}


def membrane_forces(
    problem: ErectionProblem,
    x: np.ndarray,
    cell_ids: list[np.ndarray],
    num_cells: int,
    *,
    relaxed: bool,
) -> dict[str, np.ndarray]:
    """Per-cell membrane forces and state at the positions ``x`` ``(n, 3)`` (welded cell order;
    ``cell_ids`` holds the welded ids of every membrane block's cells)."""
    names = ("warp_stress", "fill_stress", "stress_max", "stress_min", "det_F")
    out = {name: np.zeros(num_cells) for name in names}
    t = problem.thickness
    for block, ids in zip(problem.blocks, cell_ids, strict=True):
        weights = block.reference.weights
        captured = {}

        def respond(C, tangent, fibres=block.fibres, captured=captured):
            psi, S, cc = problem.response(fibres, relaxed)(C, tangent)
            captured["C"], captured["S"] = C, S
            return psi, S, cc

        forward_block(block.reference, x[block.cells], respond, order=0)
        C, S = captured["C"], captured["S"]
        det_f = np.sqrt(np.maximum(determinant(C), 1e-300))
        fibres = block.fibres
        warp = (1.0, 0.0) if fibres is None else fibres.warp
        fill = (0.0, 1.0) if fibres is None else fibres.fill
        CSC = C @ S @ C
        larger, smaller = principal_values(S @ C)
        values = {
            "warp_stress": stress_along(CSC, C, warp) / det_f,
            "fill_stress": stress_along(CSC, C, fill) / det_f,
            "det_F": det_f,
            "stress_max": larger / det_f,
            "stress_min": smaller / det_f,
        }
        for name, value in values.items():
            scale = 1.0 if name == "det_F" else t
            out[name][ids] = scale * np.sum(weights * value, axis=1) / weights.sum(axis=1)
    tolerance = COMPRESSION_TOLERANCE * problem.material.stiffness_scale * t
    out["state"] = np.where(
        out["stress_min"] > tolerance, 0.0, np.where(out["stress_max"] > tolerance, 1.0, 2.0)
    )
    return out


def node_normals(mesh: SurfaceMesh) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals ``(n, 3)`` of the surface at its nodes (cell area vectors summed) and the
    nodes' lumped areas ``(n,)`` (each cell's area shared equally by its nodes)."""
    normals = np.zeros((mesh.num_points, 3))
    lumped = np.zeros(mesh.num_points)
    vectors = mesh.area_vectors()
    areas = np.linalg.norm(vectors, axis=1)
    start = 0
    for cells in mesh.cells.values():
        mine = slice(start, start + len(cells))
        for a in range(cells.shape[1]):
            np.add.at(normals, cells[:, a], vectors[mine])
            np.add.at(lumped, cells[:, a], areas[mine] / cells.shape[1])
        start += len(cells)
    return normals / np.linalg.norm(normals, axis=1, keepdims=True), lumped


def erection_statistics(
    fields: dict[str, np.ndarray], intended: np.ndarray, area: np.ndarray
) -> dict[str, object]:
    """Stress statistics per yarn and the wrinkled and slack area fractions."""
    total = area.sum()
    return {
        "stress": {
            yarn: stress_statistics(fields[f"{yarn}_stress"], intended[:, k], area)
            for k, yarn in enumerate(("warp", "fill"))
        },
        "wrinkled_area_fraction": float(area[fields["state"] == 1].sum() / total),
        "slack_area_fraction": float(area[fields["state"] == 2].sum() / total),
    }
