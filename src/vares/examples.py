"""Parametrised example surfaces.

``cylinder160``
    The seed paper's benchmark: a 160° segment of a circular cylinder. It is developable, so its
    optimal pattern is a rectangle as wide as the discrete arc length (the sum of the chords),
    erected with zero energy.
``hypar``
    A hyperbolic paraboloid ``z = c x y`` over a square: doubly curved (anticlastic), the shape
    of a four-point sail.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .mesh import SurfaceMesh

__all__ = ["EXAMPLES", "cylinder160", "cylinder_arc_length", "grid_cells", "hypar"]


def grid_cells(n_u: int, n_v: int, cell_type: str = "triangle") -> dict[str, np.ndarray]:
    """Cells of a structured ``n_u × n_v`` grid of nodes ``j * n_u + i`` (i along u).

    Cells are counter-clockwise in the (u, v) parameter plane. Triangles alternate their diagonal
    so that the mesh has no preferred direction.
    """
    if n_u < 2 or n_v < 2:
        raise ValueError("a grid needs at least 2 × 2 nodes")
    i, j = np.meshgrid(np.arange(n_u - 1), np.arange(n_v - 1), indexing="xy")
    i, j = i.ravel(), j.ravel()
    p00, p10 = j * n_u + i, j * n_u + i + 1
    p01, p11 = (j + 1) * n_u + i, (j + 1) * n_u + i + 1
    if cell_type == "quad":
        return {"quad": np.column_stack([p00, p10, p11, p01])}
    if cell_type != "triangle":
        raise ValueError(f"cell_type must be 'triangle' or 'quad'; got {cell_type!r}")
    even = (i + j) % 2 == 0
    first = np.where(
        even[:, None], np.column_stack([p00, p10, p11]), np.column_stack([p00, p10, p01])
    )
    second = np.where(
        even[:, None], np.column_stack([p00, p11, p01]), np.column_stack([p10, p11, p01])
    )
    return {"triangle": np.vstack([first, second])}


def cylinder160(
    radius: float = 1.0,
    length: float = 2.0,
    angle: float = 160.0,
    n_around: int = 32,
    n_along: int = 16,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """Cylinder segment of ``angle`` degrees about the y-axis, symmetric about the z-axis.

    Nodes ``x = R sin θ``, ``y ∈ [0, length]``, ``z = R cos θ``, ``θ ∈ [−angle/2, angle/2]``, with
    ``n_around`` cells around and ``n_along`` along. Cells face outwards (+z at the crown), so
    the projection on the x-y plane is the seed's initial guess.
    """
    if not 0 < angle < 360:
        raise ValueError(f"angle must lie in (0, 360) degrees; got {angle}")
    theta = np.radians(np.linspace(-angle / 2, angle / 2, n_around + 1))
    y = np.linspace(0.0, length, n_along + 1)
    t, yy = np.meshgrid(theta, y, indexing="xy")
    points = np.column_stack([radius * np.sin(t.ravel()), yy.ravel(), radius * np.cos(t.ravel())])
    return SurfaceMesh(points, grid_cells(n_around + 1, n_along + 1, cell_type))


def cylinder_arc_length(radius: float = 1.0, angle: float = 160.0, n_around: int = 32) -> float:
    """Discrete arc length of :func:`cylinder160`: the sum of its chords around the axis."""
    return n_around * 2.0 * radius * np.sin(np.radians(angle) / (2 * n_around))


def hypar(
    size: float = 10.0,
    rise: float = 0.06,
    n: int = 20,
    cell_type: str = "triangle",
) -> SurfaceMesh:
    """Hyperbolic paraboloid ``z = rise · x · y`` over the square ``[−size/2, size/2]²``."""
    s = np.linspace(-size / 2, size / 2, n + 1)
    x, y = np.meshgrid(s, s, indexing="xy")
    points = np.column_stack([x.ravel(), y.ravel(), rise * x.ravel() * y.ravel()])
    return SurfaceMesh(points, grid_cells(n + 1, n + 1, cell_type))


#: Example generators by name (used by ``vares example``).
EXAMPLES: dict[str, Callable[..., SurfaceMesh]] = {"cylinder160": cylinder160, "hypar": hypar}
