"""Length units: what a coordinate of 1 means, and what size is plausible for a membrane or part."""

from __future__ import annotations

__all__ = ["METRES", "PLAUSIBLE_SIZE", "implausible_size", "unit_factor"]

#: Length unit → metres per unit.
METRES = {"mm": 1e-3, "cm": 1e-2, "m": 1.0, "in": 0.0254, "ft": 0.3048}
#: Sizes (largest extent, metres) outside this range are not a membrane or a part.
PLAUSIBLE_SIZE = (1e-3, 1e3)


def implausible_size(extent: float, units: str) -> str | None:
    """A sentence with the likely fix when a surface ``extent`` (in ``units``) is too large or
    too small to be a membrane or a part, else ``None``."""
    metres = extent * METRES[units]
    low, high = PLAUSIBLE_SIZE
    if low <= metres <= high:
        return None
    fits = [u for u, scale in METRES.items() if low <= extent * scale <= high and u != units]
    # the unit that gives the most typical size (about 10 m) is the likely one
    likely = min(fits, key=lambda u: abs(_log10(extent * METRES[u]) - 1.0), default=None)
    size = f"{metres / 1000:.3g} km" if metres > high else f"{metres * 1000:.3g} mm"
    advice = f"; if the file is in {likely}, pass --units {likely}" if likely else ""
    return f"the surface is {size} across in {units}: implausible for a membrane or part{advice}"


def unit_factor(source: str, target: str) -> float:
    """How many ``target`` units one ``source`` unit is (``unit_factor("m", "mm") = 1000``)."""
    for name in (source, target):
        if name not in METRES:
            raise ValueError(f"units must be one of {', '.join(METRES)}; got {name!r}")
    return METRES[source] / METRES[target]


def _log10(value: float) -> float:
    import math

    return math.log10(value) if value > 0 else -300.0
