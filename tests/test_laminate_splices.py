"""Splices in the plies of a laminate: a ply cut into pieces along lines across it, each piece
draped, cut, nested and booked on its own, its fibre directions read back per mould cell."""

import itertools
import json
import re

import ezdxf
import meshio
import numpy as np
import pytest
from conftest import run
from test_laminate_cutting import chromium
from test_laminate_darts import JOB, parse

from vares.analysis.dart_lines import erected_yarns
from vares.app.job import JobError
from vares.app.laminate_outputs import orientation_tables
from vares.app.ply_book import ply_book
from vares.geometry.examples import cap_over_square
from vares.geometry.mesh import SurfaceMesh
from vares.geometry.surface_lines import CuttingError
from vares.io.meshes import write_surface
from vares.io.ply_dxf import write_ply_dxf, write_ply_nest_dxf
from vares.materials import NonCrimpFabric
from vares.options import OptionsError
from vares.structures.laminate import Ply, PlyOptions, drape_laminate
from vares.structures.laminate_blanks import nest_plies, ply_blanks, side_by_side
from vares.structures.laminate_tasks import cut_origin

NCF = NonCrimpFabric.from_moduli(1000.0, 1000.0, 1.0)
RADIUS = 12.0


def mould():
    """A spherical cap of radius 12 over the square [-5, 5]², 200 triangles."""
    return cap_over_square(10.0, RADIUS, 10)


def across(x=None, y=None, reach=4.999):
    """A line on the cap from its boundary to its boundary: along y at ``x``, or along x at
    ``y``; off the grid's lines, so that it cuts cells."""
    t = np.linspace(-reach, reach, 60)
    xs, ys = (np.full_like(t, x), t) if x is not None else (t, np.full_like(t, y))
    z = np.sqrt(RADIUS**2 - xs**2 - ys**2) - np.sqrt(RADIUS**2 - 50.0)
    return np.column_stack([xs, ys, z])


SPLICES = (across(x=0.37), across(y=-0.41))


def plies(splices=SPLICES):
    return [
        Ply(PlyOptions(name="A", orientation=0.0), NCF, splice_lines=splices),
        Ply(PlyOptions(name="B", orientation=45.0), NCF),
    ]


@pytest.fixture(scope="module")
def plain():
    return drape_laminate(mould(), plies(None), workers=1, kinematic=True, trim_allowance=0.5)


@pytest.fixture(scope="module")
def spliced():
    return drape_laminate(mould(), plies(), workers=1, kinematic=True, trim_allowance=0.5)


def test_a_spliced_ply_is_four_pieces_and_the_other_ply_is_untouched(plain, spliced):
    a, b = spliced.drape("A"), spliced.drape("B")
    assert spliced.converged and a.is_spliced and not b.is_spliced
    assert [p.piece for p in a.pieces] == [f"piece-{k}" for k in range(1, 5)]
    assert [p.piece for p in b.pieces] == [None]
    # the whole ply is the pattern of the laminate without splices (the pair check's)
    np.testing.assert_array_equal(
        a.pattern.material_coordinates, plain.drape("A").pattern.material_coordinates
    )
    np.testing.assert_array_equal(b.warp, plain.drape("B").warp)
    for value in ("warp_compressed_fraction", "largest_compression", "mean_deviation"):
        np.testing.assert_array_equal(spliced.pair_matrix(value), plain.pair_matrix(value))
    # the pieces drape with less shear than the whole ply (8.2° on this cap)
    before, after = a.spliced.max_shear_before, a.spliced.max_shear_after
    assert before == pytest.approx(plain.drape("A").summary()["max_shear"])
    assert after < 0.5 * before
    summary = a.summary()
    assert summary["max_shear"] == pytest.approx(after)
    assert summary["splices"]["pieces"][0]["name"] == "piece-1"


def test_the_pieces_cells_lie_in_the_mould_cells_and_make_up_their_areas(spliced):
    a = spliced.drape("A")
    cut = a.spliced.cut
    origin = cut_origin(a.mesh, cut.mesh)
    count = np.bincount(origin, minlength=a.mesh.num_cells)
    assert count.min() == 1 and count.max() > 1  # the lines cut cells
    np.testing.assert_allclose(
        np.bincount(origin, cut.mesh.cell_areas(), a.mesh.num_cells), a.mesh.cell_areas(), rtol=1e-9
    )
    # every piece's cells are those of the cut mesh it is made of, in their order
    for index, piece in enumerate(a.spliced.pieces):
        cells = np.flatnonzero(cut.panel_ids == index)
        np.testing.assert_allclose(
            piece.mesh.cell_areas(), cut.mesh.cell_areas()[cells], rtol=1e-12
        )


def test_orientations_of_a_spliced_ply_are_its_pieces_per_mould_cell(spliced):
    """One row per mould cell: a whole cell's directions and shear are those of its piece's
    pattern, a split cell's the area-weighted mean of its parts' (normalised)."""
    a = spliced.drape("A")
    (table,) = [t for t in orientation_tables(spliced) if t.name == "A"]
    np.testing.assert_array_equal(table.elements, np.arange(1, spliced.mesh.num_cells + 1))
    cut = a.spliced.cut
    warp = np.zeros((cut.mesh.num_cells, 3))
    for index, (piece, result) in enumerate(zip(a.spliced.pieces, a.spliced.results, strict=False)):
        cells = cut.panel_ids == index
        warp[cells] = erected_yarns(
            piece.mesh, result.material_coordinates, result.fibres.warp, result.fibres.fill
        )[0]
    shear = a.spliced.cell_field("shear_angle")
    origin, areas = cut_origin(a.mesh, cut.mesh), cut.mesh.cell_areas()
    count = np.bincount(origin, minlength=a.mesh.num_cells)
    whole = np.flatnonzero(count[origin] == 1)
    np.testing.assert_allclose(table.warp[origin[whole]], warp[whole], rtol=0, atol=1e-12)
    np.testing.assert_allclose(table.shear_angle[origin[whole]], shear[whole], atol=1e-12)
    for cell in np.flatnonzero(count > 1):
        parts = origin == cell
        mean = areas[parts] @ warp[parts]
        np.testing.assert_allclose(table.warp[cell], mean / np.linalg.norm(mean), atol=1e-12)
        np.testing.assert_allclose(
            table.shear_angle[cell], areas[parts] @ shear[parts] / areas[parts].sum(), atol=1e-12
        )


def test_every_piece_has_its_own_kinematic_net(plain, spliced):
    a = spliced.drape("A")
    nets = a.spliced.nets
    assert nets is not None and all(n is not None for n in nets)
    cut = a.spliced.cut
    origin = cut_origin(a.mesh, cut.mesh)
    count = np.bincount(origin, minlength=a.mesh.num_cells)
    for index, net in enumerate(nets):
        cells = np.flatnonzero(cut.panel_ids == index)
        whole = cells[count[origin[cells]] == 1]
        shear = net.drape.shear_angle[np.searchsorted(cells, whole)]
        np.testing.assert_allclose(a.kinematic_shear_angle[origin[whole]], shear, atol=1e-12)
    # each net seeded on its own piece shears less than the whole ply's
    whole_net = np.nanmax(np.abs(plain.drape("A").kinematic_shear_angle))
    assert np.nanmax(np.abs(a.kinematic_shear_angle)) < whole_net
    # the whole ply's net stays beside the whole pattern
    assert a.kinematic is not None
    ours, whole = a.summary()["kinematic_drape"], plain.drape("A").summary()["kinematic_drape"]
    assert ours["producibility"] == whole["producibility"]
    assert ours["against_pattern"] == whole["against_pattern"]


def test_each_piece_is_a_blank_and_all_are_nested(spliced, tmp_path):
    blanks = ply_blanks(spliced)
    assert [b.label for b in blanks] == [f"A piece-{k}" for k in range(1, 5)] + ["B"]
    pieces = blanks[:4]
    assert all(b.pieces == 4 for b in pieces) and blanks[4].pieces == 1
    # the pieces cover the mould: their areas on it add up to the ply's
    total = sum(b.surface_area for b in pieces)
    assert total == pytest.approx(spliced.mesh.cell_areas().sum(), rel=1e-12)
    # the net boundary along a splice is the drawn line's, not the mesh's edge (which runs
    # through the nodes at x = 0, 0.37 from the line): each piece's net area is that of its
    # region of the sphere bounded by the drawn lines (integrated over the plan), times its
    # pattern's flat-over-mould area ratio, to 0.2 % (measured 0.06 %); the mesh's loops are
    # up to 13 % off
    n = 2000
    plan = (np.arange(n) + 0.5) / n * 10.0 - 5.0
    x, y = np.meshgrid(plan, plan)
    element = RADIUS / np.sqrt(RADIUS**2 - x**2 - y**2) * (10.0 / n) ** 2
    errors = []
    for blank, piece in zip(pieces, spliced.drape("A").pieces, strict=True):
        assert blank.mesh is piece.mesh
        assert blank.trim_area > blank.net_area
        middle = piece.mesh.points.mean(axis=0)
        region = ((x < 0.37) == (middle[0] < 0.37)) & ((y < -0.41) == (middle[1] < -0.41))
        flat = piece.pattern.fields["pattern_area"].sum()
        expected = element[region].sum() * flat / piece.mesh.area
        assert blank.net_area == pytest.approx(expected, rel=2e-3)
        errors.append(abs(flat - expected) / expected)
    assert max(errors) > 0.1  # the mesh's own boundary would not do
    # the seed (the mould's node nearest its centroid, (0, 0)) lies on the splice (the line at
    # x = 0.37 is cut through the nodes at x = 0): every rosette at its piece's node nearest
    # its middle (a seed inside a piece: test_a_seed_inside_a_piece_holds_its_rosette)
    seed = spliced.drape("A").seed
    held = []
    for blank in pieces:
        points = blank.mesh.points
        node = int(np.argmin(np.linalg.norm(points - seed, axis=1)))
        inside = np.allclose(points[node], seed) and node not in blank.mesh.boundary_edges()
        if not inside:
            node = int(np.argmin(np.linalg.norm(points - points.mean(axis=0), axis=1)))
        held.append(inside)
        np.testing.assert_array_equal(blank.origin, blank.coordinates[node])
    assert sum(held) == 0
    from shapely.geometry import Point, Polygon

    for blank in pieces:
        assert Polygon(blank.net[0]).buffer(1e-9).contains(Point(blank.origin))
    nest = nest_plies(blanks, 30.0, time_limit=1.0)
    assert sorted(p.index for p in nest.pieces) == list(range(5))
    write_ply_nest_dxf(tmp_path / "nest.dxf", blanks, nest, units="mm")
    space = ezdxf.readfile(tmp_path / "nest.dxf").modelspace()
    assert len([e for e in space if e.dxf.layer == "NET"]) == 5
    labels = [e.dxf.text for e in space if e.dxf.layer == "LABEL"]
    assert sum(text == "A piece-3" for text in labels) == 1


def test_the_laminates_automatic_darts_pass_a_spliced_ply_by():
    """``darts = "auto"`` for the laminate darts the ply that names no splices and leaves the
    spliced one to its pieces: at a locking angle of 6° the 0° and 90° plies (8.2° on this cap)
    both need darts; the 90° ply C gets them, the spliced 0° ply A none."""
    result = drape_laminate(
        mould(),
        [plies()[0], Ply(PlyOptions(name="C", orientation=90.0), NCF)],
        workers=1,
        kinematic=False,
        darts="auto",
        locking_angle=6.0,
    )
    a, c = result.drape("A"), result.drape("C")
    assert a.is_spliced and a.darted is None and not a.is_darted
    assert c.is_darted and not c.is_spliced


def test_plies_share_a_drape_only_with_the_same_splices():
    """The drape's key digests the lines one by one: two lines are not their concatenation,
    and the same lines give the same key (the plies of a symmetric stack share a drape)."""
    from vares.structures.laminate_options import LaminateOptions
    from vares.structures.laminate_tasks import drape_key

    ply, options = plies()[0], LaminateOptions()
    seed, cells = np.zeros(3), np.arange(4)

    def key(lines):
        return drape_key(ply, options, seed, cells, None, {"locking_angle": 50.0,
                                                           "polylines": lines})  # fmt: skip

    first, second = SPLICES
    assert key([first, second]) == key([first.copy(), second.copy()])
    assert key([first, second]) != key([np.vstack([first, second])])
    assert key([first, second]) != key([second, first])


def test_a_seed_inside_a_piece_holds_its_rosette():
    seed = mould().points[23]  # (-4, -3): inside the piece on x < 0.37, y < -0.41
    result = drape_laminate(
        mould(), plies()[:1], workers=1, kinematic=False, seed=tuple(seed.tolist())
    )
    origins = []
    for blank in ply_blanks(result):
        points = blank.mesh.points
        at_seed = np.flatnonzero(np.all(points == seed, axis=1))
        middle = int(np.argmin(np.linalg.norm(points - points.mean(axis=0), axis=1)))
        node = int(at_seed[0]) if at_seed.size else middle
        np.testing.assert_array_equal(blank.origin, blank.coordinates[node])
        origins.append(bool(at_seed.size))
    assert origins.count(True) == 1


def test_a_spliced_plys_cutter_file_holds_its_pieces_side_by_side(spliced, tmp_path):
    pieces = [b for b in ply_blanks(spliced) if b.name == "A"]
    write_ply_dxf(tmp_path / "A.dxf", pieces, units="mm")
    space = ezdxf.readfile(tmp_path / "A.dxf").modelspace()
    nets = [np.array([p[:2] for p in e.get_points()]) for e in space if e.dxf.layer == "NET"]
    shifts = side_by_side(pieces)
    assert len(nets) == 4
    for drawn, blank, shift in zip(nets, pieces, shifts, strict=False):
        np.testing.assert_allclose(drawn, blank.net[0] + shift, atol=1e-9)
    # laid out without overlap: each piece's trim line clear of the next one's
    from shapely.geometry import Polygon

    trims = [Polygon(b.trim[0] + s) for b, s in zip(pieces, shifts, strict=False)]
    assert all(not p.intersects(q) for p, q in itertools.pairwise(trims))


def test_the_ply_book_has_a_section_per_piece(spliced):
    blanks = ply_blanks(spliced)
    text = ply_book(spliced, blanks, None, units="mm")
    a = spliced.drape("A").spliced
    for k in range(1, 5):
        section = text.split(f"id='ply-A-piece-{k}'")[1].split("</section>")[0]
        assert f"Ply A, piece-{k} of 4" in section
        assert "<h3>Splices</h3>" in section
        assert f"{a.max_shear_before:.4g}°" in section
        # the whole ply's picture with its splices, once: in the first piece's section
        assert (f'id="figure-A-piece-{k}-splices"' in section) == (k == 1)
    assert text.count('-splices"') == 1
    assert "id='ply-B'" in text


def write_curves(path, lines):
    text = "\n\n".join("\n".join(" ".join(f"{v:.17g}" for v in p) for p in line)
                       for line in lines)  # fmt: skip
    path.write_text(text + "\n", encoding="utf-8")


def test_cli_cuts_a_spliced_ply_into_pieces(tmp_path):
    write_surface(tmp_path / "mould.obj", mould())
    write_curves(tmp_path / "splices.txt", SPLICES)
    job = JOB.replace(
        "kinematic = false", "trim_allowance = 0.5\nroll_width = 30.0\nnest_time = 1.0"
    )
    job += '\n[[ply]]\nname = "A"\nsplice_lines = "splices.txt"\n'
    job += '\n[[ply]]\nname = "B"\norientation = 45.0\n'
    (tmp_path / "job.toml").write_text(job, encoding="utf-8")
    result = run("laminate", tmp_path / "job.toml")
    assert result.exit_code == 0, result.stderr
    assert re.search(r"4 pieces: largest shear 8\.\d\d° -> [0-4]\.\d\d°", result.stderr)
    assert "nest: 5 blanks on a roll" in result.stderr
    out = tmp_path / "out"
    summary = json.loads((out / "laminate.json").read_text(encoding="utf-8"))
    pieces = [b["piece"] for b in summary["blanks"]]
    assert pieces == ["piece-1", "piece-2", "piece-3", "piece-4", None]
    assert summary["drapes"][0]["splices"]["splices"] >= 2
    assert len(summary["nest"]["pieces"]) == 5
    # the flat pieces in one pattern file, each cell's piece named
    flat = meshio.read(out / "patterns" / "drape_0deg.vtu")
    number = np.concatenate(flat.cell_data["piece"])
    cut = sum(p["cells"] for p in summary["drapes"][0]["splices"]["pieces"])
    assert len(number) == cut > mould().num_cells
    assert sorted(np.unique(number)) == [1, 2, 3, 4]
    assert np.ptp(flat.points[:, 2]) == 0.0
    # the cutter file: the four pieces
    space = ezdxf.readfile(out / "plies" / "A.dxf").modelspace()
    assert len([e for e in space if e.dxf.layer == "NET"]) == 4
    # the orientation table: one row per mould cell
    inp = (out / "orientations.inp").read_text(encoding="utf-8")
    assert inp.count("*ORIENTATION, NAME=") == 2
    csv = (out / "orientations.csv").read_text(encoding="utf-8").splitlines()
    assert sum(line.split(",")[1] == "A" for line in csv[1:]) == mould().num_cells
    # the ply book as Chromium reads it: a section per piece, with its pictures
    dom = chromium(tmp_path, "--dump-dom", (out / "plybook.html").as_uri()).stdout
    for k in range(1, 5):
        section = dom.split(f'id="ply-A-piece-{k}"')[1].split("</section>")[0]
        assert f'id="splices-A-piece-{k}"' in section
        for kind in ("blank", "shear", "producibility"):
            assert f'id="figure-A-piece-{k}-{kind}"' in section
        assert (f'id="figure-A-piece-{k}-splices"' in section) == (k == 1)


def test_splice_options_are_checked(tmp_path):
    ply = '\n[[ply]]\nname = "A"\n'
    job = parse(JOB + ply + 'splice_lines = "s.txt"\n')
    assert job.plies[0].splice_lines == "s.txt"
    with pytest.raises(JobError, match="darts or splice_lines, not both"):
        parse(JOB + ply + 'splice_lines = "s.txt"\ndarts = "auto"\n')
    with pytest.raises(JobError, match="darts or splice_lines, not both"):
        parse(JOB + ply + 'splice_lines = "s.txt"\ndart_lines = "d.txt"\n')
    with pytest.raises(OptionsError, match="darts or splice lines, not both"):
        Ply(PlyOptions(name="A", darts="auto"), NCF, splice_lines=SPLICES)
    # a missing file, named with its ply and key
    write_surface(tmp_path / "mould.obj", mould())
    (tmp_path / "job.toml").write_text(JOB + ply + 'splice_lines = "none.txt"\n', "utf-8")
    result = run("laminate", tmp_path / "job.toml")
    assert result.exit_code == 2, result.stderr
    assert "[[ply]] A splice_lines:" in result.stderr and "none.txt" in result.stderr
    assert not (tmp_path / "out").exists()


def test_splices_that_cannot_be_cut_are_refused_with_the_ply_named():
    with pytest.raises(CuttingError, match=r"ply A: .*away from the surface's boundary"):
        drape_laminate(mould(), plies((across(x=0.37, reach=2.0),)), workers=1, kinematic=False)
    quads = SurfaceMesh(
        np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0.2], [2, 1, 0]], float),
        {"quad": np.array([[0, 1, 4, 3], [1, 2, 5, 4]])},
    )
    with pytest.raises(OptionsError, match="splices need a mould of triangles"):
        drape_laminate(quads, plies()[:1], kinematic=False)


def _with_options(result, **changes):
    """The laminate's result with its options changed (the drapes as they are)."""
    options = result.laminate.options.replace(**changes)
    laminate = type(result.laminate)(result.laminate.plies, options)
    return type(result)(**{**result.__dict__, "laminate": laminate})


def _offsets(blank, joints):
    """Per edge of a piece's net outline: how far its trim line lies from the edge's middle, and
    the piece across the edge (−1 on the mould's edge)."""
    from shapely.geometry import LinearRing, Point

    trim = LinearRing(blank.trim[0])
    ring = blank.net[0]
    middles = 0.5 * (ring + np.roll(ring, -1, axis=0))
    return np.array([trim.distance(Point(m)) for m in middles]), joints


def test_splices_butt_by_default_and_a_later_piece_laps_by_the_overlap(spliced):
    """Along a splice a piece is cut to the line (butt), not grown by the trim allowance: two
    pieces cut with it would overlap by twice the allowance. With ``splice_overlap`` each piece
    laps over the pieces before it by the overlap. The mould's edge keeps the trim allowance."""
    drape = spliced.drape("A")
    pieces = drape.spliced
    for overlap in (0.0, 0.3):
        blanks = [b for b in ply_blanks(_with_options(spliced, splice_overlap=overlap))[:4]]
        for index, blank in enumerate(blanks):
            (joints,) = pieces.joints(index)  # (one loop: the piece's outline)
            assert (joints >= 0).any() and (joints < 0).any()
            # the net ring as the blank has it (counter-clockwise): its edges' pieces
            if not np.allclose(blank.net[0], pieces.outline(index)[0]):
                joints = np.roll(joints[::-1], -1)
            distance, across = _offsets(blank, joints)
            ring = blank.net[0]
            length = np.linalg.norm(np.roll(ring, -1, axis=0) - ring, axis=1)
            # edges away from the outline's corners (whose mitres reach further)
            corner = np.zeros(len(ring), dtype=bool)
            for k in np.flatnonzero(np.diff(np.concatenate([across, across[:1]])) != 0):
                corner[[(k + d) % len(ring) for d in (-1, 0, 1, 2)]] = True
            edge = (across < 0) & ~corner
            before, after = (across >= 0) & (across < index) & ~corner, (across > index) & ~corner
            assert np.allclose(distance[edge], 0.5, atol=1e-9)
            assert np.allclose(distance[after], 0.0, atol=1e-9)
            assert np.allclose(distance[before], overlap, atol=1e-9)
            expected = sorted({int(j) for j in across[(across >= 0) & (across < index)]})
            names = tuple(pieces.pieces[j].name for j in expected) if overlap else ()
            assert blank.laps_over == names and blank.splice_overlap == overlap
            # the trim area: the net's grown by the allowance along the mould's edge (and the
            # overlap along the splices before it), never along the others
            grown = blank.net_area + 0.5 * length[across < 0].sum()
            grown += overlap * length[(across >= 0) & (across < index)].sum()
            assert blank.trim_area == pytest.approx(grown, rel=0.05)
        assert blanks[0].laps_over == () and (overlap == 0 or blanks[-1].laps_over)
    # an overlap as wide as half a piece is no strip beside a splice: refused, naming the ply
    with pytest.raises(CuttingError, match=r"ply A: splice_overlap = 3 is half as wide as its"):
        ply_blanks(_with_options(spliced, splice_overlap=3.0))
    # the other ply, cut whole, has the trim allowance all round
    whole = ply_blanks(spliced)[4]
    distance, _ = _offsets(whole, np.full(len(whole.net[0]), -1))
    assert np.median(distance) == pytest.approx(0.5, abs=1e-9) and whole.laps_over == ()


def test_splices_placed_in_a_laminates_plies():
    """``splices = "auto"``: a laminate's ply that reaches its locking angle is spliced through
    its seed (the shipped double dome along its long axis, below 35°); a ply that says
    ``splices = "none"`` is not; a ply's own darts or lines override the laminate's splices.
    Both at once are refused."""
    from vares.geometry.double_dome import double_dome
    from vares.structures.laminate_options import LaminateOptions
    from vares.structures.laminate_tasks import cutting_modes

    ncf = NonCrimpFabric([-250.0, 250.0], [-250.0, 250.0], [0.5])
    laminate = drape_laminate(
        double_dome(),
        [Ply(PlyOptions(name="A"), ncf), Ply(PlyOptions(name="B", splices="none"), ncf)],
        splices="auto",
        workers=1,
        kinematic=False,
    )
    a, b = laminate.drape("A"), laminate.drape("B")
    assert a.is_spliced and [p.piece for p in a.pieces] == ["piece-1", "piece-2"]
    assert a.spliced.relieved and a.spliced.max_shear_after < 35.0
    (line,) = a.spliced.polylines
    # along the warp, through the seed: the warp at the seed is the reference x on the facet
    # there, within a degree of x in plan
    assert np.ptp(line[:, 0]) > 300.0 and np.ptp(line[:, 1]) < 0.02 * np.ptp(line[:, 0])
    assert not b.is_spliced and np.nanmax(np.abs(b.shear_angle)) > 50.0
    placed = a.summary()["splices"]["placed"]
    assert placed["needed"] and placed["angles"] == [0.0] and len(placed["trials"]) == 2
    assert b.summary()["splices"] is None
    book = ply_book(laminate, ply_blanks(laminate), None, units="mm")
    assert "through the seed at 0° from the warp (tried 0°" in book
    blanks = ply_blanks(laminate)
    assert [(k.name, k.piece) for k in blanks] == [("A", "piece-1"), ("A", "piece-2"), ("B", None)]
    spliced, darted = LaminateOptions(splices="auto"), LaminateOptions(darts="auto")
    plain = LaminateOptions()
    cases = [
        (PlyOptions(name="P"), spliced, ("none", "auto")),
        (PlyOptions(name="P", darts="auto"), spliced, ("auto", "none")),
        (PlyOptions(name="P", darts="none"), spliced, ("none", "auto")),
        (PlyOptions(name="P", splices="none"), spliced, ("none", "none")),
        (PlyOptions(name="P", splices="auto"), darted, ("none", "auto")),
        (PlyOptions(name="P"), darted, ("auto", "none")),
        (PlyOptions(name="P"), plain, ("none", "none")),
    ]
    for options, table, modes in cases:
        assert cutting_modes(Ply(options, ncf), table) == modes, (options, table)
    lines = Ply(PlyOptions(name="P"), ncf, splice_lines=SPLICES)
    assert cutting_modes(lines, darted) == ("none", "lines")
    with pytest.raises(OptionsError, match="darts = 'auto' or splices = 'auto'"):
        LaminateOptions(darts="auto", splices="auto")
    with pytest.raises(OptionsError, match="splices = 'auto', darts or splice_lines"):
        PlyOptions(name="P", splices="auto", darts="auto")
    with pytest.raises(OptionsError, match="splices = 'auto', darts or splice_lines"):
        PlyOptions(name="P", splices="auto", splice_lines="s.txt")
