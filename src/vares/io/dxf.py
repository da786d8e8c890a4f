"""DXF files for the cutter: seam and cut lines, warp arrow, match marks and labels.

Each pattern becomes closed polylines in real units on named layers:

``SEAM``   the pattern boundary (the weld or sewing line), outer loop and holes;
``CUT``    the boundary grown by the seam allowance (shapely buffer with mitred corners);
``WARP``   an arrow along the warp direction;
``MARKS``  match marks: short ticks across the seam line at a fixed spacing along it;
``LABEL``  the panel name, areas and compensation.

Several patterns are laid out side by side, without overlap, along x.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..geometry.mesh import SurfaceMesh
from ..geometry.units import UNITS
from .files import atomic_path

__all__ = ["UNITS", "CutPiece", "boundary_loops", "cut_outline", "write_dxf"]

LAYERS = {"SEAM": 7, "CUT": 1, "WARP": 5, "MARKS": 3, "LABEL": 2}


@dataclass
class CutPiece:
    """One pattern to draw: coordinates ``(n, 2)`` in model units, warp direction ``(2,)``,
    label lines, and optionally match mark positions (model units, ``(k, 2)``, on the seam
    line) that replace the regularly spaced ones."""

    name: str
    mesh: SurfaceMesh
    coordinates: np.ndarray
    warp: np.ndarray | None = None
    label: Sequence[str] = ()
    marks: np.ndarray | None = field(default=None, repr=False)


def boundary_loops(mesh: SurfaceMesh) -> list[np.ndarray]:
    """Closed node loops of the mesh boundary, longest first, each in cell orientation
    (counter-clockwise for the outer loop of a positively oriented pattern)."""
    edges = mesh.boundary_edges()
    following = {int(a): int(b) for a, b in edges}
    loops, seen = [], set()
    for start in sorted(following):
        if start in seen:
            continue
        loop = [start]
        seen.add(start)
        node = following[start]
        while node != start:
            loop.append(node)
            seen.add(node)
            node = following[node]
        loops.append(np.array(loop))
    return sorted(loops, key=len, reverse=True)


def _signed_area(ring: np.ndarray) -> float:
    x, y = ring[:, 0], ring[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def cut_outline(seam_rings: list[np.ndarray], allowance: float) -> list[np.ndarray]:
    """The cut line: the region inside the seam rings grown by ``allowance`` (mitred corners).

    The largest ring is the outline, the others are holes. Returns closed rings ``(k, 2)``.
    """
    from shapely.geometry import Polygon

    outer = max(seam_rings, key=lambda r: abs(_signed_area(r)))
    holes = [r for r in seam_rings if r is not outer]
    polygon = Polygon(outer, holes)
    if allowance > 0:
        polygon = polygon.buffer(allowance, join_style="mitre", mitre_limit=4.0)
    geoms = getattr(polygon, "geoms", [polygon])
    rings = []
    for geom in geoms:
        rings.append(np.asarray(geom.exterior.coords)[:-1])
        rings.extend(np.asarray(interior.coords)[:-1] for interior in geom.interiors)
    return rings


def _marks_along(ring: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``spacing`` along a closed ring (from its first point) and the outward
    normals there (for a counter-clockwise ring)."""
    closed = np.vstack([ring, ring[:1]])
    segment = np.diff(closed, axis=0)
    length = np.linalg.norm(segment, axis=1)
    cumulative = np.concatenate([[0.0], np.cumsum(length)])
    positions = np.arange(0.0, cumulative[-1] - 0.5 * spacing, spacing)
    index = np.clip(np.searchsorted(cumulative, positions, side="right") - 1, 0, len(length) - 1)
    fraction = (positions - cumulative[index]) / length[index]
    points = closed[index] + fraction[:, None] * segment[index]
    tangent = segment[index] / length[index, None]
    return points, np.column_stack([tangent[:, 1], -tangent[:, 0]])


def write_dxf(
    path: str | Path,
    pieces: Sequence[CutPiece],
    *,
    units: str = "mm",
    model_units: str = "m",
    allowance: float = 0.0,
    mark_spacing: float | None = None,
    text_height: float | None = None,
) -> None:
    """Write the patterns to a DXF file (R2010), laid out side by side.

    ``allowance`` (seam allowance) and ``mark_spacing`` are in the DXF ``units``; model
    coordinates are converted from ``model_units``. The file is written atomically.
    """
    import ezdxf

    if units not in UNITS or model_units not in UNITS:
        raise ValueError(f"units must be one of {', '.join(UNITS)}; got {units!r}/{model_units!r}")
    if not (np.isfinite(allowance) and allowance >= 0):
        raise ValueError(f"the seam allowance must be ≥ 0; got {allowance!r}")
    if mark_spacing is not None and not (np.isfinite(mark_spacing) and mark_spacing > 0):
        raise ValueError(f"the match mark spacing must be > 0; got {mark_spacing!r}")
    factor = UNITS[model_units][0] / UNITS[units][0]

    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = UNITS[units][1]
    doc.header["$MEASUREMENT"] = 1
    for name, colour in LAYERS.items():
        doc.layers.add(name, color=colour)
    space = doc.modelspace()

    cursor = 0.0
    for piece in pieces:
        coordinates = np.asarray(piece.coordinates, dtype=float) * factor
        seams = [coordinates[loop] for loop in boundary_loops(piece.mesh)]
        cuts = cut_outline(seams, allowance)
        everything = np.vstack(cuts + seams)
        low, high = everything.min(axis=0), everything.max(axis=0)
        size = float(np.max(high - low))
        shift = np.array([cursor - low[0], -low[1]])
        height = text_height or 0.03 * size
        for ring in seams:
            space.add_lwpolyline(ring + shift, close=True, dxfattribs={"layer": "SEAM"})
        for ring in cuts:
            space.add_lwpolyline(ring + shift, close=True, dxfattribs={"layer": "CUT"})
        centre = coordinates.mean(axis=0) + shift
        if piece.warp is not None:
            warp = np.asarray(piece.warp, dtype=float)
            warp = warp / np.linalg.norm(warp)
            tip = centre + 0.2 * size * warp
            side = np.array([-warp[1], warp[0]])
            head = 0.03 * size
            space.add_lwpolyline([centre, tip], dxfattribs={"layer": "WARP"})
            space.add_lwpolyline(
                [tip - head * warp + 0.5 * head * side, tip, tip - head * warp - 0.5 * head * side],
                dxfattribs={"layer": "WARP"},
            )
        tick = allowance if allowance > 0 else 0.01 * size
        outer = seams[0]
        if piece.marks is not None:
            points = np.asarray(piece.marks, dtype=float) * factor
            normals = _normals_at(outer, points)
        elif mark_spacing is not None:
            start = int(np.lexsort((outer[:, 1], outer[:, 0]))[0])
            points, normals = _marks_along(np.roll(outer, -start, axis=0), mark_spacing)
        else:
            points = normals = np.zeros((0, 2))
        for point, normal in zip(points, normals, strict=True):
            space.add_line(
                point + shift, point + shift + tick * normal, dxfattribs={"layer": "MARKS"}
            )
        for row, line in enumerate([piece.name, *piece.label]):
            space.add_text(line, height=height, dxfattribs={"layer": "LABEL"}).set_placement(
                tuple(centre - [0.0, (row + 1.5) * 1.6 * height])
            )
        cursor += float(high[0] - low[0]) + max(2 * allowance, 0.05 * size)

    with atomic_path(Path(path)) as temporary:
        doc.saveas(temporary)


def _normals_at(ring: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Outward normals of a counter-clockwise ring at the segments nearest to ``points``."""
    closed = np.vstack([ring, ring[:1]])
    a, b = closed[:-1], closed[1:]
    out = []
    for p in points:
        t = np.clip(np.einsum("ij,ij->i", p - a, b - a) / np.einsum("ij,ij->i", b - a, b - a), 0, 1)
        nearest = int(np.argmin(np.linalg.norm(a + t[:, None] * (b - a) - p, axis=1)))
        d = (b - a)[nearest] / np.linalg.norm((b - a)[nearest])
        out.append([d[1], -d[0]])
    return np.array(out).reshape(-1, 2)
