"""Biaxial test records and their load cycles.

A record is what a biaxial test machine exports for one specimen: time, the warp and fill force
per width and the warp and fill strain, sample by sample, and optionally the load stage each
sample belongs to. Files are read into records by :func:`vares.io.biaxial.read_biaxial`; the
generator of :mod:`vares.materials.biaxial_model` makes them from a known fabric model.

A *stage* is a stretch of the record at one load ratio (MSAJ/M-02: 1:1, 2:1, 1:2, 1:0, 0:1); a
*cycle* runs from a trough of the load to the next one through one peak. Cycles are found from
the force signal (:func:`find_cycles`); stages from the record's stage column or, without one,
by grouping consecutive cycles of the same load ratio.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

__all__ = ["BiaxialRecord", "Cycle", "NotInRecord", "RecordError", "find_cycles", "ratio_label"]


class RecordError(ValueError):
    """A record cannot be evaluated as asked (no cycles, no hold at the prestress, …)."""


class NotInRecord(RecordError):
    """A record lacks what was asked of it (two load ratios for a fit, a hold at the
    prestress for compensation values); other records may have it."""


@dataclass(frozen=True)
class BiaxialRecord:
    """One specimen's biaxial test, in vares' units.

    ``time`` ``(n,)`` in s, increasing; ``force`` ``(n, 2)`` warp and fill force per width in
    kN/m; ``strain`` ``(n, 2)`` warp and fill strain in mm/mm (engineering strain from the
    length the machine zeroed its extensometers at); ``stage`` ``(n,)`` integer stage numbers
    from the file, or None when the file has none. ``name`` names the specimen, ``source``
    where the record comes from (a file path, or the generator and its parameters).
    """

    time: np.ndarray
    force: np.ndarray
    strain: np.ndarray
    stage: np.ndarray | None = None
    name: str = "specimen"
    source: str = ""
    metadata: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        time = np.asarray(self.time, dtype=float)
        force = np.asarray(self.force, dtype=float)
        strain = np.asarray(self.strain, dtype=float)
        n = len(time)
        if time.ndim != 1 or force.shape != (n, 2) or strain.shape != (n, 2):
            raise RecordError(
                f"{self.name}: time (n,), force (n, 2) and strain (n, 2) must have one row per "
                f"sample; got {time.shape}, {force.shape}, {strain.shape}"
            )
        if n < 3:
            raise RecordError(f"{self.name}: a record needs at least 3 samples; got {n}")
        if not (np.isfinite(time).all() and np.isfinite(force).all() and np.isfinite(strain).all()):
            raise RecordError(f"{self.name}: time, force and strain must be finite")
        if np.any(np.diff(time) <= 0):
            i = int(np.argmax(np.diff(time) <= 0)) + 1
            raise RecordError(f"{self.name}: time must increase (sample {i + 1})")
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "force", force)
        object.__setattr__(self, "strain", strain)
        if self.stage is not None:
            stage = np.asarray(self.stage)
            if stage.shape != (n,):
                raise RecordError(f"{self.name}: stage must have one entry per sample")
            object.__setattr__(self, "stage", stage.astype(int))

    @property
    def samples(self) -> int:
        return len(self.time)


@dataclass(frozen=True)
class Cycle:
    """One load cycle: sample indices of its start (trough), the end of its loading branch
    (first sample at the peak load), its peak and its end (the next trough).

    ``stage`` numbers the stage (from the file's column, or 1, 2, … in order when found from the
    force signal), ``number`` the cycle within its stage (1-based), ``ratio`` the warp:fill force
    at the peak, normalised to a largest component of 1 (shape ``(2,)``).
    """

    stage: int
    number: int
    start: int
    loaded: int
    peak: int
    end: int
    ratio: tuple[float, float]

    @property
    def label(self) -> str:
        return ratio_label(self.ratio)


def ratio_label(ratio: tuple[float, float] | np.ndarray) -> str:
    """``"2:1"``-style label of a warp:fill ratio (either part below 5 % of the other is 0)."""
    warp, fill = (max(float(r), 0.0) for r in ratio)
    top = max(warp, fill)
    if top <= 0:
        return "0:0"
    warp, fill = warp / top, fill / top
    if fill < 0.05:
        return "1:0"
    if warp < 0.05:
        return "0:1"
    if warp >= fill:
        return f"{_short(warp / fill)}:1"
    return f"1:{_short(fill / warp)}"


def _short(value: float) -> str:
    rounded = round(value, 1)
    return f"{rounded:g}"


def find_cycles(record: BiaxialRecord, prominence: float = 0.2) -> list[Cycle]:
    """The load cycles of a record, in order.

    Peaks are maxima of the total force (warp + fill) that rise above the troughs on both sides
    by at least ``prominence`` × the record's force range (so noise and holds make no cycles);
    the trough between two peaks is the lowest total force between them. A record with a stage
    column has its cycles found stage by stage; without one, consecutive cycles whose load
    ratio differs by less than 10° (as an angle of the warp:fill force at the peak) make one
    stage.

    Raises :class:`RecordError` when the record has no cycle.
    """
    from scipy.signal import find_peaks

    total = record.force.sum(axis=1)
    span = float(np.ptp(total))
    if span <= 0:
        raise RecordError(f"{record.name}: the force never changes: no load cycles")
    if record.stage is not None:
        parts = _runs(record.stage)
    else:
        parts = [(0, record.samples)]
    cycles: list[Cycle] = []
    for first, stop in parts:
        segment = total[first:stop]
        peaks, _ = find_peaks(segment, prominence=prominence * span)
        if len(peaks) == 0:
            continue
        troughs = [int(np.argmin(segment[: peaks[0] + 1]))]
        for a, b in itertools.pairwise(peaks):
            troughs.append(int(a + np.argmin(segment[a : b + 1])))
        troughs.append(int(peaks[-1] + np.argmin(segment[peaks[-1] :])))
        stage = int(record.stage[first]) if record.stage is not None else 0
        for k, peak in enumerate(peaks):
            start, end = first + troughs[k], first + troughs[k + 1]
            peak = first + int(peak)
            tolerance = 0.005 * (total[peak] - total[start])
            loaded = start + int(np.argmax(total[start : peak + 1] >= total[peak] - tolerance))
            top = float(np.max(np.abs(record.force[peak])))
            ratio = (float(record.force[peak, 0] / top), float(record.force[peak, 1] / top))
            cycles.append(Cycle(stage, 0, start, loaded, peak, end, ratio))
    if not cycles:
        raise RecordError(f"{record.name}: no load cycle found in the force signal")
    if record.stage is None:
        cycles = _group_by_ratio(cycles)
    return _numbered(cycles)


def _runs(stage: np.ndarray) -> list[tuple[int, int]]:
    """``(first, stop)`` of each run of equal stage numbers."""
    edges = np.flatnonzero(np.diff(stage) != 0) + 1
    bounds = np.concatenate([[0], edges, [len(stage)]])
    return [(int(a), int(b)) for a, b in itertools.pairwise(bounds)]


def _group_by_ratio(cycles: list[Cycle]) -> list[Cycle]:
    out: list[Cycle] = []
    stage, previous = 0, None
    for cycle in cycles:
        angle = float(np.degrees(np.arctan2(cycle.ratio[1], cycle.ratio[0])))
        if previous is None or abs(angle - previous) > 10.0:
            stage += 1
        previous = angle
        out.append(Cycle(stage, 0, cycle.start, cycle.loaded, cycle.peak, cycle.end, cycle.ratio))
    return out


def _numbered(cycles: list[Cycle]) -> list[Cycle]:
    out: list[Cycle] = []
    count: dict[int, int] = {}
    for c in cycles:
        count[c.stage] = count.get(c.stage, 0) + 1
        out.append(Cycle(c.stage, count[c.stage], c.start, c.loaded, c.peak, c.end, c.ratio))
    return out
