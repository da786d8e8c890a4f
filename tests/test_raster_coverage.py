"""The pixels a preview's cells cover (``raster.covered``) are those of the index image: the
same pixels, for meshes drawn at the picture's own pixels, as array arithmetic and compiled."""

import numpy as np
import pytest

from vares._jit import sized_for
from vares.geometry.examples import four_point_sail, hypar
from vares.io.raster import _fill, covered, rasterise


def _index_image(cells, points, grid, compiled: bool) -> np.ndarray:
    with sized_for(compiled):
        return rasterise(cells, points, grid=grid).index


@pytest.mark.parametrize("seed", range(6))
def test_covered_pixels_are_the_index_images(seed):
    """Random triangles and quads, slivers, cells off the picture and of no area: the same
    pixels as the index image, by runs (small meshes) and by the compiled fill."""
    rng = np.random.default_rng(seed)
    points = rng.uniform(-20, 80, (60, 2))  # the picture wider than the cells
    points[:5] = points[5]  # cells of no area
    points[10:14] = points[14] + rng.normal(0, 1e-3, (4, 2))  # slivers
    triangles = rng.integers(0, 60, (40, 3))
    quads = rng.integers(0, 60, (12, 4))
    cells = {"triangle": triangles, "quad": quads}
    grid = (0.0, 0.0, 1.0, 97, 83)
    for compiled in (False, True):
        with sized_for(compiled):
            mask = covered(cells, points, grid)
        assert mask.shape == (83, 97) and mask.dtype == bool
        assert np.array_equal(mask, _index_image(cells, points, grid, compiled) >= 0)
    assert np.array_equal(mask, _index_image(cells, points, grid, not compiled) >= 0)
    assert 0 < mask.sum() < mask.size


def test_a_pattern_at_preview_size_covers_the_same_pixels():
    """A sail's and a roof's patterns at 975 × 960 pixels (a preview's size): the same pixels
    as the index image, whose fill the compiled loop checks pixel by pixel."""
    for mesh in (four_point_sail(n=16), hypar(n=20)):
        xy = mesh.points[:, :2]
        xy = (xy - xy.min(axis=0)) / np.ptp(xy, axis=0).max() * 900 + 30.3
        grid = (0.0, 0.0, 1.0, 975, 960)
        mask = covered(mesh.cells, xy, grid)
        assert np.array_equal(mask, _index_image(mesh.cells, xy, grid, True) >= 0)
        assert mask.sum() > 0.5 * 900 * 900 * 0.5


def test_the_compiled_fill_is_what_the_runs_reproduce():
    """The reference the tests compare against is the compiled loop itself (not its numpy
    form): one triangle, each pixel centre tested."""
    index = np.full((10, 10), -1, dtype=np.int64)
    depth = np.full((10, 10), np.inf)
    px, py = np.array([0.2, 9.7, 0.2]), np.array([0.2, 0.2, 9.7])
    _fill(px, py, np.zeros(3), np.array([[0, 1, 2]]), np.array([0]), index, depth)
    grid = (0.0, 0.0, 1.0, 10, 10)
    with sized_for(False):
        mask = covered({"triangle": np.array([[0, 1, 2]])}, np.column_stack([px, py]), grid)
    assert np.array_equal(mask, index >= 0) and mask.sum() == 45
