"""What the pictures of a run share, and what a sketch is made of.

Sizes (the resolution, the longer side of a picture of a pattern, the margins around its axes),
colours and type sizes, the length of the warp and fill arrows; and the primitives of a
:class:`vares.io.sketch.Sketch`, placed in figure points (y down), that its SVG and PNG writers
draw. The matplotlib pictures (:mod:`vares.io.plot`) take the same sizes and colours.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

import numpy as np

__all__ = [
    "DPI",
    "FACE",
    "FONT_SIZE",
    "INK",
    "MARGINS",
    "MARK",
    "MESH",
    "MESH_LINES_UP_TO",
    "POINT",
    "SIDE",
    "SUPERSAMPLE",
    "TITLE_SIZE",
    "Arrow",
    "FilledCells",
    "Lines",
    "Rings",
    "arrow_parts",
    "fibre_arrow_length",
]

#: Resolution of the pictures a run writes (``pattern.png``, ``surface_FIELD.png``, …): the
#: cells of a picture are rasterised for it unless a plot is given another ``dpi``.
DPI = 150
#: Points per inch.
POINT = 72.0
#: The longer side of a picture of a pattern, inches (the preview and matplotlib's).
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


class FilledCells(NamedTuple):
    """Cells filled: their outline ``loops`` (for SVG, the non-zero rule), the ``cells`` at
    placed ``points`` (for PNG, rasterised), in ``colour``."""

    loops: list[np.ndarray]
    cells: Mapping[str, np.ndarray]
    points: np.ndarray
    colour: str


class Lines(NamedTuple):
    """Line segments ``(k, 2, 2)``, or closed polylines (``closed``: a list of ``(m, 2)``)."""

    lines: np.ndarray | list[np.ndarray]
    colour: str
    width: float
    closed: bool


class Arrow(NamedTuple):
    start: np.ndarray
    end: np.ndarray
    label: str
    dashed: bool
    width: float


class Rings(NamedTuple):
    points: np.ndarray
    colour: str
    diameter: float


def arrow_parts(arrow: Arrow) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An arrow's parts in figure points: the shaft's end (short of the tip), the head's
    triangle and the label's centre, clear of the tip (text about 0.55 em wide per letter)."""
    a, b, width = arrow.start, arrow.end, arrow.width
    direction = (b - a) / max(float(np.linalg.norm(b - a)), 1e-12)
    normal = np.array([-direction[1], direction[0]])
    length, half = 4.5 * width, 2.2 * width
    base = b - length * direction
    head = np.array([b, base + half * normal, base - half * normal])
    half_text = np.array([0.28 * FONT_SIZE * len(arrow.label), 0.5 * FONT_SIZE])
    clearance = float(np.abs(direction) @ half_text) + 3.0
    return base, head, b + clearance * direction
