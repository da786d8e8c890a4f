import io

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib import colormaps
from matplotlib.colors import TwoSlopeNorm

import vares
from vares.analysis.erection_fields import CELL_FIELDS
from vares.geometry.examples import hypar
from vares.io.plot import (
    FIELD_LABELS,
    pattern_image,
    plot_convergence,
    plot_pattern,
    plot_pattern_fields,
    plot_surface,
    plot_surface_fields,
    save_pattern_figure,
)
from vares.mechanics.fields import FIELD_DESCRIPTIONS


def test_every_field_has_a_colour_bar_label():
    """Every per-cell field of a pattern and of an erection (and the erection's per-node
    deviation, drawn per cell) has a label, and nothing else does."""
    erection = set(CELL_FIELDS) | {"normal_deviation"}
    assert set(FIELD_LABELS) == set(FIELD_DESCRIPTIONS) | erection


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_pattern_figures_are_written(tmp_path, suffix):
    mesh = hypar(n=6, cell_type="quad")
    result = vares.solve(mesh, vares.materials.NeoHooke(1000.0, 0.3))
    path = tmp_path / f"det_F{suffix}"
    save_pattern_figure(
        path,
        mesh,
        result.material_coordinates,
        result.fields["det_F"],
        field="det_F",
        fibres=result.fibres,
        title="hypar",
    )
    assert path.stat().st_size > 5000
    head = path.read_bytes()[:8]
    assert head.startswith(b"\x89PNG") if suffix == ".png" else b"<?xml" in head


def _flat_hypar(n: int = 4):
    mesh = hypar(n=n)
    return mesh, vares.projection_plane(mesh).project(mesh.points)


def _centroid_pixels(fig, mesh, x) -> np.ndarray:
    """The picture's RGBA bytes at every cell's centroid ``(cells, 4)``, read off the image
    drawn in the axes by its extent (row 0 at the bottom)."""
    image = fig.axes[0].images[0]
    rgba = np.asarray(image.get_array())
    x0, x1, y0, y1 = image.get_extent()
    rows, columns = rgba.shape[:2]
    centroids = x[mesh.cells["triangle"]].mean(axis=1)
    i = ((centroids[:, 0] - x0) / (x1 - x0) * columns).astype(int)
    j = ((centroids[:, 1] - y0) / (y1 - y0) * rows).astype(int)
    return rgba[j, i]


def test_colour_scale_is_centred_on_the_neutral_value():
    """det F from 0.9 to 1.3: 1 is the colour map's middle, the ends its ends, and the colour
    bar spans the values."""
    mesh, x = _flat_hypar()
    values = np.linspace(0.9, 1.3, mesh.num_cells)
    fig = plot_pattern(mesh, x, values, field="det_F")
    shown = _centroid_pixels(fig, mesh, x)
    coolwarm = colormaps["coolwarm"]
    expected = coolwarm(TwoSlopeNorm(1.0, 0.9, 1.3)(values), bytes=True)
    assert np.array_equal(shown, expected)
    assert np.array_equal(shown[0], coolwarm(0.0, bytes=True))
    assert np.array_equal(shown[-1], coolwarm(1.0, bytes=True))
    assert fig.axes[1].get_ylim() == pytest.approx((0.9, 1.3))
    assert fig.axes[1].get_ylabel().startswith("det F")
    plt.close(fig)


def test_a_field_picture_shows_each_cells_colour_and_nothing_outside():
    """Every pixel at a cell's centroid has the colour of that cell's value (viridis over the
    values' range), the margin around the pattern is transparent, and the colours are bytes."""
    mesh, x = _flat_hypar()
    values = np.random.default_rng(1).uniform(2.0, 7.0, mesh.num_cells)
    fig = plot_pattern(mesh, x, values, field="energy")
    rgba = np.asarray(fig.axes[0].images[0].get_array())
    assert rgba.dtype == np.uint8
    low, high = values.min(), values.max()
    expected = colormaps["viridis"]((values - low) / (high - low), bytes=True)
    assert np.array_equal(_centroid_pixels(fig, mesh, x), expected)
    assert np.all(rgba[0, :] == 0) and np.all(rgba[:, -1] == 0)  # the margin: no cell
    assert fig.axes[1].get_ylabel() == "strain energy"
    plt.close(fig)


def test_a_plain_pattern_is_drawn_in_one_colour():
    mesh, x = _flat_hypar()
    fig = plot_pattern(mesh, x)
    shown = _centroid_pixels(fig, mesh, x)
    assert np.all(shown == shown[0]) and shown[0, 3] == 255
    assert len(fig.axes) == 1  # no colour bar
    plt.close(fig)


def _png(fig, dpi: float = 100) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    plt.close(fig)
    return buffer.getvalue()


def test_a_shared_cell_image_draws_the_same_pictures_as_a_fresh_one():
    """Several fields drawn from one rasterisation (as the report does) are, byte for byte, the
    pictures each draws on its own; the shared image is left as it was."""
    result = vares.solve(hypar(n=6), vares.materials.NeoHooke(1000.0, 0.3))
    mesh, x = result.mesh, result.material_coordinates
    shared = pattern_image(mesh, x, dpi=100)
    index = shared.index.copy()
    for name in ("det_F", "warp_stress", "shear_angle"):
        style = {"field": name, "fibres": result.fibres, "title": name, "stress_scale": 1000.0}
        alone = _png(plot_pattern(mesh, x, result.fields[name], dpi=100, **style))
        drawn = _png(plot_pattern(mesh, x, result.fields[name], image=shared, **style))
        assert drawn == alone
    assert np.array_equal(shared.index, index)


def test_fields_drawn_on_one_figure_are_the_pictures_drawn_one_by_one():
    """A centred and an uncentred scale, stresses and degrees, one after the other on one
    figure: each picture is, byte for byte, plot_pattern's own; the figure is closed after."""
    result = vares.solve(hypar(n=6), vares.materials.NeoHooke(1000.0, 0.3))
    mesh, x = result.mesh, result.material_coordinates
    names = ("det_F", "energy_density", "warp_stress", "shear_angle", "stress_min")
    fields = {name: result.fields[name] for name in names}
    style = {"fibres": result.fibres, "stress_scale": 1000.0, "stress_unit": "kPa"}
    shared = pattern_image(mesh, x, dpi=100)
    drawn, numbers = [], set()
    for name, fig in plot_pattern_fields(mesh, x, fields, image=shared, **style):
        drawn.append(name)
        numbers.add(fig.number)
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=100)
        assert fig.axes[0].get_title() == name
        assert fig.axes[1].get_ylabel() == FIELD_LABELS[name].replace("{stress}", "kPa")
        alone = plot_pattern(mesh, x, fields[name], field=name, title=name, dpi=100, **style)
        assert buffer.getvalue() == _png(alone)
    assert drawn == list(names) and len(numbers) == 1  # one figure
    assert not plt.fignum_exists(numbers.pop())  # closed at the end
    assert list(plot_pattern_fields(mesh, x, {})) == []


def test_surface_fields_drawn_on_one_figure_are_the_pictures_drawn_one_by_one():
    """As for patterns: views of the surface re-coloured field after field (shaded, with mesh
    lines and a centred scale after an uncentred one) are plot_surface's own, to the byte."""
    result = vares.solve(hypar(n=6), vares.materials.NeoHooke(1000.0, 0.3))
    mesh = result.mesh
    names = ("energy", "det_F", "compressed_yarns", "fill_stress")
    fields = {name: result.fields[name] for name in names}
    titles = {name: f"{name} on the design surface" for name in names}
    style = {"stress_scale": 1000.0, "stress_unit": "force/length", "dpi": 100}
    drawn, numbers = [], set()
    for name, fig in plot_surface_fields(mesh, fields, titles=titles, **style):
        drawn.append(name)
        numbers.add(fig.number)
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=100)
        assert fig.axes[0].get_title() == titles[name]
        alone = plot_surface(mesh, fields[name], field=name, title=titles[name], **style)
        assert buffer.getvalue() == _png(alone)
    assert drawn == list(names) and len(numbers) == 1
    assert not plt.fignum_exists(numbers.pop())


def test_cells_are_rasterised_at_the_resolution_the_picture_is_saved_at():
    """The cells' image is never enlarged where the picture is shown (no blocks of pixels) and
    not much finer than that (work for nothing), at the report's 100 dpi as at the files' 150."""
    mesh, x = _flat_hypar()
    values = np.linspace(0.0, 1.0, mesh.num_cells)
    for dpi in (100, 150):
        fig = plot_pattern(mesh, x, values, field="energy", dpi=dpi)
        fig.set_dpi(dpi)
        fig.canvas.draw()
        image = fig.axes[0].images[0]
        x0, x1, y0, y1 = image.get_extent()
        (a, b), (c, d) = fig.axes[0].transData.transform([[x0, y0], [x1, y1]])
        shown = max(c - a, d - b)  # the image's longer side on the canvas, pixels
        assert shown <= max(image.get_array().shape[:2]) <= 1.3 * shown
        plt.close(fig)


def test_round_off_level_fields_are_drawn_uniform():
    mesh, x = _flat_hypar()
    noise = np.random.default_rng(0).normal(size=mesh.num_cells)

    def colour_bar_range(values, **kwargs):
        fig = plot_pattern(mesh, x, values, **kwargs)
        low, high = fig.axes[1].get_ylim()
        plt.close(fig)
        return low, high

    low, high = colour_bar_range(1.0 + 1e-11 * noise, field="det_F")
    assert high - low >= 1e-6 * 0.999  # not stretched over the noise
    low, high = colour_bar_range(1e-8 * noise, field="warp_stress", stress_scale=1000.0)
    assert high - low >= 1e-3 * 0.999
    low, high = colour_bar_range(5.0 * noise, field="warp_stress", stress_scale=1000.0)
    assert high == pytest.approx(5.0 * noise.max()) and low == pytest.approx(5.0 * noise.min())


def test_convergence_plot_labels_decades_and_iterations():
    """Decades labelled 10⁻ⁿ in plain text, whole iteration numbers, fixed margins."""
    result = vares.solve(hypar(n=6), vares.materials.NeoHooke(1000.0, 0.3))
    fig = plot_convergence(result.history)
    fig.canvas.draw()
    ax = fig.axes[0]
    low, high = ax.get_ylim()
    ticks = zip(ax.get_yticks(), ax.get_yticklabels(), strict=True)
    shown = [(t, label.get_text()) for t, label in ticks if low <= t <= high]
    assert len(shown) >= 4
    digits = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")
    for value, text in shown:
        assert text.startswith("10") and "$" not in text
        assert 10.0 ** int(text[2:].translate(digits)) == pytest.approx(value)
    assert all(float(t).is_integer() for t in ax.get_xticks())
    assert fig.get_layout_engine() is None
    assert ax.get_title() == "convergence"
    plt.close(fig)
