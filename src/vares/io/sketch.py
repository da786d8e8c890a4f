"""The pattern's preview, ``pattern.svg`` and ``pattern.png``, drawn without matplotlib.

A run's preview is lines and one fill colour: the pattern filled, its mesh lines (up to
:data:`MESH_LINES_UP_TO` cells), its outline, the warp and fill arrows, circles
where the outline crosses itself, axes with ticks and a title. Here they are a list of
primitives (:mod:`vares.io.drawing`) in drawing coordinates, written as SVG text and painted by
Pillow (:mod:`vares.io.sketch_png`, supersampled, so lines are smooth). Importing matplotlib
and saving its figure twice took 0.8 s of a 2.2 s small job; this takes a few hundredths
(docs/benchmarks.md). Fields, with their colour bars, are drawn by :mod:`vares.io.plot`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from html import escape
from typing import NamedTuple

import numpy as np

from ..geometry.mesh import SurfaceMesh
from ..materials import Fibres
from .drawing import (
    DPI,
    FACE,
    FONT_SIZE,
    INK,
    MARGINS,
    MARK,
    MESH,
    MESH_LINES_UP_TO,
    POINT,
    SIDE,
    TITLE_SIZE,
    Arrow,
    FilledCells,
    Lines,
    Rings,
    arrow_parts,
    fibre_arrow_length,
)
from .sketch_png import paint_png

__all__ = [
    "DPI",
    "MARGINS",
    "MESH_LINES_UP_TO",
    "SIDE",
    "Sketch",
    "fibre_arrow_length",
    "nice_ticks",
    "pattern_sketch",
]


def nice_ticks(low: float, high: float, most: int = 8) -> np.ndarray:
    """Round tick values in ``[low, high]``: multiples of 1, 2, 2.5 or 5 × 10ᵏ, at most ``most``
    of them (and at least two where the span allows)."""
    span = high - low
    if not (math.isfinite(span) and span > 0):
        return np.array([low])
    for decade in (10.0 ** math.floor(math.log10(span / most)) * f for f in (1, 10)):
        for factor in (1.0, 2.0, 2.5, 5.0):
            step = decade * factor
            first, last = math.ceil(low / step - 1e-9), math.floor(high / step + 1e-9)
            if last - first + 1 <= most:
                return np.arange(first, last + 1) * step
    return np.array([low, high])  # not reached: 10 × the smallest decade gives ≤ most


def _tick_label(value: float, step: float) -> str:
    """A tick's text with as many decimals as the step needs, a true minus sign."""
    decimals = 0
    while decimals < 15:
        scaled = step * 10**decimals  # a whole number of the last decimal's units?
        if round(scaled) >= 1 and abs(scaled - round(scaled)) <= 1e-6 * scaled:
            break
        decimals += 1
    text = f"{value:.{decimals}f}"
    if float(text) == 0:
        text = f"{0:.{decimals}f}"
    return text.replace("-", "\u2212")


@dataclass
class Sketch:
    """A drawing of a pattern in its own coordinates: the axes' data ``limits`` (x0, x1, y0,
    y1) shown in a ``size`` (width, height, points) figure; primitives added by the methods
    below, then written by :meth:`svg` and :meth:`png`."""

    limits: tuple[float, float, float, float]
    size: tuple[float, float]
    title: str | None = None
    _items: list[NamedTuple] = field(default_factory=list)

    # -- placing -------------------------------------------------------------------------
    @property
    def axes(self) -> tuple[float, float, float, float]:
        """The axes box in points: left, top, width, height (y down)."""
        left, right, bottom, top = (POINT * m for m in MARGINS)
        width, height = self.size
        return left, top, width - left - right, height - top - bottom

    def place(self, points: np.ndarray) -> np.ndarray:
        """Drawing coordinates ``(..., 2)`` → figure points (y down)."""
        x0, x1, _, y1 = self.limits
        left, top, width, _ = self.axes
        scale = width / (x1 - x0)
        points = np.asarray(points, dtype=float)
        return np.stack(
            [left + (points[..., 0] - x0) * scale, top + (y1 - points[..., 1]) * scale], axis=-1
        )

    # -- primitives (drawing coordinates) ------------------------------------------------
    def cells(self, mesh: SurfaceMesh, coordinates: np.ndarray, colour: str) -> None:
        """The cells of ``mesh`` at ``coordinates`` ``(n, 2)`` filled: where the pattern laps
        over itself too, and its holes left empty."""
        loops = [self.place(coordinates[loop]) for loop in mesh.boundary_loops()]
        self._items.append(FilledCells(loops, mesh.cells, self.place(coordinates), colour))

    def segments(self, segments: np.ndarray, colour: str, width: float) -> None:
        """Line segments ``(k, 2, 2)``, ``width`` points wide."""
        self._items.append(Lines(self.place(segments), colour, width, closed=False))

    def loops(self, loops: list[np.ndarray], colour: str, width: float) -> None:
        """Closed polylines (each ``(m, 2)``)."""
        self._items.append(Lines([self.place(loop) for loop in loops], colour, width, True))

    def arrow(self, start, end, label: str, dashed: bool = False, width: float = 1.4) -> None:
        """An arrow from ``start`` to ``end`` with ``label`` just beyond its head."""
        a, b = self.place(np.asarray([start, end], dtype=float))
        self._items.append(Arrow(a, b, label, dashed, width))

    def rings(self, points: np.ndarray, colour: str, diameter: float = 9.0) -> None:
        """Circles of ``diameter`` points around ``points`` ``(k, 2)``."""
        self._items.append(Rings(self.place(np.reshape(points, (-1, 2))), colour, diameter))

    # -- the axes ------------------------------------------------------------------------
    def _ticks(self) -> list[tuple[str, float, str]]:
        """``(axis, position in points, label)`` of every tick."""
        x0, x1, y0, y1 = self.limits
        _, _, width, height = self.axes
        ticks = []
        # labels side by side need some 45 points each along x, 25 along y
        room = {"x": max(3, int(width / 45)), "y": max(3, int(height / 25))}
        for axis, low, high in (("x", x0, x1), ("y", y0, y1)):
            values = nice_ticks(low, high, min(8, room[axis]))
            step = float(values[1] - values[0]) if len(values) > 1 else abs(high - low) or 1.0
            for value in values:
                point = (value, y0) if axis == "x" else (x0, value)
                placed = self.place(np.array(point))
                ticks.append(
                    (axis, float(placed[0 if axis == "x" else 1]), _tick_label(value, step))
                )
        return ticks

    # -- SVG -----------------------------------------------------------------------------
    def svg(self) -> str:
        """The sketch as an SVG document (sizes in points)."""
        width, height = self.size
        left, top, w, h = self.axes
        out = [
            '<?xml version="1.0" encoding="utf-8"?>',
            f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.2f}pt" '
            f'height="{height:.2f}pt" viewBox="0 0 {width:.2f} {height:.2f}" '
            'font-family="DejaVu Sans, Arial, Helvetica, sans-serif">',
            f'<rect width="{width:.2f}" height="{height:.2f}" fill="#ffffff"/>',
        ]
        arrows = []
        for item in self._items:
            if isinstance(item, FilledCells):
                path = " ".join(_svg_loop(loop) for loop in item.loops)
                out.append(
                    f'<path d="{path}" fill="{item.colour}" fill-rule="nonzero" stroke="none"/>'
                )
            elif isinstance(item, Lines):
                if item.closed:
                    path = " ".join(_svg_loop(loop) for loop in item.lines)
                else:
                    path = "".join(
                        f"M{a[0]:.2f} {a[1]:.2f}L{b[0]:.2f} {b[1]:.2f}" for a, b in item.lines
                    )
                out.append(
                    f'<path d="{path}" fill="none" stroke="{item.colour}" '
                    f'stroke-width="{item.width}" stroke-linejoin="round"/>'
                )
            elif isinstance(item, Rings):
                out += [
                    f'<circle cx="{x:.2f}" cy="{y:.2f}" r="{item.diameter / 2:.2f}" '
                    f'fill="none" stroke="{item.colour}" stroke-width="1.5"/>'
                    for x, y in item.points
                ]
            else:
                arrows.append(item)
        out.append(
            f'<rect x="{left:.2f}" y="{top:.2f}" width="{w:.2f}" height="{h:.2f}" '
            f'fill="none" stroke="{INK}" stroke-width="0.8"/>'
        )
        for axis, position, label in self._ticks():
            if axis == "x":
                y = top + h
                out.append(
                    f'<line x1="{position:.2f}" y1="{y:.2f}" x2="{position:.2f}" '
                    f'y2="{y + 3.5:.2f}" stroke="{INK}" stroke-width="0.8"/>'
                )
                out.append(_svg_text((position, y + 5), label, FONT_SIZE, "middle", "hanging"))
            else:
                out.append(
                    f'<line x1="{left - 3.5:.2f}" y1="{position:.2f}" x2="{left:.2f}" '
                    f'y2="{position:.2f}" stroke="{INK}" stroke-width="0.8"/>'
                )
                out.append(_svg_text((left - 5, position), label, FONT_SIZE, "end", "central"))
        for arrow in arrows:
            a, lw = arrow.start, arrow.width
            base, head, at = arrow_parts(arrow)
            dash = f' stroke-dasharray="{3.7 * lw:.2f} {1.6 * lw:.2f}"' if arrow.dashed else ""
            out += [
                f'<line x1="{a[0]:.2f}" y1="{a[1]:.2f}" x2="{base[0]:.2f}" '
                f'y2="{base[1]:.2f}" stroke="{INK}" stroke-width="{lw}"{dash}/>',
                f'<path d="{_svg_loop(head)}" fill="{INK}"/>',
                _svg_text(at, arrow.label, FONT_SIZE, "middle", "central"),
            ]
        if self.title:
            out.append(_svg_text((left + w / 2, top - 6), self.title, TITLE_SIZE, "middle", "auto"))
        out.append("</svg>")
        return "\n".join(out) + "\n"

    # -- PNG -----------------------------------------------------------------------------
    def png(self, dpi: float = DPI, compress_level: int = 4) -> bytes:
        """The sketch painted at ``dpi`` as PNG bytes (Pillow); cells are rasterised at the
        picture's own pixels (:func:`vares.io.raster.rasterise`), lines at 3 × 3 samples a
        pixel."""
        return paint_png(
            self._items, self._ticks(), self.axes, self.size, self.title, dpi, compress_level
        )


def _svg_loop(points: np.ndarray) -> str:
    head, *rest = points
    return f"M{head[0]:.2f} {head[1]:.2f}" + "".join(f"L{x:.2f} {y:.2f}" for x, y in rest) + "Z"


def _svg_text(at, text: str, size: float, anchor: str, baseline: str) -> str:
    return (
        f'<text x="{at[0]:.2f}" y="{at[1]:.2f}" font-size="{size}" text-anchor="{anchor}" '
        f'dominant-baseline="{baseline}">{escape(text)}</text>'
    )


def _frame(coordinates: np.ndarray) -> tuple[tuple[float, float, float, float], tuple]:
    """Data limits (the pattern with a margin, widened to the axes' shape) and figure size."""
    low, high = coordinates.min(axis=0), coordinates.max(axis=0)
    span = high - low
    longest = float(span.max()) or 1.0
    low, high = low - 0.03 * longest, high + 0.03 * longest
    span = high - low
    aspect = float(np.clip(span[1] / span[0], 0.15, 4.0))  # axes height / width
    left, right, bottom, top = (POINT * m for m in MARGINS)
    if aspect <= 1:
        w = POINT * SIDE - left - right
        h = w * aspect
    else:
        h = POINT * SIDE - bottom - top
        w = h / aspect
    scale = min(w / span[0], h / span[1])  # equal axes: the pattern fits, centred
    centre = 0.5 * (low + high)
    half = 0.5 * np.array([w, h]) / scale
    limits = (centre[0] - half[0], centre[0] + half[0], centre[1] - half[1], centre[1] + half[1])
    return limits, (w + left + right, h + bottom + top)


def pattern_sketch(
    mesh: SurfaceMesh,
    coordinates: np.ndarray,
    *,
    fibres: Fibres | None = None,
    title: str | None = None,
    marks: np.ndarray | None = None,
) -> Sketch:
    """A pattern ``(n, 2)`` as :func:`vares.io.plot.plot_pattern` draws it without a field:
    filled, with its mesh lines (up to :data:`MESH_LINES_UP_TO` cells), its outline, warp
    (solid) and fill (dashed) arrows and ``marks`` ``(k, 2)`` circled in red."""
    coordinates = np.asarray(coordinates, dtype=float)
    limits, size = _frame(coordinates)
    sketch = Sketch(limits, size, title)
    sketch.cells(mesh, coordinates, FACE)
    if mesh.num_cells <= MESH_LINES_UP_TO:
        sketch.segments(coordinates[mesh.edges()], MESH, 0.2)
    sketch.loops([coordinates[loop] for loop in mesh.boundary_loops()], INK, 0.6)
    if marks is not None and len(marks):
        sketch.rings(np.asarray(marks, dtype=float), MARK)
    if fibres is not None:
        centre = coordinates.mean(axis=0)
        length = fibre_arrow_length(coordinates)
        sketch.arrow(centre, centre + length * np.asarray(fibres.warp), "warp")
        sketch.arrow(centre, centre + length * np.asarray(fibres.fill), "fill", dashed=True)
    return sketch
