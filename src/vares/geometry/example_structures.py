"""Example structures: surfaces cut into panels, each a mesh and the panel id of every cell
(``vares panels``)."""

from __future__ import annotations

import itertools

import numpy as np

from .example_surfaces import grid_cells
from .mesh import SurfaceMesh

__all__ = ["catenoid_band", "hypar_strips", "irregular_hypar_strips"]


def hypar_strips(
    strips: int = 6,
    size: float = 10.0,
    height: float = 2.0,
    cells_per_strip: int = 4,
    n: int = 24,
    cell_type: str = "triangle",
) -> tuple[SurfaceMesh, np.ndarray]:
    """A four-point sail cut into ``strips`` strips across x (seams along y), as a membrane is
    welded from fabric of roll width: the mesh and the strip id of every cell."""
    columns = strips * cells_per_strip
    s_x = np.linspace(-size / 2, size / 2, columns + 1)
    s_y = np.linspace(-size / 2, size / 2, n + 1)
    x, y = (a.ravel() for a in np.meshgrid(s_x, s_y, indexing="xy"))
    z = 2.0 * height / size**2 * x * y
    mesh = SurfaceMesh(np.column_stack([x, y, z]), grid_cells(columns + 1, n + 1, cell_type))
    centroid_x = np.concatenate([mesh.points[c][:, :, 0].mean(axis=1) for c in mesh.cells.values()])
    ids = np.clip(((centroid_x + size / 2) / (size / strips)).astype(int), 0, strips - 1)
    return mesh, ids


def catenoid_band(
    panels: int = 12,
    waist: float = 3.0,
    height: float = 3.0,
    n_along: int = 16,
    n_around: int = 4,
    cell_type: str = "triangle",
) -> tuple[SurfaceMesh, np.ndarray]:
    """A whole catenoid band (a minimal surface between two rings: waist radius ``waist``,
    ``±height/2`` along z) cut along its meridians into ``panels`` gores of ``n_around`` cells
    around each: the mesh and the panel id of every cell. Erected, the rings are the supports.
    """
    if panels < 2:
        raise ValueError(f"a band needs at least two panels; got {panels}")
    v = np.linspace(-height / 2, height / 2, n_along + 1)
    count = panels * n_around
    phi = np.linspace(0.0, 2 * np.pi, count + 1)[:-1]
    r, p = np.meshgrid(waist * np.cosh(v / waist), phi, indexing="xy")
    points = np.column_stack([(r * np.cos(p)).ravel(), (r * np.sin(p)).ravel(), np.tile(v, count)])
    cells = grid_cells(len(v), count + 1, cell_type)
    cells = {t: np.where(c >= len(points), c - len(points), c) for t, c in cells.items()}
    mesh = SurfaceMesh(points, cells)
    centroids = np.concatenate([mesh.points[c].mean(axis=1) for c in mesh.cells.values()])
    angle = np.mod(np.arctan2(centroids[:, 1], centroids[:, 0]), 2 * np.pi)
    return mesh, np.minimum((angle / (2 * np.pi / panels)).astype(int), panels - 1)


def irregular_hypar_strips(
    strips: int = 10,
    size: float = 10.0,
    rise: float = 0.06,
    columns_per_strip: int = 4,
    n: int = 40,
    near: float = 0.02,
    seed: int = 0,
) -> tuple[SurfaceMesh, np.ndarray]:
    """A hypar ``z = rise x y`` over a square cut into ``strips`` strips along y, meshed
    irregularly, and the strip id of every cell.

    The seam lines x = const carry their nodes at random heights, a tenth of them ``near`` × the
    mean spacing above another one, as where a cutting line crosses the edges of a mesh close to
    a node (seams through cells); inside a strip the node columns have random spacing too.
    Neighbouring columns are joined by triangles that zip along both (every triangle
    counter-clockwise seen from +z).
    """
    rng = np.random.default_rng(seed)
    half = size / 2
    boundaries = np.linspace(-half, half, strips + 1)
    xs = [boundaries[0]]
    for a, b in itertools.pairwise(boundaries):
        inner = np.sort(rng.uniform(a, b, columns_per_strip - 1))
        xs += [*inner, b]
    columns = []
    for x in xs:
        heights = np.sort(rng.uniform(-half, half, n - 1))
        close = rng.choice(n - 2, size=max(1, n // 10), replace=False)
        heights[close + 1] = heights[close] + near * size / n
        columns.append((x, np.concatenate([[-half], np.sort(heights), [half]])))
    points, index = [], []
    for x, ys in columns:
        index.append(np.arange(len(points), len(points) + len(ys)))
        points += [(x, y, rise * x * y) for y in ys]
    triangles, ids = [], []
    for k in range(len(columns) - 1):
        for triangle in _zip_columns(index[k], columns[k][1], index[k + 1], columns[k + 1][1]):
            triangles.append(triangle)
            ids.append(k // columns_per_strip)
    mesh = SurfaceMesh(np.array(points), {"triangle": np.array(triangles)})
    return mesh, np.array(ids)


def _zip_columns(left, left_y, right, right_y) -> list[tuple[int, int, int]]:
    """Triangles between two node columns (left of right), each column sorted by height."""
    out, i, j = [], 0, 0
    while i < len(left) - 1 or j < len(right) - 1:
        up_left = j == len(right) - 1 or (i < len(left) - 1 and left_y[i + 1] < right_y[j + 1])
        if up_left:
            out.append((left[i], right[j], left[i + 1]))
            i += 1
        else:
            out.append((left[i], right[j], right[j + 1]))
            j += 1
    return out
