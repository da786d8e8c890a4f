"""Blank outlines from DXF, and a draped blank's cutting drawing.

:func:`read_blank_outline` reads a blank's outline: the closed polyline (LWPOLYLINE or
POLYLINE) of a DXF file's model space enclosing the largest area, or the one on ``layer``; its
coordinates are taken as they are (the warp along +x). :func:`write_blank_dxf` writes the blank
flat: its outline on layer ``EXTENDED`` (the blank as cut), the trim lines on layer ``NET``
(where the part's edge falls on it after draping: trimmed there) and the warp direction from
the seed on layer ``ROSETTE``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..geometry.blank import Blank

__all__ = ["read_blank_outline", "write_blank_dxf"]


def read_blank_outline(path: str | Path, layer: str | None = None) -> np.ndarray:
    """The outline ``(k, 2)`` of a blank drawn in a DXF file (module docs).

    Raises ``FileNotFoundError`` for a missing file and ``ValueError`` for a file without a
    closed polyline (on ``layer``) or one that ezdxf cannot read.
    """
    import ezdxf

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    try:
        document = ezdxf.readfile(path)
    except (OSError, ezdxf.DXFError) as exc:
        raise ValueError(f"{path}: not a readable DXF file ({exc})") from None
    rings = []
    for entity in document.modelspace().query("LWPOLYLINE POLYLINE"):
        if layer is not None and entity.dxf.layer != layer:
            continue
        if not entity.is_closed:
            continue
        if entity.dxftype() == "LWPOLYLINE":
            points = np.array([p[:2] for p in entity.get_points("xy")], dtype=float)
        else:
            points = np.array([v.dxf.location[:2] for v in entity.vertices], dtype=float)
        if len(points) >= 3:
            rings.append(points)
    if not rings:
        where = f" on layer {layer!r}" if layer is not None else ""
        raise ValueError(f"{path} has no closed polyline{where} to cut the blank to")
    return max(rings, key=lambda ring: abs(_area(ring)))


def _area(ring: np.ndarray) -> float:
    x, y = ring[:, 0], ring[:, 1]
    return 0.5 * float(x @ np.roll(y, -1) - y @ np.roll(x, -1))


def write_blank_dxf(
    path: str | Path, blank: Blank, trim_lines: list[np.ndarray], *, units: str = "mm"
) -> None:
    """Write the flat blank's outline, trim lines and warp (module docs) in ``units``
    (the drawing's ``$INSUNITS``; coordinates as they are)."""
    import ezdxf
    from ezdxf import units as dxf_units

    document = ezdxf.new("R2010")
    document.units = {"mm": dxf_units.MM, "cm": dxf_units.CM, "m": dxf_units.M}.get(
        units, dxf_units.MM
    )
    for name, colour in (("EXTENDED", 7), ("NET", 1), ("ROSETTE", 3)):
        document.layers.add(name, color=colour)
    space = document.modelspace()
    space.add_lwpolyline(blank.outline.tolist(), close=True, dxfattribs={"layer": "EXTENDED"})
    for line in trim_lines:
        closed = len(line) > 2 and np.allclose(line[0], line[-1])
        points = line[:-1] if closed else line
        space.add_lwpolyline(points.tolist(), close=closed, dxfattribs={"layer": "NET"})
    seed = blank.coordinates[blank.seed]
    length = 0.1 * float(np.ptp(blank.outline, axis=0).max())
    tip = seed + np.array([length, 0.0])
    space.add_line(tuple(seed), tuple(tip), dxfattribs={"layer": "ROSETTE"})
    document.saveas(path)
