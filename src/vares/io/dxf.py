"""DXF files for the cutter: seam and cut lines, warp arrow, match marks and labels.

Each pattern becomes closed polylines in real units on named layers:

``SEAM``   the pattern boundary (the weld or sewing line), outer loop and holes;
``CUT``    the boundary grown by the seam allowance (shapely buffer with mitred corners);
``WARP``   an arrow along the warp direction;
``MARKS``  match marks: short ticks across the seam line at a fixed spacing along it;
``LABEL``  the panel name, areas and compensation;
``DART``   the darts of a ply: each dart's two lips from the mouth to the tip and back, an open
           polyline (the notch the seam line runs round).

Several patterns are laid out side by side, without overlap, along x.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..geometry.mesh import SurfaceMesh
from ..geometry.outline import cut_outline
from ..units import unit_factor
from .files import atomic_path

__all__ = [
    "INSUNITS",
    "CutPiece",
    "NestedDrawing",
    "cut_outline",
    "label_place",
    "write_dxf",
    "write_nest_dxf",
]

#: DXF ``$INSUNITS`` code of each length unit.
INSUNITS = {"mm": 4, "cm": 5, "m": 6, "in": 1, "ft": 2}
LAYERS = {"SEAM": 7, "CUT": 1, "WARP": 5, "MARKS": 3, "LABEL": 2, "DART": 6}


@dataclass
class CutPiece:
    """One pattern to draw: coordinates ``(n, 2)`` in model units, warp direction ``(2,)``,
    label lines, optionally match mark positions (model units, ``(k, 2)``, on the seam line)
    that replace the regularly spaced ones, optionally its cut line (a ring ``(k, 2)`` in
    model units, e.g. with an allowance per edge, or a list of rings: the outline, then holes)
    that replaces the seam line grown by the drawing's allowance, its darts (open polylines
    ``(k, 2)`` in model units, drawn on layer ``DART``), and optionally its seam rings
    (``(k, 2)`` each, model units) that replace the mesh's boundary loops (a spliced piece's
    edges on the drawn splice line)."""

    name: str
    mesh: SurfaceMesh
    coordinates: np.ndarray
    warp: np.ndarray | None = None
    label: Sequence[str] = ()
    marks: np.ndarray | None = field(default=None, repr=False)
    cut: np.ndarray | Sequence[np.ndarray] | None = field(default=None, repr=False)
    darts: Sequence[np.ndarray] = field(default=(), repr=False)
    seams: Sequence[np.ndarray] | None = field(default=None, repr=False)


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

    if units not in INSUNITS or model_units not in INSUNITS:
        raise ValueError(
            f"units must be one of {', '.join(INSUNITS)}; got {units!r}/{model_units!r}"
        )
    if not (np.isfinite(allowance) and allowance >= 0):
        raise ValueError(f"the seam allowance must be ≥ 0; got {allowance!r}")
    if mark_spacing is not None and not (np.isfinite(mark_spacing) and mark_spacing > 0):
        raise ValueError(f"the match mark spacing must be > 0; got {mark_spacing!r}")
    factor = unit_factor(model_units, units)

    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = INSUNITS[units]
    doc.header["$MEASUREMENT"] = 1
    for name, colour in LAYERS.items():
        doc.layers.add(name, color=colour)
    space = doc.modelspace()

    cursor = 0.0
    for piece in pieces:
        coordinates = np.asarray(piece.coordinates, dtype=float) * factor
        if piece.seams is not None:
            seams = [np.asarray(ring, dtype=float) * factor for ring in piece.seams]
        else:
            seams = [coordinates[loop] for loop in piece.mesh.boundary_loops()]
        if piece.cut is not None:
            rings = [piece.cut] if np.ndim(piece.cut[0]) == 1 else piece.cut  # one ring, or rings
            cuts = [np.asarray(r, dtype=float) * factor for r in rings]
        else:
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
        for dart in piece.darts:
            line = np.asarray(dart, dtype=float) * factor + shift
            space.add_lwpolyline(line, dxfattribs={"layer": "DART"})
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


@dataclass
class NestedDrawing:
    """A piece as laid on the roll (model units): its seam and cut rings, its warp direction,
    its label lines and its match marks ``(name, point (2,), outward normal (2,))``."""

    name: str
    seam: np.ndarray
    cut: np.ndarray
    warp: np.ndarray
    label: Sequence[str]
    marks: Sequence[tuple[str, np.ndarray, np.ndarray]] = ()
    tick: float = 0.0


#: Width of a character of the drawing's text, in text heights (generous, so labels fit).
_CHARACTER_WIDTH = 0.8


def write_nest_dxf(
    path: str | Path,
    rolls: Sequence[tuple[float, float, Sequence[NestedDrawing]]],
    *,
    units: str = "mm",
    model_units: str = "m",
) -> None:
    """Write nested pieces to a DXF file (R2010): one drawing per roll ``(width, length,
    pieces)``, the rolls one above the other. Each roll is a rectangle on layer ``ROLL`` (the
    roll runs along x); each piece has its seam and cut lines, a warp arrow and its label (name
    and area) inside it, placed where they cross no line (the pole of inaccessibility of the
    seam polygon, shapely's ``polylabel``), and its match marks named by seam."""
    import ezdxf
    from ezdxf.enums import TextEntityAlignment

    factor = unit_factor(model_units, units)
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = INSUNITS[units]
    doc.header["$MEASUREMENT"] = 1
    for name, colour in {**LAYERS, "ROLL": 8}.items():
        doc.layers.add(name, color=colour)
    space = doc.modelspace()
    centred = {"align": TextEntityAlignment.MIDDLE_CENTER}
    offset = 0.0
    for number, (width, length, pieces) in enumerate(rolls, start=1):
        shift = np.array([0.0, offset])
        corners = np.array([[0, 0], [length, 0], [length, width], [0, width]]) * factor + shift
        space.add_lwpolyline(corners, close=True, dxfattribs={"layer": "ROLL"})
        title = f"roll {number}: {width:g} × {length:.4g} {model_units}"
        space.add_text(
            title, height=0.04 * width * factor, dxfattribs={"layer": "ROLL"}
        ).set_placement(tuple(corners[3] + [0.0, 0.03 * width * factor]))
        for piece in pieces:
            _draw_nested(space, piece, factor, shift, centred)
        offset += 1.3 * width * factor
    with atomic_path(Path(path)) as temporary:
        doc.saveas(temporary)


def _draw_nested(space, piece: NestedDrawing, factor: float, shift: np.ndarray, centred) -> None:
    from shapely.geometry import Polygon, box

    seam = piece.seam * factor + shift
    space.add_lwpolyline(seam, close=True, dxfattribs={"layer": "SEAM"})
    space.add_lwpolyline(piece.cut * factor + shift, close=True, dxfattribs={"layer": "CUT"})
    polygon = Polygon(seam)
    centre, height = label_place(polygon, len(piece.label) + 1, max(map(len, piece.label)))
    warp = np.asarray(piece.warp, dtype=float) / np.linalg.norm(piece.warp)
    rows = len(piece.label) + 1
    top = centre[1] + 0.5 * (rows - 1) * 1.6 * height
    half = 0.5 * _CHARACTER_WIDTH * height * max(map(len, piece.label))
    tail, tip = centre + np.array([-half * warp[0], 0.0]), centre + np.array([half * warp[0], 0.0])
    tail[1] = tip[1] = top
    head = 0.5 * height
    space.add_lwpolyline([tail, tip], dxfattribs={"layer": "WARP"})
    space.add_lwpolyline(
        [tip - head * warp + [0, 0.5 * head], tip, tip - head * warp - [0, 0.5 * head]],
        dxfattribs={"layer": "WARP"},
    )
    for row, line in enumerate(piece.label, start=1):
        space.add_text(line, height=height, dxfattribs={"layer": "LABEL"}).set_placement(
            (centre[0], top - row * 1.6 * height), **centred
        )
    block = box(
        centre[0] - half, top - (rows - 0.5) * 1.6 * height, centre[0] + half, top + 0.8 * height
    )
    mark_height = 0.5 * height
    tick = piece.tick * factor
    for name, point, normal in piece.marks:
        at = np.asarray(point) * factor + shift
        space.add_line(at, at + tick * np.asarray(normal), dxfattribs={"layer": "MARKS"})
        size = mark_height
        for _ in range(3):  # the name inside the piece, clear of every line and of the label
            spot = at - np.asarray(normal) * (
                0.8 * size + 0.5 * _CHARACTER_WIDTH * size * len(name) * abs(normal[0])
            )
            half_w = 0.5 * _CHARACTER_WIDTH * size * len(name)
            area = box(
                spot[0] - half_w, spot[1] - 0.6 * size, spot[0] + half_w, spot[1] + 0.6 * size
            )
            if polygon.contains(area) and not area.intersects(block):
                space.add_text(name, height=size, dxfattribs={"layer": "MARKS"}).set_placement(
                    tuple(spot), **centred
                )
                break
            size *= 0.5


def label_place(polygon, rows: int, characters: int) -> tuple[np.ndarray, float]:
    """Centre and text height of a label block of ``rows`` rows of at most ``characters``
    characters that fits inside a shapely polygon: centred on its pole of inaccessibility, as
    large as fits (at most a tenth of the polygon's smaller extent)."""
    from shapely.geometry import box
    from shapely.ops import polylabel

    low_x, low_y, high_x, high_y = polygon.bounds
    size = min(high_x - low_x, high_y - low_y)
    pole = polylabel(polygon, tolerance=1e-3 * size)
    centre = np.array([pole.x, pole.y])
    height = 0.1 * size
    for _ in range(40):
        half_w = 0.5 * _CHARACTER_WIDTH * height * characters
        half_h = 0.5 * rows * 1.6 * height
        block = box(centre[0] - half_w, centre[1] - half_h, centre[0] + half_w, centre[1] + half_h)
        if polygon.buffer(-0.2 * height).contains(block):
            break
        height *= 0.85
    return centre, height
