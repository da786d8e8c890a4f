"""DXF files for the ply cutter: each ply's net and extended boundaries, its rosette and label, and
every ply nested on the roll. A spliced ply's cutter file holds its pieces, one above the other
across the warp (:func:`vares.structures.laminate_blanks.side_by_side`), each with its own
boundaries, rosette and label.

Coordinates are the mesh's, in its units (``$INSUNITS``), each ply in its pattern frame (warp
along +x). Layers:

``NET``      the net boundary (the part's edge): the pattern's boundary rings;
``TRIM``     the extended boundary (the blank as cut: the net grown by the trim allowance
             along the mould's edge; at a splice or a dart's lips butt, or by its overlap);
``ROSETTE``  at the ply's seed: a circle, the 0° arrow along the warp and the 90° arrow along
             the fill, each with its angle as text;
``LABEL``    the ply's name, orientation and areas;
``DART``     the ply's darts (darted plies only): each dart's two lips from the mouth to the tip
             and back, an open polyline;
``ROLL``     (nest only) the roll used: a rectangle from x = 0 to its length, its title.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..structures.laminate_blanks import PlyBlank, side_by_side
from ..structures.nesting import RollNest
from .dxf import INSUNITS, label_place
from .files import atomic_path

__all__ = ["PLY_LAYERS", "ply_label", "write_ply_dxf", "write_ply_nest_dxf"]

#: The layers and their colours (AutoCAD colour index).
PLY_LAYERS = {"NET": 7, "TRIM": 1, "ROSETTE": 5, "LABEL": 2, "DART": 6}


def ply_label(blank: PlyBlank, units: str) -> list[str]:
    """The lines of a ply's label: name, orientation, net area and trim allowance, and the
    number of darts when it has any."""
    lines = [
        blank.label,
        f"orientation {blank.orientation:+g} deg",
        f"net {blank.net_area:.6g} {units}2, trim +{blank.allowance:g} {units}",
    ]
    if blank.darts:
        lines.append(f"{len(blank.darts)} dart(s)")
    return lines


def _document(units: str, layers: dict[str, int]):
    import ezdxf

    if units not in INSUNITS:
        raise ValueError(f"units must be one of {', '.join(INSUNITS)}; got {units!r}")
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = INSUNITS[units]
    doc.header["$MEASUREMENT"] = 1
    for name, colour in layers.items():
        doc.layers.add(name, color=colour)
    return doc


def _arrow(space, start: np.ndarray, direction: np.ndarray, length: float, text: str) -> None:
    """An arrow from ``start`` along the unit ``direction`` with ``text`` past its tip."""
    tip = start + length * direction
    side = np.array([-direction[1], direction[0]])
    head = 0.2 * length
    layer = {"layer": "ROSETTE"}
    space.add_lwpolyline([start, tip], dxfattribs=layer)
    back, wing = tip - head * direction, 0.4 * head * side
    space.add_lwpolyline([back + wing, tip, back - wing], dxfattribs=layer)
    space.add_text(text, height=0.25 * length, dxfattribs=layer).set_placement(
        tuple(tip + 0.15 * length * direction)
    )


def _draw(space, blank: PlyBlank, place, rotation: float, label_inside: bool, units: str) -> None:
    """Draw one blank, its points moved by ``place`` and its directions turned by
    ``rotation`` degrees (a nested piece's placement)."""
    for ring in blank.net:
        space.add_lwpolyline(place(ring), close=True, dxfattribs={"layer": "NET"})
    for ring in blank.trim:
        space.add_lwpolyline(place(ring), close=True, dxfattribs={"layer": "TRIM"})
    for dart in blank.darts:
        space.add_lwpolyline(place(dart), dxfattribs={"layer": "DART"})
    low, high = blank.trim[0].min(axis=0), blank.trim[0].max(axis=0)
    size = float(np.max(high - low))
    angle = np.radians(rotation)
    turn = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    origin = place(blank.origin[None])[0]
    arrow = 0.15 * size
    space.add_circle(tuple(origin), 0.1 * arrow, dxfattribs={"layer": "ROSETTE"})
    for direction, text in ((blank.warp, "0"), (blank.fill, "90")):
        unit = turn @ (direction / np.linalg.norm(direction))
        _arrow(space, origin, unit, arrow, text)
    lines = ply_label(blank, units)
    if label_inside:
        from shapely.geometry import Polygon

        centre, height = label_place(Polygon(place(blank.net[0])), len(lines), max(map(len, lines)))
        top = centre + np.array([0.0, 0.5 * (len(lines) - 1) * 1.6 * height])
    else:  # below the blank, clear of every line
        height = 0.03 * size
        top = place(np.array([[low[0], low[1] - 2.0 * height]]))[0]
    for row, line in enumerate(lines):
        space.add_text(line, height=height, dxfattribs={"layer": "LABEL"}).set_placement(
            tuple(top - [0.0, row * 1.6 * height])
        )


def write_ply_dxf(
    path: str | Path, blank: PlyBlank | Sequence[PlyBlank], *, units: str = "mm"
) -> None:
    """Write one ply's cutter file (R2010, module docs) in its pattern frame, in mesh
    ``units``; atomically. ``blank``: the ply's blank, or the blanks of its pieces (laid out
    one above the other)."""
    blanks = [blank] if isinstance(blank, PlyBlank) else list(blank)
    doc = _document(units, PLY_LAYERS)
    for each, shift in zip(blanks, side_by_side(blanks, gap=0.4), strict=True):
        _draw(
            doc.modelspace(),
            each,
            lambda points, shift=shift: np.asarray(points) + shift,
            0.0,
            False,
            units,
        )
    with atomic_path(Path(path)) as temporary:
        doc.saveas(temporary)


def write_ply_nest_dxf(
    path: str | Path, blanks: Sequence[PlyBlank], nest: RollNest, *, units: str = "mm"
) -> None:
    """Write the plies as nested on the roll (R2010, module docs): the roll on ``ROLL``, each
    ply moved and turned as :class:`~vares.structures.nesting.NestedPiece` places it, its label
    inside its net boundary."""
    doc = _document(units, {**PLY_LAYERS, "ROLL": 8})
    space = doc.modelspace()
    width, length = nest.roll_width, nest.length
    corners = np.array([[0.0, 0.0], [length, 0.0], [length, width], [0.0, width]])
    space.add_lwpolyline(corners, close=True, dxfattribs={"layer": "ROLL"})
    title = f"roll {width:g} x {length:.6g} {units}, yield {100 * nest.yield_:.1f} %"
    space.add_text(title, height=0.04 * width, dxfattribs={"layer": "ROLL"}).set_placement(
        (0.0, 1.03 * width)
    )
    for piece in nest.pieces:
        _draw(space, blanks[piece.index], piece.place, piece.rotation, True, units)
    with atomic_path(Path(path)) as temporary:
        doc.saveas(temporary)
