"""Rings in the pattern plane (vares/geometry/outline.py): the signed area of a ring, and the
region inside a pattern's seam rings grown by one allowance (a DXF's cut line, a ply's extended
boundary)."""

import numpy as np
import pytest

from vares.geometry.outline import cut_outline, ring_area


def square(side: float, centre=(0.0, 0.0)) -> np.ndarray:
    h = 0.5 * side
    return np.array([[-h, -h], [h, -h], [h, h], [-h, h]]) + centre


def test_ring_area_is_signed_by_orientation():
    ring = square(2.0)
    assert ring_area(ring) == 4.0
    assert ring_area(ring[::-1]) == -4.0
    triangle = np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 2.0]])
    assert ring_area(triangle) == 3.0


@pytest.mark.parametrize("flip", [False, True])
def test_a_square_with_a_hole_grows_by_the_allowance(flip):
    """A square's mitred corners stay square: the outline is the square widened by the
    allowance on every side, the hole narrowed by it; the outline turns counter-clockwise, the
    hole clockwise, whichever way the rings were given and whichever comes first."""
    outer, hole = square(4.0), square(2.0)
    rings = [hole, outer[::-1]] if flip else [outer, hole[::-1]]
    grown = cut_outline(rings, 0.25)
    assert len(grown) == 2
    assert ring_area(grown[0]) == pytest.approx(4.5**2, rel=1e-12)
    assert ring_area(grown[1]) == pytest.approx(-(1.5**2), rel=1e-12)
    assert np.abs(grown[0]).max() == pytest.approx(2.25, rel=1e-12)


def test_no_allowance_keeps_the_rings():
    outer, hole = square(4.0), square(2.0)
    grown = cut_outline([outer, hole], 0.0)
    assert ring_area(grown[0]) == pytest.approx(16.0, rel=1e-12)
    assert ring_area(grown[1]) == pytest.approx(-4.0, rel=1e-12)
    assert {tuple(p) for p in grown[0]} == {tuple(p) for p in outer}


def test_a_hole_closed_by_the_allowance_is_gone():
    grown = cut_outline([square(4.0), square(0.4)], 0.25)
    assert len(grown) == 1
    assert ring_area(grown[0]) == pytest.approx(4.5**2, rel=1e-12)


def test_a_sharp_corner_is_mitred_at_most_four_allowances_out():
    """A thin spike's mitre would reach far beyond its tip: it is cut at four allowances."""
    spike = np.array([[0.0, 0.0], [10.0, 0.5], [0.0, 1.0]])
    grown = cut_outline([spike], 0.1)[0]
    assert grown[:, 0].max() <= 10.0 + 4 * 0.1 + 1e-9
    assert grown[:, 0].max() > 10.0 + 0.1
