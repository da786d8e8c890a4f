"""Is a pattern a cutting pattern? It must be one-to-one: no cell inverted, and an outline that
does not cross itself (nor a hole the outline or another hole).

With every cell positively oriented (a locally one-to-one map) and boundary loops that are
simple, non-crossing closed curves, the pattern covers every point of the plane at most once.
A surface that turns too far (a head, a deep cap without darts) can give a pattern whose
outline laps over itself although every cell is fine: such a pattern cannot be cut in one
piece, and :func:`pattern_overlap` says where.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .flatten import inverted_cells
from .mesh import SurfaceMesh

__all__ = ["Overlap", "pattern_overlap"]


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
