import json

import meshio
import numpy as np
import pytest
from conftest import error_line, run

import vares
from vares.geometry.examples import cylinder160, cylinder_arc_length, hypar


def test_example_cylinder160_writes_surface_pattern_and_summary(tmp_path):
    out = tmp_path / "cyl"
    result = run("example", "cylinder160", "-o", out, "--cell-type", "quad")
    assert result.exit_code == 0, result.stderr
    assert "converged" in result.stderr and "step" in result.stderr  # progress was shown
    surface = meshio.read(out / "surface.obj")
    pattern = meshio.read(out / "pattern.obj")
    np.testing.assert_array_equal(pattern.cells_dict["quad"], surface.cells_dict["quad"])
    np.testing.assert_array_equal(pattern.points[:, 2], 0.0)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["converged"] is True
    assert summary["iterations"] > 0
    assert summary["pattern_area"] == pytest.approx(summary["surface_area"], rel=1e-9)
    assert abs(summary["energy"]) < 1e-9
    width = np.ptp(pattern.points[:, 0])
    assert width == pytest.approx(cylinder_arc_length(), rel=1e-9)
    assert summary["fields"]["det_F"]["max"] == pytest.approx(1.0, abs=1e-8)
    assert len(summary["history"]) == summary["iterations"] + len(summary["steps"])


def test_pattern_command_on_a_mesh_file(tmp_path):
    mesh = hypar(size=4.0, rise=0.15, n=8)
    source = tmp_path / "hypar.ply"
    meshio.write(source, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]))
    out = tmp_path / "out"
    result = run(
        "pattern",
        source,
        "-o",
        out,
        "--material",
        "st-venant-kirchhoff",
        "--E",
        600,
        "--nu",
        0.4,
        "--thickness",
        0.5,
        "-q",
    )
    assert result.exit_code == 0, result.stderr
    assert result.stderr == ""
    summary = json.loads((out / "summary.json").read_text())
    assert summary["material"] == {"law": "StVenantKirchhoff", "E": 600.0, "nu": 0.4}
    assert summary["thickness"] == 0.5
    expected = vares.solve(mesh, vares.materials.StVenantKirchhoff(600.0, 0.4), 0.5)
    assert summary["energy"] == pytest.approx(expected.energy, rel=1e-9)
    pattern = meshio.read(out / "pattern.obj")
    assert len(pattern.points) == mesh.num_points


def test_existing_outputs_are_not_overwritten_without_force(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text("keep me")
    result = run("example", "cylinder160", "-o", out, "-q")
    assert result.exit_code == 2
    assert "output exists" in error_line(result) and "--force" in error_line(result)
    assert (out / "summary.json").read_text() == "keep me"
    assert not (out / "pattern.obj").exists()
    result = run("example", "cylinder160", "-o", out, "-q", "--force")
    assert result.exit_code == 0
    assert json.loads((out / "summary.json").read_text())["converged"] is True


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("", "is empty"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 nan\nf 1 2 3\n", "non-finite coordinates"),
        ("v 0 0 0\nv 1 0 0\nf 1 2 5\n", "face 1 refers to vertex 5 but the file has 2 vertices"),
        ("this is not a mesh\n", "contains no vertices"),
    ],
)
def test_bad_input_gives_one_line_and_exit_2(tmp_path, content, message):
    path = tmp_path / "bad.obj"
    path.write_text(content)
    result = run("pattern", path, "-o", tmp_path / "out")
    assert result.exit_code == 2
    assert message in error_line(result)
    assert "Traceback" not in result.stderr + result.stdout
    assert not (tmp_path / "out").exists()


def test_missing_file_and_bad_options(tmp_path):
    result = run("pattern", tmp_path / "nope.obj", "-o", tmp_path / "out")
    assert result.exit_code == 2 and "no such file" in error_line(result)
    result = run("example", "cylinder160", "-o", tmp_path / "o", "--nu", 0.7)
    assert result.exit_code == 2 and "Poisson" in error_line(result)
    result = run("example", "sphere", "-o", tmp_path / "o")
    assert result.exit_code == 2 and "--example must be one of cylinder160" in error_line(result)
    result = run("example", "cylinder160", "-o", tmp_path / "o", "--plane", "1,a,0")
    assert result.exit_code == 2 and "--plane" in error_line(result)


def test_an_internal_error_is_no_usage_error(tmp_path, monkeypatch):
    """Exit 2 is for what vares refuses; a ValueError that numpy raises (arrays vares got wrong)
    is an internal error, exit 3, although it is a ValueError too."""
    import typer

    from vares.app.cli.common import guarded
    from vares.geometry.mesh import MeshError
    from vares.units import unit_factor

    def code(body) -> int:
        with pytest.raises(typer.Exit) as raised:
            guarded(body)
        return raised.value.exit_code

    def mesh_error():
        raise MeshError("bad cells")

    assert code(lambda: np.ones(37) * np.ones(39)) == 3
    assert code(lambda: np.linalg.inv(np.ones((2, 3)))) == 3
    assert code(lambda: unit_factor("parsec", "m")) == 2  # vares's own ValueError
    assert code(mesh_error) == 2
    assert code(lambda: b"\xff".decode("utf-8")) == 2  # a file that is no text

    def broadcasting(*args, **kwargs):
        return np.ones(37) * np.ones(39)

    monkeypatch.setattr("vares.structures.cutting.plan_strips", broadcasting)
    path = tmp_path / "hypar.obj"
    mesh = hypar(n=4)
    meshio.write(path, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]))
    result = run("cut", path, "--roll-width", 2.5, "-o", tmp_path / "out", "-q")
    assert result.exit_code == 3, result.stderr
    assert error_line(result).startswith("vares: error: internal error: ValueError: operands")


def test_failed_solve_exits_1_with_the_reason_and_writes_no_pattern(tmp_path):
    out = tmp_path / "out"
    result = run("example", "cylinder160", "-o", out, "--strategy", "newton", "-q")
    assert result.exit_code == 1
    assert "did not converge: inverted elements" in error_line(result)
    assert not (out / "pattern.obj").exists()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["converged"] is False and summary["reason"].startswith("inverted")


def test_an_absurd_mark_spacing_is_refused_before_the_solve(tmp_path):
    mesh = hypar(size=4.0, rise=0.15, n=8)
    source = tmp_path / "hypar.obj"
    meshio.write(source, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]))
    (loop,) = mesh.boundary_loops()
    ring = mesh.points[np.append(loop, loop[0])]
    boundary = np.linalg.norm(np.diff(ring, axis=0), axis=1).sum()  # metres
    out = tmp_path / "out"
    for command in ("pattern", "cut"):
        extra = ("--roll-width", 1.5) if command == "cut" else ()
        result = run(command, source, "-o", out, "--mark-spacing", 1e-9, *extra)
        assert result.exit_code == 2, result.stderr
        line = error_line(result)
        assert "--mark-spacing" in line and f"{boundary:.3g} m of the surface's boundary" in line
        assert f"at least {boundary * 1000 / 100_000:.3g} mm" in line
        assert "step" not in result.stderr and not out.exists()  # before the solve
    # a spacing that leaves fewer marks than the bound is drawn
    result = run("pattern", source, "-o", out, "--mark-spacing", 500, "-q")
    assert result.exit_code == 0, result.stderr
    import ezdxf

    marks = ezdxf.readfile(out / "pattern.dxf").modelspace().query("LINE[layer=='MARKS']")
    assert len(marks) == pytest.approx(boundary / 0.5, abs=1)


def test_plane_normal_option(tmp_path):
    mesh = cylinder160(n_around=12, n_along=3)
    source = tmp_path / "c.vtu"
    meshio.write(source, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]))
    result = run("pattern", source, "-o", tmp_path / "out", "--plane", "0,0,1", "-q")
    assert result.exit_code == 0, result.stderr


def test_anisotropic_pattern_with_a_warp_direction_writes_fields(tmp_path):
    mesh = hypar(size=4.0, rise=0.2, n=8)
    source = tmp_path / "sail.obj"
    meshio.write(source, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]))
    out = tmp_path / "out"
    result = run(
        "pattern",
        source,
        "-o",
        out,
        "--material",
        "orthotropic",
        "--E1",
        800,
        "--E2",
        640,
        "--G12",
        40,
        "--nu12",
        0.4,
        "--warp-direction",
        "1,1,0",
    )
    assert result.exit_code == 0, result.stderr
    assert "warp_stress" in result.stderr  # the results table
    summary = json.loads((out / "summary.json").read_text())
    assert summary["material"] == {
        "law": "OrthotropicStVenantKirchhoff",
        "E1": 800.0,
        "E2": 640.0,
        "G12": 40.0,
        "nu12": 0.4,
    }
    assert summary["fibres"]["orientation"] == "direction"
    assert abs(summary["fibres"]["warp_deviation_degrees"]) < 1e-6
    for name in ("warp_stretch", "shear_angle", "warp_stress", "fill_stress", "det_F"):
        assert set(summary["fields"][name]) == {"min", "max", "mean"}
    vtu = meshio.read(out / "pattern.vtu")
    assert np.abs(vtu.points[:, 2]).max() == 0.0
    expected = vares.solve(
        mesh,
        vares.materials.OrthotropicStVenantKirchhoff(800, 640, 40, 0.4),
        warp_direction=(1, 1, 0),
    )
    np.testing.assert_allclose(
        vtu.cell_data["shear_angle"][0], expected.fields["shear_angle"], rtol=1e-6, atol=1e-9
    )
    surface = meshio.read(out / "surface.vtu")
    np.testing.assert_allclose(surface.points, mesh.points)
    assert set(surface.cell_data) == set(vtu.cell_data)
    assert summary["fields"]["warp_stress"]["max"] == pytest.approx(
        expected.fields["warp_stress"].max(), rel=1e-6
    )


def test_ncf_and_evaluate_ply_check(tmp_path):
    out = tmp_path / "rib"
    result = run(
        "example",
        "hypar",
        "-o",
        out,
        "--material",
        "ncf",
        "--A",
        "-250,250",
        "--B",
        "-250,250",
        "--C",
        "2.5",
        "--warp-angle",
        45,
        "-q",
    )
    assert result.exit_code == 0, result.stderr
    check = tmp_path / "check"
    result = run(
        "evaluate",
        out / "surface.obj",
        out / "pattern.obj",
        "-o",
        check,
        "--material",
        "ncf",
        "--A",
        "-250,250",
        "--B",
        "-250,250",
        "--C",
        "2.5",
        "--warp-angle",
        0,
    )
    assert result.exit_code == 0, result.stderr
    data = json.loads((check / "evaluation.json").read_text())
    assert 0 < data["compressed_area_fraction"] <= 1
    assert len(data["compressed_cells"]) > 0
    assert "yarns in compression" in result.stderr
    vtu = meshio.read(check / "evaluation.vtu")
    flags = vtu.cell_data["compressed_yarns"][0]
    np.testing.assert_array_equal(np.flatnonzero(flags), data["compressed_cells"])
    # a pattern that is not of this surface is refused
    other = tmp_path / "other.obj"
    meshio.write(other, meshio.Mesh(np.zeros((3, 3)), [("triangle", [[0, 1, 2]])]))
    result = run(
        "evaluate",
        out / "surface.obj",
        other,
        "-o",
        tmp_path / "x",
        "--material",
        "ncf",
        "--A",
        "-250,250",
        "--B",
        "-250,250",
        "--C",
        "2.5",
    )
    assert result.exit_code == 2 and "nodes and faces" in error_line(result)


def test_evaluate_names_the_nodes_of_a_pattern_that_is_not_finite(tmp_path):
    mesh = hypar(size=4.0, rise=0.15, n=6)
    surface = tmp_path / "surface.obj"
    meshio.write(surface, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]))
    flat = np.column_stack([mesh.points[:, :2], np.zeros(mesh.num_points)])
    flat[[5, 17], 0] = np.nan
    flat[30, 1] = np.inf
    pattern = tmp_path / "pattern.obj"
    meshio.write(pattern, meshio.Mesh(flat, [("triangle", mesh.cells["triangle"])]))
    result = run("evaluate", surface, pattern, "-o", tmp_path / "check", "--E", 100, "--nu", 0.3)
    assert result.exit_code == 2
    line = error_line(result)
    assert "pattern.obj: the pattern's coordinates are not finite" in line
    assert line.endswith("at nodes 5, 17, 30") and "inverts" not in line
    assert not (tmp_path / "check").exists()
    material = vares.materials.NeoHooke(E=100.0, nu=0.3)
    with pytest.raises(ValueError, match=r"not finite .* at nodes 5, 17, 30$"):
        vares.evaluate(mesh, flat[:, :2], material)


def test_material_option_errors(tmp_path):
    result = run("example", "hypar", "-o", tmp_path / "o", "--material", "orthotropic", "--E1", 800)
    assert result.exit_code == 2 and "orthotropic needs E2, G12, nu12" in error_line(result)
    result = run("example", "hypar", "-o", tmp_path / "o", "--material", "ncf", "--A", "1,x")
    assert result.exit_code == 2 and "--A" in error_line(result)
    result = run("example", "hypar", "-o", tmp_path / "o", "--warp-direction", "1,0")
    assert result.exit_code == 2 and "three numbers" in error_line(result)


def test_fabric_preset_and_prestress_report(tmp_path):
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
    )
    assert result.exit_code == 0, result.stderr
    assert "compensation, mean" in result.stderr
    summary = json.loads((out / "summary.json").read_text())
    compensation = summary["compensation"]
    assert compensation["warp"]["compensation_mean"] > 0.1
    assert compensation["fill"]["compensation_mean"] > 0.1
    assert compensation["warp"]["target_mean"] == pytest.approx(2.0)
    assert compensation["fill"]["achieved_mean"] == pytest.approx(1.5, rel=0.01)
    assert summary["material"]["E1"] == 840.0


def test_prestress_field_option(tmp_path):
    mesh = vares.examples.four_point_sail(n=6)
    m = mesh.num_cells
    source = tmp_path / "sail.vtu"
    meshio.write(
        source,
        meshio.Mesh(
            mesh.points,
            [("triangle", mesh.cells["triangle"])],
            cell_data={
                "nw": [np.full(m, 2.0)],
                "nf": [np.full(m, 1.5)],
                "n": [np.tile([2.0, 1.5], (m, 1))],
            },
        ),
    )
    runs = {}
    for option in ("nw,nf", "n"):
        out = tmp_path / option.replace(",", "_")
        result = run(
            "pattern",
            source,
            "-o",
            out,
            "--fabric",
            "pes-pvc-type-2",
            "--prestress-field",
            option,
            "-q",
        )
        assert result.exit_code == 0, result.stderr
        runs[option] = json.loads((out / "summary.json").read_text())
    uniform = tmp_path / "uniform"
    assert (
        run(
            "pattern",
            source,
            "-o",
            uniform,
            "--fabric",
            "pes-pvc-type-2",
            "--prestress",
            "2,1.5",
            "-q",
        ).exit_code
        == 0
    )
    expected = json.loads((uniform / "summary.json").read_text())["energy"]
    assert runs["n"]["energy"] == pytest.approx(expected, rel=1e-9)
    assert runs["nw,nf"]["energy"] == pytest.approx(expected, rel=1e-9)
    result = run(
        "pattern",
        source,
        "-o",
        tmp_path / "x",
        "--fabric",
        "pes-pvc-type-2",
        "--prestress-field",
        "sigma",
    )
    assert result.exit_code == 2 and "no cell data" in error_line(result)
    result = run(
        "pattern",
        source,
        "-o",
        tmp_path / "x",
        "--fabric",
        "pes-pvc-type-2",
        "--prestress",
        "2",
        "--prestress-field",
        "n",
    )
    assert result.exit_code == 2 and "not both" in error_line(result)
    result = run("pattern", source, "-o", tmp_path / "x", "--fabric", "mystery")
    assert result.exit_code == 2 and "unknown fabric preset" in error_line(result)
    result = run("pattern", source, "-o", tmp_path / "x", "--fabric", "pes-pvc-type-2", "--E1", 5)
    assert result.exit_code == 2 and "a fabric preset sets the material" in error_line(result)


def test_fabrics_lists_the_presets():
    result = run("fabrics")
    assert result.exit_code == 0
    assert "pes-pvc-type-2" in result.stdout and "typical value" in result.stdout


def test_no_previews_writes_everything_but_the_pictures(tmp_path):
    out = tmp_path / "out"
    result = run("example", "hypar", "-o", out, "--no-previews")
    assert result.exit_code == 0, result.stderr
    written = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    assert "pattern.dxf" in written and "pattern.obj" in written and "summary.json" in written
    assert "pattern.png" not in written and "pattern.svg" not in written
    # the job file records the choice, so a rerun of it writes the same files
    assert "previews = false" in (out / "job.toml").read_text()


def test_the_vares_script_exits_with_the_commands_status(tmp_path):
    import subprocess
    import sys

    script = "from vares.app.cli import main; main()"
    ok = subprocess.run(
        [sys.executable, "-c", script, "fabrics"], capture_output=True, text=True, check=False
    )
    assert ok.returncode == 0 and "PES/PVC" in ok.stdout
    missing = subprocess.run(
        [sys.executable, "-c", script, "pattern", str(tmp_path / "none.obj"), "-o", tmp_path],
        capture_output=True,
        text=True,
        check=False,
    )
    assert missing.returncode == 2
    assert "no such file" in missing.stderr


def test_version_and_help():
    from vares import __version__

    result = run("--version")
    assert result.exit_code == 0 and result.stdout.strip() == f"vares {__version__}"
    result = run("--help")
    assert result.exit_code == 0
    for command in ("pattern", "run", "panels", "cut", "erect", "batch", "--version"):
        assert command in result.stdout


def test_plot_writes_each_field_on_the_pattern_and_the_surface(tmp_path):
    from PIL import Image

    out = tmp_path / "out"
    # a doubly curved sail: on a developable surface both fields are round-off, and how much
    # two pictures of round-off differ depends on the round-off
    result = run("example", "sail", "-o", out, "--plot", "det_F,warp_stress")
    assert result.exit_code == 0, result.stderr
    pictures = {}
    for field in ("det_F", "warp_stress"):
        for name in (f"pattern_{field}.svg", f"pattern_{field}.png", f"surface_{field}.png"):
            assert (out / name).stat().st_size > 1000
        pictures[field] = np.asarray(Image.open(out / f"pattern_{field}.png").convert("RGB"))
    # one figure re-coloured field after field: the second picture is its own, not the first's
    assert pictures["det_F"].shape == pictures["warp_stress"].shape
    assert (pictures["det_F"] != pictures["warp_stress"]).any(axis=-1).mean() > 0.05


def test_the_iterations_a_run_reports_are_those_the_limit_bounds_per_solve(tmp_path):
    """--max-iterations bounds each attempt and pseudo-time step; the run's line says so: the
    total, and the limit with the number of solves it bounded (a sail started from its
    projection with a limit of 2 falls back to pseudo-time stepping with its steps cut back;
    from the automatic start, one ARAP step further, it converges in 2)."""
    limited = ("--max-iterations", "2", "--initial-guess", "projection")
    result = run("example", "sail", "-o", tmp_path / "s", *limited)
    assert result.exit_code == 0, result.stderr
    line = next(x for x in result.stderr.splitlines() if x.startswith("sail: converged"))
    summary = json.loads((tmp_path / "s" / "summary.json").read_text())
    total = summary["iterations"]
    assert f"in {total} Newton iterations" in line and "at most 2 in each of" in line
    solves = int(line.split("at most 2 in each of ")[1].split(")")[0])
    assert total <= 2 * solves
