"""Splices: a ply cut into pieces along lines across the mould, each piece's pattern solved; and
the Gauss curvature that tells where darts cannot relieve the shear (docs/composites.md,
"Splices")."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import error_line, run
from scipy.spatial import Delaunay

from vares.analysis.darts import over_locking_curvature
from vares.analysis.splices import SPLICE_SNAP, solve_with_splices, yarn_strain
from vares.geometry.curvature import FLAT, angle_defects, cell_gauss_curvature
from vares.geometry.double_dome import axis_splice, double_dome, double_dome_height
from vares.geometry.examples import irregular_cap
from vares.geometry.mesh import SurfaceMesh
from vares.geometry.outline import ring_area
from vares.geometry.surface_lines import CuttingError
from vares.materials import NonCrimpFabric

LOCKING = 50.0
NCF = NonCrimpFabric([-250.0, 250.0], [-250.0, 250.0], [0.5])


def plan_mesh(height, n: int = 21, half: float = 0.1) -> SurfaceMesh:
    """Delaunay triangles of an ``n × n`` plan grid over ``[-half, half]²`` at ``height(x, y)``."""
    s = np.linspace(-half, half, n)
    x, y = np.meshgrid(s, s)
    plan = np.column_stack([x.ravel(), y.ravel()])
    triangles = Delaunay(plan).simplices
    return SurfaceMesh(
        np.column_stack([plan, height(plan[:, 0], plan[:, 1])]), {"triangle": triangles}
    )


def test_the_gauss_curvature_of_a_sphere_a_plane_and_a_saddle():
    """K = 1/R² on the irregular hemisphere (the median to 0.5 %, every cell within 50 %: the
    angle defect of an irregular mesh scatters), 0 on a plane, −1 at the saddle point of z = xy."""
    cap = irregular_cap(100.0, 90.0, 30, 0.3, 1)
    curvature = cell_gauss_curvature(cap)
    assert np.isfinite(curvature).all()
    assert np.median(curvature) == pytest.approx(1e-4, rel=5e-3)
    assert curvature.min() > 0.5e-4 and curvature.max() < 1.5e-4
    plane = plan_mesh(lambda x, y: 0.3 * x - 0.2 * y + 1.0)
    assert np.abs(cell_gauss_curvature(plane) * plane.cell_areas()).max() < FLAT * 1e-6
    saddle = plan_mesh(lambda x, y: x * y)
    centres = saddle.points[saddle.cells["triangle"]].mean(axis=1)
    middle = np.argmin(np.linalg.norm(centres[:, :2], axis=1))
    assert cell_gauss_curvature(saddle)[middle] == pytest.approx(-1.0, rel=1e-2)


def test_the_double_domes_curvature_adds_up_to_nothing():
    """Gauss–Bonnet: the mould's boundary lies on the flat flange (its turning is 2π), so the
    interior nodes' angle defects add up to zero: the domes' positive curvature is balanced by
    the negative curvature of their concave feet and of the saddle. More than half of the area is
    negatively curved."""
    mould = double_dome()
    defects, _ = angle_defects(mould)
    assert defects.sum() == pytest.approx(0.0, abs=1e-9)
    assert defects[defects > 0].sum() > 5.0  # radians
    curvature = cell_gauss_curvature(mould)
    area = mould.cell_areas()
    assert area[curvature * area < -FLAT].sum() > 0.5 * area.sum()


@pytest.fixture(scope="module")
def spliced():
    """The shipped double dome spliced along its long axis (y = 0), the README's non-crimp
    fabric, warp along x."""
    mould = double_dome()
    return mould, solve_with_splices(
        mould, NCF, locking_angle=LOCKING, polylines=[axis_splice("x")], warp_direction=(1, 0, 0)
    )


def test_a_splice_along_the_long_axis_brings_the_double_dome_below_the_locking_angle(spliced):
    """The test that fails if the pieces did not drape separately: the whole ply shears to
    57.8°, beyond the locking angle, its two halves to 28.7° and 30.0° (measured). The pieces
    cover the mould: their areas add up to its area, every cell of the cut mould is in one."""
    mould, ply = spliced
    assert ply.before.converged and ply.converged
    assert ply.max_shear_before > LOCKING + 5.0
    assert len(ply.pieces) == 2 and len(ply.splice_lines) == 1
    shears = [np.abs(r.fields["shear_angle"]).max() for r in ply.results]
    assert max(shears) < 35.0 and ply.max_shear_after == pytest.approx(max(shears))
    # the part is symmetric about y = 0, its mesh is not: the halves agree (measured 28.83° and
    # 29.94°), a check of each piece against its mirror image
    assert abs(shears[0] - shears[1]) < 2.0
    assert ply.relieved
    areas = [r.mesh.area for r in ply.results]
    assert sum(areas) == pytest.approx(mould.area, rel=1e-9)
    assert abs(areas[0] - areas[1]) < 0.01 * mould.area  # the halves of a symmetric part
    assert sorted(np.unique(ply.cut.panel_ids)) == [0, 1]
    shear = ply.cell_field("shear_angle")
    for index, result in enumerate(ply.results):
        assert np.array_equal(shear[ply.cut.panel_ids == index], result.fields["shear_angle"])
        assert not result.overlap
    assert np.bincount(ply.cut.panel_ids).tolist() == [r.mesh.num_cells for r in ply.results]
    # (crossings within SPLICE_SNAP of a node moved onto it: no slivers)
    line = ply.splice_lines[0]
    edges = mould.points[mould.edges()]
    longest = np.linalg.norm(edges[:, 0] - edges[:, 1], axis=1).max()
    assert np.abs(line[:, 1]).max() < SPLICE_SNAP * longest
    assert np.ptp(line[:, 0]) > 0.99 * 310.0
    from vares.app.cli.drape import splices_verdict

    assert splices_verdict(ply).endswith("of its 2 pieces: below the locking angle")


def test_the_pieces_outlines_follow_the_drawn_splice_not_the_mesh(spliced):
    """The cut runs through nodes within SPLICE_SNAP of a cell from the line, so the pieces'
    edges along it zigzag (teeth whose corners turn by up to 143° in the halves' outlines, and
    the two halves of the symmetric part 0.8 % apart in flat area). Their outlines put those
    nodes onto the drawn line y = 0 (mapped into each pattern): no corner but the two where the
    splice meets the outline turns by more than 25° (measured 18.3°), and the halves' areas
    agree to 0.1 % (measured 0.04 %)."""
    _, ply = spliced
    areas, mesh_areas = [], []
    for index, (piece, result) in enumerate(zip(ply.pieces, ply.results, strict=True)):
        loops = piece.mesh.boundary_loops()
        rings = ply.outline(index)
        assert [len(r) for r in rings] == [len(loop) for loop in loops]
        outer = int(np.argmax([len(loop) for loop in loops]))
        ring, own = rings[outer], result.material_coordinates[loops[outer]]
        turns = {}
        for name, points in (("outline", ring), ("mesh", own)):
            before, after = points - np.roll(points, 1, 0), np.roll(points, -1, 0) - points
            cross = before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0]
            turns[name] = np.sort(np.abs(np.degrees(np.arctan2(cross, (before * after).sum(1)))))
        assert turns["outline"][-3] < 25.0 and turns["mesh"][-3] > 90.0  # two corners each
        moved = np.linalg.norm(ring - own, axis=1)
        assert 0.0 < moved.max() < SPLICE_SNAP * 15.0  # within 0.4 of the longest edge
        areas.append(abs(ring_area(ring)))
        mesh_areas.append(abs(ring_area(own)))
    assert abs(areas[0] - areas[1]) < 1e-3 * areas[0]
    assert abs(mesh_areas[0] - mesh_areas[1]) > 5e-3 * mesh_areas[0]


def test_the_spliced_pieces_buy_their_shear_with_no_yarn_strain(spliced):
    """The shear is not bought with yarn strain (as a law that stiffens towards locking does,
    docs/composites.md): the pieces' largest yarn strain cell by cell is well below the whole
    ply's (measured 4.6 and 5.0 % against 8.6 %), that of the nodal means about the same (1.1
    and 1.4 % against 1.3 %)."""
    _, ply = spliced
    whole = yarn_strain(ply.before)
    whole_mean = yarn_strain(ply.before, nodal_mean=True)
    summary = ply.summary()
    for piece in summary["pieces"]:
        assert piece["converged"] and piece["over_locking_fraction"] == 0.0
        assert piece["max_yarn_strain"] < 0.7 * whole.max()
        assert piece["max_yarn_strain_nodal_mean"] < 1.1 * whole_mean.max()
    assert summary["relieved"] and summary["splices"] == 1
    assert summary["splice_lengths"][0] > 310.0  # along the surface, over both domes


def test_the_double_domes_sheared_area_is_negatively_curved_the_hemispheres_positively(spliced):
    """Why darts do not relieve the double dome: nearly all of its area beyond the locking angle
    is negatively curved (measured 89 %), where a notch takes out fabric the mould needs; the
    hemisphere's is all positively curved, where darts relieve it."""
    _, ply = spliced
    shares = over_locking_curvature(ply.before, LOCKING)
    assert shares["negative"] > 0.8
    assert sum(shares.values()) == pytest.approx(1.0)
    import vares

    cap = irregular_cap(100.0, 90.0, 12, 0.3, 1)
    result = vares.solve(cap, NCF, warp_direction=(1.0, 0.0, 0.0))
    assert result.converged and np.abs(result.fields["shear_angle"]).max() > LOCKING
    assert over_locking_curvature(result, LOCKING)["positive"] == pytest.approx(1.0)


def test_darts_left_beyond_the_locking_angle_on_negative_curvature_advise_a_splice(spliced):
    """The darts' verdict on the double dome's pattern: the shear stays beyond the locking angle
    on negatively curved surface, and the line says to splice the ply there."""
    from vares.analysis.darts import DartedPattern
    from vares.app.cli.drape import darts_verdict

    _, ply = spliced
    darted = DartedPattern(ply.before, None, None, LOCKING)
    assert not darted.relieved and darted.needs_splices
    assert darted.summary()["over_locking_curvature"]["negative"] > 0.8
    assert "negatively curved" in darts_verdict(darted) and "--splice-lines" in darts_verdict(
        darted
    )
    from vares.app.ply_sections import curvature_advice  # the ply book's line for a laminate

    assert "negatively curved" in curvature_advice(darted)
    relaxed = DartedPattern(ply.before, None, None, 60.0)  # below a 60° locking angle already
    assert relaxed.relieved and not relaxed.needs_splices and not curvature_advice(relaxed)
    assert relaxed.summary()["over_locking_curvature"] is None


def test_a_piece_whose_kinematic_net_cannot_be_made_is_reported(spliced, monkeypatch):
    """The net is beside the pattern: a piece whose net fails (here every one) keeps its pattern
    and the summary says why, instead of the command failing."""
    import vares.analysis.drape as drape
    from vares.analysis.drape_options import DrapeOptions
    from vares.analysis.splices import drape_pieces
    from vares.geometry.drape_net import DrapeError

    _, ply = spliced
    fine = drape_pieces(ply, DrapeOptions(spacing=4.0), (1.0, 0.0, 0.0))
    assert all(p["kinematic"]["max_shear"] < LOCKING for p in fine.summary()["pieces"])

    def refuse(*_, **__):
        raise DrapeError("the warp direction is within 5° of the mould's normal at the seed")

    monkeypatch.setattr(drape, "drape_ply", refuse)
    failed = drape_pieces(ply, DrapeOptions(spacing=4.0), (1.0, 0.0, 0.0))
    for piece in failed.summary()["pieces"]:
        assert piece["kinematic"]["error"].startswith("no net: the warp direction")
        assert piece["converged"]


def test_crossing_splice_lines_cut_the_double_dome_into_quarters(tmp_path):
    """Splices along both axes cross at the saddle (refused before: "cutting lines 1 and 2
    meet"). The second is cut piece by piece, ending on the first: four pieces that cover the
    mould and meet at one node, three splices (the long one whole, the short one in two, each
    from the boundary to the crossing); each quarter shears far less than the whole ply
    (measured 57.8° whole, 16.6–21.3° the quarters). ``vares drape`` writes the four pieces."""
    mould = double_dome()
    lines = [axis_splice("x"), axis_splice("y")]
    ply = solve_with_splices(
        mould, NCF, locking_angle=LOCKING, polylines=lines, warp_direction=(1, 0, 0)
    )
    assert ply.converged and len(ply.pieces) == 4 and len(ply.cut.lines) == 3
    assert sum(r.mesh.area for r in ply.results) == pytest.approx(mould.area, rel=1e-9)
    assert ply.max_shear_before > LOCKING + 5.0 and ply.max_shear_after < 25.0
    points, chains = ply.cut.mesh.points, ply.cut.lines
    boundary = set(ply.cut.mesh.boundary_edges().ravel().tolist())
    ends = [int(c[k]) for c in chains for k in (0, -1)]
    crossing = [n for n in ends if n not in boundary]
    assert len(crossing) == 2 and crossing[0] == crossing[1]  # the short splice's two halves
    assert crossing[0] in chains[0][1:-1]  # on the long splice, between its ends
    assert np.abs(points[crossing[0], :2]).max() < 5.0  # at the saddle, x = y = 0 (mm)
    cells = ply.cut.mesh.cells["triangle"]
    around = ply.cut.panel_ids[np.any(cells == crossing[0], axis=1)]
    assert sorted(set(around.tolist())) == [0, 1, 2, 3]
    assert np.bincount(ply.cut.panel_ids).tolist() == [r.mesh.num_cells for r in ply.results]
    curves = tmp_path / "quarters.txt"
    curves.write_text(
        "\n\n".join("\n".join(" ".join(f"{v:.6f}" for v in p) for p in line) for line in lines)
        + "\n"
    )
    fabric = ["--material", "ncf", "--A=-250,250", "--B=-250,250", "--C", "0.5"]
    out = tmp_path / "out"
    result = run("drape", "--example", "double-dome", "--splice-lines", curves, *fabric, "-o", out)
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "drape.json").read_text())["splices"]
    assert len(data["pieces"]) == 4 and data["splices"] == 3 and data["relieved"]


def test_splice_lines_that_do_not_cut_the_mould_are_refused():
    mould = double_dome(cell_size=8.0)
    with pytest.raises(CuttingError, match="at least one splice line"):
        solve_with_splices(mould, NCF, locking_angle=LOCKING, polylines=[])
    inside = axis_splice("x")[150:250]  # ends on the domes, away from the outline
    with pytest.raises(CuttingError, match="boundary"):
        solve_with_splices(mould, NCF, locking_angle=LOCKING, polylines=[inside])
    # the same splice twice: the second runs along the first (it said "curve 1 is shorter than
    # a cell of the mesh" before)
    twice = [axis_splice("x"), axis_splice("x")]
    with pytest.raises(CuttingError, match="splice line 2 runs along a splice cut before it"):
        solve_with_splices(mould, NCF, locking_angle=LOCKING, polylines=twice)


def test_drape_command_with_splice_lines(tmp_path):
    """``vares drape --splice-lines``: the pieces' table and verdict, drape.json's splices,
    splices.vtu (the mould cut into pieces) and pieces.dxf (one seam and cut line per piece, the
    seam along the drawn splice);
    splices with darts, or without a fabric, are refused before anything is solved."""
    lines = tmp_path / "splice.txt"
    lines.write_text("\n".join(" ".join(f"{v:.6f}" for v in p) for p in axis_splice("x")) + "\n")
    fabric = ["--material", "ncf", "--A=-250,250", "--B=-250,250", "--C", "0.5"]
    out = tmp_path / "out"
    common = ["drape", "--example", "double-dome", "--splice-lines", lines]
    edges = ["--trim-allowance", "5", "--splice-overlap", "10"]
    result = run(*common, *fabric, *edges, "-o", out, "--report")
    assert result.exit_code == 0, result.stderr
    blank = json.loads((out / "drape.json").read_text())["blank"]
    data = json.loads((out / "drape.json").read_text())["splices"]
    assert data["relieved"] and len(data["pieces"]) == 2
    assert data["max_shear_before"] > 55.0 and data["max_shear_after"] < 35.0
    for piece in data["pieces"]:  # each piece's own kinematic net, from a seed on it
        assert piece["kinematic"]["max_shear"] < LOCKING  # measured 41.3° and 38.3°
        assert abs(piece["kinematic"]["seed"][1]) > 20.0  # on its own side of the splice
    html = (out / "drape.html").read_text()
    assert "<h2>Splices</h2>" in html and "figure-splices" in html
    assert (out / "splices.png").stat().st_size > 10_000
    import ezdxf
    import meshio

    cut = meshio.read(out / "splices.vtu")
    assert set(np.unique(cut.cell_data["piece"][0])) == {0.0, 1.0}
    assert np.nanmax(np.abs(cut.cell_data["shear_angle"][0])) == pytest.approx(
        data["max_shear_after"]
    )
    space = ezdxf.readfile(out / "pieces.dxf").modelspace()
    layers = [e.dxf.layer for e in space]
    assert layers.count("SEAM") == 2 and layers.count("CUT") == 2
    # the seam lines follow the drawn splice, not the zigzag of the cut's nodes: no corner but
    # the two where the splice meets the outline turns by more than 25° (the mesh's edges: teeth
    # of up to 143°)
    for seam in (e for e in space if e.dxf.layer == "SEAM"):
        ring = np.array([p[:2] for p in seam.get_points()])
        before, after = ring - np.roll(ring, 1, 0), np.roll(ring, -1, 0) - ring
        cross = before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0]
        turns = np.sort(np.abs(np.degrees(np.arctan2(cross, (before * after).sum(1)))))
        assert turns[-3] < 25.0 < turns[-2]
    # the cut lines: 5 outside the net along the mould's edge; along the splice the first
    # piece butt (cut to the line), the second lapping over it by 10
    from shapely.geometry import Point, Polygon

    seams = [np.array(e.get_points("xy")) for e in space if e.dxf.layer == "SEAM"]
    cuts = [np.array(e.get_points("xy")) for e in space if e.dxf.layer == "CUT"]
    for k, (seam, cut) in enumerate(zip(seams, cuts, strict=True)):
        net, trim = Polygon(seam), Polygon(cut)
        assert trim.contains(net.buffer(-1e-6))
        away = np.array([net.exterior.distance(Point(p)) for p in cut])
        assert np.sum(np.abs(away - 5.0) < 1e-6) > 20
        assert (np.sum(away < 1e-9) > 5) == (k == 0) and (
            np.sum(np.abs(away - 10.0) < 1e-6) > 5
        ) == (k == 1)
        assert blank["pieces"][k]["trim_area"] == pytest.approx(trim.area, rel=1e-9)
    assert blank["splice_overlap"] == 10.0
    refused = run(*common, *fabric, "--darts", "auto", "-o", tmp_path / "both")
    assert refused.exit_code == 2
    assert "give darts or --splice-lines, not both" in error_line(refused)
    # a curves file kept in the output folder is an input, which the run would replace: refused
    # in so many words, and the file is left as it was
    inside = out / "splice.txt"
    inside.write_text(lines.read_text())
    again = run(
        "drape", "--example", "double-dome", "--splice-lines", inside, *fabric, "-o", out, "-f"
    )
    assert again.exit_code == 2
    assert "lies in the output folder" in error_line(again)
    assert inside.read_text() == lines.read_text() and (out / "pieces.dxf").exists()
    bare = run(*common, "-o", tmp_path / "bare")
    assert bare.exit_code == 2
    assert "splices need the ply's fabric" in error_line(bare)
    assert not (tmp_path / "both").exists() and not (tmp_path / "bare").exists()


def test_the_nearest_segment_of_a_line_with_a_repeated_point():
    """A drawn line may repeat a point (a CAD polyline's doubled vertex): its segment of zero
    length is its point, not a NaN that the search for the nearest would pick."""
    from vares.analysis.dart_lines import to_segments

    line = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    distance, index, t = to_segments(np.array([1.5, 0.5, 0.0]), line[:-1], line[1:])
    assert (distance, index, t) == (pytest.approx(0.5), 2, pytest.approx(0.5))
    distance, index, t = to_segments(np.array([1.0, 2.0, 0.0]), line[1:2], line[2:3])
    assert np.isfinite(t) and distance == pytest.approx(2.0)


def test_splices_placed_through_the_seed(spliced):
    """``place_splices``: on the double dome from the saddle's centre the splice along the warp
    (the long axis) relieves the ply, as the designer's line along it does (to 0.5°); the fill's
    is tried beside it, the diagonals are not. A 45° ply is relieved along a diagonal of its
    yarns (the mould's long axis again) once neither yarn's splice does. A ply laid from a
    hemisphere's rim with its warp up the wall is spliced along the meridian. A ply below the
    locking angle gets none."""
    from vares.analysis.splice_lines import place_splices

    seed = (0.0, 0.0, float(double_dome_height(np.zeros(1), np.zeros(1))[0]))
    mould = double_dome()
    placed = place_splices(mould, NCF, locking_angle=LOCKING, seed=seed, warp_direction=(1, 0, 0))
    assert [t.angles for t in placed.trials] == [(0.0,), (90.0,)]
    assert placed.angles == (0.0,) and placed.spliced.relieved
    assert placed.spliced.max_shear_after == pytest.approx(spliced[1].max_shear_after, abs=0.5)
    (line,) = placed.spliced.polylines
    # the plane y = const through the seed's point on the mould (the faceted surface's, 0.06 mm
    # from the smooth dome's), the draw direction z and the warp x in it
    assert np.ptp(line[:, 1]) < 1e-9 and abs(line[0, 1]) < 0.1 and np.ptp(line[:, 0]) > 300.0
    assert placed.trials[1].max_shear > placed.trials[0].max_shear
    turned = place_splices(mould, NCF, locking_angle=LOCKING, seed=seed, warp_direction=(1, 1, 0))
    assert [t.angles for t in turned.trials][:4] == [(0.0,), (90.0,), (45.0,), (135.0,)]
    assert all(t.max_shear > LOCKING for t in turned.trials[:2])
    assert turned.angles == (135.0,) and turned.spliced.max_shear_after < 30.0
    (line,) = turned.spliced.polylines
    assert np.ptp(line[:, 1]) < 1e-9 and abs(line[0, 1]) < 0.1  # 135° from (1, 1, 0): along x
    # a ply laid from the rim with its warp up the wall (along the draw direction): the planes
    # contain the normal at the seed, and the splice runs along the meridian over the pole
    rim = place_splices(
        irregular_cap(100.0, 90.0, 20, 0.3, 1),
        NCF,
        locking_angle=LOCKING,
        seed=(100.0, 0.0, 0.0),
        warp_direction=(0, 0, 1),
    )
    (line,) = rim.spliced.polylines
    assert rim.angles == (0.0,) and rim.spliced.relieved
    assert np.abs(line[:, 1]).max() < 1.0 and line[:, 2].max() > 99.0  # over the pole
    soft = place_splices(
        irregular_cap(100.0, 90.0, 12, 0.3, 1),
        NonCrimpFabric([-250.0, 250.0], [-250.0, 250.0], [500.0]),
        locking_angle=LOCKING,
        seed=(0.0, 0.0, 100.0),
        warp_direction=(1, 0, 0),
    )
    assert soft.spliced is None and not soft.needed and soft.summary()["angles"] is None


def test_drape_command_places_splices(tmp_path):
    """``vares drape --splices auto``: the lines tried and the one taken on the console and in
    drape.json, the pieces' files; refused beside darts or drawn splice lines, or without a
    fabric; a ply that needs no splice gets none and no pieces' files."""
    fabric = ["--material", "ncf", "--A=-250,250", "--B=-250,250", "--C", "0.5"]
    out = tmp_path / "out"
    result = run(
        "drape", "--example", "double-dome", "--splices", "auto", *fabric, "-o", out, "--report"
    )
    assert result.exit_code == 0, result.stderr
    said = "splices placed through the seed at 0° from the warp (tried 0° 30.00°, 90° 44.22°)"
    assert said in result.stderr and said in (out / "drape.html").read_text()
    data = json.loads((out / "drape.json").read_text())["splices"]
    assert data["placed"]["angles"] == [0.0] and data["relieved"] and len(data["pieces"]) == 2
    assert (out / "pieces.dxf").exists() and (out / "splices.vtu").exists()
    for extra, message in [
        (["--darts", "auto", *fabric], "not both"),
        (["--splice-lines", tmp_path / "none.txt", *fabric], "not both"),
        ([], "splices need the ply's fabric"),
    ]:
        refused = run(
            "drape", "--example", "double-dome", "--splices", "auto", *extra, "-o", tmp_path / "r"
        )
        assert refused.exit_code == 2 and message in error_line(refused), refused.stderr
        assert not (tmp_path / "r").exists()
    soft = [
        "--material",
        "orthotropic",
        "--E1",
        "1000",
        "--E2",
        "1000",
        "--G12",
        "500",
        "--nu12",
        "0.3",
    ]
    calm = run("drape", "--example", "hemisphere", "--splices", "auto", *soft, "-o", tmp_path / "c")
    assert calm.exit_code == 0, calm.stderr
    assert "no splice needed" in calm.stderr
    assert not (tmp_path / "c" / "pieces.dxf").exists()
    assert json.loads((tmp_path / "c" / "drape.json").read_text())["splices"]["placed"] == {
        "needed": False,
        "trials": [],
        "angles": None,
    }
