"""Units of length: the mesh's and the cutter drawing's."""

from __future__ import annotations

__all__ = ["UNITS", "unit_factor"]

#: Length units: name → (metres per unit, DXF $INSUNITS code).
UNITS = {"mm": (1e-3, 4), "cm": (1e-2, 5), "m": (1.0, 6)}


def unit_factor(source: str, target: str) -> float:
    """How many ``target`` units one ``source`` unit is (e.g. ``unit_factor("m", "mm") = 1000``)."""
    for name in (source, target):
        if name not in UNITS:
            raise ValueError(f"units must be one of {', '.join(UNITS)}; got {name!r}")
    return UNITS[source][0] / UNITS[target][0]
