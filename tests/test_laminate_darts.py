"""Darts in the plies of a laminate (a ply cut open where its shear reaches its locking angle) and a
laminate's plies draped on a Dask cluster."""

import re
import tomllib
from dataclasses import replace

import ezdxf
import numpy as np
import pytest
from conftest import run
from test_laminate_cutting import chromium

from vares.analysis.dart_lines import erected_yarns
from vares.app.job import JobError
from vares.app.laminate_job import LaminateJob, load_laminate_job
from vares.app.laminate_outputs import orientation_tables
from vares.app.ply_book import ply_book
from vares.geometry.examples import cap_over_square
from vares.io.meshes import write_surface
from vares.io.orientations import read_orientation_csv
from vares.io.ply_dxf import write_ply_dxf, write_ply_nest_dxf
from vares.materials import NonCrimpFabric
from vares.options import OptionsError
from vares.structures.laminate import Ply, PlyOptions, drape_laminate
from vares.structures.laminate_blanks import nest_plies, ply_blanks

NCF = NonCrimpFabric.from_moduli(1000.0, 1000.0, 1.0)
#: Below the 0° ply's largest shear on this cap (8.2°), above the 45° ply's (5.1°).
LOCKING = 6.0


def mould():
    """A spherical cap over a square, 200 triangles."""
    return cap_over_square(10.0, 12.0, 10)


def plies():
    return [
        Ply(PlyOptions(name="A", orientation=0.0), NCF),
        Ply(PlyOptions(name="B", orientation=45.0), NCF),
    ]


@pytest.fixture(scope="module")
def plain():
    return drape_laminate(mould(), plies(), workers=1, kinematic=False, trim_allowance=0.5)


@pytest.fixture(scope="module")
def darted():
    return drape_laminate(
        mould(),
        plies(),
        workers=1,
        kinematic=False,
        trim_allowance=0.5,
        darts="auto",
        locking_angle=LOCKING,
    )


def test_darts_relieve_the_ply_that_needs_them_and_leave_the_other(plain, darted):
    a, b = darted.drape("A"), darted.drape("B")
    assert darted.converged and a.is_darted and not b.is_darted
    assert a.darted.max_shear_before == pytest.approx(plain.drape("A").summary()["max_shear"])
    assert a.darted.max_shear_before >= LOCKING > a.darted.max_shear_after
    assert a.darted.relieved and len(a.darted.dart_lines) >= 1
    # the ply without darts needed is the very pattern of the laminate without darts
    np.testing.assert_array_equal(
        b.pattern.material_coordinates, plain.drape("B").pattern.material_coordinates
    )
    np.testing.assert_array_equal(b.warp, plain.drape("B").warp)
    # the pair check is of the blanks without darts: the same as without darts
    for value in ("warp_compressed_fraction", "largest_compression", "mean_deviation"):
        np.testing.assert_array_equal(darted.pair_matrix(value), plain.pair_matrix(value))


def test_darted_cells_lie_in_the_mould_cells(darted):
    """The opened mesh is not the mould's cells with twin nodes: the dart lines' points become
    nodes, so every cell a dart crosses is split. Each opened cell lies in one mould cell, the
    pieces of a cell make up its area, and a cell no dart crosses is that very triangle."""
    a = darted.drape("A")
    slits = a.darted.slits
    origin, opened = slits.cell_origin, slits.mesh
    count = np.bincount(origin, minlength=a.mesh.num_cells)
    assert count.min() == 1 and count.max() > 1  # split cells exist: one-to-one it is not
    np.testing.assert_allclose(
        np.bincount(origin, opened.cell_areas(), a.mesh.num_cells),
        a.mesh.cell_areas(),
        rtol=1e-9,
    )
    whole = np.flatnonzero(count[origin] == 1)
    corners = np.sort(opened.points[opened.cells["triangle"][whole]], axis=1)
    mould_corners = np.sort(a.mesh.points[a.mesh.cells["triangle"][origin[whole]]], axis=1)
    np.testing.assert_array_equal(corners, mould_corners)


def test_orientation_table_of_a_darted_ply_is_per_mould_cell(darted, tmp_path):
    """One row per mould cell; a whole cell's directions are its piece's in the darted pattern,
    a split cell's the area-weighted mean of its pieces', normalised."""
    a = darted.drape("A")
    tables = {t.name: t for t in orientation_tables(darted)}
    table = tables["A"]
    np.testing.assert_array_equal(table.elements, np.arange(1, darted.mesh.num_cells + 1))
    slits, after = a.darted.slits, a.darted.after
    warp, fill = erected_yarns(
        slits.mesh, after.material_coordinates, after.fibres.warp, after.fibres.fill
    )
    origin, areas = slits.cell_origin, slits.mesh.cell_areas()
    count = np.bincount(origin, minlength=a.mesh.num_cells)
    whole = np.flatnonzero(count[origin] == 1)
    np.testing.assert_allclose(table.warp[origin[whole]], warp[whole], rtol=0, atol=1e-12)
    np.testing.assert_allclose(table.fill[origin[whole]], fill[whole], rtol=0, atol=1e-12)
    shear = after.fields["shear_angle"]
    np.testing.assert_allclose(table.shear_angle[origin[whole]], shear[whole], atol=1e-12)
    for cell in np.flatnonzero(count > 1):
        pieces = origin == cell
        mean = areas[pieces] @ warp[pieces]
        np.testing.assert_allclose(table.warp[cell], mean / np.linalg.norm(mean), atol=1e-12)


def test_darted_dxf_has_the_dart_lines_on_layer_dart(darted, tmp_path):
    blanks = {b.name: b for b in ply_blanks(darted)}
    a, b = blanks["A"], blanks["B"]
    assert len(a.darts) == len(darted.drape("A").darted.dart_lines) and not b.darts
    path = tmp_path / "A.dxf"
    write_ply_dxf(path, a, units="mm")
    space = ezdxf.readfile(path).modelspace()
    lines = [e for e in space if e.dxf.layer == "DART"]
    assert len(lines) == len(a.darts)
    (net,) = [e for e in space if e.dxf.layer == "NET"]
    outline = np.array([p[:2] for p in net.get_points()])
    for line, dart in zip(lines, a.darts, strict=True):
        drawn = np.array([p[:2] for p in line.get_points()])
        assert not line.closed
        np.testing.assert_allclose(drawn, dart, rtol=0, atol=1e-9)
        # both lips are the blank's boundary: every point of the dart is a point of the net
        gaps = np.linalg.norm(drawn[:, None] - outline[None], axis=2).min(axis=1)
        assert gaps.max() < 1e-9
        # the mouth is open, the tip one point
        assert np.linalg.norm(drawn[0] - drawn[-1]) > 0.01
    path = tmp_path / "B.dxf"
    write_ply_dxf(path, b, units="mm")
    assert not [e for e in ezdxf.readfile(path).modelspace() if e.dxf.layer == "DART"]
    # on the roll: each dart placed with its ply
    nest = nest_plies([a, b], 40.0, time_limit=1.0)
    write_ply_nest_dxf(tmp_path / "nest.dxf", [a, b], nest, units="mm")
    space = ezdxf.readfile(tmp_path / "nest.dxf").modelspace()
    nested = [e for e in space if e.dxf.layer == "DART"]
    assert len(nested) == len(a.darts)
    (piece,) = [p for p in nest.pieces if p.index == 0]
    for line, dart in zip(nested, a.darts, strict=True):
        drawn = np.array([p[:2] for p in line.get_points()])
        np.testing.assert_allclose(drawn, piece.place(dart), rtol=0, atol=1e-9)


def test_ply_book_shows_the_darts(darted):
    blanks = ply_blanks(darted)
    text = ply_book(darted, blanks, None, units="mm")
    a = darted.drape("A").darted
    rows = re.search(r'<table id="darts-table-A">.*?</table>', text, re.S)
    assert rows is not None
    assert rows.group(0).count("<tr>") - 1 == len(a.dart_lines)
    summary = re.search(r"<p id='darts-A'>(.*?)</p>", text, re.S).group(1)
    assert f"{a.max_shear_before:.4g}°" in summary and f"{a.max_shear_after:.4g}°" in summary
    assert "below the locking angle" in summary
    assert "The lips butt" in summary  # (no dart_overlap)
    assert "No darts needed" in re.search(r"<p id='darts-B'>(.*?)</p>", text, re.S).group(1)


def test_darts_that_do_not_lower_the_shear_are_reported_and_not_cut(darted):
    """Darts whose solve leaves the largest shear as high (the rib's, docs/composites.md): the
    ply is cut whole, and the book says the darts were tried."""
    a = darted.drape("A")
    worse = replace(
        a.darted,
        rounds=[replace(r, max_shear=a.darted.max_shear_before + 0.1) for r in a.darted.rounds],
    )
    tried = replace(a, darted=worse)
    assert not tried.is_darted and tried.blank_mesh is tried.mesh
    assert tried.blank_pattern is tried.pattern
    result = replace(darted, drapes=[tried, darted.drape("B")])
    blanks = ply_blanks(result)
    assert not blanks[0].darts and blanks[0].mesh is a.mesh
    text = ply_book(result, blanks, None, units="mm")
    said = re.search(r"<p id='darts-A'>(.*?)</p>", text, re.S).group(1)
    assert f"Darts tried and not cut: {len(a.darted.dart_lines)} dart(s)" in said
    assert "negatively curved" not in said  # the cap is positively curved: darts are the remedy


def test_given_dart_lines_are_opened_as_given(darted, tmp_path):
    """The automatic darts of ply A written as a curves file and given back to the ply."""
    auto = darted.drape("A").darted
    curves = "\n\n".join("\n".join(" ".join(f"{v:.17g}" for v in p) for p in line)
                         for line in auto.dart_lines)  # fmt: skip
    (tmp_path / "darts.txt").write_text(curves + "\n", encoding="utf-8")
    write_surface(tmp_path / "mould.obj", mould())
    (tmp_path / "job.toml").write_text(
        JOB + f'\n[[ply]]\nname = "A"\norientation = 0.0\ndart_lines = "darts.txt"\n'
        f"locking_angle = {LOCKING}\n",
        encoding="utf-8",
    )
    job = load_laminate_job(tmp_path / "job.toml")
    result = drape_laminate(
        mould(), job.build_plies(), job.laminate, solve_settings=job.job.solve.to_dict()
    )
    given = result.drape("A").darted
    assert given.rounds[0].tip_angle is None and len(given.dart_lines) == len(auto.dart_lines)
    # a given line ends in the cell of its last point: the automatic lines end on an edge, so
    # each given one is as long, or up to one cell shorter, from the same mouth
    mesh = mould()
    edge = np.linalg.norm(np.diff(mesh.points[mesh.edges()], axis=1), axis=2).max()
    for line in given.dart_lines:
        other = min(auto.dart_lines, key=lambda o: np.linalg.norm(o[0] - line[0]))
        np.testing.assert_allclose(line[0], other[0], atol=1e-9)
        length = np.linalg.norm(np.diff(line, axis=0), axis=1).sum()
        full = np.linalg.norm(np.diff(other, axis=0), axis=1).sum()
        assert full - edge <= length <= full + 1e-9
    assert given.max_shear_after < given.max_shear_before


JOB = """
[input]
mesh = "mould.obj"
units = "mm"

[material]
law = "ncf"
A = [-250.0, 250.0]
B = [-250.0, 250.0]
C = [0.5]

[laminate]
kinematic = false

[output]
directory = "out"
"""


def parse(text: str) -> LaminateJob:
    return LaminateJob.from_dict(tomllib.loads(text), "job.toml")


def test_dart_options_are_checked():
    ply = '\n[[ply]]\nname = "A"\n'
    job = parse(JOB.replace("kinematic = false", 'darts = "auto"') + ply + 'darts = "none"\n')
    assert job.laminate.darts == "auto" and job.plies[0].darts == "none"
    with pytest.raises(JobError, match=r"\[laminate\] darts must be one of"):
        parse(JOB.replace("kinematic = false", 'darts = "yes"') + ply)
    with pytest.raises(JobError, match=r"unknown key 'dart'.*'darts'"):
        parse(JOB + ply + 'dart = "auto"\n')
    with pytest.raises(JobError, match="darts = 'auto' or dart_lines, not both"):
        parse(JOB + ply + 'darts = "auto"\ndart_lines = "d.txt"\n')
    with pytest.raises(JobError, match="locking_angle must be at most 90"):
        parse(JOB + ply + "locking_angle = 95.0\n")
    with pytest.raises(JobError, match="workers or a scheduler, not both"):
        parse(JOB.replace("kinematic = false", 'workers = 2\nscheduler = "tcp://h:1"') + ply)
    with pytest.raises(OptionsError, match="darts need a mould of triangles"):
        from vares.geometry.mesh import SurfaceMesh

        quads = SurfaceMesh(
            np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0.2], [2, 1, 0]], float),
            {"quad": np.array([[0, 1, 4, 3], [1, 2, 5, 4]])},
        )
        drape_laminate(quads, plies()[:1], darts="auto", kinematic=False)


def test_cli_refuses_bad_darts_and_both_workers_and_scheduler(tmp_path):
    write_surface(tmp_path / "mould.obj", mould())
    (tmp_path / "job.toml").write_text(JOB + '\n[[ply]]\nname = "A"\n', encoding="utf-8")
    result = run("laminate", tmp_path / "job.toml", "--darts", "yes")
    assert result.exit_code == 2 and "'yes' is not one of 'none', 'auto'" in result.stderr
    result = run("laminate", tmp_path / "job.toml", "--workers", 1, "--scheduler", "tcp://h:1")
    assert result.exit_code == 2 and "not both" in result.stderr
    # the flags are the [laminate] table's options: their bounds, the flag named
    result = run("laminate", tmp_path / "job.toml", "--workers", 0)
    assert result.exit_code == 2 and "--workers must be > 0; got 0" in result.stderr
    # and the job's table with a scheduler takes no --workers beside it
    (tmp_path / "job.toml").write_text(
        JOB.replace("[laminate]", '[laminate]\nscheduler = "tcp://h:1"')
        + '\n[[ply]]\nname = "A"\n',
        encoding="utf-8",
    )
    result = run("laminate", tmp_path / "job.toml", "--workers", 2)
    assert result.exit_code == 2 and "not both" in result.stderr
    assert not (tmp_path / "out").exists()


def test_cli_darts_the_plies(tmp_path):
    write_surface(tmp_path / "mould.obj", mould())
    text = JOB.replace("kinematic = false", f"kinematic = false\nlocking_angle = {LOCKING}")
    (tmp_path / "job.toml").write_text(text + '\n[[ply]]\nname = "A"\n', encoding="utf-8")
    result = run("laminate", tmp_path / "job.toml", "--darts", "auto", "--workers", 1)
    assert result.exit_code == 0, result.stderr
    assert re.search(r"dart\(s\): largest shear 8\.\d\d° -> [0-5]\.\d\d°", result.stderr)
    csv = read_orientation_csv(tmp_path / "out" / "orientations.csv")
    assert len(csv["A"].elements) == mould().num_cells
    dart = [e for e in ezdxf.readfile(tmp_path / "out" / "plies" / "A.dxf").modelspace()
            if e.dxf.layer == "DART"]  # fmt: skip
    assert dart
    # the ply book as Chromium reads it: the darts' table, one row per dart, and the pictures
    dom = chromium(tmp_path, "--dump-dom", (tmp_path / "out" / "plybook.html").as_uri()).stdout
    section = dom.split('id="ply-A"')[1].split("</section>")[0]
    table = section.split('id="darts-table-A"')[1].split("</table>")[0]
    assert table.count("<tr>") == 1 + len(dart)
    for kind in ("blank", "shear", "producibility"):
        assert f'id="figure-A-{kind}"' in section


@pytest.mark.parametrize(
    "cluster_options",
    [
        # one worker with two threads in this process: its threads drape plies at once
        dict(n_workers=1, threads_per_worker=2, processes=False),
        # two worker processes: the tasks and their outcomes pickled across
        dict(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1"),
    ],
    ids=["threads", "processes"],
)
def test_plies_on_a_dask_cluster_are_those_draped_here(darted, cluster_options):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(dashboard_address=None, **cluster_options) as cluster:
        remote = drape_laminate(
            mould(),
            plies(),
            scheduler=cluster.scheduler_address,
            kinematic=False,
            trim_allowance=0.5,
            darts="auto",
            locking_angle=LOCKING,
        )
    assert remote.workers == cluster_options["n_workers"]
    for name in ("A", "B"):
        here, there = darted.drape(name), remote.drape(name)
        np.testing.assert_array_equal(
            there.blank_pattern.material_coordinates, here.blank_pattern.material_coordinates
        )
        np.testing.assert_array_equal(there.warp, here.warp)
        np.testing.assert_array_equal(there.shear_angle, here.shear_angle)
    for value in ("warp_compressed_fraction", "mean_deviation"):
        np.testing.assert_array_equal(remote.pair_matrix(value), darted.pair_matrix(value))


def test_dart_lips_butt_by_default_and_the_left_lip_laps_by_the_overlap(darted):
    """A darted blank's trim line keeps the trim allowance along the mould's edge and follows
    the darts' lips (butt); with ``dart_overlap`` the left lip's edge moves out by it (it laps
    over the right lip when the dart closes). Cut with the trim allowance on the lips, the lips
    would overlap by twice the allowance."""
    from shapely.geometry import LinearRing, Point, Polygon

    from vares.geometry.surface_lines import CuttingError
    from vares.structures.laminate_blanks import ply_blanks

    drape = darted.drape("A")
    lips = drape.darted.slits.lips
    coordinates = drape.blank_pattern.material_coordinates
    for overlap in (0.0, 0.02):  # (the notches are 0.06–0.27 wide along the inner edges)
        options = darted.laminate.options.replace(dart_overlap=overlap)
        laminate = type(darted.laminate)(darted.laminate.plies, options)
        result = type(darted)(**{**darted.__dict__, "laminate": laminate})
        blanks = ply_blanks(result)
        blank = blanks[0]
        assert blank.name == "A" and blank.darts and blank.dart_overlap == overlap
        if overlap:
            text = ply_book(result, blanks, None, units="mm")
            assert "left lip (from its mouth in) laps 0.02 mm over the right one" in text
        trim = LinearRing(blank.trim[0])
        for left, right in lips:
            for chain, expected in ((left, overlap), (right, 0.0)):
                points = coordinates[chain]
                middles = 0.5 * (points[1:] + points[:-1])
                # the lip's inner edges (its mouth's and tip's corners mitre further)
                inner = middles[1:-1]
                assert len(inner) >= 1
                distance = [trim.distance(Point(m)) for m in inner]
                assert np.allclose(distance, expected, atol=1e-9)
        ring = blank.net[0]
        on_lip = np.zeros(len(ring), dtype=bool)  # edges with an end on a lip
        for left, right in lips:
            for chain in (left, right):
                near = np.linalg.norm(ring[:, None] - coordinates[chain][None], axis=2)
                on_lip |= near.min(axis=1) < 1e-12
        edge = ~on_lip & ~np.roll(on_lip, -1)
        middles = 0.5 * (ring + np.roll(ring, -1, axis=0))[edge]
        distance = np.array([trim.distance(Point(m)) for m in middles])
        assert np.median(distance) == pytest.approx(0.5, abs=1e-9)  # the mould's edge
        assert Polygon(blank.trim[0]).contains(Polygon(blank.net[0]).buffer(-1e-9))
    options = darted.laminate.options.replace(dart_overlap=6.0)  # the cap is 10 across
    laminate = type(darted.laminate)(darted.laminate.plies, options)
    with pytest.raises(CuttingError, match=r"ply A: dart_overlap = 6 is half as wide"):
        ply_blanks(type(darted)(**{**darted.__dict__, "laminate": laminate}))


def test_joint_overlaps_are_read_from_a_job_file_and_checked():
    ply = '\n[[ply]]\nname = "A"\nsplice_overlap = 0.0\n[[ply]]\nname = "B"\n'
    text = JOB.replace("kinematic = false", "splice_overlap = 12.5\ndart_overlap = 3.0") + ply
    job = parse(text)
    assert job.laminate.splice_overlap == 12.5 and job.laminate.dart_overlap == 3.0
    assert job.plies[0].splice_overlap == 0.0 and job.plies[1].splice_overlap is None
    with pytest.raises(JobError, match=r"splice_overlap must be ≥ 0"):
        parse(JOB.replace("kinematic = false", "splice_overlap = -1.0") + ply)
    with pytest.raises(JobError, match=r"dart_overlap must be ≥ 0"):
        parse(JOB + ply + "dart_overlap = -2.0\n")
