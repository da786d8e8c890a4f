"""The shipped double-dome mould: a valid surface of the stated size and symmetry, meshed with
irregular triangles, whose kinematic drape exceeds a 50° locking angle (docs/composites.md,
"The double dome")."""

from __future__ import annotations

import numpy as np
import pytest

from vares.analysis.drape import drape_ply
from vares.geometry.double_dome import double_dome, double_dome_height
from vares.geometry.drape_net import kinematic_net
from vares.geometry.examples import EXAMPLES

LOCKING = 50.0


@pytest.fixture(scope="module")
def mould():
    return double_dome()


def surface_area(radius=70.0, height=60.0, spacing=110.0, blend=12.0, flange=30.0, n=2001):
    """The area of the mould's surface by the midpoint rule on a fine plan grid: the integral
    of sqrt(1 + |grad z|²) over the elliptic outline, the gradient by central differences."""
    a, b = spacing / 2 + radius + flange, radius + flange
    x = np.linspace(-a, a, n)
    y = np.linspace(-b, b, n)
    h = x[1] - x[0], y[1] - y[0]
    xm, ym = np.meshgrid(0.5 * (x[1:] + x[:-1]), 0.5 * (y[1:] + y[:-1]), indexing="xy")
    step = 1e-4

    def z(u, v):
        return double_dome_height(u, v, radius, height, spacing, blend)

    zx = (z(xm + step, ym) - z(xm - step, ym)) / (2 * step)
    zy = (z(xm, ym + step) - z(xm, ym - step)) / (2 * step)
    inside = (xm / a) ** 2 + (ym / b) ** 2 < 1.0
    return float(np.sum(np.sqrt(1.0 + zx**2 + zy**2)[inside]) * h[0] * h[1])


def test_the_height_is_symmetric_and_has_the_stated_size():
    rng = np.random.default_rng(3)
    x, y = rng.uniform(-160, 160, 500), rng.uniform(-110, 110, 500)
    z = double_dome_height(x, y)
    assert np.allclose(z, double_dome_height(-x, y), atol=1e-12)
    assert np.allclose(z, double_dome_height(x, -y), atol=1e-12)
    # the tops are at the domes' centres, 60 mm high, the saddle between them lower; the
    # flange (beyond 70 mm of both centres, less the blend) is flat
    top = double_dome_height(np.array([55.0]), np.array([0.0]))[0]
    saddle = double_dome_height(np.array([0.0]), np.array([0.0]))[0]
    assert 0.97 * 60.0 < top <= 60.0
    assert 0.1 * top < saddle < 0.3 * top
    assert np.all(double_dome_height(np.array([0.0, 130.0]), np.array([75.0, 0.0])) == 0.0)


def test_the_mesh_is_a_valid_irregular_surface_of_the_stated_extents(mould):
    points, triangles = mould.points, mould.cells["triangle"]
    assert 2000 < mould.num_cells < 6000  # a few thousand cells
    # the outline is the ellipse of half-lengths 155 mm and 100 mm, on the flange (z = 0)
    (loop,) = mould.boundary_loops()
    outline = points[loop]
    assert np.allclose((outline[:, 0] / 155.0) ** 2 + (outline[:, 1] / 100.0) ** 2, 1.0)
    assert np.all(outline[:, 2] == 0.0)
    assert np.ptp(points[:, 0]) == pytest.approx(310.0, abs=0.1)
    assert np.ptp(points[:, 1]) == pytest.approx(200.0, abs=0.1)
    assert 58.0 < points[:, 2].max() <= 60.0 and points[:, 2].min() == 0.0
    # every node on the surface z = h(x, y), facing up
    assert np.allclose(points[:, 2], double_dome_height(points[:, 0], points[:, 1]))
    corners = points[triangles]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    assert np.all(normals[:, 2] > 0)
    # its area is the surface's (the chords cut the curved parts a little short)
    assert mould.area == pytest.approx(surface_area(), rel=5e-3)
    assert mould.area < surface_area()
    # irregular triangles of about the asked size (5 mm: no two nodes nearer), none a sliver
    edges = np.linalg.norm(np.diff(points[mould.edges()], axis=1)[:, 0], axis=1)
    assert edges.min() > 0.7 * 5.0 and 5.0 < np.mean(edges) < 2 * 5.0
    assert np.std(edges) / np.mean(edges) > 0.1
    sides = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2)
    cosines = (sides**2 + np.roll(sides, 1, axis=1) ** 2 - np.roll(sides, 2, axis=1) ** 2) / (
        2 * sides * np.roll(sides, 1, axis=1)
    )
    assert np.degrees(np.arccos(np.clip(cosines, -1, 1))).min() > 10.0
    # the area is shared out evenly between the four quadrants (the mirror symmetry)
    centres = corners.mean(axis=1)
    areas = mould.cell_areas()
    quarters = [
        areas[(np.sign(centres[:, 0]) == sx) & (np.sign(centres[:, 1]) == sy)].sum()
        for sx in (1, -1)
        for sy in (1, -1)
    ]
    assert np.ptp(quarters) < 0.01 * mould.area / 4


def test_the_mesh_is_reproducible_and_registered():
    one = double_dome(cell_size=8.0, seed=2)
    assert np.array_equal(one.points, double_dome(cell_size=8.0, seed=2).points)
    assert one.num_points != double_dome(cell_size=8.0, seed=3).num_points or not np.array_equal(
        one.points, double_dome(cell_size=8.0, seed=3).points
    )
    assert EXAMPLES["double-dome"] is double_dome


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"cell_type": "quad"}, "irregular triangles only"),
        ({"spacing": 150.0}, "spacing must lie in"),
        ({"height": 0.0}, "height must be positive"),
        ({"flange": 5.0}, "wider than two cells"),
        ({"cell_size": 20.0, "flange": 50.0}, "cell_size must lie in"),
    ],
)
def test_bad_dimensions_are_refused(settings, message):
    with pytest.raises(ValueError, match=message):
        double_dome(**settings)


#: The saddle's centre, on both planes of symmetry: the seed of a symmetric drape.
CENTRE = (0.0, 0.0, float(double_dome_height(np.zeros(1), np.zeros(1))[0]))


def test_the_kinematic_drape_exceeds_the_locking_angle_on_all_four_walls(mould):
    ply = drape_ply(mould, seed=CENTRE, warp=(1.0, 0.0, 0.0), spacing=2.0)
    shear = np.abs(ply.drape.shear_angle)
    # 58.1° and 4.9 % as measured (docs/composites.md); the net's largest shear moves by up to
    # 1.6° with the seed moved by 0.1 mm (the net resolves the mesh's facets, whose curvature
    # is lumped at the nodes), its area beyond 50° by about a quarter of a percent of the part
    assert ply.producibility.max_shear > 55.0
    assert 0.02 < ply.producibility.fractions["limit"] < 0.1
    # each of the four symmetric dome walls (quadrants) is sheared to near or beyond 50°
    centres = mould.points[mould.cells["triangle"]].mean(axis=1)
    for sx in (1, -1):
        for sy in (1, -1):
            quadrant = (np.sign(centres[:, 0]) == sx) & (np.sign(centres[:, 1]) == sy)
            assert np.nanmax(shear[quadrant]) > 0.9 * LOCKING


def node(net, i, j):
    """The net's node ``(i, j)``, NaN off its grid."""
    nu, nv = net.faces.shape
    return net.positions[i, j] if 0 <= i < nu and 0 <= j < nv else np.full(3, np.nan)


def test_the_net_is_continuous_in_its_seed(mould):
    # seeds 0.1 mm (1/20 of the spacing) beside the saddle's centre, across the sides of the
    # face the centre lies in: the generator yarns move with the seed (measured: at most
    # 0.50 mm over their first 118 mm; with the yarns traced from the seed's face along its
    # plane they jumped by 6–8 mm, and the largest shear from 57.1° to 70.3°)
    reference = kinematic_net(mould, CENTRE, (1.0, 0.0, 0.0), 2.0)
    si, sj = reference.seed
    largest = [np.nanmax(np.abs(reference.cell_shear))]
    for dx, dy in ((0.1, 0.0), (-0.1, 0.0), (0.0, 0.1), (0.0, -0.1)):
        seed = np.add(CENTRE, (dx, dy, 0.0))
        net = kinematic_net(mould, seed, (1.0, 0.0, 0.0), 2.0)
        ti, tj = net.seed
        moves = []
        for k in range(1, 60):
            pairs = [((si + k, sj), (ti + k, tj)), ((si - k, sj), (ti - k, tj))]
            pairs += [((si, sj + k), (ti, tj + k)), ((si, sj - k), (ti, tj - k))]
            for a, b in pairs:
                p, q = node(reference, *a), node(net, *b)
                if np.isfinite(p).all() and np.isfinite(q).all():
                    moves.append(np.linalg.norm(p - q))
        assert len(moves) > 150 and max(moves) < 1.0
        largest.append(np.nanmax(np.abs(net.cell_shear)))
    # measured: 58.09°, 58.31°, 57.91°, 57.32°, 58.85°
    assert np.ptp(largest) < 2.0


def test_the_drape_command_drapes_the_shipped_part(tmp_path, mould):
    import json

    from conftest import run

    from vares.io.meshes import read_mesh, write_surface

    surface = tmp_path / "double-dome.obj"
    write_surface(surface, mould)
    out = tmp_path / "out"
    seed_flag = ",".join(f"{v:.6f}" for v in CENTRE)
    result = run(
        "drape", surface, "--seed", seed_flag, "--warp", "1,0,0", "--spacing", 2, "-o", out
    )
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "drape.json").read_text())
    written = read_mesh(surface)  # the file's digits
    given = tuple(float(v) for v in seed_flag.split(","))  # the net is sensitive to those too
    direct = drape_ply(written, seed=given, warp=(1.0, 0.0, 0.0), spacing=2.0)
    expected = direct.producibility.fractions["limit"]
    assert data["producibility"]["limit_fraction"] == pytest.approx(expected, rel=1e-6)
    assert data["producibility"]["limit_fraction"] > 0.02


def test_the_example_command_refuses_quads_in_one_line(tmp_path):
    from conftest import error_line, run

    result = run("example", "double-dome", "--cell-type", "quad", "-o", tmp_path / "out", "-q")
    assert result.exit_code == 2
    assert "the double dome is meshed with irregular triangles only" in error_line(result)
    assert not (tmp_path / "out").exists()


def test_side_darts_open_on_a_locking_fabric():
    """The darts of docs/composites.md ("Side darts on a fabric that locks") on the coarser mesh
    of the part (``cell_size = 8``, 1,094 cells; a few seconds), on a fabric that locks at 50°
    (stiffness 100 G there): the four darts from the long sides open and lower the largest
    shear by more than 1° (measured: 48.93° before, 47.13° after, 30 and 56 iterations; mouths
    8.0, 62.7, 15.4, 14.4 mm). On this mesh the shear is below 50° before the darts too, so
    "below 50°" alone would not show that they relieve it; the same dart lines made edges of
    the mesh but not opened give 49.07° (1,224 cells, 32 iterations), which fails the margin."""
    from vares.analysis.darts import solve_with_darts
    from vares.geometry.double_dome import side_darts
    from vares.materials.shear_locking import locking_fabric

    mesh = double_dome(cell_size=8.0)
    law = locking_fabric([-250.0, 250.0], [-250.0, 250.0], [0.5], LOCKING, 100.0)
    darted = solve_with_darts(
        mesh,
        law,
        locking_angle=LOCKING,
        polylines=side_darts([55.0], 75.0),
        warp_direction=(1.0, 0.0, 0.0),
    )
    assert darted.before.converged and darted.after.converged
    assert len(darted.dart_lines) == 4
    assert darted.max_shear_before < LOCKING and darted.max_shear_after < LOCKING
    assert darted.max_shear_after < darted.max_shear_before - 1.0  # the darts relieve it
    for gaps in darted.slits.lip_gaps(darted.after.material_coordinates):
        assert gaps[0] > 5.0  # every mouth opens (mm)
        assert gaps[-1] == 0.0  # the tip is one node
    assert darted.after.mesh.area == pytest.approx(mesh.area, rel=1e-9)
    assert not darted.after.overlap


def test_darts_that_raise_the_shear_are_not_cut(tmp_path):
    """``vares drape --darts auto`` on the shipped part: the automatic dart raises the largest
    shear (measured 57.78° → 62.62°), so the ply is cut without it, as a laminate's ply is:
    pattern.dxf has no DART layer and says so, drape.json's darts are not kept, and the verdict
    names the negatively curved walls and the splice."""
    import json

    import ezdxf
    from conftest import run

    out = tmp_path / "out"
    fabric = ["--material", "ncf", "--A=-250,250", "--B=-250,250", "--C", "0.5"]
    result = run("drape", "--example", "double-dome", "--darts", "auto", *fabric, "-o", out)
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "drape.json").read_text())["darts"]
    assert data["darts"] >= 1 and data["max_shear_after"] > data["max_shear_before"]
    assert not data["kept"] and not data["relieved"]
    assert data["over_locking_curvature"]["negative"] > 0.8
    entities = list(ezdxf.readfile(out / "pattern.dxf").modelspace())
    assert "DART" not in {e.dxf.layer for e in entities}
    texts = [e.dxf.text for e in entities if e.dxftype() == "TEXT"]
    assert any(t.startswith("darts tried, not kept") for t in texts)
