"""The cut line of a pattern: its seam line grown outwards by an allowance that may differ from
edge to edge (a seam, a hemmed free edge, a cable pocket, a clamp edge), or by one allowance
round its outline and holes (:func:`cut_outline`: a DXF's cut line, a ply's extended boundary);
the signed area of a ring (:func:`ring_area`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = [
    "MITRE_LIMIT",
    "allowance_outline",
    "cut_outline",
    "edge_outline",
    "region_rings",
    "ring_area",
]

#: Corners whose mitre would reach further than this many allowances are bevelled.
MITRE_LIMIT = 4.0


def ring_area(ring: np.ndarray) -> float:
    """The signed area of a closed ring ``(k, 2)`` (positive counter-clockwise; the shoelace
    formula)."""
    x, y = ring[:, 0], ring[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def cut_outline(rings: Sequence[np.ndarray], allowance: float) -> list[np.ndarray]:
    """The region inside ``rings`` ``(k, 2)`` (the largest the outline, the others its holes)
    grown by ``allowance`` ≥ 0 with mitred corners (at most :data:`MITRE_LIMIT` allowances
    out): its rings ``(k, 2)``, not closed, the outline first and counter-clockwise, then what
    is left of the holes, clockwise. Of a region in several pieces the largest is kept."""
    from shapely.geometry import Polygon

    outer = max(range(len(rings)), key=lambda k: abs(ring_area(rings[k])))
    polygon = Polygon(rings[outer], [r for k, r in enumerate(rings) if k != outer])
    if allowance > 0:
        polygon = polygon.buffer(allowance, join_style="mitre", mitre_limit=MITRE_LIMIT)
    return region_rings(polygon)


def region_rings(region) -> list[np.ndarray]:
    """The rings ``(k, 2)`` of a shapely region (of a region in several pieces, the largest),
    not closed: the outline first and counter-clockwise, then its holes, clockwise."""
    from shapely.geometry.polygon import orient

    if region.geom_type != "Polygon":
        region = max(region.geoms, key=lambda g: g.area)
    region = orient(region, 1.0)
    outline = [np.asarray(region.exterior.coords)[:-1]]
    return outline + [np.asarray(r.coords)[:-1] for r in region.interiors]


def edge_outline(
    rings: Sequence[np.ndarray], allowances: Sequence[np.ndarray], hole_allowance: float
) -> list[np.ndarray]:
    """:func:`cut_outline` with an allowance per edge of the outline (``allowances[0]``, edge
    ``i`` from ``rings[0][i]`` to the next; a ply's splices butt or lap where its mould's edge
    has the trim allowance); the holes (``rings[1:]``) are shrunk by ``hole_allowance``. Where
    every edge has the same allowance, :func:`cut_outline` itself."""
    outer = np.asarray(allowances[0], dtype=float)
    if np.all(outer == outer[0]) and (len(rings) == 1 or outer[0] == hole_allowance):
        return cut_outline(rings, float(outer[0]))
    from shapely.geometry import Polygon

    polygon = Polygon(allowance_outline(rings[0], outer))
    for hole in rings[1:]:
        shrunk = Polygon(hole).buffer(-hole_allowance, join_style="mitre", mitre_limit=MITRE_LIMIT)
        polygon = polygon.difference(shrunk) if not shrunk.is_empty else polygon
    return region_rings(polygon)


def allowance_outline(ring: np.ndarray, allowances: Sequence[float] | np.ndarray) -> np.ndarray:
    """The cut line ``(m, 2)`` around the counter-clockwise seam ring ``(k, 2)``.

    Edge ``i`` (from ``ring[i]`` to ``ring[i + 1]``, closing back to ``ring[0]``) is moved
    outwards by ``allowances[i]``; at a convex corner the two moved edges meet in a mitre (a
    bevel if the mitre is longer than :data:`MITRE_LIMIT` allowances). With one allowance for
    all edges this is the mitred buffer of the ring.
    """
    from shapely import make_valid
    from shapely.geometry import Polygon
    from shapely.ops import unary_union

    ring = np.asarray(ring, dtype=float)
    width = np.broadcast_to(np.asarray(allowances, dtype=float), (len(ring),))
    following = np.roll(ring, -1, axis=0)
    direction = following - ring
    length = np.linalg.norm(direction, axis=1)
    keep = length > 0
    ring, following, direction, length, width = (
        a[keep] for a in (ring, following, direction, length, width)
    )
    tangent = direction / length[:, None]
    normal = np.column_stack([tangent[:, 1], -tangent[:, 0]])  # outwards of a ccw ring
    parts = [Polygon(ring)]
    for a, b, n, w in zip(ring, following, normal, width, strict=True):
        if w > 0:
            parts.append(Polygon([a, b, b + w * n, a + w * n]))
    previous = np.roll(np.arange(len(ring)), 1)
    for i, j in zip(previous, range(len(ring)), strict=True):  # corner at ring[j]
        corner = _corner(ring[j], tangent[i], normal[i], width[i], tangent[j], normal[j], width[j])
        if corner is not None:
            parts.append(Polygon(corner))
    outline = unary_union([part if part.is_valid else make_valid(part) for part in parts])
    if outline.geom_type != "Polygon":
        outline = max(outline.geoms, key=lambda g: g.area)
    return np.asarray(outline.exterior.coords)[:-1]


def _corner(point, t1, n1, w1, t2, n2, w2) -> np.ndarray | None:
    """The piece that fills a convex corner between two moved edges (none if concave)."""
    turn = t1[0] * t2[1] - t1[1] * t2[0]
    if turn <= 0 or max(w1, w2) <= 0:
        return None
    a, b = point + w1 * n1, point + w2 * n2
    if turn < 1e-6:  # (nearly) straight on: no mitre to speak of
        return np.array([point, a, b])
    # a + s t1 = b + u t2  →  s t1 − u t2 = b − a
    matrix = np.column_stack([t1, -t2])
    s, _ = np.linalg.solve(matrix, b - a)
    mitre = a + s * t1
    if s >= 0 and np.linalg.norm(mitre - point) <= MITRE_LIMIT * max(w1, w2):
        return np.array([point, a, mitre, b])
    return np.array([point, a, b])
