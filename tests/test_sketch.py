"""The run's preview drawn without matplotlib (io/sketch.py): ticks, the SVG's content, the PNG's
pixels, and a `vares pattern` that never imports matplotlib."""

from __future__ import annotations

import io
import math
import subprocess
import sys
import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from PIL import Image

from vares.geometry.examples import grid_cells
from vares.geometry.mesh import SurfaceMesh
from vares.io.sketch import (
    FACE,
    MESH_LINES_UP_TO,
    Sketch,
    _frame,
    _tick_label,
    nice_ticks,
    pattern_sketch,
)
from vares.materials import Fibres

SVG = "{http://www.w3.org/2000/svg}"


@pytest.mark.parametrize(
    ("low", "high"),
    [(-5.2, 5.4), (0.0, 1.0), (1e6, 1e6 + 3.0), (-1e-7, 2e-7), (0.013, 0.0131), (-80.0, -2.0)],
)
def test_nice_ticks_are_round_and_inside(low: float, high: float) -> None:
    ticks = nice_ticks(low, high)
    assert 2 <= len(ticks) <= 8
    assert ticks.min() >= low - 1e-9 * abs(high - low) and ticks.max() <= high + 1e-9 * abs(high)
    step = float(ticks[1] - ticks[0])
    np.testing.assert_allclose(np.diff(ticks), step, rtol=1e-9)
    mantissa = step / 10 ** math.floor(math.log10(step))
    assert min(abs(mantissa - m) for m in (1, 2, 2.5, 5, 10)) < 1e-9
    np.testing.assert_allclose(ticks / step, np.round(ticks / step), atol=1e-6)


def test_nice_ticks_of_the_roof_are_matplotlibs() -> None:
    np.testing.assert_allclose(nice_ticks(-5.2, 5.4), [-4, -2, 0, 2, 4])
    assert [_tick_label(v, 2.0) for v in (-4.0, 0.0, 2.0)] == ["\u22124", "0", "2"]
    assert [_tick_label(v, 0.25) for v in (0.25, 0.5)] == ["0.25", "0.50"]
    assert _tick_label(3e-7, 1e-7) == "0.0000003"
    assert _tick_label(2.5, 2.5) == "2.5"


def _square_with_hole(n: int = 9) -> tuple[SurfaceMesh, np.ndarray]:
    """A flat 4 × 4 square of n × n quads split into triangles, the middle cells left out."""
    s = np.linspace(0.0, 4.0, n + 1)
    x, y = np.meshgrid(s, s, indexing="xy")
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    cells = grid_cells(n + 1, n + 1, "triangle")["triangle"]
    centres = points[cells].mean(axis=1)
    keep = np.max(np.abs(centres[:, :2] - 2.0), axis=1) > 0.9
    with warnings.catch_warnings():  # the nodes of the hole's middle are dropped
        warnings.simplefilter("ignore", UserWarning)
        mesh = SurfaceMesh(points, {"triangle": cells[keep]}, drop_unused_nodes=True)
    return mesh, mesh.points[:, :2]


def test_sketch_svg_holds_the_outline_the_mesh_lines_and_labels() -> None:
    mesh, x = _square_with_hole()
    sketch = pattern_sketch(
        mesh, x, fibres=Fibres.from_angles(30.0), title="sq & hole", marks=x[:3]
    )
    root = ET.fromstring(sketch.svg())
    paths = root.findall(f".//{SVG}path")
    fill = next(p for p in paths if p.get("fill") == FACE)
    assert fill.get("d").count("M") == 2  # the outer loop and the hole
    mesh_lines = next(p for p in paths if p.get("stroke") == "#5b7a99")
    assert mesh_lines.get("d").count("M") == len(mesh.edges())
    outline = next(p for p in paths if p.get("stroke") == "#000000" and p.get("fill") == "none")
    assert outline.get("d").count("M") == 2
    texts = [t.text for t in root.iter(f"{SVG}text")]
    assert {"sq & hole", "warp", "fill"} <= set(texts)
    assert len(root.findall(f".//{SVG}circle")) == 3
    # the data limits fill the axes box exactly, and hold the pattern with equal scales
    x0, x1, y0, y1 = sketch.limits
    left, top, width, height = sketch.axes
    np.testing.assert_allclose(
        sketch.place(np.array([[x0, y1], [x1, y0]])), [[left, top], [left + width, top + height]]
    )
    assert x0 < 0.0 < 4.0 < x1 and y0 < 0.0 < 4.0 < y1
    assert (x1 - x0) / width == pytest.approx((y1 - y0) / height)


def test_sketch_png_paints_the_pattern_and_leaves_the_hole() -> None:
    mesh, x = _square_with_hole()
    sketch = pattern_sketch(mesh, x, title="square")
    dpi = 100.0
    image = Image.open(io.BytesIO(sketch.png(dpi))).convert("RGB")
    width, height = sketch.size
    assert image.size == (round(width * dpi / 72), round(height * dpi / 72))

    def colour(point) -> tuple[int, int, int]:
        return _colour(sketch, image, point, dpi)

    face = tuple(int(FACE[i : i + 2], 16) for i in (1, 3, 5))
    cell = 4.0 / 9
    inside = (0.5 * cell + 0.1 * cell, 1.5 * cell + 0.2 * cell)  # inside a cell, off its lines
    assert np.abs(np.subtract(colour(inside), face)).max() <= 3
    assert colour((2.0, 2.0)) == (255, 255, 255)  # the hole
    assert colour((-0.05, 2.0)) == (255, 255, 255)  # beside the pattern, inside the axes
    column, row = (sketch.place(np.array([0.0, 2.0])) * dpi / 72).astype(int)
    around = np.asarray(image)[row - 1 : row + 2, column - 1 : column + 2]
    assert around.max(axis=-1).min() < 200  # the outline: darker than the fill (217+) and paper


def test_sketch_of_a_fine_mesh_draws_no_mesh_lines() -> None:
    n = 60
    s = np.linspace(0.0, 1.0, n + 1)
    x, y = np.meshgrid(s, s, indexing="xy")
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    mesh = SurfaceMesh(points, grid_cells(n + 1, n + 1, "triangle"))
    assert mesh.num_cells > MESH_LINES_UP_TO
    svg = pattern_sketch(mesh, points[:, :2]).svg()
    assert "#5b7a99" not in svg


def test_pattern_command_does_not_import_matplotlib(tmp_path) -> None:
    """The default run writes its previews without matplotlib (0.8 s of a small job)."""
    code = (
        "import sys\n"
        "from vares.app.cli.main import app\n"
        "try:\n"
        f"    app(['example', 'cylinder160', '-o', {str(tmp_path / 'out')!r}, '-q'])\n"
        "except SystemExit as e:\n"
        "    assert not e.code, e.code\n"
        "print('matplotlib' in sys.modules)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "False"
    png = Image.open(tmp_path / "out" / "pattern.png")
    assert png.size[0] > 500
    ET.parse(tmp_path / "out" / "pattern.svg")


def test_a_long_strip_keeps_its_arrows_inside_and_its_ticks_apart() -> None:
    """A strip 20 × 2 (as a cut job's): the fibre arrows end inside the strip's box, and the
    short axis carries no more tick labels than fit: 10-point labels 15 points apart or more."""
    n_u, n_v = 41, 5
    u, v = np.meshgrid(np.linspace(-10.0, 10.0, n_u), np.linspace(-1.0, 1.0, n_v))
    points = np.column_stack([u.ravel(), v.ravel(), np.zeros(u.size)])
    mesh = SurfaceMesh(points, grid_cells(n_u, n_v, "triangle"))
    sketch = pattern_sketch(mesh, points[:, :2], fibres=Fibres.from_angles(0.0))
    root = ET.fromstring(sketch.svg())
    low, high = sketch.place(np.array([[-10.0, 1.0], [10.0, -1.0]]))
    shafts = [line for line in root.iter(f"{SVG}line") if line.get("stroke-width") == "1.4"]
    assert len(shafts) == 2  # warp and fill
    for line in shafts:
        for end in ("1", "2"):
            x, y = float(line.get(f"x{end}")), float(line.get(f"y{end}"))
            assert low[0] <= x <= high[0] and low[1] <= y <= high[1]
    ticks = [t for t in sketch._ticks() if t[0] == "y"]
    assert len(ticks) >= 2
    positions = sorted(t[1] for t in ticks)
    assert min(np.diff(positions)) >= 15.0


def test_a_pattern_that_laps_over_itself_is_filled_where_it_laps(tmp_path) -> None:
    """A strip wound 420° (a helix seen from above): its outline crosses itself, and the PNG
    fills the 60° where it laps over itself, as the SVG's non-zero rule does (an even-odd
    polygon fill left it white)."""
    angles, radii = np.radians(np.linspace(0.0, 420.0, 85)), np.array([1.0, 1.5])
    a, r = np.meshgrid(angles, radii)
    points = np.column_stack([(r * np.cos(a)).ravel(), (r * np.sin(a)).ravel(), 0.1 * a.ravel()])
    mesh = SurfaceMesh(points, grid_cells(len(angles), len(radii), "triangle"))
    limits, size = _frame(points[:, :2])
    sketch = Sketch(limits, size)
    sketch.cells(mesh, points[:, :2], FACE)  # the fill alone: no mesh lines over it
    assert 'fill-rule="nonzero"' in sketch.svg()
    dpi = 100.0
    image = Image.open(io.BytesIO(sketch.png(dpi))).convert("RGB")
    face = np.array([int(FACE[i : i + 2], 16) for i in (1, 3, 5)])
    for degrees in (20.0, 40.0, 200.0):  # lapped twice, twice, once
        point = 1.25 * np.array([np.cos(np.radians(degrees)), np.sin(np.radians(degrees))])
        assert np.abs(np.subtract(_colour(sketch, image, point, dpi), face)).max() <= 3
    assert _colour(sketch, image, (0.0, 0.0), dpi) == (255, 255, 255)  # the middle: no cloth


def _colour(sketch, image, point, dpi: float) -> tuple[int, int, int]:
    column, row = sketch.place(np.asarray(point, dtype=float)) * dpi / 72
    return image.getpixel((int(column), int(row)))
