"""Forward drape of a given blank onto a mould (issue 22 §5): blanks, the mould as a contact
surface, the drape's analytic cases, the trim line, and the hemisphere against VaReS."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import error_line, run
from shapely.geometry import Polygon

import vares
from vares.analysis.blank_compare import against_pattern
from vares.analysis.blank_drape import drape_blank
from vares.analysis.blank_trim import trim_blank
from vares.geometry.blank import outline_blank, rectangle_blank
from vares.geometry.drape import DrapeError
from vares.geometry.examples import grid_cells, irregular_cap
from vares.geometry.mesh import SurfaceMesh
from vares.geometry.mould import mould_surface
from vares.materials import OrthotropicStVenantKirchhoff

FABRIC = OrthotropicStVenantKirchhoff(E1=1000.0, E2=1000.0, G12=10.0, nu12=0.0)


def plate(size: float = 100.0, n: int = 20, jitter: float = 0.3) -> SurfaceMesh:
    """A flat square plate in z = 0 of irregular triangles (nodes moved inside)."""
    s = np.linspace(-size / 2, size / 2, n + 1)
    x, y = np.meshgrid(s, s, indexing="xy")
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    inner = (np.abs(points[:, :2]) < size / 2 - 1e-9).all(axis=1)
    rng = np.random.default_rng(3)
    points[inner, :2] += jitter * (size / n) * rng.uniform(-1, 1, (inner.sum(), 2))
    return SurfaceMesh(points, grid_cells(n + 1, n + 1, "triangle"))


def cylinder(radius: float = 50.0, facets: int = 96, angle: float = 2.4) -> SurfaceMesh:
    """A faceted cylinder segment about the y axis, its crest along z = radius."""
    phi = np.linspace(-angle / 2, angle / 2, facets + 1)
    y = np.linspace(-60.0, 60.0, 41)
    p, z = np.meshgrid(phi, y, indexing="xy")
    points = np.column_stack([radius * np.sin(p.ravel()), z.ravel(), radius * np.cos(p.ravel())])
    return SurfaceMesh(points, grid_cells(facets + 1, 41, "triangle"))


# ---------------------------------------------------------------------------------- blanks
def test_rectangle_blank_is_a_yarn_grid_centred_on_its_seed():
    blank = rectangle_blank(60.0, 40.0, 2.0)
    assert np.allclose(blank.coordinates[blank.seed], 0.0)
    assert blank.area == pytest.approx(2400.0, rel=1e-12)
    p = blank.coordinates[blank.triangles]
    sides = p - np.roll(p, 1, axis=1)
    along_x = (np.abs(sides[..., 1]) < 1e-12).sum(axis=1)
    along_y = (np.abs(sides[..., 0]) < 1e-12).sum(axis=1)
    assert (along_x == 1).all() and (along_y == 1).all()  # both legs along the yarns


def test_outline_blank_keeps_the_outline_and_its_seed():
    ring = np.array([[0, 0], [60, 0], [60, 20], [25, 20], [25, 45], [0, 45]], dtype=float)
    blank = outline_blank(ring, 2.5, seed=(10.0, 10.0))
    assert blank.area == pytest.approx(Polygon(ring).area, rel=1e-9)
    assert np.allclose(blank.coordinates[blank.seed], (10.0, 10.0))
    with pytest.raises(ValueError, match="outside its outline"):
        outline_blank(ring, 2.5, seed=(50.0, 40.0))
    with pytest.raises(ValueError, match="positive"):
        rectangle_blank(10.0, -1.0, 1.0)


def test_trim_of_a_linear_field_is_its_zero_line_and_the_area_on_its_side():
    blank = rectangle_blank(40.0, 20.0, 2.0)
    values = blank.coordinates @ np.array([1.0, 0.5]) - 3.3  # zero on x + y/2 = 3.3
    lines, area = trim_blank(blank, values)
    exact = Polygon([(-20, -10), (3.3 + 5, -10), (3.3 - 5, 10), (-20, 10)]).area
    assert area == pytest.approx(exact, rel=1e-12)
    assert len(lines) == 1
    assert np.allclose(lines[0] @ np.array([1.0, 0.5]), 3.3, atol=1e-9)


def test_flange_continues_the_faces_at_the_edge():
    cap = irregular_cap(100.0, 90.0, 10, 0.3, 1)
    mould = mould_surface(cap, flange_width=30.0)
    rim = cap.boundary_loops()[0]
    flange = mould.mesh.points[cap.num_points :].reshape(-1, len(rim), 3)  # layer by layer
    direction = (flange[-1] - cap.points[rim]) / 30.0
    assert np.allclose(np.linalg.norm(direction, axis=1), 1.0, atol=1e-12)
    assert np.allclose(mould.outwardness[cap.num_points :].reshape(-1, len(rim))[-1], 30.0)
    # a hemisphere cut at the equator: about the cylinder below it, tilted outward by at most
    # the tilt of the last ring's faces (half the ring angle of 9°)
    tilt = np.degrees(np.arccos(-direction[:, 2]))
    assert tilt.max() < 5.5
    assert (np.einsum("ki,ki->k", direction[:, :2], cap.points[rim, :2]) >= 0).all()
    assert (mould.outwardness[: cap.num_points] <= 0).all()


# ---------------------------------------------------------------------------------- analytic
def test_sliding_basis_has_two_tangents_per_free_node_one_per_guided_none_held():
    from vares.mechanics.contact import SlidingNodes

    surface = mould_surface(irregular_cap(100.0, 60.0, 8, 0.3, 1), 5.0)
    points = surface.mesh.points[:40] + 0.1
    held = np.zeros(40, dtype=bool)
    held[[3, 7]] = True
    plane = np.array([0.6, 0.8, 0.0])
    guided = {5: (plane, 0.0), 7: (plane, 0.0), 11: (np.array([0.0, 1.0, 0.0]), 0.0)}
    nodes = SlidingNodes.placed(surface, points, held, guided)
    T = nodes.basis().toarray()
    assert T.shape == (120, 2 * 36 + 2)
    assert np.allclose(T.T @ T, np.eye(T.shape[1]))  # orthonormal columns
    per_node = np.abs(T).reshape(40, 3, -1).sum(axis=1) > 0  # (nodes, columns)
    assert (per_node.sum(axis=0) == 1).all()  # every column moves one node
    counts = per_node.sum(axis=1)
    assert counts[[3, 7]].tolist() == [0, 0] and counts[[5, 11]].tolist() == [1, 1]
    assert (np.delete(counts, [3, 5, 7, 11]) == 2).all()
    normals = surface.normals[nodes.faces]
    moves = T.reshape(40, 3, -1)
    assert np.allclose(np.einsum("ni,nic->nc", normals, moves), 0.0)  # tangential
    assert np.allclose(plane @ moves[5], 0.0)  # the guided node stays in its plane
    assert np.flatnonzero(per_node[:, :2].any(axis=1)).tolist() == [0]  # columns in node order


def test_flat_mould_leaves_the_blank_unchanged():
    angle = np.radians(16.7)
    warp = np.array([np.cos(angle), np.sin(angle), 0.0])
    blank = rectangle_blank(60.0, 40.0, 2.0)
    result = drape_blank(plate(), blank, FABRIC, seed=(3.0, -2.0, 0.0), warp_direction=warp)
    assert result.converged, result.reason
    turn = np.array([[warp[0], -warp[1]], [warp[1], warp[0]]])
    expected = blank.coordinates @ turn.T + (3.0, -2.0)
    assert np.abs(result.positions[:, :2] - expected).max() < 1e-9
    assert np.abs(result.positions[:, 2]).max() < 1e-12
    assert np.abs(result.shear_angle).max() < 1e-8
    assert max(np.abs(result.warp_strain).max(), np.abs(result.fill_strain).max()) < 1e-12
    assert result.net_area == pytest.approx(2400.0, rel=1e-12) and result.excess_area < 1e-9


def test_blank_larger_than_the_plate_has_its_excess_beyond_the_trim_line():
    blank = rectangle_blank(140.0, 80.0, 2.0)
    result = drape_blank(plate(), blank, FABRIC, seed=(10.5, 0.0, 0.0), warp_direction=(1, 0, 0))
    assert result.converged, result.reason
    shifted = blank.coordinates + np.array([10.5, 0.0])
    assert np.abs(result.positions[:, :2] - shifted).max() < 1e-9
    # the plate spans x in [−50, 50]: the blank from x = −60.5 to 39.5 lies on it
    assert result.net_area == pytest.approx(100.0 * 80.0, rel=1e-9)
    assert result.excess_area == pytest.approx(140.0 * 80.0 - 8000.0, rel=1e-9)
    ends = np.vstack(result.trim_lines)[:, 0]
    assert np.allclose(np.minimum(np.abs(ends + 60.5), np.abs(ends - 39.5)), 0.0, atol=1e-9)
    assert result.on_part.sum() == pytest.approx(len(blank.triangles) * 100 / 140, abs=2 * 40)


@pytest.mark.parametrize("angle", [0.0, 30.0])
def test_cylinder_drape_is_isometric_without_shear(angle):
    radius = 50.0
    a = np.radians(angle)
    warp, normal = np.array([np.sin(a), np.cos(a), 0.0]), np.array([0.0, 0.0, 1.0])
    fill = np.cross(normal, warp)
    blank = rectangle_blank(60.0, 40.0, 2.0)
    result = drape_blank(cylinder(radius), blank, FABRIC, seed=(0, 0, radius), warp_direction=warp)
    assert result.converged, result.reason
    # the exact isometry: arc length s round the axis, y along it
    X = blank.coordinates
    s = X[:, 0] * warp[0] + X[:, 1] * fill[0]
    y = X[:, 0] * warp[1] + X[:, 1] * fill[1]
    exact = np.column_stack([radius * np.sin(s / radius), y, radius * np.cos(s / radius)])
    sag = radius * (1 - np.cos(2.4 / 96 / 2))  # the facets lie this far inside the cylinder
    assert np.linalg.norm(result.positions - exact, axis=1).max() < 1.5 * sag
    assert np.abs(result.shear_angle).max() < 0.02
    assert max(np.abs(result.warp_strain).max(), np.abs(result.fill_strain).max()) < 5e-5


def test_seed_off_the_mould_is_refused():
    with pytest.raises(DrapeError, match="not on the mould"):
        blank = rectangle_blank(20, 20, 2)
        drape_blank(plate(), blank, FABRIC, seed=(0, 0, 30), warp_direction=(1, 0, 0))


# ---------------------------------------------------------------------------------- hemisphere
@pytest.fixture(scope="module")
def hemisphere_pair():
    mould = irregular_cap(100.0, 45.0, 20, 0.3, 1)  # a 45° cap of R = 100 mm, edges 3.9 mm
    blank = rectangle_blank(120.0, 120.0, 4.0)  # its corners lie beyond the cap's edge
    drape = drape_blank(mould, blank, FABRIC, seed=(0, 0, 100), warp_direction=(1, 0, 0))
    pattern = vares.solve(mould, FABRIC, 1.0, warp_direction=(1.0, 0.0, 0.0))
    return mould, drape, pattern


def test_hemisphere_forward_drape_reproduces_the_vares_pattern(hemisphere_pair):
    mould, drape, pattern = hemisphere_pair
    assert drape.converged, drape.reason
    assert pattern.converged
    polar = np.degrees(np.arccos(np.clip(mould.points[:, 2] / 100.0, -1, 1)))
    assert 0 < drape.excess_area < 0.05 * drape.blank.area  # the corners beyond the edge
    near = polar < 30.0  # away from both edges: the blank's (34° from the pole) and the cap's
    c = against_pattern(
        drape, mould, pattern.material_coordinates, pattern.fields["shear_angle"], within=near
    )
    # measured: 0.097 mm, 0.33°, 0.55° (docs/composites.md, Forward drape)
    assert c["nodes"] > 300
    assert c["max_position_difference"] < 0.2  # mm
    assert c["rms_shear_difference"] < 0.5  # degrees
    assert abs(c["turn"]) < 1.0


def test_cli_drape_blank_writes_its_files(tmp_path):
    from vares.io.meshes import write_surface

    mould = tmp_path / "plate.vtu"
    write_surface(mould, plate())
    fabric = ["--material", "orthotropic", "--E1", "1000", "--E2", "1000", "--G12", "10"]
    fabric += ["--nu12", "0"]
    out = tmp_path / "out"
    result = run("drape-blank", mould, "--blank-length", 140, "--blank-width", 80,
                 "--seed", "10.5,0,0", *fabric, "-o", out, "-q")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    summary = json.loads((out / "blank.json").read_text())
    assert summary["converged"] and summary["net_area"] == pytest.approx(8000.0, rel=1e-9)
    assert (out / "blank.vtu").is_file() and (out / "blank.dxf").is_file()
    again = run("drape-blank", mould, "--blank-length", 140, "--blank-width", 80, *fabric,
                "-o", out)  # fmt: skip
    assert again.exit_code == 2 and "exist" in error_line(again)
    alone = run("drape-blank", mould, "--blank-length", 140, *fabric, "-o", tmp_path / "o2")
    assert alone.exit_code == 2 and "--blank-width" in error_line(alone)


def test_cli_drape_blank_refuses_a_zero_spacing_and_a_blank_too_fine(tmp_path):
    from vares.io.meshes import write_surface

    mould = tmp_path / "plate.vtu"
    write_surface(mould, plate())
    fabric = ["--material", "orthotropic", "--E1", "1000", "--E2", "1000", "--G12", "10"]
    fabric += ["--nu12", "0"]
    blank = ["--blank-length", 140, "--blank-width", 80]
    zero = run("drape-blank", mould, *blank, "--spacing", 0, *fabric, "-o", tmp_path / "a")
    assert zero.exit_code == 2 and "--spacing must be > 0; got 0" in error_line(zero)
    huge = ["--blank-length", "1e6", "--blank-width", "1e6", "--spacing", 4]
    fine = run("drape-blank", mould, *huge, *fabric, "-o", tmp_path / "b")
    assert fine.exit_code == 2, fine.stderr
    assert "62,500,500,001 nodes" in error_line(fine) and "larger spacing" in error_line(fine)
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


def test_a_blank_of_too_many_nodes_is_refused_before_it_is_meshed():
    with pytest.raises(ValueError, match="4,004,001 nodes"):
        rectangle_blank(2000.0, 2000.0, 1.0)
    with pytest.raises(ValueError, match="nodes"):
        outline_blank(np.array([[0, 0], [2000, 0], [2000, 2000], [0, 2000.0]]), 1.0)


def test_blank_outline_from_dxf_and_the_cutting_drawing(tmp_path):
    import ezdxf

    from vares.io.blank_files import read_blank_outline, write_blank_dxf

    ring = [(0, 0), (80, 0), (80, 30), (40, 50), (0, 30)]
    document = ezdxf.new("R2010")
    space = document.modelspace()
    space.add_lwpolyline([(0, 0), (5, 0), (5, 5)], close=True)  # a small one: not the blank
    space.add_lwpolyline(ring, close=True, dxfattribs={"layer": "BLANK"})
    space.add_lwpolyline([(0, 0), (200, 0)])  # open: not an outline
    document.saveas(tmp_path / "blank.dxf")
    outline = read_blank_outline(tmp_path / "blank.dxf")
    assert np.allclose(outline, ring)
    assert np.allclose(read_blank_outline(tmp_path / "blank.dxf", layer="BLANK"), ring)
    with pytest.raises(ValueError, match="no closed polyline on layer 'X'"):
        read_blank_outline(tmp_path / "blank.dxf", layer="X")
    blank = outline_blank(outline, 3.0)
    lines = [np.array([[10.0, 0.0], [10.0, 30.0]])]
    write_blank_dxf(tmp_path / "cut.dxf", blank, lines)
    drawn = ezdxf.readfile(tmp_path / "cut.dxf").modelspace()
    layers = sorted(e.dxf.layer for e in drawn)
    assert layers == ["EXTENDED", "NET", "ROSETTE"]
