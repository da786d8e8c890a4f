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
    rgba = np.asarray(fig.axes[0].images[0].get_array())
    assert fig.axes[1].get_ylabel() == "strain energy"  # the colour bar
    plt.close(fig)
    image = rasterise(mesh.cells, *view.project(mesh.points))  # the same drawing's cells
    shown = image.index >= 0
    assert set(np.unique(image.index[shown])) == set(range(mesh.num_cells))
    assert np.all(rgba[~shown, 3] == 0) and np.all(rgba[shown, 3] == 1)
    expected = colormaps["viridis"](values)[image.index[shown], :3]  # energy: 0 … 1, viridis
    ratio = rgba[shown, :3] / expected
    assert np.all(ratio >= 0.55 - 1e-12) and np.all(ratio <= 1 + 1e-12)
    assert np.ptp(ratio, axis=1).max() < 1e-12  # one shade per pixel: the colour's own hue


def test_a_drawing_no_pixel_centre_falls_in_is_empty_not_an_error():
    sliver = np.array([[0.0, 0.0], [1000.0, 0.0], [500.0, 1e-4]])
    image = rasterise({"triangle": np.array([[0, 1, 2]])}, sliver)
    assert np.all(image.index == -1)
    assert image.lookup(np.array([3.0])).mask.all()
