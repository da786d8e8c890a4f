"""Nesting the pieces on the roll: the shortest length of fabric that holds every cut outline.

The roll runs along x, its usable width along y (``0 ≤ y ≤ roll width``); every piece keeps its
warp along the roll (patterns come with the warp along +x) and may be turned by 180° when
allowed. The layout is found by sparrow (Gardeyn & Wauters 2025, "An open-source heuristic to
reboot 2D nesting research"), a maintained strip-packing heuristic in Rust, through its Python
bindings ``spyrrow`` (MIT), which bundle it with its collision engine jagua-rs (MPL-2.0). The
result is checked independently here with shapely: no two pieces overlap, every piece lies
inside the roll.

The search is bounded by ``time_limit`` seconds and ends earlier by itself when it has stopped
improving (sparrow's early termination: a number of attempts, not a time). It runs on one
thread from ``seed``, so a search that ended by itself gives the same placements for the same
outlines every time, on any machine as fast or slower; one stopped by its time bound ends
where the time ran out, which depends on the machine's load (``RollNest.finished`` says
which).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "NestError",
    "NestedPiece",
    "RollNest",
    "check_nest",
    "clearance_of",
    "nest_pieces",
    "single_precision_step",
    "usable_width",
]

#: Clearance the nesting search keeps between pieces and to the roll's edges, relative to the
#: roll width (the search works in single precision; the clearance makes the result exact).
_CLEARANCE = 2e-5
#: Shares of the time bound given to the search's exploration and to its compression.
_EXPLORATION, _COMPRESSION = 0.5, 0.5
#: A search counts as ended by itself if it took less than the shorter phase's bound by this
#: share of it (sparrow checks its clock between moves).
_MARGIN = 0.05


class NestError(RuntimeError):
    """The nesting gave pieces that overlap or leave the roll (it never should)."""


@dataclass(frozen=True)
class NestedPiece:
    """Where a piece lies on the roll: turned by ``rotation`` degrees (0 or 180) about the
    origin of its own coordinates, then moved by ``translation`` ``(2,)``."""

    index: int
    rotation: float
    translation: np.ndarray

    def place(self, points: np.ndarray) -> np.ndarray:
        """Points ``(n, 2)`` of the piece as laid on the roll."""
        angle = np.radians(self.rotation)
        c, s = np.cos(angle), np.sin(angle)
        return np.asarray(points) @ np.array([[c, s], [-s, c]]) + self.translation


@dataclass(frozen=True)
class RollNest:
    """Pieces on one roll: their placements, the length of roll used (from x = 0 to the end of
    the last piece), the net area (the patterns inside their seam lines) and the yield, net area
    / (roll width × length); the search's bound and time and whether it ended by itself (module
    docs), and the ``method``: ``search`` or ``pairs`` (:mod:`.pair_nest`)."""

    roll_width: float
    length: float
    pieces: list[NestedPiece]
    net_area: float
    elapsed: float
    time_limit: float = 0.0
    search_time: float = 0.0
    finished: bool = False
    method: str = "search"

    @property
    def yield_(self) -> float:
        return self.net_area / (self.roll_width * self.length)

    @property
    def waste(self) -> float:
        """Fraction of the roll used that is cut away: 1 − yield."""
        return 1.0 - self.yield_


def clearance_of(roll_width: float) -> float:
    """The clearance kept between pieces and to the roll's edges on a roll of ``roll_width``."""
    return _CLEARANCE * roll_width


def usable_width(roll_width: float) -> float:
    """The widest piece a roll of ``roll_width`` takes: the search keeps its clearance and
    the pieces' separation to both edges and grows every piece by half a clearance all round
    (measured: a piece fits at the roll's width less six clearances, not five, at roll widths
    from 0.5 to 1500); eight leave a margin."""
    return roll_width * (1.0 - 8.0 * _CLEARANCE)


def single_precision_step(outlines: Sequence[np.ndarray], roll_width: float) -> float:
    """Twice the spacing of single-precision numbers at the farthest a nest of ``outlines``
    ``(k_i, 2)`` can reach along the roll (their lengths laid end to end): the search places
    pieces in single precision, so far along a long roll its pieces are that much off the
    places it checked (the form-found sail's 91 strips at 2.5 m: 2.6 km of roll, two pieces
    overlapping by 5e-5 m where the clearance is 5e-5 m)."""
    reach = roll_width + sum(float(np.ptp(np.asarray(o)[:, 0])) for o in outlines)
    return 2.0 * float(np.spacing(np.float32(reach)))


def nest_pieces(
    outlines: Sequence[np.ndarray],
    roll_width: float,
    *,
    net_areas: Sequence[float],
    allow_turn: bool = True,
    gap: float = 0.0,
    time_limit: float = 10.0,
    seed: int = 0,
) -> RollNest:
    """Lay the cut outlines ``(k_i, 2)`` (warp along +x) on a roll of ``roll_width`` (module
    docs), ``gap`` apart, searching for ``time_limit`` seconds at most (rounded to whole
    seconds, at least one) from ``seed``."""
    import spyrrow
    from shapely.geometry import Polygon

    started = time.perf_counter()
    clearance = _CLEARANCE * roll_width
    shapes = [np.asarray(o, dtype=float) for o in outlines]
    for index, shape in enumerate(shapes):
        if np.ptp(shape[:, 1]) > usable_width(roll_width):
            raise ValueError(
                f"piece {index + 1} is {np.ptp(shape[:, 1]):.6g} wide across the warp; a roll "
                f"of {roll_width:g} takes at most {usable_width(roll_width):.6g}"
            )
    config_seconds = max(1, round(time_limit))
    offsets = [shape.min(axis=0) for shape in shapes]  # sparrow likes pieces near the origin
    items = [
        spyrrow.Item(
            str(index),
            _search_shape(shape - offset, clearance),
            demand=1,
            allowed_orientations=[0.0, 180.0] if allow_turn else [0.0],
        )
        for index, (shape, offset) in enumerate(zip(shapes, offsets, strict=True))
    ]
    # pieces kept a further single-precision step apart; the strip widened by as much at
    # either edge, since the search keeps the pieces' separation to its edges too
    extra = single_precision_step(shapes, roll_width)
    instance = spyrrow.StripPackingInstance(
        "roll", strip_height=roll_width - 2 * clearance + 2 * extra, items=items
    )
    config = spyrrow.StripPackingConfig(
        early_termination=True,
        total_computation_time=None,
        exploration_time=max(1, round(_EXPLORATION * config_seconds)),
        compression_time=max(1, round(_COMPRESSION * config_seconds)),
        min_items_separation=gap + clearance + extra,
        num_workers=1,
        seed=seed,
    )
    solution, search_time, finished = _search(instance, config, config_seconds)
    pieces = []
    for placed in solution.placed_items:
        index = int(placed.id)
        rotation = float(np.round(placed.rotation)) % 360.0
        moved = NestedPiece(index, rotation, np.zeros(2))
        turned_offset = moved.place(-offsets[index][None])[0]
        translation = np.array(placed.translation, dtype=float) + turned_offset
        translation += [0.0, clearance - extra]
        pieces.append(NestedPiece(index, rotation, translation))
    pieces.sort(key=lambda p: p.index)
    placed_shapes = [Polygon(p.place(shapes[p.index])) for p in pieces]
    start = min(s.bounds[0] for s in placed_shapes)
    pieces = [NestedPiece(p.index, p.rotation, p.translation - [start, 0.0]) for p in pieces]
    placed_shapes = [Polygon(p.place(shapes[p.index])) for p in pieces]
    check_nest(placed_shapes, roll_width)
    length = max(s.bounds[2] for s in placed_shapes)
    return RollNest(
        roll_width,
        length,
        pieces,
        float(sum(net_areas)),
        time.perf_counter() - started,
        float(config_seconds),
        search_time,
        finished,
    )


def _search(instance, config, seconds: float):
    """The solution, the search's wall time and whether it ended by itself: a phase stopped by
    its bound ran for that long, so a search that took less than the shorter bound (by
    ``_MARGIN``) was stopped by neither."""
    started = time.perf_counter()
    try:
        solution = instance.solve(config)
    except BaseException as exc:  # a panic in the Rust code arrives as a BaseException
        if isinstance(exc, KeyboardInterrupt | SystemExit):
            raise
        raise NestError(f"the nesting search failed: {exc}") from None
    elapsed = time.perf_counter() - started
    shorter = min(config.exploration_time, config.compression_time).total_seconds()
    return solution, elapsed, elapsed < (1 - _MARGIN) * shorter


def _search_shape(shape: np.ndarray, clearance: float) -> list[tuple[float, float]]:
    """The outline the search works with: grown by half the clearance and simplified within a
    quarter of it (so it still covers the piece), without repeated or nearly repeated points."""
    from shapely.geometry import Polygon

    grown = Polygon(shape).buffer(0.5 * clearance, join_style="mitre").simplify(0.25 * clearance)
    if grown.geom_type != "Polygon":
        grown = max(grown.geoms, key=lambda g: g.area)
    return [tuple(p) for p in np.asarray(grown.exterior.coords)[:-1]]


def check_nest(shapes: Sequence, roll_width: float) -> None:
    """Raise :class:`NestError` if two shapely polygons overlap or touch, or one leaves the roll
    (``0 ≤ y ≤ roll_width``, ``x ≥ 0``)."""
    from shapely.strtree import STRtree

    for index, shape in enumerate(shapes):
        low_x, low_y, _, high_y = shape.bounds
        if low_y < 0 or high_y > roll_width or low_x < 0:
            raise NestError(f"nested piece {index + 1} leaves the roll ({shape.bounds})")
    tree = STRtree(list(shapes))
    for index, shape in enumerate(shapes):
        for other in tree.query(shape, predicate="intersects"):
            if other != index:
                raise NestError(f"nested pieces {index + 1} and {int(other) + 1} overlap")
