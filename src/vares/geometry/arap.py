"""As-rigid-as-possible flattening (Liu et al. 2008, libigl's ``arap``).

ARAP finds the pattern whose every triangle is as close as it can be to a rotated copy of
itself: it minimises ``Σ_t A_t |J_t − R_t|²`` over the pattern and the rotations ``R_t``, with
``J_t`` the triangle's 2×2 map from its own plane to the pattern. The local step takes each
``R_t`` as the rotation nearest ``J_t``; the global step solves for the pattern with the
rotations held, a linear system whose matrix (the cotangent Laplacian) never changes and is
factorised once. Its minimum is an isometry wherever the surface is developable; on a rough
scan it lies close to the elastic optimum, so one local–global step from the projection or the
conformal map is a start from which Newton's method needs the iterations of a smooth mesh.
The global step can fold cells (it knows no barrier): callers check.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from .flatten import factorized, triangle_gradients, triangulated
from .mesh import SurfaceMesh

__all__ = ["ArapFlattening", "arap", "nearest_rotations"]


class ArapFlattening:
    """ARAP on one mesh: each triangle's shape-function gradients in its own plane and its area,
    and the cotangent Laplacian with node 0 held, factorised once (``factorize``: a function
    from a sparse symmetric positive definite matrix to its solver ``rhs ↦ x``)."""

    def __init__(
        self,
        mesh: SurfaceMesh,
        factorize: Callable[[sp.spmatrix], Callable[[np.ndarray], np.ndarray]] = factorized,
    ) -> None:
        self.num_points = n = mesh.num_points
        self.triangles = tris = triangulated(mesh)
        self.gx, self.gy, self.areas = triangle_gradients(mesh.points, tris)
        area = self.areas[:, None, None]
        local = area * (self.gx[:, :, None] * self.gx[:, None, :])
        local += area * (self.gy[:, :, None] * self.gy[:, None, :])
        rows = np.repeat(tris, 3, axis=1).ravel()
        cols = np.tile(tris, (1, 3)).ravel()
        laplacian = sp.csr_matrix((local.ravel(), (rows, cols)), shape=(n, n))
        self._held_column = laplacian[1:, 0].toarray().ravel()
        self._solve = factorize(laplacian[1:, 1:])

    def jacobians(self, coordinates: np.ndarray) -> np.ndarray:
        """Each triangle's map ``(k, 2, 2)`` from its own plane to the pattern ``(n, 2)``
        (row ``d``: the gradient of pattern coordinate ``d``)."""
        corner = coordinates[self.triangles]  # (k, 3, 2)
        along = np.einsum("kc,kcd->kd", self.gx, corner)
        across = np.einsum("kc,kcd->kd", self.gy, corner)
        return np.stack([along, across], axis=2)

    def energy(self, coordinates: np.ndarray) -> float:
        """``Σ_t A_t |J_t − R_t|²`` with each ``R_t`` the rotation nearest ``J_t`` (an area)."""
        j = self.jacobians(coordinates)
        return float(self.areas @ np.sum((j - nearest_rotations(j)) ** 2, axis=(1, 2)))

    def step(self, coordinates: np.ndarray) -> np.ndarray:
        """One local–global step: the pattern that minimises the energy with the rotations
        nearest the triangles of ``coordinates`` held, node 0 kept where it is."""
        rotations = nearest_rotations(self.jacobians(coordinates))
        n, area = self.num_points, self.areas[:, None]
        rhs = np.empty((n, 2))
        for d in range(2):
            weights = area * (self.gx * rotations[:, d, 0:1] + self.gy * rotations[:, d, 1:2])
            rhs[:, d] = np.bincount(self.triangles.ravel(), weights.ravel(), minlength=n)
        result = np.empty((n, 2))
        result[0] = coordinates[0]
        # the held node's column of the Laplacian moves to the right-hand side
        right = rhs[1:] - self._held_column[:, None] * coordinates[0]
        result[1:] = np.column_stack([self._solve(right[:, d]) for d in range(2)])
        return result


def nearest_rotations(j: np.ndarray) -> np.ndarray:
    """The rotation nearest each 2×2 matrix of ``j`` ``(k, 2, 2)`` in the Frobenius norm, of
    angle ``atan2(j₁₀ − j₀₁, j₀₀ + j₁₁)``: a proper rotation even where ``j`` reflects."""
    angle = np.arctan2(j[:, 1, 0] - j[:, 0, 1], j[:, 0, 0] + j[:, 1, 1])
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([np.stack([c, -s], axis=1), np.stack([s, c], axis=1)], axis=1)


def arap(
    mesh: SurfaceMesh,
    start: np.ndarray,
    iterations: int = 10,
    flattening: ArapFlattening | None = None,
) -> np.ndarray:
    """``iterations`` local–global ARAP steps from the pattern ``start`` ``(n, 2)`` (a
    flattening that folds nothing: the conformal map, Tutte's embedding). Returns the pattern
    ``(n, 2)``; it may fold cells where the surface is far from developable."""
    flat = ArapFlattening(mesh) if flattening is None else flattening
    x = np.array(start, dtype=float)
    for _ in range(iterations):
        x = flat.step(x)
    return x
