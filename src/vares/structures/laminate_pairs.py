"""The ply-stack check of a laminate (the seed's Fig. 11): the blank of one drape erected with
the yarns of another, and the erected yarn directions of a pattern.

A blank cut for drape A from a roll turned for drape B has B's yarns at ``θ_B − θ_A`` in A's
pattern frame (where A's warp runs along +x). :func:`pair_check` reports the area whose warp or
fill is compressed (shortened by more than a strain), the largest yarn compression and the
deviation of the erected yarns from B's own drape.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..analysis.evaluate import PatternEvaluation, evaluate
from ..geometry.elements import ELEMENTS, inverse
from ..geometry.mesh import SurfaceMesh

if TYPE_CHECKING:
    from .laminate_plies import PlyDrapeResult

__all__ = [
    "PAIR_TITLES",
    "PAIR_VALUES",
    "PairCheck",
    "blank_used_for",
    "draped_yarns",
    "pair_check",
]


def draped_yarns(
    mesh: SurfaceMesh, coordinates: np.ndarray, warp: np.ndarray, fill: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The erected warp and fill ``(m, 3)`` per cell (unit, global cell order) of the pattern
    ``coordinates`` ``(n, 2)`` with the yarn directions ``warp``, ``fill`` ``(2,)`` of the pattern
    plane: ``F Φ`` averaged over the cell's quadrature points (pattern-area weights), normalised."""
    out = []
    for phi in (np.asarray(warp, dtype=float), np.asarray(fill, dtype=float)):
        blocks = []
        for cell_type, cells in mesh.cells.items():
            element = ELEMENTS[cell_type]
            j = element.jacobians(mesh.points, cells)
            J = element.jacobians(coordinates, cells)
            erected = np.einsum("mqik,mqkl,l->mqi", j, inverse(J), phi)
            weight = np.linalg.det(J) * element.quadrature_weights
            mean = np.einsum("mq,mqi->mi", weight, erected)
            blocks.append(mean / np.linalg.norm(mean, axis=1)[:, None])
        out.append(np.vstack(blocks))
    return out[0], out[1]


@dataclass(frozen=True)
class PairCheck:
    """The blank of drape ``blank`` erected with the yarns of drape ``ply`` (their labels).

    ``compressed_area_fraction``: the share of the 3D area whose warp or fill is shortened by
    more than the threshold; ``warp_compressed_fraction``, ``fill_compressed_fraction``: of each
    yarn alone; ``largest_compression``: the largest yarn shortening (strain, 1 − stretch; 0
    when none is shorter); ``min_yarn_stress``: the most compressive Cauchy yarn stress;
    ``mean_deviation``, ``max_deviation``: the angle (degrees, area-weighted mean and largest)
    between the erected warp and the warp of ``ply``'s own drape; ``energy``: of the erection.
    ``checked`` is False (and the numbers NaN) when the two cover different cells.
    """

    blank: str
    ply: str
    checked: bool
    compressed_area_fraction: float = np.nan
    warp_compressed_fraction: float = np.nan
    fill_compressed_fraction: float = np.nan
    largest_compression: float = np.nan
    min_yarn_stress: float = np.nan
    mean_deviation: float = np.nan
    max_deviation: float = np.nan
    energy: float = np.nan

    def summary(self) -> dict[str, Any]:
        return dict(self.__dict__)


#: The numbers of a :class:`PairCheck` that the pair matrices show.
PAIR_VALUES = (
    "compressed_area_fraction",
    "warp_compressed_fraction",
    "fill_compressed_fraction",
    "largest_compression",
    "min_yarn_stress",
    "mean_deviation",
    "max_deviation",
)


def _angle_of(vector: np.ndarray) -> float:
    return float(np.degrees(np.arctan2(vector[1], vector[0])))


#: What each pair matrix shows, and how its values are printed.
PAIR_TITLES = {
    "compressed_area_fraction": ("area with a compressed yarn", "%"),
    "warp_compressed_fraction": ("area with compressed warp", "%"),
    "fill_compressed_fraction": ("area with compressed fill", "%"),
    "largest_compression": ("largest yarn compression (strain)", "%"),
    "min_yarn_stress": ("most compressive yarn stress", "stress"),
    "mean_deviation": ("mean deviation from the ply's own drape", "°"),
    "max_deviation": ("largest deviation from the ply's own drape", "°"),
}


def blank_used_for(blank: PlyDrapeResult, ply: PlyDrapeResult) -> PatternEvaluation:
    """The blank of ``blank`` erected with the material and yarns of ``ply``: ``ply``'s yarns at
    ``θ_ply − θ_blank`` in the blank's pattern frame (:func:`vares.evaluate`; its per-cell
    ``fields`` are those of ``blank.mesh``). Both must cover the same cells."""
    if not np.array_equal(blank.cells, ply.cells):
        raise ValueError(f"drapes {blank.label} and {ply.label} cover different cells")
    pattern = blank.pattern
    turn = ply.orientation - blank.orientation
    own = ply.pattern.fibres
    warp_angle = _angle_of(pattern.fibres.warp) + turn
    fill_angle = warp_angle + _angle_of(own.fill) - _angle_of(own.warp)
    return evaluate(
        blank.mesh,
        pattern.material_coordinates,
        ply.material,
        warp_angle=warp_angle,
        fill_angle=fill_angle,
    )


def pair_check(blank: PlyDrapeResult, ply: PlyDrapeResult, strain: float) -> PairCheck:
    """The blank of ``blank`` erected with the yarns of ``ply`` (module docs)."""
    if not np.array_equal(blank.cells, ply.cells):
        return PairCheck(blank.label, ply.label, False)
    pattern = blank.pattern
    check = blank_used_for(blank, ply)
    f = check.fields
    area = f["surface_area"]
    total = area.sum()
    warp_short = f["warp_stretch"] < 1.0 - strain
    fill_short = f["fill_stretch"] < 1.0 - strain
    compression = 1.0 - np.minimum(f["warp_stretch"], f["fill_stretch"])
    erected, _ = draped_yarns(
        blank.mesh, pattern.material_coordinates, check.fibres.warp, check.fibres.fill
    )
    own = ply.pattern  # the ply without darts, on the mould's cells
    target, _ = draped_yarns(ply.mesh, own.material_coordinates, own.fibres.warp, own.fibres.fill)
    deviation = np.degrees(
        np.arctan2(
            np.linalg.norm(np.cross(erected, target), axis=1),
            np.abs(np.einsum("mi,mi->m", erected, target)),
        )
    )
    return PairCheck(
        blank.label,
        ply.label,
        True,
        compressed_area_fraction=float(area[warp_short | fill_short].sum() / total),
        warp_compressed_fraction=float(area[warp_short].sum() / total),
        fill_compressed_fraction=float(area[fill_short].sum() / total),
        largest_compression=float(max(compression.max(), 0.0)),
        min_yarn_stress=float(min(f["warp_stress"].min(), f["fill_stress"].min())),
        mean_deviation=float(area @ deviation / total),
        max_deviation=float(deviation.max()),
        energy=float(check.energy),
    )
