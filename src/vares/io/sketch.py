"""The pattern's preview, ``pattern.svg`` and ``pattern.png``, drawn without matplotlib.

A run's preview is lines and one fill colour: the pattern filled, its mesh lines (up to
:data:`MESH_LINES_UP_TO` cells), its outline, the warp and fill arrows, circles
where the outline crosses itself, axes with ticks and a title. Here they are a list of
primitives in drawing coordinates, written as SVG text and painted by Pillow (supersampled, so
lines are smooth). Importing matplotlib and saving its figure twice took 0.8 s of a 2.2 s small
job; this takes a few hundredths (docs/benchmarks.md). Fields, with their colour bars, are
drawn by :mod:`vares.io.plot`.
"""

from __future__ import annotations

import io
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from html import escape
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..geometry.mesh import SurfaceMesh
from ..materials import Fibres

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

#: Resolution of the pictures a run writes (``pattern.png``, ``surface_FIELD.png``, …): the
#: cells of a picture are rasterised for it unless a plot is given another ``dpi``.
DPI = 150
#: Points per inch.
POINT = 72.0
#: The longer side of a picture of a pattern, inches (the preview here, matplotlib's in plot.py).
SIDE = 6.5
#: Margins around the axes, inches: left, right, bottom, top (tick labels, title).
MARGINS = (0.7, 0.25, 0.45, 0.4)
#: Each pixel of a PNG is painted from SUPERSAMPLE × SUPERSAMPLE samples (smooth lines).
SUPERSAMPLE = 3

#: Meshes with at most this many cells show their mesh lines (on finer ones, a grey blur).
MESH_LINES_UP_TO = 5_000
FACE = "#d9e6f2"
MESH = "#5b7a99"
INK = "#000000"
MARK = "#ff0000"
FONT_SIZE = 10.0
TITLE_SIZE = 12.0


def fibre_arrow_length(coordinates: np.ndarray) -> float:
    """The length of the warp and fill arrows drawn on a pattern ``(n, 2)``: 15 % of its longer
    side, and inside its box however narrow it is (a strip of roll width)."""
    extent = np.ptp(np.asarray(coordinates, dtype=float), axis=0)
    return min(0.15 * float(extent.max()), 0.35 * float(extent.min()))


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


class _Cells(NamedTuple):
    """Cells filled: their outline ``loops`` (for SVG, the non-zero rule), the ``cells`` at
    placed ``points`` (for PNG, rasterised), in ``colour``."""

    loops: list[np.ndarray]
    cells: Mapping[str, np.ndarray]
    points: np.ndarray
    colour: str


class _Lines(NamedTuple):
    """Line segments ``(k, 2, 2)``, or closed polylines (``closed``: a list of ``(m, 2)``)."""

    lines: np.ndarray | list[np.ndarray]
    colour: str
    width: float
    closed: bool


class _Arrow(NamedTuple):
    start: np.ndarray
    end: np.ndarray
    label: str
    dashed: bool
    width: float


class _Rings(NamedTuple):
    points: np.ndarray
    colour: str
    diameter: float


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
        self._items.append(_Cells(loops, mesh.cells, self.place(coordinates), colour))

    def segments(self, segments: np.ndarray, colour: str, width: float) -> None:
        """Line segments ``(k, 2, 2)``, ``width`` points wide."""
        self._items.append(_Lines(self.place(segments), colour, width, closed=False))

    def loops(self, loops: list[np.ndarray], colour: str, width: float) -> None:
        """Closed polylines (each ``(m, 2)``)."""
        self._items.append(_Lines([self.place(loop) for loop in loops], colour, width, True))

    def arrow(self, start, end, label: str, dashed: bool = False, width: float = 1.4) -> None:
        """An arrow from ``start`` to ``end`` with ``label`` just beyond its head."""
        a, b = self.place(np.asarray([start, end], dtype=float))
        self._items.append(_Arrow(a, b, label, dashed, width))

    def rings(self, points: np.ndarray, colour: str, diameter: float = 9.0) -> None:
        """Circles of ``diameter`` points around ``points`` ``(k, 2)``."""
        self._items.append(_Rings(self.place(np.reshape(points, (-1, 2))), colour, diameter))

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

    @staticmethod
    def _arrow_parts(arrow: _Arrow):
        """The shaft's end (short of the tip), the head's triangle and the label's centre,
        clear of the tip (text about 0.55 em wide per letter)."""
        a, b, width = arrow.start, arrow.end, arrow.width
        direction = (b - a) / max(float(np.linalg.norm(b - a)), 1e-12)
        normal = np.array([-direction[1], direction[0]])
        length, half = 4.5 * width, 2.2 * width
        base = b - length * direction
        head = np.array([b, base + half * normal, base - half * normal])
        half_text = np.array([0.28 * FONT_SIZE * len(arrow.label), 0.5 * FONT_SIZE])
        clearance = float(np.abs(direction) @ half_text) + 3.0
        return base, head, b + clearance * direction

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
            if isinstance(item, _Cells):
                path = " ".join(_svg_loop(loop) for loop in item.loops)
                out.append(
                    f'<path d="{path}" fill="{item.colour}" fill-rule="nonzero" stroke="none"/>'
                )
            elif isinstance(item, _Lines):
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
            elif isinstance(item, _Rings):
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
            base, head, at = self._arrow_parts(arrow)
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
        from PIL import Image, ImageDraw

        from .raster import rasterise

        k = dpi / POINT * SUPERSAMPLE  # samples per point
        width, height = self.size
        pixels = (round(width * dpi / POINT), round(height * dpi / POINT))
        image = Image.new("RGB", (pixels[0] * SUPERSAMPLE, pixels[1] * SUPERSAMPLE), "#ffffff")
        draw = ImageDraw.Draw(image)
        left, top, w, h = self.axes

        def px(points) -> list[tuple[float, float]]:
            return [(float(x) * k, float(y) * k) for x, y in np.reshape(points, (-1, 2))]

        def stroke(points_width: float) -> int:
            return max(1, round(points_width * k))

        font, minus = _font(FONT_SIZE * k)
        title_font, _ = _font(TITLE_SIZE * k)
        arrows = []
        for item in self._items:
            if isinstance(item, _Cells):  # pixel rows downwards, as the picture's
                grid = (0.0, 0.0, 1.0, pixels[0], pixels[1])
                covered = rasterise(item.cells, item.points * dpi / POINT, grid=grid).index >= 0
                mask = Image.fromarray(covered.astype(np.uint8) * 255)
                image.paste(item.colour, mask=mask.resize(image.size, Image.Resampling.NEAREST))
            elif isinstance(item, _Lines):
                lw = stroke(item.width)
                if item.closed:
                    for loop in item.lines:
                        points = px(loop)
                        draw.line(points + points[:1], fill=item.colour, width=lw, joint="curve")
                else:
                    for a, b in item.lines * k:
                        draw.line([tuple(a), tuple(b)], fill=item.colour, width=lw)
            elif isinstance(item, _Rings):
                r = item.diameter / 2 * k
                for x, y in item.points * k:
                    draw.ellipse(
                        [x - r, y - r, x + r, y + r], outline=item.colour, width=stroke(1.5)
                    )
            else:
                arrows.append(item)
        lw = stroke(0.8)
        draw.rectangle([left * k, top * k, (left + w) * k, (top + h) * k], outline=INK, width=lw)
        for axis, position, label in self._ticks():
            label = label.replace("\u2212", minus)
            if axis == "x":
                y = (top + h) * k
                draw.line([(position * k, y), (position * k, y + 3.5 * k)], fill=INK, width=lw)
                draw.text((position * k, y + 5 * k), label, fill=INK, font=font, anchor="mt")
            else:
                x = left * k
                draw.line([(x - 3.5 * k, position * k), (x, position * k)], fill=INK, width=lw)
                draw.text((x - 5 * k, position * k), label, fill=INK, font=font, anchor="rm")
        for arrow in arrows:
            a, aw = arrow.start, arrow.width
            base, head, at = self._arrow_parts(arrow)
            pieces = _dashes(a, base, 3.7 * aw, 1.6 * aw) if arrow.dashed else [(a, base)]
            for piece in pieces:
                draw.line(px(np.array(piece)), fill=INK, width=stroke(aw))
            draw.polygon(px(head), fill=INK)
            draw.text(tuple(at * k), arrow.label, fill=INK, font=font, anchor="mm")
        if self.title:
            draw.text(
                ((left + w / 2) * k, (top - 6) * k), self.title, fill=INK, font=title_font,
                anchor="ms",
            )  # fmt: skip
        image = image.reduce(SUPERSAMPLE)
        buffer = io.BytesIO()
        image.save(buffer, format="PNG", compress_level=compress_level, dpi=(dpi, dpi))
        return buffer.getvalue()


def _font(size: float):
    """The font of matplotlib's pictures (DejaVu Sans, shipped in its data; found without
    importing it) at ``size`` pixels, and the minus sign it has; else Pillow's own font, which
    has no U+2212."""
    from importlib.util import find_spec

    from PIL import ImageFont

    size = max(1, round(size))
    spec = find_spec("matplotlib")
    folders = (spec.submodule_search_locations or []) if spec is not None else []
    for folder in folders:
        path = Path(folder, "mpl-data", "fonts", "ttf", "DejaVuSans.ttf")
        if path.is_file():
            return ImageFont.truetype(str(path), size), "\u2212"
    return ImageFont.load_default(size=size), "-"


def _svg_loop(points: np.ndarray) -> str:
    head, *rest = points
    return f"M{head[0]:.2f} {head[1]:.2f}" + "".join(f"L{x:.2f} {y:.2f}" for x, y in rest) + "Z"


def _svg_text(at, text: str, size: float, anchor: str, baseline: str) -> str:
    return (
        f'<text x="{at[0]:.2f}" y="{at[1]:.2f}" font-size="{size}" text-anchor="{anchor}" '
        f'dominant-baseline="{baseline}">{escape(text)}</text>'
    )


def _dashes(a: np.ndarray, b: np.ndarray, on: float, off: float) -> list[tuple]:
    """The dashes of a dashed line from ``a`` to ``b``."""
    length = float(np.linalg.norm(b - a))
    direction = (b - a) / max(length, 1e-12)
    pieces, s = [], 0.0
    while s < length:
        pieces.append((a + s * direction, a + min(s + on, length) * direction))
        s += on + off
    return pieces


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
