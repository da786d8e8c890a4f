import numpy as np
import pytest

import vares
from vares.analysis.erection_fields import CELL_FIELDS
from vares.geometry.examples import hypar
from vares.io.plot import FIELD_LABELS, plot_pattern, save_pattern_figure
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


def test_colour_scale_is_centred_on_the_neutral_value():
    mesh = hypar(n=4)
    x = vares.projection_plane(mesh).project(mesh.points)
    values = np.linspace(0.9, 1.3, mesh.num_cells)
    fig = plot_pattern(mesh, x, values, field="det_F")
    norm = fig.axes[0].images[0].norm
    assert norm.vcenter == 1.0
    assert norm.vmin == pytest.approx(0.9) and norm.vmax == pytest.approx(1.3)
    assert fig.axes[1].get_ylabel().startswith("det F")


def test_round_off_level_fields_are_drawn_uniform():
    mesh = hypar(n=4)
    x = vares.projection_plane(mesh).project(mesh.points)
    noise = np.random.default_rng(0).normal(size=mesh.num_cells)
    fig = plot_pattern(mesh, x, 1.0 + 1e-11 * noise, field="det_F")
    norm = fig.axes[0].images[0].norm
    assert norm.vmax - norm.vmin >= 1e-6 * 0.999  # not stretched over the noise
    fig = plot_pattern(mesh, x, 1e-8 * noise, field="warp_stress", stress_scale=1000.0)
    norm = fig.axes[0].images[0].norm
    assert norm.vmax - norm.vmin >= 1e-3 * 0.999
    fig = plot_pattern(mesh, x, 5.0 * noise, field="warp_stress", stress_scale=1000.0)
    assert fig.axes[0].images[0].norm.vmax == pytest.approx(5.0 * noise.max())
