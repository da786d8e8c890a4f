"""Any pattern, any ply: the energy and per-cell results of a given pattern erected onto a
surface (the ply-stack check: a pattern made for one fibre orientation, checked for another)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.mesh import SurfaceMesh, index_listing
from ..materials import Fibres, Hyperelastic
from ..mechanics.fields import cell_fields
from ..mechanics.problem import Problem

__all__ = ["PatternEvaluation", "evaluate"]


@dataclass(frozen=True)
class PatternEvaluation:
    """Energy and per-cell fields of a given pattern erected onto a surface.

    ``compressed_cells``: cells whose warp or fill is in compression (where a ply cut from this
    pattern would wrinkle); ``compressed_area_fraction``: their share of the 3D area.
    """

    energy: float
    fields: dict[str, np.ndarray]
    inverted_cells: np.ndarray
    fibres: Fibres

    @property
    def compressed_cells(self) -> np.ndarray:
        return np.flatnonzero(self.fields["compressed_yarns"] > 0)

    @property
    def compressed_area_fraction(self) -> float:
        area = self.fields["surface_area"]
        return float(area[self.compressed_cells].sum() / area.sum())


def evaluate(
    mesh: SurfaceMesh,
    coordinates: np.ndarray,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    warp_angle: float = 0.0,
    fill_angle: float | None = None,
    prestress: np.ndarray | None = None,
    warp_direction: np.ndarray | None = None,
    compression_threshold: float = 0.0,
) -> PatternEvaluation:
    """Evaluate any pattern ``(n, 2)`` (optimised or not) with a material and yarn directions.

    ``warp_angle``/``fill_angle`` are degrees in the pattern frame, so a pattern optimised for
    one ply can be checked for another (the ply-stack check): e.g. a pattern made with
    ``warp_angle=45, fill_angle=-45`` evaluated with ``warp_angle=0``. Yarn stresses below
    ``−compression_threshold`` count as compressed (see :func:`cell_fields`).
    """
    coordinates = np.asarray(coordinates, dtype=float)
    if coordinates.shape != (mesh.num_points, 2):
        raise ValueError(
            f"coordinates must have shape ({mesh.num_points}, 2); got {coordinates.shape}"
        )
    bad = np.flatnonzero(~np.isfinite(coordinates).all(axis=1))
    if bad.size:
        raise ValueError(
            f"the pattern's coordinates are not finite (NaN or inf) at nodes {index_listing(bad)}"
        )
    fibres = Fibres.from_angles(warp_angle, fill_angle)
    problem = Problem(mesh, material, thickness, fibres=fibres, prestress=prestress)
    inverted = problem.inverted_cells(coordinates)
    energy = problem.energy(coordinates)
    with np.errstate(invalid="ignore", divide="ignore"):
        fields = cell_fields(
            mesh,
            coordinates,
            material,
            thickness,
            fibres=fibres,
            prestress=prestress,
            warp_direction=warp_direction,
            compression_threshold=compression_threshold,
        )
    return PatternEvaluation(energy, fields, inverted, fibres)
