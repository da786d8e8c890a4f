"""A surface's strips as planned (:func:`vares.structures.layout.plan_strips`): the cut mesh,
its panels, the cutting lines and what the planning tried. Its own module so that the widths
(:mod:`.widths`) and the pairing (:mod:`.pairing`) read a plan without importing the planner."""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from ..geometry.cutting import CutMesh
from ..geometry.line_families import LineFamily
from ..geometry.surface_lines import SurfaceLine
from .panels import Panel

__all__ = ["StripPlan", "along_strips"]


@dataclass
class StripPlan:
    """Strips cut from a surface.

    ``cut`` is the cut mesh (panel ids in strip order), ``panels`` the strips (``strip-1`` …),
    ``lines`` the cutting lines as computed (geodesics or plane sections, on the mesh the cut
    started from) and ``warps`` the 3D direction along every strip. ``widths`` are the flattened
    strips' extents across their warps, allowances included (mesh units); ``evaluations`` counts
    the layouts tried, ``history`` the widest strip for every number of gaps between lines tried.
    ``refinements`` is the number of rounds the surface was refined on its own faces before it
    was cut (``input_cells`` its triangles before, ``refined_cells`` after), and
    ``replaced_geodesics`` the number of geodesics replaced by their plane sections (module docs).
    With ``interlock`` the strips are planned in pairs (``widths`` are pairs' widths);
    ``lengths`` are the strips' extents along the warp, ``straight_pairs`` the widths their
    pairs would need with one seam along the warp, ``compared`` the roll estimates of both
    plans (:mod:`.pairing`), ``pairs_refused`` why strips planned alone could not be planned in
    pairs (where that was tried) and ``split`` the two halves of a strip cut across, if any.
    Where strips too wide for the roll were cut across into pieces (:mod:`.cross_seams`),
    ``panels`` are the pieces, ``strip_of`` gives the strip of each (indices of the strips
    before the cut; empty where none was cut), ``pieces`` the parts each strip cut was cut into
    and ``cross_cut`` the number of strips cut.
    """

    cut: CutMesh
    panels: list[Panel]
    lines: list[SurfaceLine]
    warps: list[np.ndarray]
    widths: list[float]
    family: LineFamily | None = None
    evaluations: int = 0
    history: list[tuple[int, float]] = field(default_factory=list)  # (gaps, widest)
    refinements: int = 0
    input_cells: int = 0
    refined_cells: int = 0
    replaced_geodesics: int = 0
    interlock: bool = False
    lengths: list[float] = field(default_factory=list)
    straight_pairs: list[float] = field(default_factory=list)
    compared: dict[str, tuple[int, float]] = field(default_factory=dict)
    split: tuple[int, int] | None = None
    pairs_refused: str = ""
    straight_warp: bool = False
    strip_of: list[int] = field(default_factory=list)
    pieces: int = 1
    cross_cut: int = 0

    @property
    def counted(self) -> str:
        """``"12 strips"``, or ``"96 pieces of 68 strips"`` where strips were cut across."""
        if self.cross_cut:
            return f"{len(self.panels)} pieces of {len(set(self.strip_of))} strips"
        return f"{len(self.panels)} strips"


def along_strips(
    cut: CutMesh, panels: list[Panel], family, one_seam: bool = False
) -> list[np.ndarray]:
    """Per panel: the sum of its seam segments (lines oriented alike), normalised; with
    ``one_seam``, of one seam only, on the same side of every strip."""
    points, cells = cut.mesh.points, cut.mesh.cells["triangle"]
    n = len(points)
    sides = np.stack([cells, np.roll(cells, -1, axis=1)], axis=-1).reshape(-1, 2)
    owner = np.repeat(cut.panel_ids, 3)
    keys = sides[:, 0] * n + sides[:, 1]
    lookup = dict(zip(keys.tolist(), owner.tolist(), strict=True))
    by_side = np.zeros((2, len(panels), 3))  # the seams a strip lies left of, and right of
    for chain in cut.lines:
        for u, w in itertools.pairwise(chain):
            vector = points[w] - points[u]
            for side, key in enumerate((u * n + w, w * n + u)):
                if key in lookup:
                    by_side[side, lookup[key]] += vector
    sums = by_side.sum(axis=0)
    if one_seam:  # the seam on the strip's right (looking along it), where it has one
        right = np.linalg.norm(by_side[0], axis=1)[:, None] > 0
        sums = np.where(right, by_side[0], by_side[1])
    out = []
    for index, panel in enumerate(panels):
        length = np.linalg.norm(sums[index])
        if length > 0:
            out.append(sums[index] / length)
        elif family is not None:
            out.append(family.warp(panel.mesh.points))
        else:
            from ..geometry.flatten import projection_plane

            out.append(projection_plane(panel.mesh).axes[0])
    return out
