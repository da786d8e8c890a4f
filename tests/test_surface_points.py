"""Points on a triangle mesh (vares/geometry/surface_points.py): barycentric coordinates and
distances, also where a triangle has no plane (a kinematic net's cell sheared flat)."""

import warnings

import numpy as np
import pytest

from vares.geometry.surface_points import barycentric

TRIANGLE = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]])


def test_coordinates_and_distance_of_a_point_off_the_plane():
    lam, height = barycentric(np.array([0.5, 0.5, 0.3]), TRIANGLE)
    assert lam == pytest.approx([0.5, 0.25, 0.25], abs=1e-15)
    assert height == pytest.approx(0.3, abs=1e-15)
    lam, height = barycentric(np.array([3.0, 1.0, -1.0]), TRIANGLE[[0, 2, 1]])
    assert lam == pytest.approx([-1.0, 0.5, 1.5], abs=1e-15) and height == pytest.approx(1.0)


@pytest.mark.parametrize(
    "flat",
    [
        np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 2.0, 0.0]]),  # corners on one line
        np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 0.0]]),  # on one point
    ],
)
def test_a_triangle_without_area_holds_no_point(flat):
    """Without a plane there are no coordinates: −inf (and the distance +inf), computed
    without a division by zero, and the triangle that does hold the point is the one a search
    by the least coordinate picks, wherever the flat one stands among the candidates."""
    point = np.array([[0.5, 0.5, 0.0]])
    corners = np.stack([flat, TRIANGLE, flat])[None]  # (1 point, 3 candidates, 3, 3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lam, height = barycentric(point[:, None, :], corners)
    assert lam.shape == (1, 3, 3) and height.shape == (1, 3)
    assert np.all(lam[0, [0, 2]] == -np.inf) and np.all(height[0, [0, 2]] == np.inf)
    assert lam[0, 1] == pytest.approx([0.5, 0.25, 0.25], abs=1e-15) and height[0, 1] == 0.0
    assert int(np.argmax(lam.min(axis=-1), axis=1)[0]) == 1
