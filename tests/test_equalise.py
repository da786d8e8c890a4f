"""The search for the number of strips (vares.structures.equalise) on a model whose gap widths
are known exactly: a gap is as wide as the integral of a width density over its span."""

from types import SimpleNamespace

import numpy as np
import pytest

from vares.geometry.surface_lines import CuttingError
from vares.structures.equalise import _EQUAL, _FLOOR, NotNarrowerError, _respaced, least_count


def density_model(calls: list[int]):
    """Gap widths of spans over [0, 1] for the width density 1 + 3 s² (2 in all)."""

    def evaluate(spans):
        bounds = np.concatenate([[0.0], np.cumsum(spans)])
        widths = np.diff(bounds + bounds**3)
        calls.append(len(spans))
        return SimpleNamespace(widths=list(widths)), widths

    return evaluate


def test_respacing_into_another_number_of_gaps_equalises_a_linear_model():
    """Widths in proportion to spans within each gap: respaced into another number of gaps,
    the gaps are equally wide (the inverse of the cumulative width, piecewise linear)."""
    spans = np.array([0.1, 0.5, 0.4])
    widths = np.array([0.3, 0.5, 1.2])  # densities 3, 1, 3
    for count in (2, 4, 5, 8):
        new = _respaced(spans, widths, count, 1.0)
        assert new.sum() == pytest.approx(1.0, abs=1e-14) and np.all(new > 0)
        edges = np.concatenate([[0.0], np.cumsum(new)])
        cumulative = np.interp(edges, np.r_[0.0, np.cumsum(spans)], np.r_[0.0, np.cumsum(widths)])
        assert np.diff(cumulative) == pytest.approx(np.full(count, 2.0 / count), rel=1e-12)


@pytest.mark.parametrize("start", [3, 12])
def test_the_least_number_that_fits_is_found_and_equalised(start):
    """2 in all at a width of 0.3: 7 gaps fit (2/7), 6 cannot (2/6 = 0.333). From above and
    from below, the search ends on 7 equal gaps, spending few evaluations on the others: 6 is
    left after one (its mean is too wide), a fitting number as soon as it fits."""
    calls: list[int] = []
    plan = least_count(density_model(calls), 1.0, start, 1, 0.3, 200, False)
    assert len(plan.widths) == 7
    assert max(plan.widths) <= _EQUAL * min(plan.widths)
    assert calls.count(6) == 1
    assert plan.evaluations == len(calls) and plan.evaluations <= 12
    assert dict(plan.history)[7] == pytest.approx(max(plan.widths))


def test_no_number_up_to_the_limit_fits():
    with pytest.raises(CuttingError, match="more than 20 strips"):
        least_count(density_model([]), 1.0, 3, 1, 0.05, 20, False)


def test_gaps_that_do_not_get_narrower_are_refused_early():
    """Every gap at least 1.0 wide whatever its span (a bow that does not scale): a roll of 0.9
    fits no number of them, and the search says so once twice the gaps are not narrower,
    instead of trying numbers up to the limit."""
    calls: list[int] = []
    inner = density_model(calls)

    def bowed(spans):
        plan, widths = inner(spans)
        widths = 1.0 + 0.1 * widths
        plan.widths = list(widths)
        return plan, widths

    with pytest.raises(CuttingError, match="do not get narrower with their number"):
        least_count(bowed, 1.0, 3, 1, 0.9, 200, True)
    assert max(calls) <= 12 and len(calls) <= 8


def test_no_gap_is_squeezed_below_a_tenth_of_the_mean_span():
    """A gap whose width hardly depends on its span (a strip that bows): respacing would give
    it ever less span (the wave along y got lines 4 mm apart, and they met). Its span stops at
    a tenth of the mean, and the search refuses the strips as bowed once it is too wide there,
    instead of going on to more lines."""
    spans = np.array([0.2, 0.2, 0.2, 0.2, 0.2])
    widths = np.array([0.2, 0.2, 5.0, 0.2, 0.2])
    for count in (5, 8):
        new = _respaced(spans, widths, count, 1.0)
        assert new.sum() == pytest.approx(1.0, abs=1e-14)
        assert new.min() >= _FLOOR / count * (1 - 1e-12)
        assert np.argmin(new) == np.argmin(np.abs(np.cumsum(new) - 0.5 - new / 2))
    seen: list[np.ndarray] = []

    def bowed(spans):  # the gap over the middle is 1.2 wide however narrow its span
        seen.append(np.array(spans))
        bounds = np.concatenate([[0.0], np.cumsum(spans)])
        widths = np.array(spans, dtype=float)
        middle = np.searchsorted(bounds, 0.5, side="right") - 1
        widths[middle] = 1.2
        return SimpleNamespace(widths=list(widths)), widths

    with pytest.raises(NotNarrowerError, match="a tenth as wide as their mean spacing") as err:
        least_count(bowed, 1.0, 4, 1, 0.5, 200, False)
    assert err.value.bowed
    assert min((s / s.mean()).min() for s in seen) >= _FLOOR * (1 - 1e-12)
    assert max(len(s) for s in seen) <= 6 and len(seen) <= 16  # not on to 200 strips


def test_strips_that_cannot_be_paired_are_planned_alone():
    """With interlock auto, a plan in pairs that is refused leaves the strips alone, and the
    plan says why (a note of the cut)."""
    from vares.structures.pairing import choose_plan

    alone = SimpleNamespace(
        widths=[2.0, 2.0],
        straight_pairs=[2.0, 2.0],
        lengths=[10.0, 10.0],
        panels=[0, 1],
        compared={},
        pairs_refused="",
    )

    def planned(interlock):
        if interlock:
            raise CuttingError("strips in pairs do not get narrower with their number")
        return alone

    assert choose_plan(planned, "auto", None) is alone
    assert "do not get narrower" in alone.pairs_refused
    with pytest.raises(CuttingError):
        choose_plan(planned, "always", None)
    # planned again narrower (the patterns came out wider than the roll): alone again, and the
    # reason kept for the cut's notes
    alone.interlock = False
    again = SimpleNamespace(compared={}, pairs_refused="")
    assert choose_plan(lambda interlock: again, "auto", alone) is again
    assert "do not get narrower" in again.pairs_refused


@pytest.mark.parametrize(("even", "strips"), [(0.99, 5), (1.003, 6)])
def test_a_number_that_misses_by_the_noise_is_tried_again_from_even_spans(even, strips):
    """Five gaps miss a roll of 1.0 by 0.4 % from the lines of six respaced (widths jump with the
    mesh): they are tried once more from evenly spaced lines, and taken where those fit."""
    calls: list[tuple[int, bool]] = []

    def scripted(spans):
        is_even = bool(np.allclose(spans, spans.mean(), rtol=1e-9))
        calls.append((len(spans), is_even))
        if len(spans) == 6:
            widths = np.array([0.85, 0.9, 0.95, 0.9, 0.85, 0.9])
        elif len(spans) == 5:  # the widest 0.4 % too wide, the mean within the roll
            widths = np.full(5, even) if is_even else np.array([1.004, 0.99, 0.99, 0.99, 0.99])
        else:
            widths = np.full(len(spans), 1.3)
        return SimpleNamespace(widths=list(widths)), widths

    plan = least_count(scripted, 1.0, 6, 1, 1.0, 200, False)
    assert len(plan.widths) == strips
    assert (5, False) in calls and (5, True) in calls  # the respaced start, then the even one
    assert plan.evaluations == len(calls)


def test_a_miss_whose_mean_is_too_wide_is_not_tried_again():
    """Every layout of five gaps 0.4 % too wide on average: no other start can fit them."""
    calls: list[int] = []

    def scripted(spans):
        calls.append(len(spans))
        widths = np.full(len(spans), 1.004 if len(spans) == 5 else 0.8)
        return SimpleNamespace(widths=list(widths)), widths

    plan = least_count(scripted, 1.0, 6, 1, 1.0, 200, False)
    assert len(plan.widths) == 6 and calls.count(5) == 1


def test_gaps_equal_but_for_the_noise_start_the_next_number_evenly():
    """Widths within 3 % of each other are noise (a surface of revolution's strips): the next
    number starts from even spans, where lines fall on the mesh's own meridians; beyond that
    the cumulative width is inverted."""
    spans = np.array([0.3, 0.3, 0.4])
    even = _respaced(spans, np.array([1.0, 1.02, 0.995]), 4, 1.0)
    assert even == pytest.approx(np.full(4, 0.25), abs=1e-15)
    uneven = _respaced(spans, np.array([1.0, 1.2, 0.9]), 4, 1.0)
    assert not np.allclose(uneven, 0.25, atol=1e-3)


def test_a_miss_from_even_spans_is_not_started_evenly_again():
    """Five gaps started from even spans (six were equally wide) miss by 0.4 %: the second
    start would repeat the first, so it is not made."""
    calls: list[int] = []

    def scripted(spans):
        calls.append(len(spans))
        if len(spans) == 5:
            widths = np.array([1.004, 0.99, 0.99, 0.99, 0.99])
        else:
            widths = np.full(len(spans), 0.85)
        return SimpleNamespace(widths=list(widths)), widths

    plan = least_count(scripted, 1.0, 6, 1, 1.0, 200, False)
    assert len(plan.widths) == 6 and calls.count(5) == 6  # its own six evaluations, no more


def test_a_surface_that_fits_one_strip_is_one_strip():
    """A roll wider than the whole surface (2 in all at 2.5): one gap, found at once; there is
    no fewer to try again (the parameter span a plain float, as a user's family gives it)."""
    calls: list[int] = []
    plan = least_count(density_model(calls), 1.0, 1, 1, 2.5, 200, False)
    assert calls == [1] and max(plan.widths) == pytest.approx(2.0)
    assert plan.history == [(1, pytest.approx(2.0))]
