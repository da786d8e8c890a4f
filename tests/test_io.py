"""Files for the cutter and for people: DXF, Rhino 3dm, drawings, the HTML report, job files."""

import base64
import json
import shutil
import subprocess

import dxfgrabber
import ezdxf
import meshio
import numpy as np
import pytest
from conftest import run

import vares
from vares.app.job import JobError, load_job
from vares.geometry.examples import grid_cells
from vares.io.dxf import CutPiece, write_dxf
from vares.io.rhino import NamedMesh, read_3dm, write_3dm


def rectangle(width=2.0, height=1.0, nx=5, ny=3):
    x, y = np.meshgrid(np.linspace(0, width, nx), np.linspace(0, height, ny))
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    return vares.SurfaceMesh(points, grid_cells(nx, ny, "quad"))


def polylines(doc, layer):
    return [
        np.array(e.get_points("xy"))
        for e in doc.modelspace().query(f"LWPOLYLINE[layer=='{layer}']")
    ]


def test_cut_line_of_a_rectangle_is_the_rectangle_grown_by_the_allowance(tmp_path):
    mesh = rectangle()
    path = tmp_path / "rect.dxf"
    write_dxf(
        path,
        [CutPiece("rect", mesh, mesh.points[:, :2], warp=np.array([1.0, 0.0]))],
        units="mm",
        model_units="m",
        allowance=25.0,
    )
    doc = ezdxf.readfile(path)
    assert doc.header["$INSUNITS"] == 4  # millimetres
    (seam,) = polylines(doc, "SEAM")
    (cut,) = polylines(doc, "CUT")
    low, high = seam.min(axis=0), seam.max(axis=0)
    np.testing.assert_allclose(high - low, [2000.0, 1000.0], atol=1e-9)
    np.testing.assert_allclose(cut.min(axis=0), low - 25.0, atol=1e-9)
    np.testing.assert_allclose(cut.max(axis=0), high + 25.0, atol=1e-9)
    assert len(cut) == 4  # clean (mitred) corners: still a rectangle
    corners = {tuple(np.round(p, 6)) for p in cut}
    expected = {
        (low[0] - 25, low[1] - 25),
        (high[0] + 25, low[1] - 25),
        (high[0] + 25, high[1] + 25),
        (low[0] - 25, high[1] + 25),
    }
    assert corners == {tuple(np.round(c, 6)) for c in expected}


def test_dxf_layers_marks_labels_layout_and_other_readers(tmp_path):
    mesh = rectangle()
    pieces = [
        CutPiece("A", mesh, mesh.points[:, :2], warp=np.array([1.0, 0.0]), label=["area 2 m²"]),
        CutPiece("B", mesh, mesh.points[:, :2] * 0.5 + 7.0, warp=np.array([0.0, 1.0])),
    ]
    path = tmp_path / "two.dxf"
    write_dxf(path, pieces, units="cm", allowance=5.0, mark_spacing=50.0)
    doc = ezdxf.readfile(path)
    auditor = doc.audit()
    assert not auditor.has_errors and not auditor.has_fixes
    assert doc.header["$INSUNITS"] == 5
    assert {"SEAM", "CUT", "WARP", "MARKS", "LABEL"} <= {layer.dxf.name for layer in doc.layers}
    marks = doc.modelspace().query("LINE[layer=='MARKS']")
    assert len(marks) == 600 / 50 + 300 / 50  # perimeters 600 cm and 300 cm, every 50 cm
    texts = [t.dxf.text for t in doc.modelspace().query("TEXT")]
    assert texts == ["A", "area 2 m²", "B"]
    cuts = polylines(doc, "CUT")
    boxes = [(c.min(axis=0), c.max(axis=0)) for c in cuts]
    assert boxes[0][1][0] < boxes[1][0][0]  # side by side, no overlap
    # a reader with its own parser
    grabbed = dxfgrabber.readfile(str(path))
    assert grabbed.header["$INSUNITS"] == 5
    types = [e.dxftype for e in grabbed.entities]
    assert types.count("LWPOLYLINE") == 2 + 2 + 4 and types.count("TEXT") == 3
    seam = next(e for e in grabbed.entities if e.dxftype == "LWPOLYLINE" and e.layer == "SEAM")
    assert seam.is_closed and np.ptp(np.array(seam.points)[:, 0]) == pytest.approx(200.0)


def test_dxf_renders_with_the_drawing_add_on(tmp_path):
    import matplotlib.pyplot as plt
    from ezdxf.addons.drawing import Frontend, RenderContext
    from ezdxf.addons.drawing.matplotlib import MatplotlibBackend

    result = vares.solve(vares.examples.hypar(n=6), vares.materials.NeoHooke(1000.0, 0.3))
    path = tmp_path / "hypar.dxf"
    write_dxf(
        path,
        [CutPiece("hypar", result.mesh, result.material_coordinates, warp=result.fibres.warp)],
        allowance=20.0,
        mark_spacing=500.0,
    )
    doc = ezdxf.readfile(path)
    fig = plt.figure()
    ax = fig.add_axes([0, 0, 1, 1])
    Frontend(RenderContext(doc), MatplotlibBackend(ax)).draw_layout(doc.modelspace())
    png = tmp_path / "hypar.png"
    fig.savefig(png, dpi=60)
    plt.close(fig)
    assert png.stat().st_size > 3000
    assert len(ax.collections) + len(ax.lines) + len(ax.patches) > 0


def test_boundary_loops_with_a_hole():
    x, y = np.meshgrid(np.arange(4.0), np.arange(4.0))
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(16)])
    quads = grid_cells(4, 4, "quad")["quad"]
    ring = np.delete(quads, 4, axis=0)  # remove the centre cell
    loops = vares.SurfaceMesh(points, {"quad": ring}).boundary_loops()
    assert [len(loop) for loop in loops] == [12, 4]
    path_area = [
        0.5
        * np.sum(
            points[loop, 0] * np.roll(points[loop, 1], -1)
            - np.roll(points[loop, 0], -1) * points[loop, 1]
        )
        for loop in loops
    ]
    assert path_area[0] == pytest.approx(9.0) and path_area[1] == pytest.approx(-1.0)


def test_rhino_3dm_round_trip_and_names(tmp_path):
    sail = vares.examples.hypar(n=4)
    arch = vares.examples.cylinder160(n_around=6, n_along=2, cell_type="quad")
    path = tmp_path / "model.3dm"
    write_3dm(path, [NamedMesh("sail", "membranes", sail), NamedMesh("", "roof::arch", arch)])
    read = read_3dm(path)
    assert [(m.name, m.layer) for m in read] == [
        ("sail", "membranes"),
        ("roof::arch", "roof::arch"),
    ]
    np.testing.assert_allclose(read[0].mesh.points, sail.points, rtol=1e-6)  # single precision
    np.testing.assert_array_equal(read[1].mesh.cells["quad"], arch.cells["quad"])
    with pytest.raises(vares.MeshError, match="holds 2 meshes"):
        vares.read_mesh(path)
    single = tmp_path / "sail.3dm"
    write_3dm(single, [NamedMesh("sail", "membranes", sail)])
    assert vares.read_mesh(single).num_cells == sail.num_cells
    result = run("pattern", single, "-o", tmp_path / "out", "-q")
    assert result.exit_code == 0, result.stderr


def _unwelded_3dm(path, objects):
    """A Rhino file of meshes stored as Rhino often keeps them: a vertex per face at a seam
    (here the column x = 0 of each hypar, duplicated for the cells right of it)."""
    import rhino3dm

    model = rhino3dm.File3dm()
    for name, mesh in objects:
        points, cells = [tuple(p) for p in mesh.points], mesh.cells["triangle"].copy()
        right = mesh.points[cells].mean(axis=1)[:, 0] > 0
        copies = {}
        for row in np.flatnonzero(right):
            for k, node in enumerate(cells[row]):
                if abs(mesh.points[node, 0]) < 1e-12:
                    if node not in copies:
                        copies[node] = len(points)
                        points.append(tuple(mesh.points[node]))
                    cells[row, k] = copies[node]
        rhino_mesh = rhino3dm.Mesh()
        for point in points:
            rhino_mesh.Vertices.Add(*map(float, point))
        for a, b, c in cells:
            rhino_mesh.Faces.AddFace(int(a), int(b), int(c))
        attributes = rhino3dm.ObjectAttributes()
        attributes.Name = name
        model.Objects.AddMesh(rhino_mesh, attributes)
    model.Write(str(path), 7)
    return path


def test_rhino_meshes_with_a_vertex_per_face_at_seams_are_welded(tmp_path):
    roof = vares.examples.hypar(n=8)
    path = _unwelded_3dm(tmp_path / "roof.3dm", [("roof", roof)])
    with pytest.warns(UserWarning, match=r"welded 9 node\(s\)") as said:
        mesh = vares.read_mesh(path)
    assert "belong to no cell" not in str(said[0].message)  # welded, not also "unused"
    assert mesh.num_points == roof.num_points and len(mesh.boundary_loops()) == 1
    result = run("pattern", path, "-o", tmp_path / "out", "-q")
    assert result.exit_code == 0, result.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["repairs"]["roof.3dm"]["welded_nodes"] == 9
    # a file of panels: each object welded, the repair said
    two = _unwelded_3dm(tmp_path / "two.3dm", [("a", roof), ("b", roof)])
    meshes = read_3dm(two)
    assert [m.repair.welded_nodes for m in meshes] == [9, 9]
    assert all(m.mesh.num_points == roof.num_points for m in meshes)
    with pytest.raises(vares.MeshError, match="2 separate pieces"):
        read_3dm(two, repair_meshes=False)


def test_rhino_files_without_meshes(tmp_path):
    import rhino3dm

    model = rhino3dm.File3dm()
    model.Objects.AddBrep(rhino3dm.Sphere(rhino3dm.Point3d(0, 0, 0), 1.0).ToBrep())
    path = tmp_path / "sphere.3dm"
    model.Write(str(path), 7)
    with pytest.raises(vares.MeshError, match=r"no usable mesh.*no render mesh"):
        read_3dm(path)
    broken = tmp_path / "broken.3dm"
    broken.write_bytes(b"3D Geometry File Format  truncated")
    with pytest.raises(vares.MeshError, match="cannot read"):
        read_3dm(broken)


def test_a_file_of_no_mesh_format_is_named_by_its_suffix(tmp_path):
    mould = tmp_path / "mould.txt"
    mould.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", encoding="utf-8")
    with pytest.raises(vares.MeshError, match=r"mould.txt: '\.txt' is no mesh format .*\.obj"):
        vares.read_mesh(mould)
    assert vares.read_mesh(mould.rename(tmp_path / "mould.obj")).num_cells == 1


def test_report_pictures_are_drawn_at_the_reports_resolution(tmp_path):
    """The report's own pictures are PNGs at its 100 dpi (a 6.5-inch field map is 650 pixels
    wide, a 7-inch view 700) whose cells are opaque colours, not the 150-dpi files'; the pattern
    is the run's own pattern.png, embedded as it is."""
    import gc
    import io
    import re

    from PIL import Image

    out = tmp_path / "hypar"
    result = run("example", "hypar", "-o", out, "--report", "-q")
    assert result.exit_code == 0, result.stderr
    assert gc.get_freeze_count() == 0  # the collector as the report found it
    text = (out / "report.html").read_text()
    embedded = r'<figure id="([^"]+)"><img alt="[^"]*" src="data:image/png;base64,([^"]+)"'
    found = re.findall(embedded, text)
    pictures = {ident: Image.open(io.BytesIO(base64.b64decode(data))) for ident, data in found}
    assert set(pictures) >= {"figure-convergence", "figure-pattern", "figure-det_F"}
    for ident in ("figure-det_F", "figure-warp_stress", "figure-shear_angle", "figure-stress_min"):
        assert pictures[ident].size[0] == 650
        centre = pictures[ident].convert("RGBA").getpixel((300, pictures[ident].size[1] // 2))
        assert centre[3] == 255 and centre[:3] != (255, 255, 255)  # a cell's colour
    for ident in ("figure-convergence", "figure-surface-det_F", "figure-surface-warp_stress"):
        assert pictures[ident].size[0] == 700
    pattern = base64.b64encode((out / "pattern.png").read_bytes()).decode("ascii")
    assert dict(found)["figure-pattern"] == pattern


def test_drawing_a_report_leaves_the_collector_as_it_found_it():
    import gc

    from vares.app.html_parts import report_drawing

    assert gc.get_freeze_count() == 0
    with report_drawing():
        assert gc.get_freeze_count() > 0  # what was there before is left alone meanwhile
    assert gc.get_freeze_count() == 0
    gc.freeze()  # frozen by someone else: theirs, untouched
    try:
        frozen = gc.get_freeze_count()
        with report_drawing():
            pass
        assert gc.get_freeze_count() == frozen
    finally:
        gc.unfreeze()


def test_pattern_outputs_drawings_and_report_in_a_browser(tmp_path):
    out = tmp_path / "sail"
    result = run(
        "example",
        "sail",
        "-o",
        out,
        "--fabric",
        "pes-pvc-type-2",
        "--prestress",
        "2,1.5",
        "--warp-direction",
        "1,1,0",
        "--report",
        "--allowance",
        30,
        "--mark-spacing",
        1000,
        "--erect",
        "-q",
    )
    assert result.exit_code == 0, result.stderr
    for name in ("pattern.svg", "pattern.png", "report.html", "pattern.dxf"):
        assert (out / name).stat().st_size > 10_000
    assert (out / "pattern.svg").read_text()[:200].lstrip().startswith("<?xml")
    assert (out / "pattern.png").read_bytes()[:4] == b"\x89PNG"
    summary = json.loads((out / "summary.json").read_text())
    chromium = shutil.which("chromium")
    assert chromium, "Debian's chromium is needed (scripts/install-test-deps.sh installs it)"
    dom = subprocess.run(
        [
            chromium,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            f"--user-data-dir={tmp_path / 'profile'}",
            "--dump-dom",
            (out / "report.html").as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    ).stdout
    assert "<h1>Cutting pattern: sail</h1>" in dom
    assert 'class="status-ok">converged' in dom
    area = f"{summary['surface_area']:.5g} m²"
    assert f'<th>surface area</th><td class="num">{area}</td>' in dom
    compensation = summary["compensation"]["warp"]["compensation_mean"]
    assert f"{compensation:.3f}" in dom.split('id="compensation"')[1].split("</table>")[0]
    assert dom.count("data:image/png;base64,") >= 9
    for figure in (
        "figure-convergence",
        "figure-pattern",
        "figure-det_F",
        "figure-warp_stress",
        "figure-surface-det_F",
        *(f"figure-erection-{k}" for k in range(6)),
    ):
        assert f'id="{figure}"' in dom
    # the erected pictures embedded as erect/ holds them (0, 2, 4, 5), the design shape's drawn
    html = (out / "report.html").read_text()
    for k, name in ((0, "deviation.png"), (2, "warp_stress.png"), (5, "state.png")):
        png = base64.b64encode((out / "erect" / name).read_bytes()).decode("ascii")
        assert (
            f'id="figure-erection-{k}"><img alt="' in html
            and png in html.split(f'id="figure-erection-{k}"')[1].split("</figure>")[0]
        )
    # the erection section: design shape against erected, the numbers of erect.json
    erected = json.loads((out / "erect" / "erect.json").read_text())
    comparison = dom.split('id="erection-comparison"')[1].split("</table>")[0]
    assert "<th>on the design shape</th><th>after erection</th>" in comparison
    design, mean = (
        erected["design_shape"]["stress"]["warp"]["mean"],
        erected["stress"]["warp"]["mean"],
    )
    row = f'<th>warp: mean</th><td class="num">{design:.4g}</td><td class="num">{mean:.4g}</td>'
    assert row in comparison  # four digits, as the command line prints them
    screenshot = tmp_path / "report.png"
    subprocess.run(
        [
            chromium,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            f"--user-data-dir={tmp_path / 'profile2'}",
            "--window-size=1000,1400",
            f"--screenshot={screenshot}",
            (out / "report.html").as_uri(),
        ],
        capture_output=True,
        timeout=120,
        check=True,
    )
    from PIL import Image

    image = np.asarray(Image.open(screenshot).convert("L"), dtype=float)
    assert image.std() > 10  # the page shows text and pictures, not a blank screen


def test_job_files_run_save_and_report_bad_keys(tmp_path):
    mesh = vares.examples.hypar(size=4.0, rise=0.2, n=6)
    meshio.write(
        tmp_path / "roof.ply", meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])])
    )
    job = tmp_path / "job.toml"
    job.write_text(
        '[input]\nmesh = "roof.ply"\n\n[material]\nfabric = "pes-pvc-type-3"\n\n'
        "[fibres]\nwarp_direction = [1.0, 0.0, 0.0]\n\n[prestress]\nwarp = 2.0\nfill = 1.5\n\n"
        '[output]\ndirectory = "out"\nallowance = 20.0\n'
    )
    result = run("run", job, "-q")
    assert result.exit_code == 0, result.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["converged"] and summary["material"]["E1"] == 1100.0
    assert summary["compensation"]["warp"]["compensation_mean"] > 0
    # the command line writes the job it ran; running that job gives the same pattern
    saved = tmp_path / "saved.toml"
    result = run(
        "pattern",
        tmp_path / "roof.ply",
        "-o",
        tmp_path / "cli",
        "--fabric",
        "pes-pvc-type-3",
        "--warp-direction",
        "1,0,0",
        "--prestress",
        "2,1.5",
        "--save-job",
        saved,
        "-q",
    )
    assert result.exit_code == 0, result.stderr
    assert load_job(saved).material.to_dict() == {"thickness": 1.0, "fabric": "pes-pvc-type-3"}
    assert 'mesh = "roof.ply"' in saved.read_text()  # relative to the job file
    assert run("run", saved, "-q", "-o", tmp_path / "again").exit_code == 0
    a = meshio.read(tmp_path / "cli" / "pattern.obj").points
    b = meshio.read(tmp_path / "again" / "pattern.obj").points
    np.testing.assert_allclose(a, b, atol=1e-12)
    np.testing.assert_allclose(a, meshio.read(tmp_path / "out" / "pattern.obj").points, atol=1e-9)
    for text, message in [
        (
            '[input]\nmesh = "roof.ply"\n[solver]\ntolerence = 1e-8\n',
            "[solver] unknown key 'tolerence' (did you mean 'tolerance'?)",
        ),
        (
            '[input]\nmesh = "roof.ply"\n[material]\nthickness = "thick"\n',
            "[material] thickness must be a number",
        ),
        (
            '[input]\nmesh = "roof.ply"\n[outputs]\nreport = true\n',
            "unknown table [outputs] (did you mean [output]?)",
        ),
        ("[input]\n", "[input] needs exactly one of mesh, meshes or example"),
        ('[input]\nmesh = "roof.ply"\n[prestress]\nwarp = 2.0\n', "needs both warp and fill"),
        ('[input]\nmesh = "roof.ply"\n[output]\nreport = 1\n', "report must be true or false"),
        ("[input\n", "not valid TOML"),
    ]:
        job.write_text(text)
        result = run("run", job, "-q")
        assert result.exit_code == 2
        line = [x for x in result.stderr.splitlines() if x.startswith("vares: error:")]
        assert len(line) == 1 and message in line[0], (message, result.stderr)
    with pytest.raises(JobError):
        load_job(job)


def test_a_job_file_reads_back_whatever_its_names_and_paths_hold(tmp_path):
    from vares.app.job import Job

    odd = 'roof "north"\\ C:\\tmp\tpanel\nline two\r\x01\x7f ü Ω 屋根 🎪'
    job = Job.from_dict(
        {
            "input": {"mesh": f"{odd}.obj", "name": odd, "panel_field": odd},
            "prestress": {"field": [odd, "fill"]},
            "output": {"directory": odd},
        },
        base=tmp_path,
    )
    text = job.to_toml(tmp_path / "job.toml")
    (tmp_path / "job.toml").write_text(text, encoding="utf-8")
    again = load_job(tmp_path / "job.toml")
    assert again.input.name == odd and again.input.panel_field == odd
    assert again.prestress.field == (odd, "fill")
    assert again.path(again.input.mesh) == tmp_path / f"{odd}.obj"
    assert again.directory == tmp_path / odd
    assert again.to_dict() == job.to_dict()
    # the job a run writes into its folder runs again, from a file whose name has a newline
    mesh = vares.examples.hypar(size=4.0, rise=0.2, n=6)
    source = tmp_path / 'new\nline "quoted"\ttab.ply'
    meshio.write(source, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]))
    result = run("pattern", source, "-o", tmp_path / "first", "-q")
    assert result.exit_code == 0, result.stderr
    result = run("run", tmp_path / "first" / "job.toml", "-o", tmp_path / "second", "-q")
    assert result.exit_code == 0, result.stderr
    written = load_job(tmp_path / "first" / "job.toml")
    assert written.path(written.input.mesh).resolve() == source.resolve()
    np.testing.assert_allclose(
        meshio.read(tmp_path / "second" / "pattern.obj").points,
        meshio.read(tmp_path / "first" / "pattern.obj").points,
        atol=1e-12,
    )


@pytest.mark.parametrize(
    ("name", "content"),
    [
        ("empty.obj", b""),
        ("truncated.stl", b"solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1"),
        ("binary.stl", b"\x00" * 80 + b"\x05\x00\x00\x00" + b"\x00" * 20),
        ("picture.obj", b"\x89PNG\r\n\x1a\n" + bytes(range(256))),
        ("nan.obj", b"v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n"),
        ("broken.vtu", b"<?xml version='1.0'?><VTKFile type='UnstructuredGrid'><Unstr"),
        ("inf.obj", b"v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n"),
        ("points.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
        ("lines.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n"),
        ("range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
        ("collinear.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"),
    ],
)
def test_bad_files_fail_in_one_line_and_leave_no_output(tmp_path, name, content):
    path = tmp_path / name
    path.write_bytes(content)
    out = tmp_path / "out"
    result = run("pattern", path, "-o", out, "--report")
    assert result.exit_code == 2
    assert "Traceback" not in result.stdout + result.stderr
    lines = [x for x in result.stderr.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("vares: error:"), result.stderr
    assert name in lines[0]  # the message names the file
    assert not out.exists() or not any(out.iterdir())
