"""Lines on a triangle mesh: plane sections, geodesics and curves drawn onto the surface.

A :class:`SurfaceLine` is a polyline that runs on the mesh: each of its points lies on a mesh
edge (or is a node), and two consecutive points lie in one cell, so the line is straight inside
every cell it crosses. That is exactly what a plane section of a triangle mesh is, and what a
geodesic (a locally shortest path) on a polyhedral surface is; a user's curve is brought to this
form by drawing it onto the surface (:func:`curve_on_surface`). :mod:`vares.geometry.cutting` cuts
the mesh along such lines.

Geodesics are computed by the edge-flip algorithm of Sharp & Crane (2020, "You can find geodesic
paths in triangle meshes by just flipping edges"), as implemented in potpourri3d: the exact
locally shortest path on the polyhedral surface, not an approximation by mesh edges.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .mesh import MeshError, SurfaceMesh

__all__ = [
    "CuttingError",
    "EdgeLocator",
    "SurfaceLine",
    "geodesic_lines",
    "mesh_edges",
    "plane_sections",
    "triangulated",
]


class CuttingError(ValueError):
    """Cutting lines that cannot be made or used (they cross, end inside the surface, …)."""


@dataclass(frozen=True)
class SurfaceLine:
    """A polyline on a triangle mesh.

    Point ``k`` lies on the edge ``ends[k]`` (two node indices) at the fraction ``fractions[k]``
    from ``ends[k, 0]``; it is the node ``ends[k, 0]`` when both ends are equal. ``points`` are
    the positions ``(k, 3)``. Consecutive points lie in one cell.
    """

    ends: np.ndarray  # (k, 2) int
    fractions: np.ndarray  # (k,)
    points: np.ndarray  # (k, 3)

    @classmethod
    def at(cls, mesh_points: np.ndarray, ends: np.ndarray, fractions: np.ndarray) -> SurfaceLine:
        """The line through the given edge locations of a mesh with nodes ``mesh_points``."""
        ends = np.asarray(ends, dtype=np.int64).reshape(-1, 2)
        fractions = np.asarray(fractions, dtype=float).ravel()
        points = (1.0 - fractions)[:, None] * mesh_points[ends[:, 0]] + fractions[
            :, None
        ] * mesh_points[ends[:, 1]]
        return cls(ends, fractions, points)

    @property
    def length(self) -> float:
        """3D length of the polyline."""
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())

    def reversed(self) -> SurfaceLine:
        return SurfaceLine(self.ends[::-1], self.fractions[::-1], self.points[::-1])


def triangulated(mesh: SurfaceMesh) -> SurfaceMesh:
    """The mesh with every quad split into two triangles along the diagonal that gives the
    larger smallest angle (a triangle mesh is returned unchanged)."""
    if set(mesh.cells) == {"triangle"}:
        return mesh
    blocks = [mesh.cells.get("triangle", np.zeros((0, 3), dtype=np.int64))]
    if "quad" in mesh.cells:
        quads = mesh.cells["quad"]
        points = mesh.points

        def quality(first: list[int], second: list[int]) -> np.ndarray:
            return np.minimum(
                min_angles(points, quads[:, first]), min_angles(points, quads[:, second])
            )

        along_02 = quality([0, 1, 2], [0, 2, 3]) >= quality([0, 1, 3], [1, 2, 3])
        blocks.append(np.where(along_02[:, None], quads[:, [0, 1, 2]], quads[:, [0, 1, 3]]))
        blocks.append(np.where(along_02[:, None], quads[:, [0, 2, 3]], quads[:, [1, 2, 3]]))
    return SurfaceMesh(mesh.points, {"triangle": np.vstack(blocks)})


def min_angles(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Smallest interior angle (degrees) of every triangle ``(m, 3)``."""
    corners = points[triangles]  # (m, 3, d)
    angles = []
    for k in range(3):
        u = corners[:, (k + 1) % 3] - corners[:, k]
        v = corners[:, (k + 2) % 3] - corners[:, k]
        cross = np.cross(u, v)
        sine = np.linalg.norm(cross, axis=-1) if cross.ndim > 1 else np.abs(cross)
        angles.append(np.degrees(np.arctan2(sine, np.einsum("ij,ij->i", u, v))))
    return np.min(angles, axis=0)


def mesh_edges(triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Undirected edges ``(e, 2)`` (smaller node first) and the edge of each triangle side
    ``(m, 3)`` (side k runs from corner k to corner k + 1)."""
    sides = np.stack([triangles, np.roll(triangles, -1, axis=1)], axis=-1).reshape(-1, 2)
    edges, index = np.unique(np.sort(sides, axis=1), axis=0, return_inverse=True)
    return edges, index.reshape(-1, 3)


class EdgeLocator:
    """Finds the edges and nodes of a triangle mesh that points lie on: the search trees are
    built once per mesh (0.1 s on 20k triangles), then :meth:`line` for every line."""

    def __init__(self, mesh: SurfaceMesh, tolerance: float | None = None) -> None:
        from scipy.spatial import cKDTree

        self.nodes = mesh.points
        size = float(np.ptp(self.nodes, axis=0).max()) or 1.0
        self.tolerance = 1e-9 * size if tolerance is None else tolerance
        self.edges = np.sort(mesh.edges(), axis=1)  # smaller node first
        self.a, self.b = self.nodes[self.edges[:, 0]], self.nodes[self.edges[:, 1]]
        self.node_tree = cKDTree(self.nodes)
        self.edge_tree = cKDTree(0.5 * (self.a + self.b))

    def line(self, points: np.ndarray) -> SurfaceLine:
        """The :class:`SurfaceLine` through ``points`` ``(k, 3)``."""
        nodes, edges, a, b, tolerance = self.nodes, self.edges, self.a, self.b, self.tolerance
        node_distance, nearest_node = self.node_tree.query(points)
        edge_tree = self.edge_tree
        ends, fractions = [], []
        for point, distance, node in zip(points, node_distance, nearest_node, strict=True):
            if distance <= tolerance:
                ends.append((node, node))
                fractions.append(0.0)
                continue
            _, candidates = edge_tree.query(point, k=min(16, len(edges)))
            best, t = _nearest_edge(point, a[candidates], b[candidates])
            if best[1] > tolerance:  # rare: search every edge
                best, t = _nearest_edge(point, a, b)
                candidates = np.arange(len(edges))
            if best[1] > tolerance:
                raise CuttingError(f"point {point} of a line does not lie on the mesh's edges")
            ends.append(tuple(edges[candidates[best[0]]]))
            fractions.append(t[best[0]])
        return SurfaceLine.at(nodes, np.array(ends), np.array(fractions))


def _nearest_edge(point, a, b) -> tuple[tuple[int, float], np.ndarray]:
    direction = b - a
    t = np.clip(np.einsum("ij,ij->i", point - a, direction) / np.sum(direction**2, axis=1), 0, 1)
    distance = np.linalg.norm(a + t[:, None] * direction - point, axis=1)
    k = int(np.argmin(distance))
    return (k, float(distance[k])), t


def plane_sections(mesh: SurfaceMesh, normal: np.ndarray, offset: float) -> list[SurfaceLine]:
    """The open polylines where the plane ``normal · x = offset`` cuts a triangle mesh.

    Nodes within 1e-12 × the mesh size of the plane count as on it. Closed loops (a plane that
    cuts out an island) are left out: they are no cutting lines from boundary to boundary.
    """
    points = mesh.points
    triangles = mesh.cells["triangle"]
    size = float(np.ptp(points, axis=0).max()) or 1.0
    normal = np.asarray(normal, dtype=float)
    level = points @ normal - offset
    level[np.abs(level) <= 1e-12 * size * np.linalg.norm(normal)] = 0.0
    values = level[triangles]
    crossed = np.flatnonzero((values.min(axis=1) <= 0) & (values.max(axis=1) >= 0))
    location: dict[tuple[int, int], tuple[int, int, float]] = {}
    neighbours: dict[tuple[int, int], set[tuple[int, int]]] = {}
    for face in crossed:
        found = []
        corners = triangles[face]
        for k in range(3):
            a, b = int(corners[k]), int(corners[(k + 1) % 3])
            fa, fb = level[a], level[b]
            if fa == 0.0:
                found.append(((a, a), (a, a, 0.0)))
            elif fa * fb < 0:
                lo, hi = min(a, b), max(a, b)
                t = level[lo] / (level[lo] - level[hi])
                found.append(((lo, hi), (lo, hi, t)))
        if len(found) != 2:  # a single touching node, or the whole cell in the plane
            continue
        (k1, l1), (k2, l2) = found
        location[k1], location[k2] = l1, l2
        neighbours.setdefault(k1, set()).add(k2)
        neighbours.setdefault(k2, set()).add(k1)
    lines = []
    for chain in _chains(neighbours):
        ends = np.array([location[k][:2] for k in chain])
        fractions = np.array([location[k][2] for k in chain])
        lines.append(SurfaceLine.at(points, ends, fractions))
    return lines


def _chains(neighbours: dict) -> list[list]:
    """Open chains of a graph of degree ≤ 2 (from its degree-1 nodes); a node of higher degree
    (a plane through a saddle node) is an error."""
    if any(len(n) > 2 for n in neighbours.values()):
        raise CuttingError("a plane section branches (it passes through a saddle node)")
    seen: set = set()
    chains = []
    for start in sorted(k for k, n in neighbours.items() if len(n) == 1):
        if start in seen:
            continue
        chain, previous, node = [start], None, start
        seen.add(start)
        while True:
            following = [n for n in neighbours[node] if n != previous]
            if not following:
                break
            previous, node = node, following[0]
            chain.append(node)
            seen.add(node)
        chains.append(chain)
    return chains


def geodesic_lines(mesh: SurfaceMesh, node_pairs: Sequence[tuple[int, int]]) -> list[SurfaceLine]:
    """The geodesic (locally shortest path on the polyhedral surface) between each pair of
    nodes of a triangle mesh, by edge flips (module docs)."""
    import potpourri3d as pp3d

    solver = pp3d.EdgeFlipGeodesicSolver(mesh.points, mesh.cells["triangle"])
    locate = EdgeLocator(mesh)
    lines = []
    for start, end in node_pairs:
        if start == end:
            raise CuttingError("a geodesic needs two different end nodes")
        path = np.asarray(solver.find_geodesic_path(int(start), int(end)))
        lines.append(locate.line(path))
    return lines


def check_triangles(mesh: SurfaceMesh) -> np.ndarray:
    """The triangles of a triangle-only mesh (else a :class:`MeshError`)."""
    if set(mesh.cells) != {"triangle"}:
        raise MeshError("cutting lines need a triangle mesh (use triangulated(mesh))")
    return mesh.cells["triangle"]
