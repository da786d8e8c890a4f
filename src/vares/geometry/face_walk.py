"""Walking across a triangle mesh's faces to where a circle or two spheres meet it: the search
of the kinematic net (:mod:`vares.geometry.drape_net`), which finds each node as the point of the
mould at a yarn's spacing from its neighbours, face by face until the point lies inside the face
it was computed with; and the node normals interpolated over the faces that its geodesic
generators turn along."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .mesh import SurfaceMesh
from .surface_points import barycentric, face_neighbours

__all__ = [
    "FaceWalk",
    "circle_intersections",
    "node_normals",
    "smooth_normals",
    "sphere_intersections",
]


def node_normals(mesh: SurfaceMesh) -> np.ndarray:
    """Unit normals ``(n, 3)`` at the nodes: the sums of the area vectors of the faces round
    each node (an area-weighted mean)."""
    triangles = mesh.cells["triangle"]
    vectors = mesh.area_vectors()
    normals = np.zeros((mesh.num_points, 3))
    for corner in range(3):
        np.add.at(normals, triangles[:, corner], vectors)
    return normals / np.maximum(np.linalg.norm(normals, axis=1), 1e-300)[:, None]


def smooth_normals(node_normals, triangles, faces, bary) -> np.ndarray:
    """The node normals interpolated at points ``faces`` ``(k,)``, ``bary`` ``(k, 3)``: unit
    vectors ``(k, 3)`` that vary continuously over the mould, across its faces' sides too."""
    normals = np.einsum("kc,kci->ki", bary, node_normals[triangles[faces]])
    return normals / np.linalg.norm(normals, axis=1)[:, None]


class FaceWalk(NamedTuple):
    """A walk across the faces: their corners, unit normals, neighbours, triangles, and the
    most faces a walk may cross."""

    corners: np.ndarray
    normals: np.ndarray
    neighbours: np.ndarray
    triangles: np.ndarray
    max_steps: int

    @classmethod
    def of(cls, mesh: SurfaceMesh, spacing: float) -> FaceWalk:
        triangles = mesh.cells["triangle"]
        corners = mesh.points[triangles]
        normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        normals /= np.linalg.norm(normals, axis=1)[:, None]
        edge = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=-1).min()
        steps = 64 + 8 * int(np.ceil(spacing / edge))  # a walk crosses about spacing / edge faces
        return cls(corners, normals, face_neighbours(triangles), triangles, steps)


def sphere_intersections(p0, p1, p2, start, spacing, walk: FaceWalk):
    """The points ``(k, 3)`` of the mesh at the distance ``spacing`` from both ``p1`` and ``p2``
    ``(k, 3)``, on the side away from ``p0``, their faces ``(k,)`` (NaN and −1 where there is
    none) and whether they lie beyond the mould's edge ``(k,)`` (:func:`circle_intersections`,
    within ``spacing``), walking from the faces ``start``."""
    chord = p2 - p1
    distance = np.linalg.norm(chord, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        e = chord / distance[:, None]
    centre = 0.5 * (p1 + p2)
    radius_sq = spacing**2 - 0.25 * distance**2
    radius = np.sqrt(np.clip(radius_sq, 0.0, None))
    away = centre - p0
    away -= np.einsum("ki,ki->k", away, e)[:, None] * e
    with np.errstate(invalid="ignore", divide="ignore"):
        along = away / np.linalg.norm(away, axis=1)[:, None]
    across = np.cross(e, along)
    # the rhombus (p0, p1, ·, p2) has the yarn angle 2 arcsin(distance / 2 spacing) at p0:
    # distance → 0 or → 2 spacing is a cell sheared to ±90°, where the net ends
    usable = (radius_sq > 1e-12 * spacing**2) & (distance > 1e-6 * spacing)
    return circle_intersections(centre, radius, along, across, start, walk, usable, beyond=spacing)


def circle_intersections(
    centre, radius, along, across, start, walk: FaceWalk, usable=None, beyond: float = 0.0
):
    """The points ``(k, 3)`` where the circles ``centre + radius (cos θ along + sin θ across)``
    (``(k, 3)``, ``(k,)``, unit ``along`` ⟂ ``across``) meet the mesh, the root nearer to
    ``along``, their faces ``(k,)`` (NaN and −1 where there is none, or not ``usable``), and
    ``(k,)`` whether the point lies beyond the mould's edge: a walk that would leave the mould
    across a boundary side takes the root in the plane of the boundary face when it lies within
    ``beyond`` of that face (the net runs on over the edge), else none; walking from the faces
    ``start``."""
    corners, normals, neighbours = walk.corners, walk.normals, walk.neighbours
    count = len(centre)
    point = np.full((count, 3), np.nan)
    found = np.full(count, -1, dtype=np.int64)
    off = np.zeros(count, dtype=bool)
    face, previous = start.copy(), np.full(count, -1, dtype=np.int64)
    active = np.arange(count) if usable is None else np.flatnonzero(usable)
    for _ in range(walk.max_steps):
        if not active.size:
            break
        f = face[active]
        n = normals[f]
        alpha = np.einsum("ki,ki->k", n, along[active])
        beta = np.einsum("ki,ki->k", n, across[active])
        rho = np.hypot(alpha, beta)
        offset = np.einsum("ki,ki->k", n, corners[f, 0] - centre[active])
        with np.errstate(invalid="ignore", divide="ignore"):
            c = offset / (radius[active] * rho)
        reaches = np.abs(c) <= 1.0
        phi, delta = np.arctan2(beta, alpha), np.arccos(np.clip(c, -1.0, 1.0))
        theta = np.where(np.cos(phi + delta) >= np.cos(phi - delta), phi + delta, phi - delta)
        q = centre[active] + radius[active, None] * (
            np.cos(theta)[:, None] * along[active] + np.sin(theta)[:, None] * across[active]
        )
        lam, _ = barycentric(q, corners[f])
        worst = np.argmin(lam, axis=1)
        inside = lam[np.arange(len(f)), worst] >= -1e-9
        step = neighbours[f, worst]
        # stepping back to the face it came from: the root lies on the side the two share
        back = ~inside & (step >= 0) & (step == previous[active]) & reaches
        if back.any():
            clamped = np.clip(lam[back], 0.0, None)
            clamped /= clamped.sum(axis=1, keepdims=True)
            q[back] = np.einsum("kc,kci->ki", clamped, corners[f[back]])
        outside = ~inside & ~back & (step < 0) & reaches
        if beyond > 0 and outside.any():
            clamped = np.clip(lam[outside], 0.0, None)
            clamped /= clamped.sum(axis=1, keepdims=True)
            foot = np.einsum("kc,kci->ki", clamped, corners[f[outside]])
            near = np.linalg.norm(q[outside] - foot, axis=1) <= beyond
            off[active[np.flatnonzero(outside)[near]]] = True
            outside[np.flatnonzero(outside)[~near]] = False
        else:
            outside[:] = False
        done = (inside | back | outside) & reaches
        point[active[done]], found[active[done]] = q[done], f[done]
        moving = ~inside & ~back & (step >= 0)
        previous[active[moving]] = f[moving]
        face[active[moving]] = step[moving]
        active = active[moving]
    return point, found, off
