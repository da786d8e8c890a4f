"""The trim line of a draped blank and the areas on either side of it.

A draped blank carries a value per node that is negative where it lies on the mould and positive
beyond its edge (the mould's outwardness, :mod:`vares.geometry.mould`). Linear on each flat
triangle of the blank, its zero level is the **trim line**: straight within a triangle, from
edge to edge, joined into polylines. The **net** area is that of the part where the value is
negative (each triangle clipped at the zero level), the excess the rest.
"""

from __future__ import annotations

import numpy as np

from ..geometry.blank import Blank

__all__ = ["trim_blank"]


def trim_blank(blank: Blank, values: np.ndarray) -> tuple[list[np.ndarray], float]:
    """The trim lines (polylines ``(k, 2)`` on the flat blank) where ``values`` ``(n,)``
    crosses zero, and the area of the blank where it is negative (module docs)."""
    from shapely import MultiLineString
    from shapely.ops import linemerge

    tri = blank.triangles
    X = blank.coordinates
    v = np.asarray(values, dtype=float)[tri]  # (m, 3)
    inside = v < 0
    area = 0.0
    full = inside.all(axis=1)
    area += float(np.abs(_areas(X[tri[full]])).sum())
    segments = []
    for cell in np.flatnonzero(inside.any(axis=1) & ~full):
        polygon, crossing = _clipped(X[tri[cell]], v[cell])
        area += abs(_shoelace(polygon))
        if len(crossing) == 2:
            segments.append(crossing)
    for cell in np.flatnonzero(~inside.any(axis=1) & (v == 0).sum(axis=1).astype(bool)):
        zeros = X[tri[cell]][v[cell] == 0]
        if len(zeros) == 2:
            segments.append(list(zeros))
    if not segments:
        return [], area
    # the same crossing found from both triangles of a side, to the last bits
    digits = 9 - int(np.floor(np.log10(max(float(np.ptp(X, axis=0).max()), 1e-300))))
    unique = {tuple(sorted(map(tuple, np.round(np.asarray(s), digits)))) for s in segments}
    unique = [s for s in unique if s[0] != s[1]]
    merged = linemerge(MultiLineString([np.asarray(s) for s in unique]))
    parts = getattr(merged, "geoms", [merged])
    return [np.asarray(line.coords) for line in parts], area


def _clipped(corners: np.ndarray, values: np.ndarray):
    """The part of a triangle ``(3, 2)`` where the linear field ``values`` ``(3,)`` is
    negative (a polygon) and the points where its sides cross zero."""
    polygon, crossing = [], []
    for k in range(3):
        p, q = corners[k], corners[(k + 1) % 3]
        a, b = values[k], values[(k + 1) % 3]
        if a < 0:
            polygon.append(p)
        if (a < 0) != (b < 0) and a != b:
            t = a / (a - b)
            point = p + t * (q - p)
            polygon.append(point)
            crossing.append(point)
    return np.array(polygon), crossing


def _shoelace(polygon: np.ndarray) -> float:
    if len(polygon) < 3:
        return 0.0
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * float(x @ np.roll(y, -1) - y @ np.roll(x, -1))


def _areas(corners: np.ndarray) -> np.ndarray:
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    return 0.5 * ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
