"""How many strips, and where their lines go: the least number of gaps between cutting lines
whose widths, equalised, fit the roll (:func:`vares.structures.layout.plan_strips`).

A number of gaps is evaluated (lines placed, the surface cut, the strips flattened and measured)
and its lines moved until the gaps are equally wide: each span is scaled by (mean width / its
width)^0.7 (damped: widths jump with the mesh), ``_EQUALISE`` evaluations at most. While the
number is searched for, one stops as soon as its widest strip fits the roll (then one fewer is
tried) or its mean gap width shows that none will (``_HOPELESS``: the gaps' widths add up to
about the same whatever their spans; then as many more as the mean is too wide); the next
number starts from the last one's lines, respaced into parts of equal estimated width (from
evenly spaced lines where the last one's gaps were as wide as each other but for the mesh's
noise, ``_EVEN``). No gap is
given less than a tenth of the mean span (``_FLOOR``): one still too wide there bows, and the
strips are refused as not getting narrower with their number (:func:`_bowing`). The
number taken, the least that fits, is then equalised in full (to ``_EQUAL``, or the budget);
if one fewer missed the roll by less than the widths' noise (``_NOISE``) with its mean gap
within the roll, it is tried again from evenly spaced lines first, and taken if it fits.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..geometry.surface_lines import CuttingError
from .strip_plan import StripPlan

__all__ = ["NoFitError", "NotNarrowerError", "least_count"]

#: Equalising evaluations per number of gaps, and the width ratio that is equal enough.
_EQUALISE, _EQUAL = 6, 1.005
#: A number of gaps whose mean gap width exceeds the roll width by this factor is not equalised
#: further (module docs).
_HOPELESS = 1.02
#: Gaps whose widths differ by less than this factor are equally wide but for the mesh's noise
#: (the widths jump by 1-4 % from one layout to the next, measured on the coarse designs and
#: the tent): the next number of gaps starts from evenly spaced lines, not from theirs respaced.
_EVEN = 1.03
#: A number of gaps whose widest strip misses the roll by less than this factor (about how much
#: the widths jump with the mesh from one layout to the next) is tried again from even spans.
_NOISE = 1.01
#: Twice the gaps (or more) and still this fraction of their mean width: more will not fit.
_NARROWER = 0.8
#: No gap is respaced narrower than this fraction of the mean span of its number of gaps. A gap
#: that is still too wide at that span bows (its width does not come from its span): more lines
#: will not make it fit. Without the floor, compas-FoFin's wave along y at a 0.5 m roll got
#: lines 4 mm apart (spans 0.025 of their mean) where its strips bow, and snapping their
#: crossings onto the mesh's nodes joined them ("cutting lines 30 and 31 meet").
_FLOOR = 0.1


class NoFitError(CuttingError):
    """No number of strips fits the roll (they do not get narrower with their number, or more
    than the most strips allowed would be needed)."""


class NotNarrowerError(NoFitError):
    """Strips that do not get narrower with their number; ``mean`` is the mean gap width of the
    most gaps tried; ``bowed`` whether a gap was too wide at the least span a gap may have."""

    def __init__(self, message: str, mean: float, bowed: bool = False) -> None:
        super().__init__(message)
        self.mean, self.bowed = mean, bowed


#: A layout of gaps of the given parameter spans, and the width of each gap.
Evaluate = Callable[[np.ndarray], tuple[StripPlan, np.ndarray]]


class _Count:
    """The layouts tried for one number of gaps: the best (the narrowest widest strip), its
    spans and gap widths, the spans it started from, the evaluations spent and whether they
    were equalised to ``_EQUAL``."""

    def __init__(self) -> None:
        self.plan: StripPlan | None = None
        self.spans = self.widths = self.following = self.start = np.zeros(0)
        self.evaluations, self.equal = 0, False
        self.bowed: float | None = None  # the width of a gap too wide at the least span

    @property
    def widest(self) -> float:
        return max(self.plan.widths)

    def equalise(
        self, evaluate: Evaluate, spans: np.ndarray, total: float, width: float, polish: bool
    ) -> None:
        """Move the lines from ``spans`` until the gaps are equally wide, or (unless ``polish``)
        until the widest strip fits ``width`` or the gaps' mean width shows that none will
        (``_HOPELESS``); at most ``_EQUALISE`` evaluations for this number of gaps in all."""
        self.following = spans
        if not self.evaluations:
            self.start = spans
        while self.evaluations < _EQUALISE and not self.equal:
            spans = self.following
            candidate, widths = evaluate(spans)
            self.evaluations += 1
            widest = int(np.argmax(widths))
            if widths[widest] > width and spans[widest] <= (1 + 1e-9) * _floor(total, len(spans)):
                self.bowed = float(widths[widest])
            if self.plan is None or widths.max() < self.widest:
                self.plan, self.spans, self.widths = candidate, spans, widths
            if widths.max() <= _EQUAL * widths.min():
                self.equal = True
                break
            self.following = _respaced(spans, widths, len(spans), total, damping=0.7)
            if not polish and (
                self.widest <= width or widths.mean() > _HOPELESS * width or self.bowed
            ):
                break


def _floor(total: float, count: int) -> float:
    """The least span of a gap among ``count`` over ``total`` (:data:`_FLOOR`)."""
    return _FLOOR * total / count


def _floored(spans: np.ndarray, total: float) -> np.ndarray:
    """``spans`` (adding up to ``total``) with none below :func:`_floor`: the shortfall taken
    from the others in proportion to what they have above it."""
    spans = np.array(spans, dtype=float)
    low = _floor(total, len(spans))
    for _ in range(len(spans)):
        short = spans < low
        if not short.any():
            break
        need = float(np.sum(low - spans[short]))
        spans[short] = low
        above = np.where(short, 0.0, spans - low)
        spans -= need * above / above.sum()
    return spans


def _respaced(
    spans: np.ndarray, widths: np.ndarray, count: int, total: float, damping: float = 1.0
) -> np.ndarray:
    """New spans from the ``widths`` measured for ``spans``. For as many gaps, each span is
    scaled by (mean width / its width) ^ ``damping`` (widths jump with the mesh). For another
    ``count``, the spans of equal width if the width grew evenly within each measured gap: the
    cumulative width inverted at ``count`` equal parts; even spans where the gaps were equally
    wide to the widths' noise (``_EVEN``). An empty gap counts as a narrow one."""
    widths = np.maximum(widths, 0.1 * widths.max())
    if count != len(spans) and widths.max() <= _EVEN * widths.min():
        return np.full(count, total / count)  # equal to the noise: as wide per span everywhere
    if count == len(spans):
        scaled = spans * (widths.mean() / widths) ** damping
        return _floored(scaled * (total / scaled.sum()), total)
    cumulative = np.concatenate([[0.0], np.cumsum(widths)])
    bounds = np.interp(
        np.linspace(0.0, cumulative[-1], count + 1), cumulative, np.r_[0.0, np.cumsum(spans)]
    )
    return _floored(np.diff(bounds) * (total / bounds[-1]), total)


def _not_narrower(
    what: str, width: float, interlock: bool, mean: float, bowed: bool = False
) -> NotNarrowerError:
    """The refusal of strips that do not get narrower with their number: ``what`` was measured
    (strips at most ``width`` wide), and what to try instead."""
    kind = "strips in pairs" if interlock else "strips"
    advice = (
        "plan them one after the other (interlock never)"
        if interlock
        else "their flattened strips bow; try another strip direction or layout"
    )
    return NotNarrowerError(
        f"{kind} do not get narrower with their number: {what} (strips at most {width:g} "
        f"wide): {advice}",
        mean,
        bowed,
    )


def _bowing(trial: _Count, width: float, interlock: bool) -> None:
    """Raise if a gap of ``trial`` was too wide for ``width`` at the least span a gap may have
    (:data:`_FLOOR`): its strips bow, and more lines will not make them fit."""
    if trial.bowed is not None:
        raise _not_narrower(
            f"of {len(trial.spans)} gaps between cutting lines, one a tenth as wide as their "
            f"mean spacing still leaves a strip {trial.bowed:.4g} wide",
            width, interlock, float(trial.widths.mean()), bowed=True,
        )  # fmt: skip


def _narrowing(tried: dict[int, _Count], count: int, width: float, interlock: bool) -> None:
    """Raise if the gaps do not get narrower with their number: ``count`` gaps, too wide for
    ``width``, at least ``_NARROWER`` × as wide on average as half as many or fewer were (gaps
    as wide as their spans would be half as wide). Strips whose width does not come from their
    span (strips in pairs whose flattened seams bow more than the roll is wide) fit no roll by
    more of them."""
    mean = tried[count].widths.mean()
    for fewer, trial in tried.items():
        if 2 * fewer <= count and trial.widest > width and mean > _NARROWER * trial.widths.mean():
            raise _not_narrower(
                f"{fewer} gaps between cutting lines are {trial.widths.mean():.4g} wide on "
                f"average, {count} gaps {mean:.4g}",
                width, interlock, mean,
            )  # fmt: skip


def least_count(
    evaluate: Evaluate,
    total: float,
    count: int,
    smallest: int,
    width: float,
    max_strips: int,
    interlock: bool,
) -> StripPlan:
    """The plan of the least number of gaps (at least ``smallest``) whose equalised widths fit
    ``width``, from a first estimate ``count`` (module docs); ``total`` is the family's
    parameter span, ``interlock`` only words the error when no number up to ``max_strips``
    fits."""
    tried: dict[int, _Count] = {}
    spans = np.full(count, total / count)
    while count not in tried:
        if count > max_strips:
            raise NoFitError(f"more than {max_strips} strips would be needed")
        tried[count] = trial = _Count()
        trial.equalise(evaluate, spans, total, width, polish=False)
        fits = trial.widest <= width
        if fits and count - 1 >= smallest and count - 1 not in tried:
            following = count - 1
        elif fits:
            break
        else:  # as many more as the mean gap is too wide (then back down, one at a time)
            _bowing(trial, width, interlock)
            _narrowing(tried, count, width, interlock)
            following = max(count + 1, math.ceil(count * trial.widths.mean() / width))
        spans = _respaced(trial.spans, trial.widths, following, total)
        count = following
    best = min((c for c, t in tried.items() if t.widest <= width), default=None)
    if best is None:
        fit = "two side by side, each about half of it" if interlock else "one"
        raise NoFitError(
            f"no layout of up to {max(tried)} strips fits the roll width {width:g} ({fit})"
        )
    spent = sum(t.evaluations for t in tried.values())
    fewer = tried.get(best - 1)  # None where one gap fits (no fewer) or fewer were not tried
    even = None if fewer is None else np.full(best - 1, total / (best - 1))
    if (  # a miss by the widths' noise, where the mean width would fit, not from even spans
        fewer is not None
        and fewer.widest <= _NOISE * width
        and fewer.widths.mean() <= width
        and not np.allclose(fewer.start, even, rtol=1e-12, atol=0.0)
    ):
        again = _Count()  # another start: lines evenly spaced
        again.equalise(evaluate, even, total, width, False)
        spent += again.evaluations
        if again.widest < fewer.widest:
            tried[best - 1] = again
        if again.widest <= width:
            best = best - 1
    taken = tried[best]
    before = taken.evaluations
    taken.equalise(evaluate, taken.following, total, width, polish=True)
    plan = taken.plan
    plan.evaluations = spent + taken.evaluations - before
    plan.history = [(c, t.widest) for c, t in tried.items()]
    return plan
