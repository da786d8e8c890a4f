"""Darts: slits walked on the mould and opened, placed where a ply's shear reaches its locking
angle, and the pattern solved again with them open (docs/composites.md, "Darts")."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import error_line, run

from vares.analysis.dart_lines import (
    darts_from_polylines,
    erected_yarns,
    fall_line_darts,
    place_darts,
    smoothed,
)
from vares.analysis.darts import solve_with_darts
from vares.geometry.cutting import cut_mesh
from vares.geometry.examples import grid_cells, irregular_cap
from vares.geometry.mesh import SurfaceMesh
from vares.geometry.slits import open_slits, walk_line
from vares.geometry.surface_lines import CuttingError

R = 100.0
LOCKING = 50.0


def square(n: int = 10) -> SurfaceMesh:
    """The unit square in the plane z = 0, ``n × n`` squares split into triangles."""
    s = np.linspace(0.0, 1.0, n + 1)
    x, y = np.meshgrid(s, s, indexing="xy")
    return SurfaceMesh(
        np.column_stack([x.ravel(), y.ravel(), 0 * x.ravel()]), grid_cells(n + 1, n + 1)
    )


def straight_up(mesh: SurfaceMesh, x: float, length: float):
    """The line walked along +y from the bottom edge at ``x``."""
    triangles = mesh.cells["triangle"]
    points = mesh.points
    for face, cell in enumerate(triangles):
        for k in range(3):
            a, b = points[cell[(k + 1) % 3]], points[cell[(k + 2) % 3]]
            if a[1] == b[1] == 0.0 and min(a[0], b[0]) < x < max(a[0], b[0]):
                weights = np.zeros(3)
                t = (x - a[0]) / (b[0] - a[0])
                weights[(k + 1) % 3], weights[(k + 2) % 3] = 1.0 - t, t
                return walk_line(mesh, face, weights, lambda *_: np.array([0.0, 1.0, 0.0]), length)
    raise AssertionError("no bottom edge there")


def test_a_walked_line_is_straight_and_as_long_as_asked():
    mesh = square(10)
    line = straight_up(mesh, 0.43, 0.5)
    assert np.abs(line.points[:, 0] - 0.43).max() < 1e-12
    assert line.points[0, 1] == 0.0
    # it stops at the first edge crossing beyond the length: within one cell's diagonal
    assert 0.5 <= line.length < 0.5 + np.sqrt(2) * 0.1
    # and stops before the boundary when the length is more than the square
    through = straight_up(mesh, 0.43, 5.0)
    assert through.points[-1, 1] < 1.0 and through.points[-1, 1] > 0.85


def test_a_dart_along_a_row_of_nodes_starts_on_the_boundary_and_runs_its_length():
    """A dart line from a boundary node through a row of nodes (the grid's line x = 0.5): the
    walk records its start, goes on from node to node and the slit opens. Before, a walk that
    started on a node left its start out, and the slit was refused as not starting on the
    boundary (the Kratos cup's diagonal darts, docs/composites.md)."""
    mesh = square(10)
    dart = darts_from_polylines(mesh, [np.array([[0.5, 0.0, 0.0], [0.5, 0.6, 0.0]])])[0]
    np.testing.assert_allclose(dart.points[0], [0.5, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(dart.points[-1], [0.5, 0.6, 0.0], atol=1e-12)
    np.testing.assert_allclose(dart.points[:, 0], 0.5, atol=1e-12)
    assert dart.length == pytest.approx(0.6, abs=1e-12)
    slits = open_slits(mesh, [dart])
    assert slits.mesh.num_points == mesh.num_points + 6  # a twin for every node but the tip
    assert slits.mesh.area == pytest.approx(mesh.area, rel=1e-12)
    # across the cells' diagonals, from node to node through their corners
    slanted = darts_from_polylines(mesh, [np.array([[0.6, 0.0, 0.0], [0.1, 0.5, 0.0]])])[0]
    np.testing.assert_allclose(slanted.points[0], [0.6, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(slanted.points.sum(axis=1), 0.6, atol=1e-12)  # on x + y = 0.6
    assert slanted.length > 0.5  # to the last cell before its end (0.1, 0.5)
    assert open_slits(mesh, [slanted]).mesh.area == pytest.approx(mesh.area, rel=1e-12)


def test_a_walk_that_turns_back_stops_before_a_face_it_crossed():
    """A direction field that sends the walk back the way it came (a bisector whose sign flips
    from cell to cell) ends the line before it re-enters a face: without that check the walk
    went back and forth across one side for its 100,000 steps, a line of 100,001 points."""
    mesh = square(10)
    turns = []

    def back_and_forth(face, here, last):
        turns.append(face)
        return np.array([0.0, 1.0, 0.0]) if len(turns) % 2 else np.array([0.0, -1.0, 0.0])

    line = straight_up(mesh, 0.43, 0.05)  # the start: a point on the bottom edge
    triangles = mesh.cells["triangle"]
    face = int(np.flatnonzero(np.isin(triangles, line.ends[0]).sum(axis=1) == 2)[0])
    weights = np.zeros(3)
    a, b = line.ends[0]
    weights[triangles[face] == a], weights[triangles[face] == b] = (
        1 - line.fractions[0],
        line.fractions[0],
    )
    walked = walk_line(mesh, face, weights, back_and_forth, 10.0)
    assert len(walked.points) <= 3 and len(turns) <= 3
    assert np.all(np.linalg.norm(np.diff(walked.points, axis=0), axis=1) > 0)


def test_an_opened_slit_frees_both_lips_and_keeps_the_surface():
    mesh = square(10)
    line = straight_up(mesh, 0.43, 0.5)
    slits = open_slits(mesh, [line])
    opened = slits.mesh
    cut = cut_mesh(mesh, [line], panels=False).mesh
    chain = slits.lips[0][0]
    # every node of the slit but its tip has a twin; the surface is the same
    assert opened.num_points == cut.num_points + len(chain) - 1
    assert opened.area == pytest.approx(1.0, abs=1e-12)
    assert np.array_equal(slits.parent[: cut.num_points], np.arange(cut.num_points))
    (gap,) = slits.lip_gaps(opened.points)
    assert np.abs(gap).max() == 0.0  # on the mould the lips lie together
    # one boundary loop: the square's edge and both lips of the slit
    loops = opened.boundary_loops()
    assert len(loops) == 1
    ring = opened.points[loops[0]]
    perimeter = np.linalg.norm(ring - np.roll(ring, -1, axis=0), axis=1).sum()
    lip = np.linalg.norm(np.diff(opened.points[chain], axis=0), axis=1).sum()
    assert lip == pytest.approx(line.length, rel=1e-12)
    assert perimeter == pytest.approx(4.0 + 2.0 * lip, rel=1e-12)
    # the two lips are the two sides of the line: twins and originals never share a cell
    a, b = slits.lips[0]
    cells = opened.cells["triangle"]
    both = np.isin(cells, a[:-1]).any(axis=1) & np.isin(cells, b[:-1]).any(axis=1)
    assert not both.any()
    # the left lip keeps the nodes: seen from +z, left of a slit running along +y is x < 0.43
    centroids = opened.points[cells].mean(axis=1)
    assert np.all(centroids[np.isin(cells, a[:-1]).any(axis=1), 0] < 0.43)
    assert np.all(centroids[np.isin(cells, b[:-1]).any(axis=1), 0] > 0.43)


def test_slits_that_are_no_darts_are_refused():
    mesh = square(10)
    through = straight_up(mesh, 0.43, 5.0)
    # extended by hand to the top edge: it would cut the square in two
    top = np.array([[0.43, 1.0, 0.0]])
    from vares.geometry.surface_lines import EdgeLocator

    whole = EdgeLocator(mesh).line(np.vstack([through.points, top]))
    with pytest.raises(CuttingError, match="boundary to boundary"):
        open_slits(mesh, [whole])
    inside = EdgeLocator(mesh).line(through.points[2:])
    with pytest.raises(CuttingError, match="does not start on the surface's boundary"):
        open_slits(mesh, [inside])


def test_dart_lines_given_as_points_are_drawn_onto_the_mould():
    mesh = irregular_cap(R, 90.0, 20, 0.3, 1)
    polar = np.radians(np.linspace(65.0, 90.0, 6))[::-1]  # the mouth at the equator first
    azimuth = np.radians(45.0)
    points = R * np.column_stack(
        [np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)]
    )
    lifted = points * 1.01  # a little off the surface, as drawn in CAD
    for given in (lifted, lifted[::-1]):  # either end first: the mouth is the boundary's
        (line,) = darts_from_polylines(mesh, [given])
        assert abs(line.points[0, 2]) < 1e-9  # on the equator
        # in the meridian plane to within the faceting (cells of about 8 mm)
        off = np.abs(line.points @ np.array([np.sin(azimuth), -np.cos(azimuth), 0.0]))
        assert off.max() < 1.0
        tip = np.degrees(np.arccos(line.points[-1, 2] / R))
        assert 65.0 < tip < 72.0  # ends in the cell of the last point, or one short of it
    with pytest.raises(CuttingError, match="from the mould"):
        darts_from_polylines(mesh, [points * 1.5])


def test_darts_follow_the_bisector_of_the_sheared_yarns():
    """On the hemisphere with the warp along x the shear peaks on the 45° meridians at the
    equator, and the bisector of the yarns' acute angle there is the meridian: four darts."""
    from vares.geometry.drape import kinematic_drape

    mesh = irregular_cap(R, 90.0, 20, 0.3, 1)
    drape = kinematic_drape(mesh, [0, 0, R], [1, 0, 0], 2.0)
    lines = place_darts(mesh, drape.shear_angle, drape.warp, drape.fill, 48.0, 40.0)
    assert len(lines) == 4
    for line in lines:
        mouth = np.degrees(np.arctan2(line.points[0, 1], line.points[0, 0]))
        assert abs((mouth - 45.0 + 45.0) % 90.0 - 45.0) < 6.0  # two boundary edges of 3°
        azimuth = np.degrees(np.arctan2(line.points[:, 1], line.points[:, 0]))
        assert np.ptp(azimuth) < 6.0  # along a meridian
        assert abs(line.points[-1, 2]) > 10.0  # well inside
    assert place_darts(mesh, drape.shear_angle, drape.warp, drape.fill, 60.0, 40.0) == []


def test_erected_yarns_of_the_surface_itself_are_its_axes():
    mesh = square(4)
    warp, fill = erected_yarns(mesh, mesh.points[:, :2], np.array([1.0, 0.0]), np.array([0, 1.0]))
    assert np.allclose(warp, [1, 0, 0]) and np.allclose(fill, [0, 1, 0])
    field = np.arange(mesh.num_cells, dtype=float)
    assert smoothed(mesh, np.full(mesh.num_cells, 3.0)) == pytest.approx(3.0)
    assert smoothed(mesh, field).max() < field.max()


@pytest.fixture(scope="module")
def hemisphere_darts():
    from vares.materials import NonCrimpFabric

    mesh = irregular_cap(R, 90.0, 20, 0.3, 1)
    law = NonCrimpFabric([-250.0, 250.0], [-250.0, 250.0], [0.5])
    darted = solve_with_darts(
        mesh, law, locking_angle=LOCKING, darts="auto", warp_direction=(1.0, 0.0, 0.0)
    )
    return mesh, law, darted


def test_darts_bring_the_hemisphere_below_the_locking_angle(hemisphere_darts):
    """The test that fails if a dart does not open: the lips separate in the flat pattern and
    the largest shear drops below the locking angle (measured 56.7° → 49.3°, mouths 14–23 mm)."""
    _, _, darted = hemisphere_darts
    assert darted.before.converged and darted.after.converged
    assert darted.max_shear_before > LOCKING + 5.0
    assert darted.relieved and darted.max_shear_after < LOCKING
    assert darted.final is darted.after and darted.kept
    assert darted.max_shear_before - darted.max_shear_after > 5.0
    assert len(darted.dart_lines) == 4
    for gaps in darted.slits.lip_gaps(darted.after.material_coordinates):
        assert gaps[0] > 10.0  # the mouth opens (mm)
        assert gaps[-1] == 0.0  # the tip is one node
        assert np.all(np.diff(gaps) < 1.0)  # closing from the mouth to the tip
    # the darts' lips meet again when the pattern is erected: the mesh is the mould's surface
    assert darted.after.mesh.area == pytest.approx(darted.before.mesh.area, rel=1e-9)
    assert not darted.after.overlap
    # a sphere: the sheared area is positively curved, where darts relieve it
    assert darted.summary()["over_locking_curvature"]["positive"] == pytest.approx(1.0)
    assert not darted.needs_splices


def test_a_dart_that_is_cut_but_not_opened_relieves_nothing(hemisphere_darts):
    """The same lines made edges of the mesh, the lips left joined: the shear stays beyond the
    locking angle, so the relief above is the opening's, not the new mesh's."""
    import vares
    from vares.geometry.surface_lines import EdgeLocator

    mesh, law, darted = hemisphere_darts
    locate = EdgeLocator(mesh, tolerance=1e-6 * R)
    closed = cut_mesh(mesh, [locate.line(line) for line in darted.dart_lines], panels=False).mesh
    assert closed.num_points == darted.slits.parent.max() + 1  # the mesh the darts were cut in
    result = vares.solve(closed, law, warp_direction=(1.0, 0.0, 0.0))
    assert result.converged
    assert np.abs(result.fields["shear_angle"]).max() > LOCKING


def test_drape_command_with_dart_lines(tmp_path):
    import ezdxf
    import meshio

    from vares.io.meshes import write_surface

    mesh = irregular_cap(R, 90.0, 20, 0.3, 1)
    surface = tmp_path / "hemisphere.obj"
    write_surface(surface, mesh)
    curves = tmp_path / "darts.txt"
    text = []
    for azimuth in np.radians([45.0, 135.0, 225.0, 315.0]):
        polar = np.radians([90.0, 62.0])
        for p in polar:
            x = R * np.array([np.sin(p) * np.cos(azimuth), np.sin(p) * np.sin(azimuth), np.cos(p)])
            text.append(" ".join(f"{v:.9g}" for v in x))
        text.append("")
    curves.write_text("\n".join(text))
    out = tmp_path / "out"
    base = ["drape", surface, "--seed", "0,0,100", "--warp", "1,0,0", "--spacing", 4, "-o", out]
    ncf = ["--material", "ncf", "--A=-250,250", "--B=-250,250", "--C", "0.5"]
    edges = ["--trim-allowance", "5", "--dart-overlap", "3"]
    result = run(*base, "--dart-lines", curves, *ncf, *edges, "--report")
    assert result.exit_code == 0, result.stderr
    drape = json.loads((out / "drape.json").read_text())
    data = drape["darts"]
    assert data["darts"] == 4 and data["max_shear_after"] < data["max_shear_before"] - 4.0
    assert min(data["mouth_openings"]) > 10.0
    entities = list(ezdxf.readfile(out / "pattern.dxf").modelspace())
    layers = [e.dxf.layer for e in entities]
    assert layers.count("DART") == 4 and layers.count("SEAM") == 1 and layers.count("CUT") == 1
    (seam,) = [np.array(e.get_points("xy")) for e in entities if e.dxf.layer == "SEAM"]
    for dart in (np.array(e.get_points("xy")) for e in entities if e.dxf.layer == "DART"):
        # both lips are pieces of the pattern's outline, apart at the mouth, one at the tip
        nearest = np.linalg.norm(dart[:, None, :] - seam[None, :, :], axis=2).min(axis=1)
        assert nearest.max() < 1e-9
        assert np.linalg.norm(dart[0] - dart[-1]) > 10.0
    # the cut line: 5 outside the net along the mould's edge, on each dart's right lip (butt),
    # 3 beside its left lip (the lap), nowhere inside the net
    from shapely.geometry import LineString, Point, Polygon

    (cut,) = [np.array(e.get_points("xy")) for e in entities if e.dxf.layer == "CUT"]
    net, trim = Polygon(seam), Polygon(cut)
    assert trim.contains(net.buffer(-1e-6)) and trim.area > net.area
    away = np.array([net.exterior.distance(Point(p)) for p in cut])
    assert np.sum(np.abs(away - 5.0) < 1e-6) > 20 and np.sum(np.abs(away - 3.0) < 1e-6) >= 8
    lips = [np.array(e.get_points("xy")) for e in entities if e.dxf.layer == "DART"]
    near_lips = min(LineString(lip).distance(Point(p)) for lip in lips for p in cut)
    assert near_lips < 1e-9  # the butt lips are cut to the dart
    blank = drape["blank"]
    assert (blank["trim_allowance"], blank["dart_overlap"]) == (5.0, 3.0)
    assert blank["pieces"][0]["trim_area"] == pytest.approx(trim.area, rel=1e-9)
    assert blank["pieces"][0]["net_area"] == pytest.approx(net.area, rel=1e-9)
    opened = meshio.read(out / "darts.vtu")
    assert len(opened.points) > mesh.num_points
    assert (out / "darts.png").stat().st_size > 10_000
    html = (out / "drape.html").read_text()
    assert 'id="dart-lines"' in html and 'id="figure-darts"' in html
    assert html.count("<tr>", html.index('id="dart-lines"')) >= 5  # a header, four darts
    for extra, message in [
        ([], "darts need the ply's fabric"),
        (["--darts", "auto", *ncf], "not both"),
        (
            [
                "--material",
                "orthotropic",
                "--E1",
                "1000",
                "--E2",
                "1000",
                "--G12",
                "1",
                "--nu12",
                "0",
                "--units",
                "furlong",
            ],
            "--units",
        ),
    ]:
        refused = run(*base[:-1], tmp_path / "refused", "--dart-lines", curves, *extra)
        assert refused.exit_code == 2 and message in error_line(refused), refused.stderr
    far = tmp_path / "far.txt"
    far.write_text("0 0 300\n0 10 300\n")
    refused = run(*base[:-1], tmp_path / "refused", "--dart-lines", far, *ncf)
    assert refused.exit_code == 2 and "from the mould" in error_line(refused)
    assert not (tmp_path / "refused").exists()
    refused = run(*base[:-1], tmp_path / "refused", *ncf)
    assert refused.exit_code == 2 and "add --darts auto" in error_line(refused)
    # an allowance without a cutter file, an overlap without its joints, or one as wide as
    # half the blank: refused before anything is solved or written
    for extra, message in [
        (["--trim-allowance", "5"], "--trim-allowance is for the cutter files"),
        (["--dart-lines", curves, *ncf, "--splice-overlap", "5"], "add --splice-lines"),
        (["--dart-lines", curves, *ncf, "--dart-overlap", "1000"], "half as wide as its blank"),
    ]:
        refused = run(*base[:-1], tmp_path / "refused", *extra)
        assert refused.exit_code == 2 and message in error_line(refused), refused.stderr
        assert not (tmp_path / "refused").exists()
    refused = run(*base[:-1], tmp_path / "refused", "--darts", "auto", "--material", "neo-hooke")
    assert refused.exit_code == 2 and "yarns" in error_line(refused)


def test_darts_move_with_the_mould():
    """A rigid motion of the mould, its seed and its warp moves the darts with it: the same
    lengths, the mouths moved (the kinematic net's shear and yarns as the field)."""
    from conftest import rotation

    from vares.geometry.drape import kinematic_drape

    mesh = irregular_cap(R, 90.0, 20, 0.3, 1)
    turn, shift = rotation(3), np.array([10.0, -20.0, 5.0])
    moved = SurfaceMesh(mesh.points @ turn.T + shift, mesh.cells)
    found = []
    for surface, seed, warp in [
        (mesh, np.array([0, 0, R]), np.array([1.0, 0, 0])),
        (moved, turn @ [0, 0, R] + shift, turn @ [1.0, 0, 0]),
    ]:
        drape = kinematic_drape(surface, seed, warp, 2.0)
        found.append(place_darts(surface, drape.shear_angle, drape.warp, drape.fill, 48.0, 40.0))
    assert len(found[0]) == len(found[1]) == 4
    lengths = [sorted(line.length for line in lines) for lines in found]
    assert np.allclose(lengths[0], lengths[1], rtol=1e-6)
    mouths = np.array([line.points[0] for line in found[0]]) @ turn.T + shift
    for line in found[1]:
        assert np.linalg.norm(mouths - line.points[0], axis=1).min() < 1e-6 * R


def test_no_dart_where_none_is_needed():
    from vares.materials import NonCrimpFabric

    cap = irregular_cap(R, 45.0, 10, 0.3, 1)
    law = NonCrimpFabric([-250.0, 250.0], [-250.0, 250.0], [0.5])
    darted = solve_with_darts(cap, law, locking_angle=LOCKING, darts="auto")
    assert darted.before.converged and darted.max_shear_before < LOCKING
    assert darted.after is None and darted.rounds == [] and darted.relieved
    assert darted.final is darted.before
    assert darted.summary()["darts"] == 0
    with pytest.raises(ValueError, match="dart_lines names a file"):
        solve_with_darts(cap, law, locking_angle=LOCKING, dart_lines="darts.txt")


def test_a_pattern_that_did_not_converge_gets_no_darts_and_says_so():
    from vares.app.cli.drape import darts_verdict
    from vares.materials import NonCrimpFabric

    cap = irregular_cap(R, 90.0, 10, 0.3, 1)
    law = NonCrimpFabric([-250.0, 250.0], [-250.0, 250.0], [0.5])
    stopped = solve_with_darts(cap, law, locking_angle=LOCKING, darts="auto", max_iterations=1)
    assert not stopped.before.converged and stopped.after is None and stopped.rounds == []
    line = darts_verdict(stopped)
    assert line.startswith("the pattern without darts did NOT converge (") and "no dart" in line
    assert "no dart needed" not in line
    done = solve_with_darts(cap, law, locking_angle=LOCKING, darts="none")
    assert done.before.converged
    assert darts_verdict(done).endswith("NOT below the locking angle (0 solves with darts)")
    assert "no dart placed" in darts_verdict(done)  # beyond the locking angle, none asked for


@pytest.fixture(scope="module")
def square_cup_pattern():
    """The non-crimp fabric's pattern of a box-shaped mould (warp along x): its corners shear
    beyond the locking angle at their concave foot, inside the ply."""
    from vares.geometry.hard_surfaces import square_cup
    from vares.materials import NonCrimpFabric
    from vares.solver.api import solve

    mesh = square_cup(60, seed=1)
    law = NonCrimpFabric([-250.0, 250.0], [-250.0, 250.0], [0.5])
    return mesh, law, solve(mesh, law, warp_direction=(1.0, 0.0, 0.0))


def test_the_corners_of_a_cup_get_darts_along_their_fall_lines(square_cup_pattern):
    """Where the bisector leads nowhere (the cells between a corner's region and the flange's
    edge shear less than the tip angle), a dart runs from the flange's edge up the fall line
    through the corner's positively curved patch onto the punch face: one per corner, and with
    them open the shear is below the locking angle."""
    mesh, law, before = square_cup_pattern
    shear = before.fields["shear_angle"]
    assert before.converged and np.nanmax(np.abs(shear)) >= LOCKING
    fibres = before.fibres
    warp, fill = erected_yarns(mesh, before.material_coordinates, fibres.warp, fibres.fill)
    assert place_darts(mesh, shear, warp, fill, LOCKING, 0.8 * LOCKING) == []
    lines = fall_line_darts(mesh, shear, LOCKING, 0.8 * LOCKING)
    assert len(lines) == 4
    corners = set()
    for line in lines:
        mouth, tip = line.points[0], line.points[-1]
        assert abs(mouth[2]) < 1e-9 and np.isclose(np.abs(mouth[:2]).max(), 75.0)  # the edge
        assert tip[2] > 0.95 * 25.0  # on the punch face
        assert np.all(np.sign(mouth[:2]) == np.sign(tip[:2]))  # in one quadrant
        corners.add(tuple(np.sign(tip[:2])))
        assert np.all(np.diff(line.points[:, 2]) > -1e-9)  # up the slope all the way
    assert len(corners) == 4
    darted = solve_with_darts(
        mesh, law, locking_angle=LOCKING, darts="auto", warp_direction=(1.0, 0.0, 0.0)
    )
    summary = darted.summary()
    assert summary["chosen_rule"] == "fall line" and summary["darts"] == 4
    assert darted.after.converged and darted.kept and darted.relieved
    assert darted.max_shear_after < 0.7 * LOCKING  # 29.9° against 55.5° without darts
    assert [r.rule for r in darted.rounds] == ["fall line"]  # the bisector placed none
    from vares.app.cli.drape import darts_verdict

    assert "with the darts open (placed along the mould's fall lines)" in darts_verdict(darted)


def test_fall_line_darts_move_with_the_mould(square_cup_pattern):
    """The draw direction is the mould's own (its cells' mean normal): a rigid motion of the
    mould moves the fall lines' darts with it."""
    from conftest import rotation

    mesh, _, before = square_cup_pattern
    shear = before.fields["shear_angle"]
    turn, shift = rotation(5), np.array([300.0, -20.0, 45.0])
    moved = SurfaceMesh(mesh.points @ turn.T + shift, mesh.cells)
    found = [fall_line_darts(m, shear, LOCKING, 0.8 * LOCKING) for m in (mesh, moved)]
    assert len(found[0]) == len(found[1]) == 4
    for line, other in zip(found[0], found[1], strict=True):
        assert np.isclose(line.length, other.length, rtol=1e-9)
        assert np.allclose(line.points @ turn.T + shift, other.points, atol=1e-8)


def test_a_nearly_closed_mould_has_no_fall_lines(monkeypatch):
    """A sphere less one triangle has no draw direction (its area vectors add up to 0.05 % of
    its area): no fall-line dart, where the same sheared region on the open hemisphere gets one
    (and the sphere gets one too when the draw direction is not asked for)."""
    import vares.analysis.dart_lines as dart_lines
    from vares.geometry.hard_surfaces import spherical_cap

    cap = spherical_cap(R, 90.0, 12)
    points, triangles = cap.points, cap.cells["triangle"]
    twin = np.arange(len(points)) + len(points)  # the lower half's nodes, the equator shared
    equator = np.flatnonzero(np.abs(points[:, 2]) < 1e-9)
    twin[equator] = equator
    cells = np.vstack([triangles, twin[triangles][:, ::-1]])[1:]  # less a triangle at the pole
    used = np.unique(cells)
    number = np.full(2 * len(points), -1)
    number[used] = np.arange(len(used))
    both = np.vstack([points, points * [1, 1, -1]])
    sphere = SurfaceMesh(both[used], {"triangle": number[cells]})

    def shear_of(mesh):  # 60° on a patch of the upper half about the 45° meridian
        middle = mesh.points[mesh.cells["triangle"]].mean(axis=1)
        azimuth = np.degrees(np.arctan2(middle[:, 1], middle[:, 0]))
        band = (np.abs(azimuth - 45.0) < 15.0) & (middle[:, 2] > 10.0) & (middle[:, 2] < 50.0)
        return np.where(band, 60.0, 0.0)

    (line,) = fall_line_darts(cap, shear_of(cap), LOCKING, 0.8 * LOCKING)
    assert abs(line.points[0, 2]) < 1e-9  # its mouth on the equator
    assert fall_line_darts(sphere, shear_of(sphere), LOCKING, 0.8 * LOCKING) == []
    monkeypatch.setattr(dart_lines, "DRAWN", 0.0)
    assert len(fall_line_darts(sphere, shear_of(sphere), LOCKING, 0.8 * LOCKING)) == 1
