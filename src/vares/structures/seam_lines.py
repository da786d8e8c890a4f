"""The seams of a cut surface against the cutting lines they follow."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .layout import StripPlan
from .matching import StructureResult

__all__ = ["SeamLine", "seam_lines"]


@dataclass(frozen=True)
class SeamLine:
    """A seam of the cut surface: its two panels, its 3D length, the length of the cutting line
    it follows (as computed, before the cut, between the points nearest to the seam's ends) and
    its pattern length on each side."""

    panels: tuple[str, str]
    length_3d: float
    line_length: float
    length_2d: tuple[float, float]


def _midpoints(polyline: np.ndarray) -> np.ndarray:
    return 0.5 * (polyline[:-1] + polyline[1:])


def _stretch(polyline: np.ndarray, start: np.ndarray, end: np.ndarray) -> float:
    """Length of a polyline between the points nearest to ``start`` and ``end`` (the stretch of
    a cutting line a seam follows: its ends may have been moved onto boundary nodes)."""
    a, b = polyline[:-1], polyline[1:]
    d = b - a
    length = np.linalg.norm(d, axis=1)
    cumulative = np.concatenate([[0.0], np.cumsum(length)])

    def position(point: np.ndarray) -> float:
        t = np.clip(np.einsum("ij,ij->i", point - a, d) / np.maximum(length**2, 1e-300), 0, 1)
        k = int(np.argmin(np.linalg.norm(a + t[:, None] * d - point, axis=1)))
        return float(cumulative[k] + t[k] * length[k])

    return abs(position(end) - position(start))


def seam_lines(plan: StripPlan, structure: StructureResult) -> list[SeamLine]:
    """The seams with their 3D lengths, the lengths of the lines they follow and their
    pattern lengths on both sides."""
    from scipy.spatial import cKDTree

    # a seam's edges are edges of the chain it follows: their midpoints find it (its end nodes
    # are also on the chains it meets, a cross seam's on the seams at its ends)
    middles = [_midpoints(plan.cut.mesh.points[c]) for c in plan.cut.lines]
    tree = owner = None  # one strip: no cutting line to follow
    if any(len(m) for m in middles):
        owner = np.concatenate([np.full(len(m), k) for k, m in enumerate(middles)])
        tree = cKDTree(np.vstack(middles))
    out = []
    for seam, report in zip(structure.seams, structure.seam_reports, strict=True):
        nodes = structure.panels[seam.first].mesh.points[seam.nodes_first]
        length_3d = float(np.linalg.norm(np.diff(nodes, axis=0), axis=1).sum())
        line_length = float("nan")
        if tree is not None:
            _, found = tree.query(_midpoints(nodes))
            line = int(np.bincount(owner[found]).argmax())
            if line < len(plan.lines):
                line_length = _stretch(plan.lines[line].points, nodes[0], nodes[-1])
        out.append(
            SeamLine(
                (report.first, report.second),
                length_3d,
                line_length,
                (report.length_first_after, report.length_second_after),
            )
        )
    return out
