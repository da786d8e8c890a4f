"""A sketch painted as PNG bytes by Pillow: cells rasterised at the picture's own pixels, lines,
rings, ticks, arrows and the title drawn at SUPERSAMPLE × SUPERSAMPLE samples a pixel and
reduced, so lines are smooth (:meth:`vares.io.sketch.Sketch.png`)."""

from __future__ import annotations

import io
from collections.abc import Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np

from .drawing import (
    FONT_SIZE,
    INK,
    POINT,
    SUPERSAMPLE,
    TITLE_SIZE,
    FilledCells,
    Lines,
    Rings,
    arrow_parts,
)

__all__ = ["paint_png"]


def paint_png(
    items: Sequence[NamedTuple],
    ticks: Sequence[tuple[str, float, str]],
    axes: tuple[float, float, float, float],
    size: tuple[float, float],
    title: str | None,
    dpi: float,
    compress_level: int = 4,
) -> bytes:
    """The primitives ``items`` (:mod:`vares.io.drawing`, in figure points) of a picture of
    ``size`` (width, height, points) with its ``axes`` box (left, top, width, height), their
    ``ticks`` ``(axis, position in points, label)`` and ``title``, painted at ``dpi`` as PNG
    bytes; cells are rasterised at the picture's own pixels (:func:`vares.io.raster.covered`),
    lines at 3 × 3 samples a pixel."""
    from PIL import Image, ImageColor, ImageDraw

    k = dpi / POINT * SUPERSAMPLE  # samples per point
    width, height = size
    pixels = (round(width * dpi / POINT), round(height * dpi / POINT))
    # the cells that come first are filled at the picture's own pixels, then each pixel
    # becomes SUPERSAMPLE × SUPERSAMPLE samples (as pasting them on the samples would, at a
    # ninth of the cost); lines and text are drawn on the samples
    leading = 0
    while leading < len(items) and isinstance(items[leading], FilledCells):
        leading += 1
    leading = min(leading, 255)  # each a grey level of the labels below
    labels = np.zeros((pixels[1], pixels[0]), dtype=np.uint8)  # 0: white, n: the n-th item's
    for n, item in enumerate(items[:leading], start=1):
        labels = np.where(_covered(item, pixels, dpi), np.uint8(n), labels)
    colours = [(255, 255, 255)] + [ImageColor.getrgb(i.colour)[:3] for i in items[:leading]]
    bands = [[c[band] for c in colours] + [0] * (256 - len(colours)) for band in range(3)]
    grey = Image.fromarray(labels, mode="L")
    image = Image.merge("RGB", [grey.point(band) for band in bands]).resize(
        (pixels[0] * SUPERSAMPLE, pixels[1] * SUPERSAMPLE), Image.Resampling.NEAREST
    )
    draw = ImageDraw.Draw(image)
    left, top, w, h = axes

    def px(points) -> list[tuple[float, float]]:
        return [(float(x) * k, float(y) * k) for x, y in np.reshape(points, (-1, 2))]

    def stroke(points_width: float) -> int:
        return max(1, round(points_width * k))

    font, minus = _font(FONT_SIZE * k)
    title_font, _ = _font(TITLE_SIZE * k)
    arrows = []
    for item in items[leading:]:
        if isinstance(item, FilledCells):
            mask = Image.fromarray(_covered(item, pixels, dpi).astype(np.uint8) * 255)
            image.paste(item.colour, mask=mask.resize(image.size, Image.Resampling.NEAREST))
        elif isinstance(item, Lines):
            lw = stroke(item.width)
            if item.closed:
                for loop in item.lines:
                    points = px(loop)
                    draw.line(points + points[:1], fill=item.colour, width=lw, joint="curve")
            else:
                for a, b in item.lines * k:
                    draw.line([tuple(a), tuple(b)], fill=item.colour, width=lw)
        elif isinstance(item, Rings):
            r = item.diameter / 2 * k
            for x, y in item.points * k:
                draw.ellipse([x - r, y - r, x + r, y + r], outline=item.colour, width=stroke(1.5))
        else:
            arrows.append(item)
    lw = stroke(0.8)
    draw.rectangle([left * k, top * k, (left + w) * k, (top + h) * k], outline=INK, width=lw)
    for axis, position, label in ticks:
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
        base, head, at = arrow_parts(arrow)
        pieces = _dashes(a, base, 3.7 * aw, 1.6 * aw) if arrow.dashed else [(a, base)]
        for piece in pieces:
            draw.line(px(np.array(piece)), fill=INK, width=stroke(aw))
        draw.polygon(px(head), fill=INK)
        draw.text(tuple(at * k), arrow.label, fill=INK, font=font, anchor="mm")
    if title:
        draw.text(
            ((left + w / 2) * k, (top - 6) * k), title, fill=INK, font=title_font,
            anchor="ms",
        )  # fmt: skip
    image = image.reduce(SUPERSAMPLE)
    buffer = io.BytesIO()
    image.save(buffer, format="PNG", compress_level=compress_level, dpi=(dpi, dpi))
    return buffer.getvalue()


def _covered(item: FilledCells, pixels: tuple[int, int], dpi: float) -> np.ndarray:
    """The pixels (rows downwards, as the picture's) that the cells of ``item`` cover."""
    from .raster import covered

    return covered(item.cells, item.points * dpi / POINT, grid=(0.0, 0.0, 1.0, *pixels))


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


def _dashes(a: np.ndarray, b: np.ndarray, on: float, off: float) -> list[tuple]:
    """The dashes of a dashed line from ``a`` to ``b``."""
    length = float(np.linalg.norm(b - a))
    direction = (b - a) / max(length, 1e-12)
    pieces, s = [], 0.0
    while s < length:
        pieces.append((a + s * direction, a + min(s + on, length) * direction))
        s += on + off
    return pieces
