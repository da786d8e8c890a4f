"""The reference element: shape functions and quadrature of one cell type."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ReferenceElement:
    """Shape functions and quadrature of one meshio cell type.

    Attributes
    ----------
    cell_type
        meshio's name of the cell type.
    num_nodes
        Nodes per cell.
    quadrature_weights
        ``(q,)`` weights on the reference cell.
    shape_gradients
        ``(q, num_nodes, 2)``: ``∂N_a/∂ξ_α`` at each quadrature point.
    check_gradients
        ``(c, num_nodes, 2)``: shape function gradients at the points where ``det J > 0``
        guarantees a non-inverted cell (for a bilinear quad, its corners).
    """

    cell_type: str
    num_nodes: int
    quadrature_weights: np.ndarray
    shape_gradients: np.ndarray
    check_gradients: np.ndarray

    @property
    def num_quadrature_points(self) -> int:
        return len(self.quadrature_weights)

    def jacobians(self, coordinates: np.ndarray, cells: np.ndarray, at: str = "quadrature"):
        """``∂x/∂ξ`` of every cell, ``(m, q, d, 2)`` for node coordinates ``(n, d)``."""
        grads = self.shape_gradients if at == "quadrature" else self.check_gradients
        return np.einsum("mai,qak->mqik", coordinates[cells], grads)

    def metrics(self, points: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """Surface metric ``jᵀj`` at the quadrature points, ``(m, q, 2, 2)``."""
        j = self.jacobians(points, cells)
        return np.einsum("mqik,mqil->mqkl", j, j)

    def areas(self, points: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """Area of each cell (3D or 2D coordinates), ``(m,)``."""
        if points.shape[1] == 2:
            j = self.jacobians(points, cells)
            det = j[..., 0, 0] * j[..., 1, 1] - j[..., 0, 1] * j[..., 1, 0]
            return det @ self.quadrature_weights
        g = self.metrics(points, cells)
        det = g[..., 0, 0] * g[..., 1, 1] - g[..., 0, 1] * g[..., 1, 0]
        return np.sqrt(np.maximum(det, 0.0)) @ self.quadrature_weights

    def corner_areas(self, points: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """``|∂x/∂ξ₁ × ∂x/∂ξ₂|`` at the check points, ``(m, c)``: zero for a degenerate cell."""
        j = self.jacobians(points, cells, at="check")
        if points.shape[1] == 2:
            return np.abs(j[..., 0, 0] * j[..., 1, 1] - j[..., 0, 1] * j[..., 1, 0])
        return np.linalg.norm(np.cross(j[..., 0], j[..., 1]), axis=-1)
