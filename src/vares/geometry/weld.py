"""Welding panels into one surface, and the boundary of a surface: its loops and corners.

Panels of a structure share their seam nodes in 3D; welded, a seam node is one node of the whole
surface. :func:`weld` merges the nodes of several meshes that coincide in 3D and returns the
welded mesh with, for every panel, the welded index of each of its nodes.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .mesh import MeshError, SurfaceMesh

__all__ = ["Welded", "coincident_nodes", "corner_nodes", "weld"]


class Welded:
    """Panels welded into one surface: ``mesh`` (cell blocks in panel order), ``node_maps``
    (per panel, the welded node of each of its nodes) and ``cell_ranges`` (per panel and cell
    type, the rows of that panel's cells in the welded block)."""

    def __init__(
        self,
        mesh: SurfaceMesh,
        node_maps: list[np.ndarray],
        cell_ranges: list[dict[str, tuple[int, int]]],
    ) -> None:
        self.mesh = mesh
        self.node_maps = node_maps
        self.cell_ranges = cell_ranges


def coincident_nodes(
    points: np.ndarray,
    tolerance: float,
    candidates: np.ndarray | None = None,
    apart: np.ndarray | None = None,
) -> np.ndarray:
    """For every node, the node it is merged with: the smallest index of its cluster of nodes
    closer than ``tolerance`` to one another (chains join). Only ``candidates`` (indices; default
    all) are merged, and nodes of one ``apart`` label (one per node) never directly."""
    n = len(points)
    index = np.arange(n) if candidates is None else np.asarray(candidates, dtype=np.int64)
    if tolerance <= 0 or index.size < 2:
        return np.arange(n)
    pairs = index[_close_pairs(points[index], tolerance)]
    if apart is not None:
        pairs = pairs[apart[pairs[:, 0]] != apart[pairs[:, 1]]]
    if not len(pairs):
        return np.arange(n)
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max() + 1, n)
    np.minimum.at(first, label, np.arange(n))
    return first[label]


#: Up to this many nodes, close pairs are found by a sweep along one direction (a few
#: milliseconds); more, or nodes crowded along that direction, go through a k-d tree
#: (scipy.spatial, 0.1–0.25 s to import).
_SWEEP_NODES = 20_000

#: A direction along which no mesh's nodes line up (grids, planes of constant x, y or z).
_SWEEP = np.array([1.0, np.sqrt(2.0), np.pi]) / np.sqrt(3.0 + np.pi**2)


def _close_pairs(points: np.ndarray, tolerance: float) -> np.ndarray:
    """The pairs ``(i, j)``, ``i < j``, of points at most ``tolerance`` apart, ``(k, 2)``."""
    n = len(points)
    if n <= _SWEEP_NODES:
        # nodes sorted along the sweep: only those within the tolerance along it can be close
        along = points @ _SWEEP
        order = np.argsort(along, kind="stable")
        ends = np.searchsorted(along[order], along[order] + tolerance, side="right")
        counts = ends - np.arange(n) - 1
        if counts.sum() <= 50 * n:
            first = np.repeat(np.arange(n), counts)
            offset = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
            i, j = order[first], order[first + 1 + offset]
            close = np.linalg.norm(points[i] - points[j], axis=1) <= tolerance
            pairs = np.sort(np.column_stack([i[close], j[close]]), axis=1)
            return pairs.astype(np.int64)
    from scipy.spatial import cKDTree

    return cKDTree(points).query_pairs(tolerance, output_type="ndarray")


def weld(meshes: Sequence[SurfaceMesh], tolerance: float | None = None) -> Welded:
    """Weld meshes whose boundary nodes coincide in 3D (within ``tolerance``; default 1e-6 × the
    structure's size) into one validated surface.

    Only boundary nodes are merged, and only with nodes of other panels. Raises
    :class:`MeshError` if the welded surface is not a valid surface (e.g. panels oriented
    oppositely).
    """
    if len(meshes) == 1:  # nothing to weld: the mesh as it is
        mesh = meshes[0]
        ranges = {t: (0, len(c)) for t, c in mesh.cells.items()}
        return Welded(mesh, [np.arange(mesh.num_points)], [ranges])
    points = np.vstack([m.points for m in meshes])
    offsets = np.cumsum([0] + [m.num_points for m in meshes])
    size = float(np.ptp(points, axis=0).max()) or 1.0
    tolerance = 1e-6 * size if tolerance is None else tolerance
    owner = np.repeat(np.arange(len(meshes)), [m.num_points for m in meshes])
    candidates = np.concatenate(
        [offset + np.unique(m.boundary_edges()) for m, offset in zip(meshes, offsets, strict=False)]
    )
    merged = coincident_nodes(points, tolerance, candidates, apart=owner)
    # welded node = first node of each group, numbered in order of first appearance
    first, welded_of = np.unique(merged, return_inverse=True)
    welded_points = np.zeros((len(first), 3))
    counts = np.bincount(welded_of)
    for axis in range(3):
        welded_points[:, axis] = np.bincount(welded_of, weights=points[:, axis]) / counts
    node_maps = [welded_of[offsets[p] : offsets[p + 1]] for p in range(len(meshes))]
    blocks: dict[str, list[np.ndarray]] = {}
    cell_ranges: list[dict[str, tuple[int, int]]] = []
    for mesh, node_map in zip(meshes, node_maps, strict=True):
        ranges = {}
        for cell_type, cells in mesh.cells.items():
            start = sum(len(b) for b in blocks.get(cell_type, []))
            blocks.setdefault(cell_type, []).append(node_map[cells])
            ranges[cell_type] = (start, start + len(cells))
        cell_ranges.append(ranges)
    try:
        mesh = SurfaceMesh(welded_points, {t: np.vstack(b) for t, b in blocks.items()})
    except MeshError as exc:
        raise MeshError(f"the welded panels are not one valid surface: {exc}") from None
    return Welded(mesh, node_maps, cell_ranges)


def corner_nodes(mesh: SurfaceMesh, loop: np.ndarray, angle: float) -> np.ndarray:
    """The nodes of a boundary loop where the boundary turns by more than ``angle`` degrees
    (the angle between the incoming and the outgoing boundary edge, in 3D)."""
    points = mesh.points[loop]
    incoming = points - np.roll(points, 1, axis=0)
    outgoing = np.roll(points, -1, axis=0) - points
    cosine = np.einsum("ij,ij->i", incoming, outgoing) / (
        np.linalg.norm(incoming, axis=1) * np.linalg.norm(outgoing, axis=1)
    )
    turn = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
    return loop[turn > angle]
