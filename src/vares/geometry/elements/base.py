"""The reference element: shape functions and quadrature of one cell type; 2×2 matrix helpers."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._jit import compiled, lanes, njit


def determinant(a: np.ndarray) -> np.ndarray:
    """Determinant of 2×2 matrices ``(..., 2, 2)``."""
    return a[..., 0, 0] * a[..., 1, 1] - a[..., 0, 1] * a[..., 1, 0]


def inverse(a: np.ndarray, det: np.ndarray | None = None) -> np.ndarray:
    """Inverse of 2×2 matrices ``(..., 2, 2)``."""
    det = determinant(a) if det is None else det
    out = np.empty_like(a)
    out[..., 0, 0] = a[..., 1, 1]
    out[..., 1, 1] = a[..., 0, 0]
    out[..., 0, 1] = -a[..., 0, 1]
    out[..., 1, 0] = -a[..., 1, 0]
    return out / det[..., None, None]


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

    def jacobians(self, coordinates: np.ndarray, cells: np.ndarray, at: str = "quadrature"):
        """``∂x/∂ξ`` of every cell, ``(m, q, d, 2)`` for node coordinates ``(n, d)``."""
        grads = self.shape_gradients if at == "quadrature" else self.check_gradients
        if coordinates.dtype != np.float64:  # complex-step checks take the general path
            return np.swapaxes(coordinates[cells], 1, 2)[:, None] @ grads
        coordinates, cells = np.ascontiguousarray(coordinates), np.ascontiguousarray(cells)
        out = np.zeros((len(cells), grads.shape[0], coordinates.shape[1], 2))
        if compiled(len(cells)):
            _jacobians(coordinates, cells, grads, out)
        else:  # the same loop over all cells at once, the same sums (vares._jit)
            _jacobians.py_func(coordinates, lanes(cells), grads, lanes(out))
        return out

    def metrics(self, points: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """Surface metric ``jᵀj`` at the quadrature points, ``(m, q, 2, 2)``."""
        j = self.jacobians(points, cells)
        return np.swapaxes(j, -1, -2) @ j

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


@njit(cache=True)
def _jacobians(coordinates, cells, grads, out):  # pragma: no cover - compiled
    """Add ``∂x/∂ξ`` ``(m, q, d, 2)`` of cells ``(m, nen)`` for node coordinates ``(n, d)``
    into ``out``."""
    m, nen = cells.shape[0], cells.shape[1]
    nq, d = grads.shape[0], coordinates.shape[1]
    for e in range(m):
        for q in range(nq):
            for a in range(nen):
                node = cells[e, a]
                g0, g1 = grads[q, a, 0], grads[q, a, 1]
                for i in range(d):
                    x = coordinates[node, i]
                    out[e, q, i, 0] += x * g0
                    out[e, q, i, 1] += x * g1
