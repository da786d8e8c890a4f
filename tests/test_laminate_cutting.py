"""A laminate's plies as cut: blanks (net and trim boundaries), cutter DXFs, the nest on the roll,
and the ply book (checked in Chromium)."""

import json
import math
import shutil
import subprocess
import tomllib

import ezdxf
import numpy as np
import pytest
from conftest import error_line, run
from shapely.geometry import Point, Polygon

from vares.app.job import JobError
from vares.app.laminate_job import LaminateJob, load_laminate_job
from vares.app.laminate_outputs import laminate_cutting, laminate_files, run_laminate_job
from vares.geometry.examples import cap_over_square
from vares.io.meshes import write_surface
from vares.io.ply_dxf import PLY_LAYERS, write_ply_dxf, write_ply_nest_dxf
from vares.materials import NonCrimpFabric
from vares.structures.laminate import Ply, PlyOptions, drape_laminate
from vares.structures.laminate_blanks import MITRE_LIMIT, nest_plies, ply_blanks

NCF = NonCrimpFabric.from_moduli(1000.0, 1000.0, 1.0)
STACK = (0.0, 45.0, -45.0, 90.0)
ALLOWANCE = 0.5
ROLL = 30.0


def mould():
    """A spherical cap over a square (doubly curved, not axisymmetric), 200 triangles."""
    return cap_over_square(10.0, 12.0, 10)


@pytest.fixture(scope="module")
def laminate():
    plies = [Ply(PlyOptions(name=f"P{i}", orientation=a), NCF) for i, a in enumerate(STACK, 1)]
    return drape_laminate(
        mould(),
        plies,
        workers=1,
        kinematic=False,
        trim_allowance=ALLOWANCE,
        areal_weight=300.0,
        ply_thickness=0.25,
    )


@pytest.fixture(scope="module")
def blanks(laminate):
    return ply_blanks(laminate)


@pytest.fixture(scope="module")
def nest(blanks):
    return nest_plies(blanks, ROLL, time_limit=1.0)


def polygon(rings):
    return Polygon(rings[0], rings[1:])


def entities(path):
    """``(layer, type) → entities`` of a DXF's model space."""
    out = {}
    for entity in ezdxf.readfile(path).modelspace():
        out.setdefault((entity.dxf.layer, entity.dxftype()), []).append(entity)
    return out


def points(polyline) -> np.ndarray:
    return np.array([p[:2] for p in polyline.get_points()])


# ------------------------------------------------------------------ blanks


def test_net_boundary_is_the_patterns_and_masses_follow_its_area(laminate, blanks):
    for blank in blanks:
        drape = laminate.drape(blank.name)
        x = drape.pattern.material_coordinates
        (loop,) = drape.mesh.boundary_loops()
        np.testing.assert_allclose(blank.net[0], x[loop], rtol=0, atol=1e-12)
        # the outline's area is the pattern's area, cell by cell
        triangles = x[drape.mesh.cells["triangle"]]
        e1, e2 = triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]
        area = 0.5 * np.sum(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        assert blank.net_area == pytest.approx(area, rel=1e-12)
        assert abs(blank.net_area / blank.surface_area - 1.0) < 0.01  # stiff yarns
        # 300 g/m² of a blank in metres (the mould's units here)
        assert blank.mass(blank.net_area, "m") == pytest.approx(300.0 * area, rel=1e-12)
        assert blank.mass(blank.net_area, "mm") == pytest.approx(300e-6 * area, rel=1e-12)
        assert blank.thickness == 0.25
        # the rosette sits at the seed's node, the warp along +x
        node = np.argmin(np.linalg.norm(drape.mesh.points - drape.seed, axis=1))
        np.testing.assert_array_equal(blank.origin, x[node])
        np.testing.assert_allclose(blank.warp, [1.0, 0.0], atol=1e-12)


def test_trim_boundary_lies_outside_the_net_at_the_allowance(blanks):
    for blank in blanks:
        net, trim = polygon(blank.net), polygon(blank.trim)
        assert trim.contains(net)
        # the nearest approach of the two lines is the allowance, the farthest a mitre
        assert net.exterior.distance(trim.exterior) == pytest.approx(ALLOWANCE, abs=1e-9)
        vertices = [net.exterior.distance(Point(p)) for p in blank.trim[0]]
        assert min(vertices) >= ALLOWANCE - 1e-9
        assert trim.exterior.hausdorff_distance(net.exterior) <= MITRE_LIMIT * ALLOWANCE + 1e-9
        # Steiner: a round offset adds perimeter × a + π a²; mitred corners add more
        grown = net.area + net.length * ALLOWANCE + math.pi * ALLOWANCE**2
        assert blank.trim_area >= grown - 1e-9
        assert blank.trim_area == pytest.approx(trim.area, rel=1e-12)


def test_trim_of_zero_is_the_net(laminate):
    options = laminate.laminate.options.replace(trim_allowance=0.0)
    same = type(laminate)(**{**laminate.__dict__, "laminate": type(laminate.laminate)(
        laminate.laminate.plies, options)})  # fmt: skip
    for blank in ply_blanks(same):
        assert polygon(blank.trim).symmetric_difference(polygon(blank.net)).area < 1e-12
        assert blank.trim_area == pytest.approx(blank.net_area, rel=1e-12)


# ------------------------------------------------------------------ cutter files


def test_ply_dxf_reads_back_with_its_layers(laminate, blanks, tmp_path):
    for blank in blanks:
        path = tmp_path / f"{blank.name}.dxf"
        write_ply_dxf(path, blank, units="mm")
        doc = ezdxf.readfile(path)
        assert doc.header["$INSUNITS"] == 4
        assert set(PLY_LAYERS) <= {layer.dxf.name for layer in doc.layers}
        found = entities(path)
        counts = {key: len(v) for key, v in found.items()}
        assert counts == {
            ("NET", "LWPOLYLINE"): 1,
            ("TRIM", "LWPOLYLINE"): 1,
            ("ROSETTE", "LWPOLYLINE"): 4,  # two arrows, shaft and head
            ("ROSETTE", "CIRCLE"): 1,
            ("ROSETTE", "TEXT"): 2,
            ("LABEL", "TEXT"): 3,
        }
        (net,) = found["NET", "LWPOLYLINE"]
        drape = laminate.drape(blank.name)
        (loop,) = drape.mesh.boundary_loops()
        boundary = drape.pattern.material_coordinates[loop]
        assert net.closed
        np.testing.assert_allclose(points(net), boundary, rtol=0, atol=1e-9)
        (trim,) = found["TRIM", "LWPOLYLINE"]
        np.testing.assert_allclose(points(trim), blank.trim[0], rtol=0, atol=1e-9)
        labels = [t.dxf.text for t in found["LABEL", "TEXT"]]
        assert labels[0] == blank.name and f"{blank.orientation:+g} deg" in labels[1]
        assert sorted(t.dxf.text for t in found["ROSETTE", "TEXT"]) == ["0", "90"]
        (circle,) = found["ROSETTE", "CIRCLE"]
        np.testing.assert_allclose(tuple(circle.dxf.center)[:2], blank.origin, atol=1e-9)


# ------------------------------------------------------------------ the nest


def test_nest_has_no_overlap_and_its_yield_is_net_over_roll(blanks, nest):
    placed = [polygon([p.place(r) for r in blanks[p.index].trim]) for p in nest.pieces]
    assert sorted(p.index for p in nest.pieces) == list(range(len(blanks)))
    for i, a in enumerate(placed):
        low_x, low_y, _, high_y = a.bounds
        assert low_x >= 0.0 and low_y >= 0.0 and high_y <= ROLL
        for b in placed[i + 1 :]:
            assert a.intersection(b).area == 0.0
    length = max(p.bounds[2] for p in placed)
    assert nest.length == pytest.approx(length, rel=1e-12)
    net = sum(polygon(b.net).area for b in blanks)
    assert nest.yield_ == pytest.approx(net / (ROLL * length), rel=1e-9)
    assert 0.0 < nest.yield_ < 1.0
    # each ply keeps its warp along the roll (turned by 0° or 180° only)
    assert {p.rotation for p in nest.pieces} <= {0.0, 180.0}


def test_nest_dxf_reads_back(blanks, nest, tmp_path):
    path = tmp_path / "nest.dxf"
    write_ply_nest_dxf(path, blanks, nest, units="mm")
    found = entities(path)
    (roll,) = found["ROLL", "LWPOLYLINE"]
    np.testing.assert_allclose(
        points(roll), [[0, 0], [nest.length, 0], [nest.length, ROLL], [0, ROLL]], atol=1e-9
    )
    nets = found["NET", "LWPOLYLINE"]
    assert len(nets) == len(found["TRIM", "LWPOLYLINE"]) == len(blanks)
    assert len(found["LABEL", "TEXT"]) == 3 * len(blanks)
    assert len(found["ROSETTE", "CIRCLE"]) == len(blanks)
    for piece, drawn in zip(nest.pieces, nets, strict=True):
        expected = piece.place(blanks[piece.index].net[0])
        np.testing.assert_allclose(points(drawn), expected, rtol=0, atol=1e-9)


def test_a_blank_wider_than_the_roll_is_named(laminate, blanks):
    with pytest.raises(ValueError, match=r"ply P\d is .* wide across its warp"):
        nest_plies(blanks, 5.0)
    options = laminate.laminate.options.replace(roll_width=5.0, nest_time=1.0)
    narrow = type(laminate)(**{**laminate.__dict__, "laminate": type(laminate.laminate)(
        laminate.laminate.plies, options)})  # fmt: skip
    cut = laminate_cutting(narrow, "m")
    assert cut.nest is None and "roll_width of 5" in cut.nest_error
    assert cut.summary()["nest"] == {"error": cut.nest_error}


# ------------------------------------------------------------------ the job and the ply book

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
spacing = 0.25
areal_weight = 200.0
ply_thickness = 0.2
trim_allowance = 0.5
roll_width = 30.0
nest_time = 1.0

[output]
directory = "out"
"""


def job_text(extra_ply: str = "") -> str:
    plies = "".join(
        f'\n[[ply]]\nname = "P{i}"\norientation = {a}\n' for i, a in enumerate(STACK, start=1)
    )
    return JOB + plies + extra_ply


def parse(text: str) -> LaminateJob:
    return LaminateJob.from_dict(tomllib.loads(text), "job.toml")


def test_job_checks_the_cutting_options():
    job = parse(job_text("areal_weight = 400.0\nthickness = 0.3\n"))
    assert job.laminate.roll_width == 30.0 and job.laminate.trim_allowance == 0.5
    assert job.plies[3].areal_weight == 400.0 and job.plies[3].thickness == 0.3
    with pytest.raises(JobError, match=r"\[\[ply\]\] 4 areal_weight must be > 0"):
        parse(job_text("areal_weight = -1.0\n"))
    with pytest.raises(JobError, match=r"\[laminate\] trim_allowance must be ≥ 0"):
        parse(job_text().replace("trim_allowance = 0.5", "trim_allowance = -0.5"))
    with pytest.raises(JobError, match=r"\[laminate\] roll_width must be > 0"):
        parse(job_text().replace("roll_width = 30.0", "roll_width = 0.0"))
    with pytest.raises(JobError, match=r"unknown key 'areal_wieght'.*'areal_weight'"):
        parse(job_text().replace("areal_weight = 200.0", "areal_wieght = 200.0"))
    clash = parse(job_text('\n[[ply]]\nname = "P_5"\n[[ply]]\nname = "P 5"\n'))
    with pytest.raises(JobError, match=r"'P_5' and 'P 5' would write the same cutter file"):
        laminate_files(clash)


def test_the_files_of_a_run_not_nested_have_no_nest():
    job = parse(job_text())
    names = [p.name for p in laminate_files(job)]
    assert "nest.dxf" in names
    assert [n for n in names if n != "nest.dxf"] == [
        p.name for p in laminate_files(job, nested=False)
    ]


def chromium(tmp_path, *arguments) -> subprocess.CompletedProcess:
    """Headless Chromium (Debian's) with a profile of its own."""
    browser = shutil.which("chromium")
    assert browser, "Debian's chromium is needed (scripts/install-test-deps.sh installs it)"
    profile = tmp_path / f"profile-{len(list(tmp_path.glob('profile-*')))}"
    return subprocess.run(
        [
            browser,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            f"--user-data-dir={profile}",
            *arguments,
        ],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )


@pytest.fixture(scope="module")
def job_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("laminate-cutting")
    write_surface(folder / "mould.obj", mould())
    (folder / "job.toml").write_text(job_text(), encoding="utf-8")
    job = load_laminate_job(folder / "job.toml")
    return run_laminate_job(job, workers=1), folder / "out"


def test_job_writes_cutter_files_and_nest(job_run):
    done, out = job_run
    assert done.result.converged and done.units == "mm"
    for ply in ("P1", "P2", "P3", "P4"):
        found = entities(out / "plies" / f"{ply}.dxf")
        assert len(found["NET", "LWPOLYLINE"]) == 1 and len(found["TRIM", "LWPOLYLINE"]) == 1
    assert len(entities(out / "nest.dxf")["NET", "LWPOLYLINE"]) == 4
    summary = json.loads((out / "laminate.json").read_text())
    nest = summary["nest"]
    net = sum(b["net_area"] for b in summary["blanks"])
    assert nest["yield"] == pytest.approx(net / (nest["roll_width"] * nest["length"]), rel=1e-12)
    assert nest["net_area"] == pytest.approx(net, rel=1e-12)
    # how the search ended, as for a cut: its bound, seed, time and whether it ended by itself
    assert nest["time_limit"] == done.result.laminate.options.nest_time and nest["seed"] == 0
    assert 0 < nest["search_seconds"] <= nest["time_limit"] + 2.0
    assert nest["finished"] == done.nest.finished and done.nest.method == "search"
    blank = summary["blanks"][0]
    assert blank["net_mass"] == pytest.approx(200.0 * blank["net_area"] * 1e-6, rel=1e-12)
    assert blank["producibility"]["ok_fraction"] == 1.0
    markdown = (out / "laminate.md").read_text()
    assert "## The plies as cut" in markdown and f"yield {100 * nest['yield']:.1f} %" in markdown


def test_ply_book_opens_in_chromium_with_a_section_per_ply(job_run, tmp_path):
    done, out = job_run
    book = out / "plybook.html"
    dom = chromium(tmp_path, "--dump-dom", book.as_uri()).stdout
    assert "<h1>Ply book: job</h1>" in dom
    assert dom.count('<section class="ply"') == 4
    for blank in done.blanks:
        section = dom.split(f'id="ply-{blank.name}"')[1].split("</section>")[0]
        assert f"<h2>Ply {blank.name}: {blank.orientation:+g}°</h2>" in section
        for kind in ("blank", "shear", "producibility"):
            assert f'id="figure-{blank.name}-{kind}"' in section
        assert "No darts" in section
        mass = blank.mass(blank.net_area, "mm")
        assert f'<th>mass of the net</th><td class="num">{mass:.4g} g</td>' in section
    summary = dom.split('id="laminate-summary"')[1].split("</table>")[0]
    assert summary.count("<tr>") == 1 + 4
    assert dom.split('id="total-thickness"')[1].startswith(">Total thickness: 0.8 mm.")
    nest = dom.split('id="nest"')[1].split("</table>")[0]
    assert f"{100 * done.nest.yield_:.1f} %" in nest
    said = "stopped by its time bound" if not done.nest.finished else "search ended by itself in"
    assert said in nest
    assert dom.count("data:image/png;base64,") == 3 * 4 + 1
    assert 'id="pairs-warp_compressed_fraction"' in dom
    screenshot = tmp_path / "book.png"
    chromium(tmp_path, "--window-size=1000,1400", f"--screenshot={screenshot}", book.as_uri())
    from PIL import Image

    image = np.asarray(Image.open(screenshot).convert("L"), dtype=float)
    assert image.std() > 10  # text and pictures, not a blank page


def test_cli_prints_the_plies_and_the_yield(job_run, tmp_path):
    _, out = job_run
    folder = out.parent
    done = run("laminate", folder / "job.toml", "-o", tmp_path / "cli")
    assert done.exit_code == 0, done.stderr
    summary = json.loads((tmp_path / "cli" / "laminate.json").read_text())
    assert f"yield {100 * summary['nest']['yield']:.1f} %" in done.stderr
    stopped = "the nesting search was stopped by its time bound" in done.stderr
    assert stopped == (not summary["nest"]["finished"])
    assert "plies as cut" in done.stderr
    again = run("laminate", folder / "job.toml", "-o", tmp_path / "cli", "-q")
    assert again.exit_code == 2 and "--force" in error_line(again)


def test_cli_does_not_list_a_nest_it_did_not_write(job_run, tmp_path):
    _, out = job_run
    folder = out.parent
    (folder / "narrow.toml").write_text(
        job_text().replace("roll_width = 30.0", "roll_width = 5.0"), encoding="utf-8"
    )
    done = run("laminate", folder / "narrow.toml", "-o", tmp_path / "narrow")
    assert done.exit_code == 0, done.stderr
    assert "not nested: ply P1 is" in done.stderr and "roll_width of 5" in done.stderr
    assert not (tmp_path / "narrow" / "nest.dxf").exists()
    assert "nest.dxf" not in done.stderr
    assert f"wrote {tmp_path / 'narrow' / 'plybook.html'}" in done.stderr


def test_ply_book_without_weights_or_roll_says_so(laminate, blanks):
    from dataclasses import replace

    from vares.app.ply_book import ply_book

    light = [replace(b, areal_weight=None, thickness=None) for b in blanks]
    page = ply_book(laminate, light, None, units="m", title="cap")
    assert "no areal weight for some plies: their masses are not shown" in page
    assert "<p id='nest'>Not nested: the laminate names no roll_width.</p>" in page
    assert "<p id='total-mass'>Total mass of the nets: –.</p>" in page
    assert "<p id='total-thickness'>Total thickness: –.</p>" in page
    assert page.count("<section class='ply'") == 4
    assert page.count("data:image/png;base64,") == 3 * 4


def test_a_ply_with_a_hole_has_a_net_and_trim_ring_for_it(tmp_path):
    mesh = mould()
    centroids = mesh.points[mesh.cells["triangle"]].mean(axis=1)
    frame = (np.abs(centroids[:, :2]).max(axis=1) > 2.5).astype(float)  # a square hole
    plies = [Ply(PlyOptions(name="frame", orientation=30.0, region="frame"), NCF)]
    result = drape_laminate(
        mesh, plies, cell_data={"frame": frame}, workers=1, kinematic=False, trim_allowance=0.4
    )
    assert result.converged
    (blank,) = ply_blanks(result)
    drape = result.drape("frame")
    x = drape.pattern.material_coordinates
    assert len(blank.net) == len(blank.trim) == 2
    outer, hole = Polygon(blank.net[0]), Polygon(blank.net[1])
    assert outer.exterior.is_ccw and not Polygon(blank.net[1]).exterior.is_ccw
    cells = x[drape.mesh.cells["triangle"]]
    e1, e2 = cells[:, 1] - cells[:, 0], cells[:, 2] - cells[:, 0]
    area = 0.5 * np.sum(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    assert blank.net_area == pytest.approx(outer.area - hole.area, rel=1e-12)
    assert blank.net_area == pytest.approx(area, rel=1e-12)
    # the hole's trim line lies inside the hole, the allowance away from its edge
    trim_hole = Polygon(blank.trim[1])
    assert hole.contains(trim_hole)
    assert hole.exterior.distance(trim_hole.exterior) == pytest.approx(0.4, abs=1e-9)
    write_ply_dxf(tmp_path / "frame.dxf", blank, units="m")
    found = entities(tmp_path / "frame.dxf")
    assert len(found["NET", "LWPOLYLINE"]) == 2 and len(found["TRIM", "LWPOLYLINE"]) == 2
    loops = {len(loop): x[loop] for loop in drape.mesh.boundary_loops()}
    for drawn in found["NET", "LWPOLYLINE"]:
        ring = points(drawn)
        expected = loops[len(ring)]
        if Polygon(expected).exterior.is_ccw != Polygon(ring).exterior.is_ccw:
            expected = expected[::-1]
        np.testing.assert_allclose(ring, expected, rtol=0, atol=1e-9)
