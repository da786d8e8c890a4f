"""Points on a triangle mesh: a point with the face it lies in, found for many points at once.

:class:`FaceLocator` finds the face of a triangle mesh nearest to each of many 3D points (and the
point's barycentric coordinates there); :func:`face_neighbours` gives the face across each side
of every triangle, so that a search can walk from face to face across the surface.
"""

from __future__ import annotations

import numpy as np

from .mesh import SurfaceMesh
from .surface_lines import mesh_edges

__all__ = ["FaceLocator", "barycentric", "face_neighbours"]


def face_neighbours(triangles: np.ndarray) -> np.ndarray:
    """The face across each side of every triangle, ``(m, 3)`` int: entry ``[f, k]`` is the
    face across the side opposite corner ``k`` of face ``f`` (−1 on the boundary)."""
    _, side_edge = mesh_edges(triangles)  # side k runs from corner k to corner k + 1
    opposite = side_edge[:, [1, 2, 0]]  # side opposite corner k
    faces = np.repeat(np.arange(len(triangles)), 3)
    edge = opposite.ravel()
    order = np.argsort(edge, kind="stable")
    edge, faces_sorted = edge[order], faces[order]
    pair = np.flatnonzero(edge[1:] == edge[:-1])  # interior edges: two sides, adjacent after sort
    neighbours = np.full(3 * len(triangles), -1, dtype=np.int64)
    neighbours[order[pair]] = faces_sorted[pair + 1]
    neighbours[order[pair + 1]] = faces_sorted[pair]
    return neighbours.reshape(-1, 3)


def barycentric(points: np.ndarray, corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Barycentric coordinates ``(..., 3)`` of the projections of ``points`` ``(..., 3)`` onto
    the planes of the triangles ``corners`` ``(..., 3, 3)``, and the signed distances ``(...)``
    of the points from those planes (along the unit normal of corner order).

    A triangle of zero area (its corners on one line or one point: a kinematic net's cell
    sheared flat) has no plane and holds no point: its coordinates are −inf and its distance
    +inf, so that a search for the triangle that holds a point passes over it."""
    a, b, c = corners[..., 0, :], corners[..., 1, :], corners[..., 2, :]
    normal = np.cross(b - a, c - a)
    twice_area = np.linalg.norm(normal, axis=-1)
    has_plane = twice_area > 0
    twice_area = np.where(has_plane, twice_area, 1.0)  # its normal is 0: no division by 0
    unit = normal / twice_area[..., None]
    rel = points - a
    height = np.einsum("...i,...i->...", rel, unit)
    foot = points - height[..., None] * unit
    l1 = np.einsum("...i,...i->...", np.cross(c - b, foot - b), unit) / twice_area
    l2 = np.einsum("...i,...i->...", np.cross(a - c, foot - c), unit) / twice_area
    coordinates = np.stack([l1, l2, 1.0 - l1 - l2], axis=-1)
    return (
        np.where(has_plane[..., None], coordinates, -np.inf),
        np.where(has_plane, height, np.inf),
    )


class FaceLocator:
    """The nearest face of a triangle mesh to each of many points.

    The candidates of a point are the faces whose centroids are nearest to it (a k-d tree built
    once); the point goes to the candidate at the least distance, measured to the candidate's
    plane inside the face and to its clamped barycentric point outside. For points on or near the
    surface (the use here) that is the face they lie in.
    """

    def __init__(self, mesh: SurfaceMesh, candidates: int = 12) -> None:
        from scipy.spatial import cKDTree

        self.points = mesh.points
        self.triangles = mesh.cells["triangle"]
        self.corners = self.points[self.triangles]  # (m, 3, 3)
        self.tree = cKDTree(self.corners.mean(axis=1))
        self.candidates = min(candidates, len(self.triangles))

    def locate(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Faces ``(k,)``, barycentric coordinates ``(k, 3)`` (clamped into the face) and the
        located points ``(k, 3)`` on the surface, for ``points`` ``(k, 3)``."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        _, near = self.tree.query(points, k=self.candidates)
        near = near.reshape(len(points), -1)
        lam, _ = barycentric(points[:, None, :], self.corners[near])
        clamped = np.clip(lam, 0.0, None)
        clamped /= clamped.sum(axis=-1, keepdims=True)
        on_face = np.einsum("kcj,kcji->kci", clamped, self.corners[near])
        distance = np.linalg.norm(on_face - points[:, None, :], axis=-1)
        best = np.argmin(distance, axis=1)
        rows = np.arange(len(points))
        return near[rows, best], clamped[rows, best], on_face[rows, best]
