import matplotlib.pyplot as plt
import numpy as np
import pytest

from vares.geometry.examples import hypar
from vares.io.plot import plot_surface
from vares.io.raster import View, rasterise


def _square(z: float, x0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    points = np.array([[x0, 0, z], [x0 + 1, 0, z], [x0 + 1, 1, z], [x0, 1, z]], dtype=float)
    return points, np.array([[0, 1, 2], [0, 2, 3]])


def test_every_cell_covers_its_share_of_pixels():
    """A pixel shows the cell its centre lies in: each cell's pixel count times a pixel's area
    is the cell's area to within its perimeter's row of pixels."""
    mesh = hypar(n=8)
    xy = mesh.points[:, :2]
    image = rasterise(mesh.cells, xy, pixels=800)
    h = image.pixel
    counts = np.bincount(image.index[image.index >= 0], minlength=mesh.num_cells)
    a, b, c = np.moveaxis(xy[mesh.cells["triangle"]], 1, 0)
    areas = 0.5 * np.abs((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
    perimeter = 3.5 * np.sqrt(2 * areas)  # at most: a right triangle's legs and hypotenuse
    assert np.all(np.abs(counts * h**2 - areas) <= perimeter * h)
    assert counts.sum() * h**2 == pytest.approx(areas.sum(), rel=4 * h / np.sqrt(areas.sum()))
    assert np.all(image.index[0] == -1) and np.all(image.index[:, 0] == -1)  # the margin


def test_the_nearer_cell_hides_the_farther_in_either_order():
    near, cells = _square(1.0)
    far, _ = _square(0.0, x0=0.5)
    for first, second in ((near, far), (far, near)):
        points = np.vstack([first, second])
        top = View(elevation=90.0, azimuth=-90.0)  # looking down: screen = (x, y)
        screen, depth = top.project(points)
        assert np.allclose(screen, points[:, :2]) and np.allclose(depth, -points[:, 2])
        image = rasterise({"triangle": np.vstack([cells, cells + 4])}, screen, depth, pixels=200)
        x0 = image.extent[0]
        columns = x0 + (np.arange(image.index.shape[1]) + 0.5) * image.pixel
        overlap = image.index[:, (columns > 0.55) & (columns < 0.95)]
        overlap = overlap[overlap >= 0]
        near_cells = {0, 1} if first is near else {2, 3}
        assert overlap.size > 1000 and set(np.unique(overlap)) <= near_cells


def test_lines_behind_a_cell_are_not_seen():
    points, cells = _square(1.0)
    image = rasterise({"triangle": cells}, points[:, :2], -points[:, 2], pixels=100)
    inside = np.array([[0.5, 0.5], [0.3, 0.6]])
    assert np.all(image.seen(inside, np.array([-1.0, -1.5])))  # on the cell and in front of it
    assert not np.any(image.seen(inside, np.array([0.0, 2.0])))  # behind it
    assert np.all(image.seen(np.array([[3.0, 3.0]]), np.array([5.0])))  # off the image


def test_surface_view_draws_the_cells_it_sees():
    """A hypar seen from above: every cell shows, and every pixel has its cell's colour from the
    colour map, shaded by how squarely the cell faces the viewer (between 0.55 and 1 of it)."""
    from matplotlib import colormaps

    mesh = hypar(n=10)
    values = np.linspace(0.0, 1.0, mesh.num_cells)
    view = View(elevation=89.0)
    fig = plot_surface(mesh, values, field="energy", view=view)
    drawn = fig.axes[0].images[0]
    rgba = np.asarray(drawn.get_array())
    assert rgba.dtype == np.uint8
    assert fig.axes[1].get_ylabel() == "strain energy"  # the colour bar
    plt.close(fig)
    screen, depth = view.project(mesh.points)
    x0, x1, _, _ = drawn.get_extent()
    pixels = round(np.ptp(screen, axis=0).max() * rgba.shape[1] / (x1 - x0))
    image = rasterise(mesh.cells, screen, depth, pixels=pixels)  # the same drawing's cells
    assert image.index.shape == rgba.shape[:2]
    assert image.extent == pytest.approx(drawn.get_extent())
    shown = image.index >= 0
    assert set(np.unique(image.index[shown])) == set(range(mesh.num_cells))
    assert np.all(rgba[~shown] == 0) and np.all(rgba[shown, 3] == 255)
    expected = 255 * colormaps["viridis"](values)[image.index[shown], :3]  # energy: viridis
    colour = rgba[shown, :3].astype(float)
    shade = np.sum(colour * expected, axis=1) / np.sum(expected * expected, axis=1)
    assert np.all(shade >= 0.55 - 0.01) and np.all(shade <= 1 + 0.01)
    # one shade per pixel: the colour's own hue, to a byte's rounding
    assert np.abs(colour - shade[:, None] * expected).max() <= 1.0


def test_cell_colours_fill_their_pixels_and_leave_the_rest_transparent():
    """Two triangles of a unit square, one red, one blue (bytes or floats): a pixel inside each
    has its colour, of the same type, and the margin around them is transparent."""
    points, cells = _square(0.0)
    image = rasterise({"triangle": cells}, points[:, :2], pixels=50)
    x0, _, y0, _ = image.extent

    def at(x: float, y: float) -> tuple[int, int]:
        return int((y - y0) / image.pixel), int((x - x0) / image.pixel)

    below, above = at(0.8, 0.2), at(0.2, 0.8)  # under the diagonal (0, 2) and over it
    for colours in (
        np.array([[255, 0, 0, 255], [0, 0, 255, 255]], dtype=np.uint8),
        np.array([[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.5]]),
    ):
        rgba = image.colours(colours)
        assert rgba.dtype == colours.dtype and rgba.shape == (*image.index.shape, 4)
        assert np.array_equal(rgba[below], colours[0]) and np.array_equal(rgba[above], colours[1])
        assert np.all(rgba[image.index < 0] == 0) and np.all(rgba[0] == 0)
        assert np.array_equal(rgba[image.index >= 0], colours[image.index[image.index >= 0]])


def test_a_drawing_no_pixel_centre_falls_in_is_empty_not_an_error():
    sliver = np.array([[0.0, 0.0], [1000.0, 0.0], [500.0, 1e-4]])
    image = rasterise({"triangle": np.array([[0, 1, 2]])}, sliver)
    assert np.all(image.index == -1)
    assert image.lookup(np.array([3.0])).mask.all()
    assert not image.colours(np.array([[9, 9, 9, 255]], dtype=np.uint8)).any()
