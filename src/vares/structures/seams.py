"""Seams: where two panels meet, how long each side is, and the match marks along them.

Seams are found from boundary nodes that coincide in 3D (:func:`find_seams`). Welded together,
the two sides of a seam must have the same length; :mod:`vares.structures.matching` makes them so,
and :func:`seam_marks` puts match marks at the same arc lengths on both sides.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from .panels import Panel

__all__ = [
    "Seam",
    "SeamReport",
    "find_seams",
    "named_seam_marks",
    "seam_lengths",
    "seam_marks",
    "seam_reports",
]


@dataclass(frozen=True)
class Seam:
    """A seam between panels ``first`` and ``second``: matching node chains ``(k + 1,)`` in
    each panel's own numbering, in the same order along the seam (``k`` segments)."""

    first: int
    second: int
    nodes_first: np.ndarray
    nodes_second: np.ndarray

    @property
    def segments(self) -> int:
        return len(self.nodes_first) - 1


@dataclass(frozen=True)
class SeamReport:
    """Length of a seam on each side before and after matching (pattern units)."""

    first: str
    second: str
    segments: int
    length_first_before: float
    length_second_before: float
    length_first_after: float
    length_second_after: float
    max_segment_mismatch_after: float

    @property
    def mismatch_before(self) -> float:
        """Relative length difference of the two sides before matching."""
        return abs(self.length_first_before - self.length_second_before) / self.length_first_before

    @property
    def mismatch_after(self) -> float:
        return abs(self.length_first_after - self.length_second_after) / self.length_first_after

    def to_dict(self) -> dict[str, object]:
        return {
            **asdict(self),
            "mismatch_before": self.mismatch_before,
            "mismatch_after": self.mismatch_after,
        }


def find_seams(panels: list[Panel], tolerance: float | None = None) -> list[Seam]:
    """Seams between panels: chains of boundary edges whose end nodes coincide in 3D (within
    ``tolerance``; default 1e-6 × the structure's size) with a boundary edge of another panel."""
    from scipy.spatial import cKDTree

    all_points = np.vstack([p.mesh.points for p in panels])
    size = float(np.ptp(all_points, axis=0).max()) or 1.0
    tolerance = 1e-6 * size if tolerance is None else tolerance
    boundary = [p.mesh.boundary_edges() for p in panels]
    # one search over every panel's boundary nodes: the coinciding pairs of two panels
    offsets = np.cumsum([0] + [p.mesh.num_points for p in panels])
    owner = np.repeat(np.arange(len(panels)), np.diff(offsets))
    candidates = np.concatenate([offsets[k] + np.unique(b) for k, b in enumerate(boundary)])
    pairs = candidates[
        cKDTree(all_points[candidates]).query_pairs(tolerance, output_type="ndarray")
    ]
    pairs = pairs[owner[pairs[:, 0]] != owner[pairs[:, 1]]]
    pairs = np.where((owner[pairs[:, 0]] > owner[pairs[:, 1]])[:, None], pairs[:, ::-1], pairs)
    matches: dict[tuple[int, int], dict[int, int]] = {}
    for a, b in pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))].tolist():
        i, j = int(owner[a]), int(owner[b])
        matches.setdefault((i, j), {}).setdefault(a - int(offsets[i]), b - int(offsets[j]))
    seams = []
    for (i, j), match in sorted(matches.items()):
        if len(match) < 2:
            continue
        edges_j = {(int(a), int(b)) for a, b in boundary[j]}
        following = {}
        for a, b in boundary[i]:
            a, b = int(a), int(b)
            if a in match and b in match and (match[b], match[a]) in edges_j:
                following[a] = b  # opposite orientation on the neighbour: a shared edge
        starts = set(following) - set(following.values())
        visited = set()
        chains = []
        for start in sorted(starts) + sorted(set(following) - starts):
            if start in visited:
                continue
            chain = [start]
            visited.add(start)
            node = following[start]
            while True:
                chain.append(node)
                if node not in following or node in visited:
                    break
                visited.add(node)
                node = following[node]
            chains.append(chain)
        for chain in chains:
            nodes = np.array(chain)
            seams.append(Seam(i, j, nodes, np.array([match[n] for n in chain])))
    return seams


def seam_lengths(coordinates: list[np.ndarray], seam: Seam) -> tuple[np.ndarray, np.ndarray]:
    a = np.linalg.norm(np.diff(coordinates[seam.first][seam.nodes_first], axis=0), axis=1)
    b = np.linalg.norm(np.diff(coordinates[seam.second][seam.nodes_second], axis=0), axis=1)
    return a, b


def seam_reports(
    panels: list[Panel],
    seams: list[Seam],
    before: list[tuple[np.ndarray, np.ndarray]],
    after: list[tuple[np.ndarray, np.ndarray]],
) -> list[SeamReport]:
    """One report per seam from its segment lengths ``(first, second)`` before and after."""
    out = []
    for seam, (a0, b0), (a1, b1) in zip(seams, before, after, strict=True):
        out.append(
            SeamReport(
                panels[seam.first].name,
                panels[seam.second].name,
                seam.segments,
                float(a0.sum()),
                float(b0.sum()),
                float(a1.sum()),
                float(b1.sum()),
                float(np.max(np.abs(a1 - b1) / a1)),
            )
        )
    return out


def seam_marks(
    coordinates: list[np.ndarray], seams: list[Seam], spacing: float
) -> list[np.ndarray]:
    """Match mark points ``(k, 2)`` of every panel's pattern: every ``spacing`` (pattern units)
    along each seam, at the same arc lengths on both sides (so both patterns get the same marks)."""
    named = named_seam_marks(coordinates, seams, spacing)
    return [
        np.vstack([points for _, points in marks]) if marks else np.zeros((0, 2)) for marks in named
    ]


def named_seam_marks(
    coordinates: list[np.ndarray], seams: list[Seam], spacing: float
) -> list[list[tuple[int, np.ndarray]]]:
    """Per panel, ``(seam index, mark points (k, 2))`` for every seam it has: the marks of
    :func:`seam_marks`, each seam's on their own (mark ``j`` of a seam is at the same place of
    the weld on both sides)."""
    marks: list[list[tuple[int, np.ndarray]]] = [[] for _ in coordinates]
    for number, seam in enumerate(seams):
        sides = [
            (seam.first, coordinates[seam.first][seam.nodes_first]),
            (seam.second, coordinates[seam.second][seam.nodes_second]),
        ]
        length = np.linalg.norm(np.diff(sides[0][1], axis=0), axis=1).sum()
        positions = np.arange(spacing, length - 0.25 * spacing, spacing)
        for panel, chain in sides:
            segment = np.linalg.norm(np.diff(chain, axis=0), axis=1)
            cumulative = np.concatenate([[0.0], np.cumsum(segment)])
            index = np.clip(
                np.searchsorted(cumulative, positions, side="right") - 1, 0, len(segment) - 1
            )
            fraction = ((positions - cumulative[index]) / segment[index])[:, None]
            points = chain[index] + fraction * (chain[index + 1] - chain[index])
            marks[panel].append((number, points))
    return marks
