"""Strips planned in pairs, laid on the roll in pairs: a nest made, not searched for.

Strips planned to lie in pairs (:mod:`.pairing`) need no search: every pair is a column across
the roll, one strip at the bottom, the other turned by 180° (the warp stays along the roll) and
lowered onto it until they are a clearance apart; the columns follow one another along the
roll, each moved back against the one before until they are a clearance apart. Of the four
ways to turn the two strips the one with the narrowest column is taken. Nothing in it depends
on time or chance: the same outlines give the same nest, to the last bit, on every machine;
outlines are taken on a grid of 1e-9 of the roll's width first, so that patterns that differ
by round-off give the same nest too.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from .nesting import NestedPiece, RollNest, check_nest, clearance_of
from .widths import profiles

__all__ = ["pair_nest"]

#: Stations along a column where the two strips' edges are compared.
_STATIONS = 400
#: Halvings of the step when a strip is lowered onto another or a column moved back.
_BISECTIONS = 30
#: The outlines are taken on a grid of this fraction of the roll width.
_GRID = 1e-9


def _placed(points: np.ndarray, rotation: float, translation) -> np.ndarray:
    return NestedPiece(0, rotation, np.asarray(translation, dtype=float)).place(points)


def _column(first: np.ndarray, second: np.ndarray, separation: float, edge: float):
    """The narrowest column of two rings: (height, [(rotation, translation)] × 2), the first at
    the bottom (``edge`` above y = 0), both starting at x = 0."""
    from shapely.geometry import Polygon

    best = None
    for turn_first in (0.0, 180.0):
        bottom = _placed(first, turn_first, (0.0, 0.0))
        bottom = bottom - [bottom[:, 0].min(), bottom[:, 1].min() - edge]
        for turn_second in (0.0, 180.0):
            top = _placed(second, turn_second, (0.0, 0.0))
            top = top - top.min(axis=0)
            reach = min(np.ptp(bottom[:, 0]), np.ptp(top[:, 0]))
            stations = np.linspace(0.0, reach, _STATIONS)
            gap = np.max(profiles(bottom, stations)[0] - profiles(top, stations)[1])
            below = Polygon(bottom).buffer(separation)

            def overlaps(lift: float, top=top, below=below) -> bool:
                return below.intersects(Polygon(top + np.array([0.0, lift])))

            lift = gap + separation
            if overlaps(lift):  # they touch between the stations: up until clear, then back
                low, step = lift, 0.1 * separation
                while overlaps(lift):
                    low, lift, step = lift, lift + step, 2.0 * step
                for _ in range(_BISECTIONS):
                    middle = 0.5 * (low + lift)
                    low, lift = (low, middle) if not overlaps(middle) else (middle, lift)
            height = max(bottom[:, 1].max(), (top[:, 1] + lift).max())
            if best is None or height < best[0]:
                offsets = [
                    (turn_first, bottom[0] - _placed(first, turn_first, (0, 0))[0]),
                    (turn_second, top[0] + [0.0, lift] - _placed(second, turn_second, (0, 0))[0]),
                ]
                best = (height, offsets)
    return best


def pair_nest(
    outlines: Sequence[np.ndarray],
    roll_width: float,
    pairs: Sequence[tuple[int, ...]],
    *,
    net_areas: Sequence[float],
    gap: float = 0.0,
) -> RollNest | None:
    """Lay the cut outlines ``(k_i, 2)`` (warp along +x) on a roll of ``roll_width``, ``gap``
    apart (and the nesting's clearance), in columns of the ``pairs`` (index pairs, or single
    indices for a strip alone; module docs). ``None`` if a pair does not fit the roll."""
    from shapely.geometry import Polygon

    started = time.perf_counter()
    clearance = clearance_of(roll_width)
    separation = gap + clearance
    # on a grid of 1e-9 of the roll's width: outlines that differ by round-off (patterns solved
    # on several threads) make the same decisions, hence the same nest
    grid = _GRID * roll_width
    shapes = [np.round(np.asarray(o, dtype=float) / grid) * grid for o in outlines]
    placements: dict[int, NestedPiece] = {}
    placed: list = []
    end = 0.0
    for group in pairs:
        if len(group) == 2:
            column = _column(shapes[group[0]], shapes[group[1]], separation, clearance)
            height, offsets = column
        else:
            points = shapes[group[0]]
            offsets = [(0.0, [0.0, clearance] - points.min(axis=0))]
            height = np.ptp(points[:, 1]) + clearance
        if height > roll_width - clearance:
            return None
        rings = [_placed(shapes[k], r, t) for k, (r, t) in zip(group, offsets, strict=True)]
        shift = _back_against(rings, placed, end + separation, separation)
        for k, (rotation, translation) in zip(group, offsets, strict=True):
            moved = np.asarray(translation, dtype=float) + np.array([shift, 0.0])
            placements[k] = NestedPiece(k, rotation, moved)
        column_polygons = [Polygon(r + np.array([shift, 0.0])) for r in rings]
        placed += column_polygons
        end = max(end, max(p.bounds[2] for p in column_polygons))
    pieces = [placements[k] for k in sorted(placements)]
    polygons = [Polygon(p.place(shapes[p.index])) for p in pieces]
    check_nest(polygons, roll_width)
    length = max(p.bounds[2] for p in polygons)
    elapsed = time.perf_counter() - started
    return RollNest(
        roll_width, length, pieces, float(sum(net_areas)), elapsed, 0.0, 0.0, True, "pairs"
    )


def _back_against(rings: list[np.ndarray], before: list, start: float, separation: float) -> float:
    """How far along x a column of ``rings`` (starting at x = 0) goes: at ``start`` (clear of
    every piece ``before``), moved back (halving the step, never before the last column's
    start) while it keeps ``separation`` from them."""
    from shapely.geometry import Polygon

    if not before:
        return separation
    grown = [p.buffer(separation) for p in before]
    polygons = [Polygon(r) for r in rings]

    def clear(shift: float) -> bool:
        return not any(
            g.intersects(Polygon(np.asarray(p.exterior.coords) + np.array([shift, 0.0])))
            for p in polygons
            for g in grown
        )

    low = min(p.bounds[0] for p in before[-2:])
    high = start
    for _ in range(_BISECTIONS):
        middle = 0.5 * (low + high)
        low, high = (low, middle) if clear(middle) else (middle, high)
    return high
