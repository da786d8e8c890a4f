"""Nesting the pieces on the roll: the shortest length of fabric that holds every cut outline.

The roll runs along x, its usable width along y (``0 ≤ y ≤ roll width``); every piece keeps its
warp along the roll (patterns come with the warp along +x) and may be turned by 180° when
allowed. The layout is found by sparrow (Gardeyn & Wauters 2025, "An open-source heuristic to
reboot 2D nesting research"), a maintained strip-packing heuristic in Rust, through its Python
bindings ``spyrrow`` (MIT), which bundle it with its collision engine jagua-rs (MPL-2.0). The
result is checked independently here with shapely: no two pieces overlap, every piece lies
inside the roll.

The search runs in a process of its own (``_nest_search.py``), on one thread from ``seed``;
sparrow ends each of its two phases by itself when it stops improving (its early termination
counts failed attempts, not time): the exploration within half of ``time_limit`` seconds at
most, the compression within the rest. A search that ended by itself, its exploration before its
share of the time was up and its compression before the bound, gives the same placements for
the same outlines every time, on any machine (``RollNest.finished``). At the bound the process
is stopped and the shortest nest the search had reported is taken: where the time ran out
depends on the machine and its load.
"""

from __future__ import annotations

import json
import math
import os
import queue
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

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
#: Share of the time bound the exploration may take at most; the compression may take the rest
#: (at the default 10 s, the form-found sail's 44 strips at 2.5 m nest in 2,574.7 m of roll so,
#: 2,577.3 m with the whole bound for the exploration, docs/cutting.md).
_EXPLORATION = 0.5
#: Failed attempts in a row after which sparrow's exploration ends by itself (its early
#: termination, ``DEFAULT_MAX_CONSEQ_FAILS_EXPL``; checked by tests/test_cutting.py).
_FAILED_ATTEMPTS = 10
#: The search's own process (module docs).
_WORKER = Path(__file__).with_name("_nest_search.py")


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
    docs), the ``method``: ``search`` or ``pairs`` (:mod:`.pair_nest`), and the search's seed
    (``None`` without a search)."""

    roll_width: float
    length: float
    pieces: list[NestedPiece]
    net_area: float
    elapsed: float
    time_limit: float = 0.0
    search_time: float = 0.0
    finished: bool = False
    method: str = "search"
    seed: int | None = None

    @property
    def yield_(self) -> float:
        return self.net_area / (self.roll_width * self.length)

    @property
    def waste(self) -> float:
        """Fraction of the roll used that is cut away: 1 − yield."""
        return 1.0 - self.yield_

    @property
    def how(self) -> str:
        """How the nest was made, in a few words (reports)."""
        if self.method != "search":
            return f"laid in {self.method}, no search: the same nest on every machine"
        if self.finished:
            return (
                f"the search ended by itself in {self.search_time:.1f} s: the same nest for the "
                "same input"
            )
        return self.stopped

    @property
    def stopped(self) -> str | None:
        """What a nest the time bound stopped the search for means (``None`` for one the
        search ended by itself, and for one made without a search)."""
        if self.method != "search" or self.finished:
            return None
        return (
            f"the nesting search was stopped by its time bound ({self.time_limit:g} s): a "
            "longer one (nest_time) may nest shorter, and another run may nest otherwise"
        )


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
    docs), ``gap`` apart, searching for ``time_limit`` seconds at most from ``seed`` (the
    search's first nest is waited for, however long it takes)."""
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
    if not time_limit > 0:
        raise ValueError(f"the nesting search's time bound must be positive; got {time_limit}")
    offsets = [shape.min(axis=0) for shape in shapes]  # sparrow likes pieces near the origin
    # pieces kept a further single-precision step apart; the strip widened by as much at
    # either edge, since the search keeps the pieces' separation to its edges too
    extra = single_precision_step(shapes, roll_width)
    spec = {
        "shapes": [_search_shape(s - o, clearance) for s, o in zip(shapes, offsets, strict=True)],
        "orientations": [0.0, 180.0] if allow_turn else [0.0],
        "height": roll_width - 2 * clearance + 2 * extra,
        "separation": gap + clearance + extra,
        "seed": int(seed),
        # sparrow's phase bounds are whole seconds; the compression's never ends it before the
        # bound stops the search
        "exploration_seconds": max(1, round(_EXPLORATION * time_limit)),
        "compression_seconds": math.ceil(time_limit),
        "failed_attempts": _FAILED_ATTEMPTS,
    }
    placed, search_time, finished = _search(spec, time_limit)
    pieces = []
    for index, angle, *position in placed:
        rotation = float(np.round(angle)) % 360.0
        moved = NestedPiece(index, rotation, np.zeros(2))
        turned_offset = moved.place(-offsets[index][None])[0]
        translation = np.array(position, dtype=float) + turned_offset
        translation += [0.0, clearance - extra]
        pieces.append(NestedPiece(index, rotation, translation))
    pieces.sort(key=lambda p: p.index)
    if [p.index for p in pieces] != list(range(len(shapes))):
        raise NestError("the nesting search did not place every piece once")
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
        float(time_limit),
        search_time,
        finished,
        seed=int(seed),
    )


def _search(spec: dict, seconds: float) -> tuple[list, float, bool]:
    """The search's placements ``[index, rotation, x, y]``, its wall time and whether it ended
    by itself: run in its own process (module docs), stopped ``seconds`` after it started,
    once it has reported a nest; then the shortest nest it reported is taken. Where no Python
    process can be started (an application that embeds Python, whose executable is not an
    interpreter, and has not told :mod:`multiprocessing` where one is), the same search runs in
    a thread of this process: the same nest, but at the bound it is left to run out its own
    clocks (at most one and a half times the bound) in the background."""
    started = time.perf_counter()
    records: queue.Queue = queue.Queue()
    errors: list[str] = []
    interpreter = _interpreter()
    if interpreter is None:
        from ._nest_search import run

        threading.Thread(target=_in_thread, args=(run, spec, records), daemon=True).start()
        return _search_result(records, started, seconds, errors)
    try:
        process = subprocess.Popen(
            # -P: this package's folder not first on the search's module path (its modules
            # would hide the standard library's of the same name)
            [interpreter, "-P", str(_WORKER)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
    except OSError as exc:
        raise NestError(f"the nesting search could not start ({interpreter}): {exc}") from None

    def read(stream, searched: bool) -> None:
        """The search's records from its stdout (``searched``), anything else into ``errors``."""
        for line in stream:
            try:
                record = json.loads(line) if searched else None
            except ValueError:  # not the search's: a word for the error message
                record = None
            if record is None:
                errors.append(line)
            else:
                records.put(record)
        if searched:
            records.put(None)

    readers = [
        threading.Thread(target=read, args=(process.stdout, True), daemon=True),
        threading.Thread(target=read, args=(process.stderr, False), daemon=True),
    ]
    try:
        for reader in readers:
            reader.start()
        try:
            process.stdin.write(json.dumps(spec))
            process.stdin.close()
        except BrokenPipeError:  # the process ended at once: its last word is read below
            pass

        def ended() -> int:  # the process's exit status, its stderr read to the end
            status = process.wait()
            readers[1].join(5.0)
            return status

        return _search_result(records, started, seconds, errors, ended)
    finally:
        if process.poll() is None:
            process.kill()
        process.wait()
        for reader in readers:
            reader.join(1.0)
        for stream in (process.stdin, process.stdout, process.stderr):
            stream.close()


def _interpreter() -> str | None:
    """The Python interpreter to run the search with: this one, or where its executable is an
    application embedding Python, the one it told :mod:`multiprocessing` of; ``None`` where
    neither is a Python interpreter."""
    from multiprocessing import spawn

    for executable in (sys.executable, spawn.get_executable()):
        if executable and Path(os.fsdecode(executable)).name.lower().startswith("python"):
            return os.fsdecode(executable)
    return None


def _in_thread(run, spec: dict, records: queue.Queue) -> None:
    """:func:`._nest_search.run` in a thread, its records into ``records``, ``None`` last."""
    try:
        run(spec, records.put)
    except BaseException as exc:  # reported to the caller, which waits on the records
        records.put({"kind": "error", "message": str(exc) or type(exc).__name__})
    records.put(None)


def _search_result(
    records: queue.Queue,
    started: float,
    seconds: float,
    errors: list[str],
    ended: Callable[[], int] | None = None,
) -> tuple[list, float, bool]:
    """:func:`_search`'s result from the search's records (``None`` after the last), read
    until the search's own end or ``seconds`` after ``started`` once it has a nest; ``errors``:
    what the search's process wrote to stderr, ``ended()`` its exit status once it has ended."""
    best, finished = None, False
    while True:
        left = started + seconds - time.perf_counter()
        try:
            record = records.get(timeout=max(left, 0.0) if best is not None else None)
        except queue.Empty:  # the bound: the search has a nest, take its shortest
            break
        if record is None:  # the search ended without its own result: it failed
            best = None
            break
        if record["kind"] == "error":
            raise NestError(f"the nesting search failed: {record['message']}")
        if best is None or record["width"] <= best["width"] or record["kind"] == "final":
            best = record
        if record["kind"] == "final":
            finished = record["explored"]
            break
    elapsed = time.perf_counter() - started
    if best is None:
        status = "" if ended is None else f" (exit status {ended()})"
        message = "".join(errors).strip().splitlines()
        raise NestError(
            "the nesting search ended without its result"
            + (f": {message[-1]}" if message else status)
        )
    return best["placed"], elapsed, finished


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
