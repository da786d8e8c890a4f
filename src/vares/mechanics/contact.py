"""Frictionless contact with a mould: nodes that slide on a surface and cannot leave it.

Each sliding node ``a`` lies on a face of the mould (:class:`vares.geometry.mould.Mould`) and
moves in that face's plane, ``x_a + T_a Δu_a`` with ``T_a`` ``(3, 2)`` an orthonormal basis of
the plane, after which it is put back onto the mould at the nearest point (the retraction of
Newton's method on a surface). The reaction of a frictionless contact is normal to the mould, so
equilibrium is the vanishing of the tangential forces ``T_aᵀ g_a``; the reduced tangent is
``Tᵀ K T``. Inside a face the mould is flat and the reduced problem is the exact one: Newton's
method keeps its rate once every node stays in its face.

A **held** node does not move (the seed). A **guided** node moves only along the line where its
face's plane meets a given plane (the warp's plane through the seed): it keeps the blank from
turning about the seed; after every move it is put back into the plane and onto the mould
(:data:`GUIDE_STEPS` times: the plane crosses the mould nearly at right angles).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..geometry.mould import Mould

__all__ = ["SlidingNodes", "turned_over"]

#: Steps of putting a guided node back into its plane and onto the mould after each move.
GUIDE_STEPS = 4


@dataclass
class SlidingNodes:
    """The nodes of a blank on a mould: ``positions`` ``(n, 3)`` on it, the ``faces`` ``(n,)``
    they lie in and their barycentric coordinates ``(n, 3)``, the ``held`` nodes ``(n,)`` bool,
    and ``guided``: node → the plane it stays in, ``(unit normal (3,), offset)`` (the points
    ``p`` with ``p · normal = offset``)."""

    mould: Mould
    positions: np.ndarray
    faces: np.ndarray
    bary: np.ndarray
    held: np.ndarray
    guided: dict[int, tuple[np.ndarray, float]]

    @classmethod
    def placed(
        cls,
        mould: Mould,
        points: np.ndarray,
        held: np.ndarray,
        guided: dict[int, tuple[np.ndarray, float]] | None = None,
    ) -> SlidingNodes:
        """Nodes put onto the mould at the points nearest to ``points`` ``(n, 3)``."""
        faces, bary, on = mould.project(points)
        return cls(mould, on, faces, bary, np.asarray(held, dtype=bool), dict(guided or {}))

    def basis(self) -> sp.csr_matrix:
        """``T`` ``(3 n, k)``: the free tangent directions (two per sliding node, one per guided
        node, none for held ones), one column each."""
        n = len(self.positions)
        vectors = self.mould.tangent_bases(self.faces).transpose(0, 2, 1).copy()  # (n, 2, 3)
        counts = np.where(self.held, 0, 2)
        if self.guided:
            nodes = np.fromiter(self.guided, dtype=np.int64, count=len(self.guided))
            planes = np.array([self.guided[a][0] for a in nodes.tolist()], dtype=float)
            direction = np.cross(self.mould.normals[self.faces[nodes]], planes)
            vectors[nodes, 0] = direction / np.linalg.norm(direction, axis=1)[:, None]
            counts[nodes] = np.where(self.held[nodes], 0, 1)
        used = np.arange(2)[None, :] < counts[:, None]  # (n, 2): the node's columns
        node, _ = np.nonzero(used)
        rows = (3 * node[:, None] + np.arange(3)).ravel()
        cols = np.repeat(np.arange(len(node)), 3)
        return sp.csr_matrix((vectors[used].ravel(), (rows, cols)), shape=(3 * n, len(node)))

    def moved(self, step: np.ndarray) -> SlidingNodes:
        """The nodes moved by ``step`` ``(n, 3)`` (tangential) and put back onto the mould; held
        nodes stay where they are."""
        target = self.positions + step
        faces, bary, on = self.mould.project(target)
        on[self.held] = self.positions[self.held]
        faces[self.held] = self.faces[self.held]
        bary[self.held] = self.bary[self.held]
        for node, (normal, offset) in self.guided.items():
            point = on[node]
            for _ in range(GUIDE_STEPS):  # back into its plane, on the mould
                point = point - (point @ normal - offset) * normal
                face, weights, point = (a[0] for a in self.mould.project(point[None]))
            on[node], faces[node], bary[node] = point, face, weights
        return SlidingNodes(self.mould, on, faces, bary, self.held, self.guided)


def turned_over(
    positions: np.ndarray, faces: np.ndarray, triangles: np.ndarray, normals: np.ndarray
) -> np.ndarray:
    """Ids of the blank's ``triangles`` ``(m, 3)`` that face away from the mould: their area
    vector at ``positions`` against the mean normal of the faces ``(n,)`` their nodes lie in
    (``normals`` ``(f, 3)`` per mould face)."""
    p = positions[triangles]
    area = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    mean = normals[faces[triangles]].sum(axis=1)
    return np.flatnonzero(~(np.einsum("mi,mi->m", area, mean) > 0))
