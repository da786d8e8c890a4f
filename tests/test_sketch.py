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
from vares.io.sketch import FACE, MESH_LINES_UP_TO, _tick_label, nice_ticks, pattern_sketch
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
    # the drawing keeps the pattern's proportions: equal scales along x and y
    placed = sketch.place(np.array([[0.0, 0.0], [4.0, 4.0]]))
    assert abs(placed[1, 0] - placed[0, 0]) == pytest.approx(abs(placed[1, 1] - placed[0, 1]))


def test_sketch_png_paints_the_pattern_and_leaves_the_hole() -> None:
    mesh, x = _square_with_hole()
    sketch = pattern_sketch(mesh, x, title="square")
    dpi = 100.0
    image = Image.open(io.BytesIO(sketch.png(dpi))).convert("RGB")
    width, height = sketch.size
    assert image.size == (round(width * dpi / 72), round(height * dpi / 72))

    def colour(point) -> tuple[int, int, int]:
        column, row = sketch.place(np.asarray(point, dtype=float)) * dpi / 72
        return image.getpixel((int(column), int(row)))

    face = tuple(int(FACE[i : i + 2], 16) for i in (1, 3, 5))
    cell = 4.0 / 9
    inside = (0.5 * cell + 0.1 * cell, 1.5 * cell + 0.2 * cell)  # inside a cell, off its lines
    assert np.abs(np.subtract(colour(inside), face)).max() <= 3
    assert colour((2.0, 2.0)) == (255, 255, 255)  # the hole
    assert colour((-0.05, 2.0)) == (255, 255, 255)  # beside the pattern, inside the axes
    assert max(colour((0.0, 2.0))) < 150  # the outline is dark


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
    for line in root.iter(f"{SVG}line"):
        if line.get("stroke-width") == "1.4":  # the arrows' shafts
            for end in ("1", "2"):
                x, y = float(line.get(f"x{end}")), float(line.get(f"y{end}"))
                assert low[0] <= x <= high[0] and low[1] <= y <= high[1]
    ticks = [t for t in sketch._ticks() if t[0] == "y"]
    _, _, _, height = sketch.axes
    assert 2 <= len(ticks) <= max(3, height / 25)
    positions = sorted(t[1] for t in ticks)
    assert min(np.diff(positions)) >= 15.0


def test_an_outline_that_cannot_be_followed_fills_every_cell(monkeypatch) -> None:
    """Where the boundary's loops cannot be followed (it passes twice through a node), the
    sketch fills the cells one by one and draws the boundary edges: the same picture."""
    from vares.geometry.mesh import MeshError

    mesh, x = _square_with_hole()
    reference = Image.open(io.BytesIO(pattern_sketch(mesh, x).png(72.0))).convert("RGB")

    def refuse(self):
        raise MeshError("the boundary passes twice through node 7")

    monkeypatch.setattr(SurfaceMesh, "boundary_loops", refuse)
    sketch = pattern_sketch(mesh, x)
    root = ET.fromstring(sketch.svg())
    filled = [p for p in root.iter(f"{SVG}path") if p.get("fill") == FACE]
    assert len(filled) == mesh.num_cells
    image = Image.open(io.BytesIO(sketch.png(72.0))).convert("RGB")
    difference = np.abs(np.asarray(image, int) - np.asarray(reference, int)).max(axis=-1)
    assert np.mean(difference > 40) < 0.01  # the same picture but for antialiasing
    assert colour_at(sketch, image, (2.0, 2.0), 72.0) == (255, 255, 255)  # the hole stays empty


def colour_at(sketch, image, point, dpi: float) -> tuple[int, int, int]:
    column, row = sketch.place(np.asarray(point, dtype=float)) * dpi / 72
    return image.getpixel((int(column), int(row)))
