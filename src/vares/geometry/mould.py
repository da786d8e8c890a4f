"""A mould as a contact surface: points on it, its tangent planes, and a flange beyond its edge.

A blank draped onto a mould lies on it wherever it covers it; the part beyond the mould's edge
(the excess, trimmed after draping) still has to lie somewhere. :func:`mould_surface` extends
the mould by a **flange**: from every boundary node a straight line along the surface's outward
conormal there (in the tangent plane, at right angles to the boundary), in ``layers`` rows of
triangles out to ``width``. The flange continues the mould's tangent plane across its edge (a
hemisphere cut at the equator gets a vertical cylinder, a flat plate a wider plate), as the
binder of a forming tool does. Where the boundary is concave in the tangent plane, flange lines
converge: a width beyond the boundary's radius of curvature there folds the flange.

Every node of the extended surface carries its **outwardness**: 0 on the mould's boundary, the
distance along its flange line beyond it, and minus the distance to the boundary inside the
mould. Read at a draped point it says whether the point lies on the part (< 0) or on the excess
(> 0), and its zero level on the blank is the trim line.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from .mesh import SurfaceMesh
from .surface_lines import triangulated
from .surface_points import FaceLocator, face_neighbours

__all__ = ["Mould", "mould_surface"]


@dataclass(frozen=True)
class Mould:
    """The mould's triangles followed by its flange's (module docs).

    ``mesh``: the extended triangle mesh; ``part_cells``: its first ``part_cells`` triangles are
    the mould's own; ``outwardness`` ``(n,)`` per node (module docs); ``normals`` ``(m, 3)``:
    unit face normals; ``flange_width``: how far the flange reaches (0: none).
    """

    mesh: SurfaceMesh
    part_cells: int
    outwardness: np.ndarray
    normals: np.ndarray
    flange_width: float
    locator: FaceLocator

    @property
    def triangles(self) -> np.ndarray:
        return self.mesh.cells["triangle"]

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The nearest points of the surface to ``points`` ``(k, 3)``: their faces ``(k,)``,
        barycentric coordinates ``(k, 3)`` and positions ``(k, 3)``."""
        return self.locator.locate(points)

    def tangent_bases(self, faces: np.ndarray) -> np.ndarray:
        """Orthonormal bases ``(k, 3, 2)`` of the planes of ``faces``: the first vector along the
        face's first side, the second ``normal × first``."""
        normal = self.normals[faces]
        corners = self.mesh.points[self.triangles[faces]]
        first = corners[:, 1] - corners[:, 0]
        first -= np.einsum("ki,ki->k", first, normal)[:, None] * normal
        first /= np.linalg.norm(first, axis=1, keepdims=True)
        second = np.cross(normal, first)
        return np.stack([first, second], axis=-1)

    def outward(self, faces: np.ndarray, bary: np.ndarray) -> np.ndarray:
        """The outwardness ``(k,)`` at points given by faces and barycentric coordinates."""
        return np.einsum("kc,kc->k", bary, self.outwardness[self.triangles[faces]])


def mould_surface(mesh: SurfaceMesh, flange_width: float = 0.0, layers: int | None = None) -> Mould:
    """The mould ``mesh`` (triangles or quads; quads are split) as a contact surface, extended by
    a flange of ``flange_width`` (mesh length units; 0: none) in ``layers`` rows of triangles
    (default: as many as make the rows about as deep as the boundary's mean edge is long)."""
    tri = triangulated(mesh)
    points, triangles = tri.points, tri.cells["triangle"]
    loops = tri.boundary_loops()
    boundary = np.concatenate(loops) if loops else np.zeros(0, dtype=np.int64)
    edges = [np.column_stack([loop, np.roll(loop, -1)]) for loop in loops]
    edge_length = (
        float(np.mean([np.linalg.norm(np.diff(points[e], axis=1), axis=-1).mean() for e in edges]))
        if edges
        else 0.0
    )
    inside = _inside_outwardness(points, boundary, edges)
    if not flange_width > 0 or not loops:
        extended, outwardness = tri, inside
        flange_width = 0.0
    else:
        if layers is None:
            layers = max(1, int(np.ceil(flange_width / max(edge_length, 1e-300))))
        extended, flange_out = _with_flange(tri, loops, float(flange_width), int(layers))
        outwardness = np.concatenate([inside, flange_out])
    cells = extended.cells["triangle"]
    corners = extended.points[cells]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return Mould(
        extended,
        len(triangles),
        outwardness,
        normals,
        float(flange_width),
        FaceLocator(extended, candidates=10),
    )


def _inside_outwardness(points, boundary, edges) -> np.ndarray:
    """Minus the distance of every node to the boundary (to the nearest of the boundary edges
    near it, found through points along the edges), 0 on it."""
    from scipy.spatial import cKDTree

    if not len(boundary):
        return np.full(len(points), -np.inf)
    segments = np.vstack(edges)
    a, b = points[segments[:, 0]], points[segments[:, 1]]
    t = np.linspace(0.0, 1.0, 9)[:-1]
    samples = (a[:, None] + t[None, :, None] * (b - a)[:, None]).reshape(-1, 3)
    owner = np.repeat(np.arange(len(segments)), len(t))
    _, near = cKDTree(samples).query(points, k=min(16, len(samples)))
    near = owner[near.reshape(len(points), -1)]  # (n, k) candidate edges
    pa, pb = a[near], b[near]
    along = pb - pa
    s = np.einsum("nki,nki->nk", points[:, None] - pa, along) / np.einsum(
        "nki,nki->nk", along, along
    )
    foot = pa + np.clip(s, 0.0, 1.0)[..., None] * along
    out = -np.linalg.norm(foot - points[:, None], axis=-1).min(axis=1)
    out[boundary] = 0.0
    return out


def _boundary_faces(triangles: np.ndarray) -> dict[tuple[int, int], int]:
    """The face of every boundary side, keyed by the side's nodes in cell orientation."""
    face, corner = np.nonzero(face_neighbours(triangles) < 0)
    a = triangles[face, (corner + 1) % 3].tolist()
    b = triangles[face, (corner + 2) % 3].tolist()
    return dict(zip(zip(a, b, strict=True), face.tolist(), strict=True))


def _conormals(points, triangles, loop, key: dict[tuple[int, int], int]) -> np.ndarray:
    """Unit outward conormals ``(k, 3)`` at the nodes of a boundary ``loop`` (in cell
    orientation): the mean of the outward normals of the two boundary edges at the node, each
    ``edge × face normal`` (``key``: :func:`_boundary_faces`)."""
    nxt = np.roll(loop, -1)
    faces = np.array([key[(int(a), int(b))] for a, b in zip(loop, nxt, strict=True)])
    corners = points[triangles[faces]]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    edge = points[nxt] - points[loop]
    out_edge = np.cross(edge, normal)
    out_edge /= np.linalg.norm(out_edge, axis=1, keepdims=True)
    node = out_edge + np.roll(out_edge, 1, axis=0)  # edges after and before each node
    return node / np.linalg.norm(node, axis=1, keepdims=True)


def _with_flange(tri: SurfaceMesh, loops, width: float, layers: int):
    """The mesh with a flange along every boundary loop, and the flange nodes' outwardness."""
    points, triangles = tri.points, tri.cells["triangle"]
    new_points, new_cells, outward = [], [], []
    count = len(points)
    depth = width * np.arange(1, layers + 1) / layers
    key = _boundary_faces(triangles)
    for loop in loops:
        conormal = _conormals(points, triangles, loop, key)
        k = len(loop)
        rows = [loop]
        for d in depth:
            new_points.append(points[loop] + d * conormal)
            outward.append(np.full(k, d))
            rows.append(count + np.arange(k))
            count += k
        for inner, outer in pairwise(rows):
            a0, b0 = inner, np.roll(inner, -1)
            a1, b1 = outer, np.roll(outer, -1)
            new_cells.append(np.column_stack([b0, a0, a1]))
            new_cells.append(np.column_stack([b0, a1, b1]))
    mesh = SurfaceMesh(
        np.vstack([points, *new_points]), {"triangle": np.vstack([triangles, *new_cells])}
    )
    return mesh, np.concatenate(outward)
