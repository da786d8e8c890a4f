"""Linear triangle (meshio ``"triangle"``), one-point quadrature.

Reference cell: nodes (0, 0), (1, 0), (0, 1); N = (1 − ξ − η, ξ, η). The gradients are constant,
so a single point (the centroid, weight ½) integrates the energy of a linear triangle exactly.
"""

import numpy as np

from .base import ReferenceElement

_GRADIENTS = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])

TRIANGLE = ReferenceElement(
    cell_type="triangle",
    num_nodes=3,
    quadrature_weights=np.array([0.5]),
    shape_gradients=_GRADIENTS[None],
    check_gradients=_GRADIENTS[None],
)
