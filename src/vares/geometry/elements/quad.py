"""Bilinear quadrilateral (meshio ``"quad"``), 2×2 Gauss quadrature.

Reference cell [-1, 1]², nodes counter-clockwise from (−1, −1), as meshio orders them.
``det J`` of a bilinear map is linear in ξ and η, so it is positive on the whole cell
exactly when it is positive at the four corners: those are the check points.
"""

import numpy as np

from .base import ReferenceElement

_NODES = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])


def _gradients(points: np.ndarray) -> np.ndarray:
    """``∂N_a/∂ξ`` at reference points ``(p, 2)``, shape ``(p, 4, 2)``."""
    xi, eta = points[:, 0:1], points[:, 1:2]
    dxi = 0.25 * _NODES[:, 0] * (1.0 + _NODES[:, 1] * eta)
    deta = 0.25 * _NODES[:, 1] * (1.0 + _NODES[:, 0] * xi)
    return np.stack([dxi, deta], axis=-1)


_GAUSS = np.array([-1.0, 1.0]) / np.sqrt(3.0)
_QUADRATURE_POINTS = np.array([[x, y] for y in _GAUSS for x in _GAUSS])

QUAD = ReferenceElement(
    cell_type="quad",
    num_nodes=4,
    quadrature_weights=np.ones(4),
    shape_gradients=_gradients(_QUADRATURE_POINTS),
    check_gradients=_gradients(_NODES),
)
