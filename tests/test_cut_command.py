"""``vares cut`` and ``vares.cut``: a surface to strips, patterns with matched seams and a nest."""

import itertools
import json
from pathlib import Path

import ezdxf
import meshio
import numpy as np
import pytest
from conftest import error_line, run
from shapely.geometry import Point, Polygon

import vares
from vares.geometry.examples import saddle, tent_roof
from vares.geometry.surface_lines import triangulated

FABRIC = vares.materials.fabric("pes-pvc-type-2").material()


@pytest.fixture(scope="module")
def small_saddle_file(tmp_path_factory):
    mesh = saddle(size=8.0, height=1.6, n=12)
    path = tmp_path_factory.mktemp("input") / "saddle.obj"
    meshio.write(path, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]))
    return path, mesh


def test_cut_command_writes_the_plan_the_patterns_and_the_nest(tmp_path, small_saddle_file):
    source, mesh = small_saddle_file
    out = tmp_path / "cut"
    job = tmp_path / "cut.toml"
    result = run(
        "cut", source, "--roll-width", 1.8, "-o", out, "--fabric", "pes-pvc-type-2",
        "--prestress", "2,1.5", "--allowance", 20, "--edge-type", "cable",
        "--cable-allowance", 60, "--nest-time", 1, "--mark-spacing", 1000, "-q",
        "--save-job", job,
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "cut.json").read_text())
    assert set(data) == {"roll_width", "panels", "seams", "nesting"}
    assert data["roll_width"] == 1.8
    panels, seams, nesting = data["panels"], data["seams"], data["nesting"]
    assert len(panels) >= 2 and len(seams) == len(panels) - 1
    for panel in panels:
        assert set(panel) == {"name", "area", "width", "warp"}
        assert panel["width"] <= 1.8
    assert sum(p["area"] for p in panels) == pytest.approx(mesh.area, rel=1e-12)
    for seam in seams:
        assert set(seam) == {"panels", "length_3d", "length_2d"}
        a, b = seam["length_2d"]
        assert abs(a - b) <= 1e-9 * a
    assert set(nesting) == {"roll_width", "length", "yield"} and 0 < nesting["yield"] < 1
    details = json.loads((out / "structure.json").read_text())["cutting"]
    assert details["surface_area"] == pytest.approx(details["panels_area"], rel=1e-12)
    made = details["nest"]  # how the nest was made: a search's seed and bound, or pairs
    assert made["time_limit"] == (1.0 if made["method"] == "search" else 0.0)
    assert made["seed"] == (0 if made["method"] == "search" else None)
    for line in details["seam_lines"]:
        assert abs(line["excess"]) < 0.01  # each seam within 1 % of its geodesic
    drawing = ezdxf.readfile(out / "nest.dxf")
    space = drawing.modelspace()
    seams_drawn = [e for e in space.query("LWPOLYLINE") if e.dxf.layer == "SEAM"]
    assert len(seams_drawn) == len(panels)
    cut_lines = [
        Polygon(np.array(e.get_points("xy"))) for e in space.query("LWPOLYLINE[layer=='CUT']")
    ]
    for a, b in itertools.combinations(cut_lines, 2):
        assert not a.intersects(b)  # no overlap on the roll (mm)
    assert max(p.bounds[3] for p in cut_lines) <= 1800 and min(p.bounds[1] for p in cut_lines) >= 0
    # the yield from the drawing: the net (seam-line) areas over the roll area used
    net = sum(Polygon(np.array(e.get_points("xy"))).area for e in seams_drawn) / 1000**2
    assert nesting["yield"] == pytest.approx(net / (1.8 * nesting["length"]), rel=1e-6)
    names = {e.dxf.text for e in space.query("TEXT[layer=='MARKS']")}
    assert names and all(n.startswith("S") for n in names)
    for k, panel in enumerate(panels, start=1):  # each width from the strip's own cut line
        strip = ezdxf.readfile(out / f"strip-{k}" / "pattern.dxf").modelspace()
        ring = np.array(next(iter(strip.query("LWPOLYLINE[layer=='CUT']"))).get_points("xy"))
        across = np.array([-panel["warp"][1], panel["warp"][0]])
        assert np.ptp(ring @ across) / 1000 == pytest.approx(panel["width"], rel=1e-6)
    panel_ids = meshio.read(out / "panels.vtu").cell_data["panel"][0]
    assert len(np.unique(panel_ids)) == len(panels)
    for name in ("cut_lines.png", "nest.png", "nest.svg", "strip-1/pattern.dxf"):
        assert (out / name).is_file()
    again = run("run", job, "-o", tmp_path / "again", "-q")
    assert again.exit_code == 0, again.stderr
    rerun = json.loads((tmp_path / "again" / "cut.json").read_text())
    assert [p["width"] for p in rerun["panels"]] == [p["width"] for p in panels]


def test_cut_command_errors(tmp_path, small_saddle_file):
    source, _ = small_saddle_file
    missing = run("cut", source, "-o", tmp_path / "a")
    assert missing.exit_code == 2 and "roll-width" in error_line(missing)
    bad = run("cut", source, "--roll-width", 2, "--seams", "spline", "-o", tmp_path / "b")
    assert bad.exit_code == 2 and "--seams" in error_line(bad)
    narrow = run("cut", source, "--roll-width", 0.01, "-o", tmp_path / "c", "-q")
    assert narrow.exit_code == 2 and "strips" in error_line(narrow)
    pattern = run("pattern", source, "-o", tmp_path / "d")
    assert pattern.exit_code == 0, pattern.stderr  # the same file patterned as one piece
    example = run("example", "conic-tent", "-o", tmp_path / "e")
    assert example.exit_code == 2 and "vares cut" in error_line(example)


def test_radial_strips_of_a_tent_with_their_own_warps():
    mesh = tent_roof(outer_radius=4.0, ring_radius=0.8, height=2.5, n_radial=10, n_around=12)
    result = vares.cut(
        mesh, FABRIC, prestress=(2.0, 1.5), roll_width=2.0, nest_time=1, allowance=20.0,
        high_edge_type="clamp", clamp_allowance=50.0,
    )  # fmt: skip
    assert result.converged, result.structure.reason
    assert result.plan.family.kind == "radial" and result.plan.family.closed
    assert max(result.widths) <= 2.0
    assert result.panel_area == pytest.approx(mesh.area, rel=1e-12)
    warps = np.array(result.plan.warps)
    angles = np.degrees(np.arctan2(warps[:, 1], warps[:, 0]))
    halves = 0 if result.plan.split is None else 1  # a strip cut across: one warp, two pieces
    assert len(np.unique(np.round(angles))) == len(warps) - halves  # every strip its own warp
    for seam in result.seams:  # meridians: geodesics and plane sections alike
        assert abs(seam.length_3d / seam.line_length - 1) < 0.01
        assert abs(seam.length_2d[0] - seam.length_2d[1]) < 1e-9 * seam.length_2d[0]
    kinds = set(itertools.chain.from_iterable(o.edges for o in result.outlines))
    assert kinds == {"seam", "free", "clamp"}
    allowances = {"seam": 0.02, "free": 0.02, "clamp": 0.05}  # mm on the drawing, m here
    for outline in result.outlines:  # each edge's cut line lies its own allowance outside it
        ring = Polygon(outline.cut).exterior
        following = np.roll(outline.seam, -1, axis=0)
        middles = 0.5 * (outline.seam + following)
        distances = np.array([ring.distance(Point(m)) for m in middles])
        # away from the corners: the middle of a short segment next to one is nearer to the
        # neighbouring edge's cut line
        long = np.linalg.norm(following - outline.seam, axis=1) > 4 * max(allowances.values())
        for kind, allowance in allowances.items():
            mine = distances[(np.array(outline.edges) == kind) & long]
            if mine.size:
                assert np.median(mine) == pytest.approx(allowance, rel=1e-6), kind
    assert result.nest is not None
    assert result.nest.length >= sum(o.area for o in result.outlines) / 2.0  # no overlaps


def test_cutting_along_the_users_lines_from_the_api_the_command_and_a_job(tmp_path):
    """Two straight rulings of the hypar along mesh lines as the user's cutting lines: three
    strips whose seams are those lines (3D length 10·√(1 + (0.06·5/3)²)); lines are refused without
    seams = 'curves' and a job with seams = 'curves' needs its file."""
    mesh = vares.examples.hypar(size=10.0, rise=0.06, n=12)
    x = np.linspace(-5.0, 5.0, 9)
    lines = [np.column_stack([x, np.full_like(x, y), 0.06 * x * y]) for y in (-5 / 3, 5 / 3)]
    result = vares.cut(
        mesh, FABRIC, roll_width=5.0, seams="curves", lines=lines, nest_time=1, max_iterations=30
    )
    assert result.converged and len(result.plan.panels) == 3 and result.nest is not None
    ruling = 10.0 * np.sqrt(1.0 + (0.06 * 5 / 3) ** 2)
    assert [s.length_3d for s in result.seams] == pytest.approx([ruling, ruling], rel=1e-9)
    with pytest.raises(ValueError, match="go together"):
        vares.cut(mesh, FABRIC, roll_width=5.0, lines=lines)
    with pytest.raises(ValueError, match="go together"):
        vares.cut(mesh, FABRIC, roll_width=5.0, seams="curves")
    # the same lines from a file, on the command line
    source = tmp_path / "hypar.obj"
    meshio.write(source, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]))
    drawn = tmp_path / "lines.txt"
    drawn.write_text("\n\n".join("\n".join(f"{a} {b} {c}" for a, b, c in line) for line in lines))
    out = tmp_path / "out"
    result = run("cut", source, "--roll-width", 5, "--seams", drawn, "-o", out, "--nest-time", 1)
    assert result.exit_code == 0, result.stderr
    seams = json.loads((out / "cut.json").read_text())["seams"]
    assert [s["length_3d"] for s in seams] == pytest.approx([ruling, ruling], rel=1e-9)
    job = tmp_path / "job.toml"
    job.write_text(
        f'[input]\nmesh = "{source}"\n[cut]\nroll_width = 5.0\nseams = "curves"\n'
        '[output]\ndirectory = "job-out"\n'
    )
    result = run("run", job)
    assert result.exit_code == 2 and "needs a curves file" in error_line(result)
    assert not (tmp_path / "job-out").exists()


def test_a_coarse_design_with_sagging_edges_is_cut_patterned_and_nested(tmp_path):
    """compas-FoFin's wave (tests/data): its cable edges sag between the supports, so the
    geodesics between the ends of plane sections near them run towards each other (they met:
    exit 2 before). The strips fit, cover the surface, their seams match, they are nested."""
    source = Path(__file__).parent / "data" / "fofin_wave.obj"
    out = tmp_path / "wave"
    result = run(
        "cut", source, "--units", "m", "--roll-width", 1.5, "-o", out,
        "--fabric", "pes-pvc-type-2", "--prestress", "2,1.5", "--nest-time", 1, "-q",
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "cut.json").read_text())
    mesh = triangulated(vares.read_mesh(source))  # its quads split, as the cut splits them
    assert max(p["width"] for p in data["panels"]) <= 1.5
    assert sum(p["area"] for p in data["panels"]) == pytest.approx(mesh.area, rel=1e-12)
    for seam in data["seams"]:
        a, b = seam["length_2d"]
        assert abs(a - b) <= 1e-9 * a
    assert 0 < data["nesting"]["yield"] < 1


def test_a_cut_has_one_roll_width(small_saddle_file):
    """The structure's roll width (panels whose patterns are wider are reported) is the cut's
    in a cut: a job or a call giving the two different values is refused, naming the cut's."""
    from vares.app.job import Job, JobError
    from vares.structures.options import StructureOptions

    source, mesh = small_saddle_file
    table = {"input": {"mesh": str(source)}, "cut": {"roll_width": 2.5}}
    assert Job.from_dict(table).cut.roll_width == 2.5
    same = Job.from_dict({**table, "structure": {"roll_width": 2.5}})
    assert same.structure.roll_width == same.cut.roll_width == 2.5
    with pytest.raises(JobError, match=r"\[structure\] roll_width differs from \[cut\] roll_width"):
        Job.from_dict({**table, "structure": {"roll_width": 3.0}})
    with pytest.raises(ValueError, match="a cut has one roll width"):
        vares.cut(mesh, FABRIC, roll_width=2.5, structure=StructureOptions(roll_width=3.0))


def test_a_cut_whose_patterns_the_roll_does_not_take_exits_1(tmp_path, monkeypatch):
    """The wave at a 1 m roll: its first plan's patterns are wider than the roll (1.081 m with
    allowances, docs/cutting.md), and with one plan allowed the cut ends there. Its files are
    written with no nest, and ``vares cut`` exits 1 naming the pieces (it exited 0 before)."""
    import vares.structures.cutting as cutting

    monkeypatch.setattr(cutting, "MAX_ROUNDS", 1)
    source = Path(__file__).parent / "data" / "fofin_wave.obj"
    out = tmp_path / "wave"
    result = run(
        "cut", source, "--units", "m", "--roll-width", 1.0, "-o", out,
        "--fabric", "pes-pvc-type-2", "--prestress", "2,1.5", "--allowance", 20,
        "--edge-type", "cable", "--cable-allowance", 80, "--nest-time", 1, "-q",
        "--save-job", tmp_path / "wave.toml",
    )  # fmt: skip
    assert result.exit_code == 1
    message = error_line(result)
    assert message.startswith("vares: error: the cut does not fit the roll: strip-")
    assert "after 1 plan, so nothing was nested" in message
    details = json.loads((out / "structure.json").read_text())["cutting"]
    assert details["nest"] is None and details["widest_pattern_per_round"][0] > 0.99992
    assert not (out / "nest.dxf").exists()
    # in a batch the job failed, and a later batch runs it again rather than skip it
    from vares.app.batch import is_complete, run_job_file
    from vares.app.job import load_job

    saved = tmp_path / "wave.toml"
    status = run_job_file(str(saved))
    assert status.status == "failed", status.message
    assert status.message.startswith("the cut does not fit the roll")
    assert not is_complete(load_job(saved))
