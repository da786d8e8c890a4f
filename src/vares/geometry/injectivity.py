"""Is a pattern a cutting pattern? It must be one-to-one: no cell inverted, and an outline that
does not cross itself (nor a hole the outline or another hole); and a fabric must be able to
be erected from it: its area must be about the surface's.

With every cell positively oriented (a locally one-to-one map) and boundary loops that are
simple, non-crossing closed curves, the pattern covers every point of the plane at most once.
A surface that turns too far (a head, a deep cap without darts) can give a pattern whose
outline laps over itself although every cell is fine: such a pattern cannot be cut in one
piece, and :func:`pattern_overlap` says where.

A (nearly) closed surface, a sphere less a few cells, has no flat pattern a fabric can be
erected from: the least energy pattern is a small piece of cloth stretched over the whole
surface (a sphere less one triangle gave a pattern of 5 % of its area, cells stretched up to
3400 times their area). The ratio of the pattern's area to the surface's is the mean area
stretch (det F) the fabric must take to be erected; beyond :data:`AREA_RATIO_LIMIT` (or below
its inverse: a pattern gathered into wrinkles) no fabric takes it, woven fabrics breaking at
15–30 % strain along their yarns (1.3–1.7 in area). :func:`pattern_area_misfit` says by how
much.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .elements import ELEMENTS
from .flatten import inverted_cells
from .mesh import SurfaceMesh

__all__ = ["AREA_RATIO_LIMIT", "AreaMisfit", "Overlap", "pattern_area_misfit", "pattern_overlap"]

#: A pattern whose area is less than the surface's over this, or more than this times it, is no
#: cutting pattern (no fabric stretches by half its area again, nor gathers to two thirds).
AREA_RATIO_LIMIT = 1.5


@dataclass(frozen=True)
class Overlap:
    """Where a pattern fails to be one-to-one: the inverted cells, the points ``(k, 2)`` where
    its outline crosses itself, and for each crossing the nearest boundary node."""

    inverted: np.ndarray
    crossings: np.ndarray
    nodes: np.ndarray

    def describe(self, mesh: SurfaceMesh, units: str = "") -> str:
        """One sentence: what overlaps, where on the 3D surface, and what to do."""
        parts = []
        if self.inverted.size:
            shown = ", ".join(str(int(i)) for i in self.inverted[:5])
            parts.append(f"{self.inverted.size} cell(s) are inverted ({shown})")
        if self.crossings.size:
            places = "; ".join(
                f"node {int(n)} at ({', '.join(f'{c:.4g}' for c in mesh.points[n])}){units}"
                for n in self.nodes[:3]
            )
            parts.append(
                f"its outline crosses itself at {len(self.crossings)} place(s), near {places}"
            )
        return (
            f"the pattern overlaps itself: {' and '.join(parts)}; this surface cannot be cut "
            "in one piece as it is: cut it there (split it into panels) or add a dart"
        )


def pattern_overlap(mesh: SurfaceMesh, coordinates: np.ndarray) -> Overlap | None:
    """The :class:`Overlap` of a pattern ``(n, 2)``, or ``None`` when it is one-to-one."""
    from shapely import STRtree, intersection, linestrings

    inverted = inverted_cells(mesh, coordinates)
    loops = mesh.boundary_loops()
    starts = np.concatenate([loop for loop in loops])
    ends = np.concatenate([np.roll(loop, -1) for loop in loops])
    ring = np.concatenate([np.full(len(loop), k) for k, loop in enumerate(loops)])
    position = np.concatenate([np.arange(len(loop)) for loop in loops])
    length = np.array([len(loops[k]) for k in ring])
    segments = linestrings(np.stack([coordinates[starts], coordinates[ends]], axis=1))
    first, second = STRtree(segments).query(segments, predicate="intersects")
    keep = first < second
    first, second = first[keep], second[keep]
    same_ring = ring[first] == ring[second]
    gap = np.abs(position[first] - position[second])
    neighbours = same_ring & ((gap == 1) | (gap == length[first] - 1))
    first, second = first[~neighbours], second[~neighbours]
    if not inverted.size and not first.size:
        return None
    crossings = np.array(
        [
            np.asarray(g.representative_point().coords)[0]
            for g in intersection(segments[first], segments[second])
        ]
    ).reshape(-1, 2)
    nodes = starts[first]
    return Overlap(inverted, crossings, nodes)


@dataclass(frozen=True)
class AreaMisfit:
    """A pattern whose area is far from its surface's: the ratio of the pattern's area to the
    surface's, and the least and greatest area stretch of a cell (its surface area over its
    pattern area: ``det F`` of a triangle)."""

    ratio: float
    stretch_min: float
    stretch_max: float

    def describe(self) -> str:
        """One sentence: how far the areas are apart, why that is no pattern, and what to do."""
        how = "stretched to" if self.ratio < 1 else "gathered to"
        return (
            f"the pattern's area is {100 * self.ratio:.3g} % of the surface's (cells stretched "
            f"{self.stretch_min:.3g} to {self.stretch_max:.4g} times in area): no fabric can be "
            f"{how} {1 / self.ratio:.3g} times its area; this surface cannot be cut in one piece "
            "(is it nearly closed?): cut it into panels ('vares panels', 'vares cut') or open it"
        )


def pattern_area_misfit(mesh: SurfaceMesh, coordinates: np.ndarray) -> AreaMisfit | None:
    """The :class:`AreaMisfit` of a one-to-one pattern ``(n, 2)`` whose area is less than the
    surface's over :data:`AREA_RATIO_LIMIT` or more than that times it, else ``None``."""
    flat = np.concatenate([ELEMENTS[t].areas(coordinates, c) for t, c in mesh.cells.items()])
    ratio = float(flat.sum() / mesh.area)
    if 1 / AREA_RATIO_LIMIT <= ratio <= AREA_RATIO_LIMIT:
        return None
    stretch = mesh.cell_areas() / flat
    return AreaMisfit(ratio, float(stretch.min()), float(stretch.max()))
