"""Blanks: flat pieces of fabric as cut from the roll, meshed for draping.

A blank's coordinates are its material coordinates (length units of the mould), the warp along
+x (the roll's length), the fill along +y. Its **seed node** is the node pressed onto the mould's
seed point first; a node of the blank sits there exactly. :func:`rectangle_blank` meshes a
rectangle with a grid of right triangles whose legs run along the yarns (the diagonals mirrored
across the yarns through the seed, so the mesh has the blank's symmetries);
:func:`outline_blank` meshes any simple outline with a grid of the same kind inside it, joined
to points along the outline by a Delaunay triangulation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MAX_BLANK_NODES", "Blank", "outline_blank", "rectangle_blank"]

MAX_BLANK_NODES = 1_000_000
"""The most nodes a blank's grid may have: a blank finer than this is refused before it is
meshed (its drape would take hours; the grid alone would fill the memory long before)."""


@dataclass(frozen=True)
class Blank:
    """A meshed blank: ``coordinates`` ``(n, 2)``, ``triangles`` ``(m, 3)`` (counter-clockwise),
    the ``seed`` node, and the ``outline`` ``(k, 2)`` it was cut to (closed, not repeated)."""

    coordinates: np.ndarray
    triangles: np.ndarray
    seed: int
    outline: np.ndarray

    @property
    def area(self) -> float:
        return float(cell_areas(self.coordinates, self.triangles).sum())

    @property
    def spacing(self) -> float:
        """The mean length of the blank's edges along the yarns (its grid spacing)."""
        p = self.coordinates[self.triangles]
        sides = np.linalg.norm(p - np.roll(p, 1, axis=1), axis=-1)
        return float(np.median(sides.min(axis=1)))


def cell_areas(coordinates: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Signed areas ``(m,)`` of flat triangles (positive counter-clockwise)."""
    a, b, c = (coordinates[triangles[:, k]] for k in range(3))
    return 0.5 * ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])


def rectangle_blank(length: float, width: float, spacing: float) -> Blank:
    """A ``length`` (along the warp, x) × ``width`` (fill, y) rectangle centred on its seed node
    at the origin, in squares of about ``spacing`` (an even number along each side) split into
    right triangles along the yarns (module docs)."""
    if not (length > 0 and width > 0 and spacing > 0):
        raise ValueError(
            f"a blank needs a positive length, width and spacing; got {length}, {width}, {spacing}"
        )
    nx = 2 * max(1, round(length / (2 * spacing)))
    ny = 2 * max(1, round(width / (2 * spacing)))
    _check_size((nx + 1) * (ny + 1), length, width, spacing)
    x = np.linspace(-length / 2, length / 2, nx + 1)
    y = np.linspace(-width / 2, width / 2, ny + 1)
    grid = np.stack(np.meshgrid(x, y, indexing="ij"), axis=-1).reshape(-1, 2)
    triangles = _grid_triangles(nx, ny, nx // 2, ny // 2)
    seed = (nx // 2) * (ny + 1) + ny // 2
    outline = np.array(
        [[-length / 2, -width / 2], [length / 2, -width / 2], [length / 2, width / 2],
         [-length / 2, width / 2]]
    )  # fmt: skip
    return Blank(grid, triangles, int(seed), outline)


def _grid_triangles(nx: int, ny: int, ci: int, cj: int) -> np.ndarray:
    """Two triangles per grid square (nodes ``i (ny + 1) + j``), counter-clockwise, the
    diagonal of square ``(i, j)`` pointing away from the square ``(ci, cj)``'s corner."""
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    i, j = i.ravel(), j.ravel()
    n00 = i * (ny + 1) + j
    n10, n01, n11 = n00 + ny + 1, n00 + 1, n00 + ny + 2
    same = (i >= ci) == (j >= cj)  # diagonal (0,0)-(1,1) in the quadrants (+,+) and (−,−)
    first = np.where(same[:, None], np.column_stack([n00, n10, n11]),
                     np.column_stack([n00, n10, n01]))  # fmt: skip
    second = np.where(same[:, None], np.column_stack([n00, n11, n01]),
                      np.column_stack([n10, n11, n01]))  # fmt: skip
    return np.vstack([first, second])


def outline_blank(
    outline: np.ndarray, spacing: float, seed: tuple[float, float] | None = None
) -> Blank:
    """A blank cut to the closed ``outline`` ``(k, 2)`` (a simple polygon, the warp along +x),
    meshed at about ``spacing``, with its seed node at ``seed`` (default: the outline's
    centroid; it must lie inside)."""
    from scipy.spatial import Delaunay
    from shapely import contains_xy, distance, points
    from shapely.geometry import Polygon

    ring = np.asarray(outline, dtype=float)
    if ring.ndim != 2 or ring.shape[1] != 2 or len(ring) < 3:
        raise ValueError(f"a blank's outline needs at least three (x, y) points; got {ring.shape}")
    if np.allclose(ring[0], ring[-1]):
        ring = ring[:-1]
    polygon = Polygon(ring)
    if not polygon.is_valid or polygon.area <= 0:
        raise ValueError("the blank's outline crosses itself or encloses no area")
    if not spacing > 0:
        raise ValueError(f"the blank's spacing must be positive; got {spacing}")
    centre = np.array(polygon.centroid.coords[0]) if seed is None else np.asarray(seed, float)
    if not contains_xy(polygon, *centre):
        raise ValueError(f"the blank's seed {tuple(centre)} lies outside its outline")
    along = _densified(ring, spacing)
    low, high = ring.min(axis=0), ring.max(axis=0)
    i, j = (
        np.arange(
            np.floor((low[k] - centre[k]) / spacing), np.ceil((high[k] - centre[k]) / spacing) + 1
        )
        for k in range(2)
    )
    _check_size(len(i) * len(j), *(high - low), spacing)
    grid = centre + spacing * np.stack(np.meshgrid(i, j, indexing="ij"), axis=-1).reshape(-1, 2)
    keep = contains_xy(polygon, grid[:, 0], grid[:, 1])
    grid = grid[keep]
    clear = distance(points(grid), polygon.exterior) > 0.35 * spacing
    seed_row = np.argmin(np.linalg.norm(grid - centre, axis=1))
    clear[seed_row] = True
    nodes = np.vstack([grid[clear], along])
    triangles = Delaunay(nodes).simplices
    centroids = nodes[triangles].mean(axis=1)
    triangles = triangles[contains_xy(polygon, centroids[:, 0], centroids[:, 1])]
    area = cell_areas(nodes, triangles)
    triangles = np.where(area[:, None] > 0, triangles, triangles[:, [0, 2, 1]])
    triangles = triangles[np.abs(area) > 1e-12 * spacing**2]
    used = np.unique(triangles)
    renumber = np.full(len(nodes), -1)
    renumber[used] = np.arange(len(used))
    seed_node = int(renumber[np.count_nonzero(clear[:seed_row])])
    return Blank(nodes[used], renumber[triangles], seed_node, ring)


def _check_size(nodes: int, length: float, width: float, spacing: float) -> None:
    if nodes > MAX_BLANK_NODES:
        raise ValueError(
            f"a blank of {length:g} × {width:g} at spacing {spacing:g} would have {nodes:,} nodes "
            f"(at most {MAX_BLANK_NODES:,}): give a larger spacing"
        )


def _densified(ring: np.ndarray, spacing: float) -> np.ndarray:
    """Points along the closed ``ring``, its corners kept, none farther apart than ``spacing``."""
    out = []
    for a, b in zip(ring, np.roll(ring, -1, axis=0), strict=True):
        pieces = max(1, int(np.ceil(np.linalg.norm(b - a) / spacing)))
        t = np.arange(pieces) / pieces
        out.append(a + t[:, None] * (b - a))
    return np.vstack(out)
