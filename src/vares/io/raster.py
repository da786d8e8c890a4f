"""Cells drawn as an image: every pixel knows the cell it shows.

Matplotlib draws a mesh polygon by polygon: about a second per picture of 100k cells, most of
a report's cost; and its 3D axes sort the cells by depth instead of testing it, so hidden cells
can show through. Here the cells are rasterised once into an index image — with a depth buffer
for a view of the surface — and a picture of a per-cell field is a lookup through that image:
each cell's colour, mapped once per cell, is copied to its pixels (``colours[index]``) and the
finished RGBA image is drawn with ``imshow`` (matplotlib then has no values to normalise,
colour-map and resample per pixel). An image is best rasterised at the resolution it is shown at
(``pixels``): one the size of the axes where the figure is saved. Lines (outline, mesh lines,
cutting lines) stay vectors on top; in a view of the surface they are kept where the depth buffer
sees them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .._jit import compiled, njit

__all__ = ["CellImage", "View", "covered", "rasterise", "triangles_of"]

#: Pixels along the longer side of a cell image unless told (a 6.5-inch figure at 150 dpi is 975
#: wide).
PIXELS = 1000


@dataclass(frozen=True)
class View:
    """An orthographic view of the surface from ``elevation`` and ``azimuth`` (degrees), as
    matplotlib's 3D axes define them (defaults alike)."""

    elevation: float = 30.0
    azimuth: float = -60.0

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Screen right, screen up and the direction towards the viewer, in model axes."""
        e, a = np.radians(self.elevation), np.radians(self.azimuth)
        towards = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
        right = np.array([-np.sin(a), np.cos(a), 0.0])
        return right, np.cross(towards, right), towards

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Screen coordinates ``(n, 2)`` and depth ``(n,)`` (larger: farther away)."""
        right, up, towards = self.axes()
        return np.column_stack([points @ right, points @ up]), -(points @ towards)


@dataclass(frozen=True)
class CellImage:
    """``index[row, column]``: the cell a pixel shows (−1: none), row 0 at the bottom;
    ``extent`` (x0, x1, y0, y1) places the image in drawing coordinates; ``depth`` is the depth
    buffer (``inf`` where no cell)."""

    index: np.ndarray
    extent: tuple[float, float, float, float]
    depth: np.ndarray

    @property
    def pixel(self) -> float:
        """The side of a pixel in drawing units."""
        return (self.extent[1] - self.extent[0]) / self.index.shape[1]

    def lookup(self, per_cell: np.ndarray) -> np.ma.MaskedArray:
        """Per-cell values ``(cells, ...)`` as an image, masked where no cell shows."""
        inside = self.index >= 0
        image = np.asarray(per_cell)[np.where(inside, self.index, 0)]
        mask = ~inside if image.ndim == 2 else np.broadcast_to(~inside[..., None], image.shape)
        return np.ma.MaskedArray(image, mask=mask)

    def colours(self, per_cell: np.ndarray) -> np.ndarray:
        """Per-cell colours ``(cells, 4)`` (RGBA, floats or bytes) as an image
        ``(rows, columns, 4)`` of the same type, transparent (all zero) where no cell shows."""
        per_cell = np.asarray(per_cell)
        table = np.concatenate([per_cell, np.zeros((1, per_cell.shape[1]), per_cell.dtype)])
        return table[self.index]  # no cell (−1): the table's last row, transparent

    def seen(self, points: np.ndarray, depth: np.ndarray, slack: float = 3.0) -> np.ndarray:
        """Which of ``points`` (drawing coordinates, with their ``depth``) the view shows: no
        cell in front of them by more than ``slack`` pixels."""
        x0, _, y0, _ = self.extent
        h = self.pixel
        rows, columns = self.index.shape
        i = np.clip(((points[:, 0] - x0) / h).astype(int), 0, columns - 1)
        j = np.clip(((points[:, 1] - y0) / h).astype(int), 0, rows - 1)
        nearest = self.depth[j, i]
        for dj, di in ((-1, 0), (1, 0), (0, -1), (0, 1)):  # a line on an edge of the view
            nearest = np.maximum(
                nearest, self.depth[np.clip(j + dj, 0, rows - 1), np.clip(i + di, 0, columns - 1)]
            )
        return ~(depth > nearest + slack * h)


def triangles_of(cells: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Every cell (blocks by type, as ``SurfaceMesh.cells``) split into triangles (a quad along
    its first diagonal): the triangles' nodes ``(t, 3)`` and the cell (global order) each
    belongs to."""
    triangles, owners, offset = [], [], 0
    for block in cells.values():
        cells = np.asarray(block)
        numbers = np.arange(offset, offset + len(cells))
        for k in range(1, cells.shape[1] - 1):
            triangles.append(cells[:, [0, k, k + 1]])
            owners.append(numbers)
        offset += len(cells)
    return np.vstack(triangles).astype(np.int64), np.concatenate(owners).astype(np.int64)


def rasterise(
    cells: Mapping[str, np.ndarray],
    coordinates: np.ndarray,
    depth: np.ndarray | None = None,
    pixels: int = PIXELS,
    grid: tuple[float, float, float, int, int] | None = None,
) -> CellImage:
    """The index image of the ``cells`` (blocks by type, as ``SurfaceMesh.cells``) drawn at
    node ``coordinates`` ``(n, 2)``: the nearest cell in front where ``depth`` ``(n,)`` is
    given, else any of those covering a pixel. The image spans the cells with ``pixels``
    along its longer side, or is the pixel ``grid`` ``(x0, y0, side, columns, rows)`` given
    (a picture's own: row ``j`` covers ``y0 + j·side`` to ``y0 + (j + 1)·side``)."""
    coordinates = np.asarray(coordinates, dtype=float)
    if grid is None:
        low, high = coordinates.min(axis=0), coordinates.max(axis=0)
        span = float(np.max(high - low)) or 1.0
        h = span / pixels
        low = low - h  # one pixel of margin around the drawing
        columns, rows = (np.ceil((high - low) / h).astype(int) + 2).tolist()
    else:
        x0, y0, h, columns, rows = grid
        low = np.array([x0, y0], dtype=float)
    index = np.full((rows, columns), -1, dtype=np.int64)
    buffer = np.full((rows, columns), np.inf)
    triangles, owners = triangles_of(cells)
    pixel_coordinates = (coordinates - low) / h
    z = np.zeros(len(coordinates)) if depth is None else np.asarray(depth, dtype=float)
    fill = _fill if depth is not None or compiled(len(triangles)) else _fill_spans
    fill(pixel_coordinates[:, 0].copy(), pixel_coordinates[:, 1].copy(), z, triangles, owners,
         index, buffer)  # fmt: skip
    extent = (float(low[0]), float(low[0] + columns * h), float(low[1]), float(low[1] + rows * h))
    return CellImage(index, extent, buffer)


def covered(
    cells: Mapping[str, np.ndarray],
    coordinates: np.ndarray,
    grid: tuple[float, float, float, int, int],
) -> np.ndarray:
    """The pixels of ``grid`` (as :func:`rasterise`'s) that any of the ``cells`` covers, a
    boolean image ``(rows, columns)``: ``rasterise(cells, coordinates, grid=grid).index >= 0``,
    the same pixels, without finding which cell each pixel shows. Below the compiled kernels'
    size each run of pixels is filled whole (its two ends tested as :func:`_fill_spans` tests
    them), not pixel by pixel."""
    x0, y0, h, columns, rows = grid
    triangles, _ = triangles_of(cells)
    if compiled(len(triangles)):
        return rasterise(cells, coordinates, grid=grid).index >= 0
    pixel_coordinates = (np.asarray(coordinates, dtype=float) - np.array([x0, y0])) / h
    px, py = pixel_coordinates[:, 0].copy(), pixel_coordinates[:, 1].copy()
    t, y, start, length = _spans(px, py, triangles, rows, columns)
    # the pixels between the two tested at either end of a run lie inside: a run of them adds
    # 1 at its first pixel and takes it off after its last, summed along the row
    inner = length > 4
    row = (y[inner] - 0.5).astype(np.int64) * (columns + 1)
    first = row + (start[inner] + 2).astype(np.int64)
    after = row + (start[inner] + length[inner] - 2).astype(np.int64)
    size = rows * (columns + 1)
    steps = np.bincount(first, minlength=size) - np.bincount(after, minlength=size)
    image = np.cumsum(steps.reshape(rows, columns + 1), axis=1)[:, :columns] > 0
    for end in (0, 1, -2, -1):  # the offsets in a run that _fill_spans tests
        offset = length + end if end < 0 else np.full_like(length, end)
        exists = (offset >= 0) & (offset < length)
        e, i, ye = t[exists], start[exists] + offset[exists], y[exists]
        keep = _inside(px, py, triangles, e, i + 0.5, ye)
        image[(ye[keep] - 0.5).astype(np.int64), i[keep].astype(np.int64)] = True
    return image


def _spans(
    px: np.ndarray, py: np.ndarray, triangles: np.ndarray, rows: int, columns: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each triangle's run of pixel centres along each row it crosses (for cells seen flat):
    the triangle, the row's centre ``y``, the run's first pixel and its length (0: none). The
    run is bounded from where the triangle's edges cross the row, one pixel wider at either end;
    its two pixels at either end are to be tested, those between lie inside."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    xa, ya, xb, yb, xc, yc = px[a], py[a], px[b], py[b], px[c], py[c]
    area = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya)
    with np.errstate(invalid="ignore"):
        i0 = np.maximum(np.ceil(np.minimum(np.minimum(xa, xb), xc) - 0.5), 0)
        i1 = np.minimum(np.floor(np.maximum(np.maximum(xa, xb), xc) - 0.5), columns - 1)
        j0 = np.maximum(np.ceil(np.minimum(np.minimum(ya, yb), yc) - 0.5), 0)
        j1 = np.minimum(np.floor(np.maximum(np.maximum(ya, yb), yc) - 0.5), rows - 1)
        usable = (area != 0.0) & np.isfinite(i0 + i1 + j0 + j1) & (i1 >= i0)
    height = np.where(usable, np.maximum(j1 - j0 + 1, 0), 0).astype(np.int64)
    t = np.repeat(np.arange(len(triangles)), height)  # one (triangle, row) a run
    y = j0[t] + (np.arange(t.size) - np.repeat(np.cumsum(height) - height, height)) + 0.5
    sign = np.sign(area[t])
    low, high = i0[t] - 0.5, i1[t] + 0.5
    with np.errstate(divide="ignore", invalid="ignore"):
        # w(x) · area = p + q x for each of the three weights (DESIGN: barycentric, as _fill)
        for (x1, y1), (x2, y2) in (
            ((xb, yb), (xc, yc)),
            ((xc, yc), (xa, ya)),
            ((xa, ya), (xb, yb)),
        ):
            p = x1[t] * (y2[t] - y) - x2[t] * (y1[t] - y)
            q = (y1 - y2)[t] * sign
            p = p * sign
            crossing = -p / q
            low = np.where(q > 0, np.maximum(low, crossing), low)
            high = np.where(q < 0, np.minimum(high, crossing), high)
            high = np.where((q == 0) & (p < 0), -np.inf, high)
    start = np.maximum(np.ceil(low - 0.5) - 1, i0[t])
    stop = np.minimum(np.floor(high - 0.5) + 1, i1[t])
    length = np.where(stop >= start, stop - start + 1, 0).astype(np.int64)
    return t, y, start, length


def _inside(
    px: np.ndarray, py: np.ndarray, triangles: np.ndarray, t: np.ndarray, x: np.ndarray,
    y: np.ndarray,
) -> np.ndarray:  # fmt: skip
    """Whether each point ``(x, y)`` lies in its triangle ``t``, as :func:`_fill` tests a pixel
    centre (the same weights, the same tolerance)."""
    a, b, c = triangles[t, 0], triangles[t, 1], triangles[t, 2]
    xa, ya, xb, yb, xc, yc = px[a], py[a], px[b], py[b], px[c], py[c]
    area = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya)
    wa = ((xb - x) * (yc - y) - (xc - x) * (yb - y)) / area
    wb = ((xc - x) * (ya - y) - (xa - x) * (yc - y)) / area
    wc = 1.0 - wa - wb
    return (wa >= -1e-12) & (wb >= -1e-12) & (wc >= -1e-12)


def _fill_spans(
    px: np.ndarray,
    py: np.ndarray,
    pz: np.ndarray,
    triangles: np.ndarray,
    owners: np.ndarray,
    index: np.ndarray,
    depth: np.ndarray,
) -> None:
    """:func:`_fill` for cells seen flat (``pz`` zero: the first triangle over a pixel takes
    it) as array arithmetic, for small meshes: each triangle's run of pixel centres along each
    row (:func:`_spans`); the pixels at either end of a run are tested as :func:`_fill` tests
    every pixel (the same weights), those between lie inside."""
    rows, columns = index.shape
    t, y, start, length = _spans(px, py, triangles, rows, columns)
    t, y, start = np.repeat(t, length), np.repeat(y, length), np.repeat(start, length)
    offset = np.arange(t.size) - np.repeat(np.cumsum(length) - length, length)
    i = start + offset
    end = (offset < 2) | (np.repeat(length, length) - offset <= 2)  # the ends: tested
    keep = np.ones(t.size, dtype=bool)
    keep[end] = _inside(px, py, triangles, t[end], i[end] + 0.5, y[end])
    pixel = (y[keep] - 0.5).astype(np.int64) * columns + i[keep].astype(np.int64)
    t = t[keep]
    free = depth.reshape(-1)[pixel] > 0.0  # z = 0 is nearer than what the pixel holds
    pixel, t = pixel[free][::-1], t[free][::-1]  # the last write of a pixel is its first triangle
    depth.reshape(-1)[pixel] = 0.0
    index.reshape(-1)[pixel] = owners[t]


@njit(cache=True)
def _fill(px, py, pz, triangles, owners, index, depth):  # pragma: no cover - compiled
    """Every pixel centre inside a triangle takes its cell when nearer than what it holds."""
    rows, columns = index.shape
    for t in range(triangles.shape[0]):
        a, b, c = triangles[t, 0], triangles[t, 1], triangles[t, 2]
        xa, ya, xb, yb, xc, yc = px[a], py[a], px[b], py[b], px[c], py[c]
        area = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya)
        if area == 0.0:
            continue
        i0 = max(math.ceil(min(xa, xb, xc) - 0.5), 0)
        i1 = min(math.floor(max(xa, xb, xc) - 0.5), columns - 1)
        j0 = max(math.ceil(min(ya, yb, yc) - 0.5), 0)
        j1 = min(math.floor(max(ya, yb, yc) - 0.5), rows - 1)
        for j in range(j0, j1 + 1):
            y = j + 0.5
            for i in range(i0, i1 + 1):
                x = i + 0.5
                wa = ((xb - x) * (yc - y) - (xc - x) * (yb - y)) / area
                wb = ((xc - x) * (ya - y) - (xa - x) * (yc - y)) / area
                wc = 1.0 - wa - wb
                if wa < -1e-12 or wb < -1e-12 or wc < -1e-12:  # an edge's pixels: both cells
                    continue
                z = wa * pz[a] + wb * pz[b] + wc * pz[c]
                if z < depth[j, i]:
                    depth[j, i] = z
                    index[j, i] = owners[t]
