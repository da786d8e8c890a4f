"""Where users reach the erection: --erect on the patterning commands, vares erect DIR, job
files, and the one options model behind them."""

import base64
import inspect
import json

import meshio
import numpy as np
import pytest
from conftest import error_line, run

import vares
from vares.analysis import ErectionOptions
from vares.app.job import SECTIONS, load_job

FILES = {
    "erect.json",
    "erected.vtu",
    "erected.obj",
    "deviation.png",
    "warp_stress.png",
    "fill_stress.png",
    "state.png",
}


def test_pattern_then_erect_the_directory_matches_erect_in_the_same_run(tmp_path):
    """A mesh file patterned with prestress, then `vares erect DIR`: the same numbers as the API
    and as `--erect` in the patterning run; flags override the job's [erection] table."""
    mesh = vares.examples.four_point_sail(n=8)
    source = tmp_path / "sail.obj"
    meshio.write(source, meshio.Mesh(mesh.points, list(mesh.cells.items())))
    flags = ["--fabric", "pes-pvc-type-2", "--prestress", "2,1.5", "--warp-direction", "1,1,0"]
    result = run("pattern", source, "-o", tmp_path / "p", *flags, "-q")
    assert result.exit_code == 0, result.stderr
    assert (tmp_path / "p" / "job.toml").is_file() and not (tmp_path / "p" / "erect").exists()
    result = run("erect", tmp_path / "p")
    assert result.exit_code == 0, result.stderr
    assert "on the design shape" in result.stderr and "normal deviation" in result.stderr
    assert {p.name for p in (tmp_path / "p" / "erect").iterdir()} == FILES
    later = json.loads((tmp_path / "p" / "erect" / "erect.json").read_text())
    result = run("pattern", source, "-o", tmp_path / "q", *flags, "--erect", "-q")
    assert result.exit_code == 0, result.stderr
    same_run = json.loads((tmp_path / "q" / "erect" / "erect.json").read_text())
    # summary.json says the erection beside the design shape (erect.json has the whole of it)
    told = json.loads((tmp_path / "q" / "summary.json").read_text())["erection"]
    assert told["converged"] and not told["optimised"] and told["file"] == "erect/erect.json"
    assert set(told["states"]) == {"design_shape", "erected"}
    assert told["states"]["erected"]["deviation"] == same_run["deviation"]
    assert told["states"]["erected"]["area"] == same_run["erected_area"]
    for yarn in ("warp", "fill"):
        assert told["states"]["erected"]["stress"][yarn] == same_run["stress"][yarn]
        assert (
            told["states"]["design_shape"]["stress"][yarn]
            == (same_run["design_shape"]["stress"][yarn])
        )
    assert told["states"]["design_shape"]["deviation"] == {"max": 0.0, "rms": 0.0}
    assert "erection" not in json.loads((tmp_path / "p" / "summary.json").read_text())
    fabric = vares.materials.fabric("pes-pvc-type-2").material()
    api = vares.erect(
        vares.solve(vares.read_mesh(source), fabric, warp_direction=(1, 1, 0), prestress=(2, 1.5))
    ).to_dict()
    for data in (later, same_run):
        assert data["converged"] and data["units"] == "m"
        assert data["deviation"]["max"] == pytest.approx(api["deviation"]["max"], rel=1e-9)
        for yarn in ("warp", "fill"):
            for key in ("mean", "min", "max", "intended", "rms_deviation"):
                assert data["stress"][yarn][key] == pytest.approx(
                    api["stress"][yarn][key], rel=1e-9
                )
    erected = meshio.read(tmp_path / "p" / "erect" / "erected.vtu")
    design = vares.read_mesh(source).points  # the file holds the erected positions
    np.testing.assert_allclose(
        erected.points - design, erected.point_data["displacement"], atol=1e-12
    )
    deviation = erected.point_data["normal_deviation"]
    assert np.abs(deviation).max() == pytest.approx(api["deviation"]["max"], rel=1e-9)
    assert "design_warp_stress" in erected.cell_data and "state" in erected.cell_data
    # nothing is overwritten without --force; flags override the job's table
    result = run("erect", tmp_path / "p", "-q")
    assert result.exit_code == 2 and "output exists" in error_line(result)
    result = run("erect", tmp_path / "p", "--pressure", "0.05", "--report", "-f", "-q")
    assert result.exit_code == 0, result.stderr
    pressed = json.loads((tmp_path / "p" / "erect" / "erect.json").read_text())
    assert pressed["options"]["pressure"] == 0.05
    assert pressed["deviation"]["max"] > later["deviation"]["max"]
    assert "erection-comparison" in (tmp_path / "p" / "erect" / "report.html").read_text()


def test_panels_with_erect_weld_the_strips_and_run_again_from_the_saved_job(tmp_path):
    mesh, ids = vares.examples.hypar_strips(strips=3, cells_per_strip=2, n=8)
    source = tmp_path / "strips.vtu"
    cells = [("triangle", mesh.cells["triangle"])]
    meshio.write(source, meshio.Mesh(mesh.points, cells, cell_data={"panel": [ids]}))
    out = tmp_path / "strips"
    result = run(
        "panels",
        source,
        "-o",
        out,
        "--fabric",
        "pes-pvc-type-2",
        "--prestress",
        "2,1.5",
        "--warp-direction",
        "0,1,0",
        "--erect",
        "--cable-stiffness",
        "5000",
        "--cable-force",
        "20",
        "--report",
        "-q",
    )
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "erect" / "erect.json").read_text())
    assert data["converged"] and len(data["panels"]) == 3
    # the structure's report embeds the erection's pictures as written, not drawn again
    report = (out / "report.html").read_text()
    for name in ("deviation.png", "warp_stress.png", "state.png"):
        assert base64.b64encode((out / "erect" / name).read_bytes()).decode() in report
    assert data["nodes"] == mesh.num_points  # the seams are welded: one node each
    assert data["held_nodes"] == 4 and data["cables"]["force_min"] > 0  # a four-point sail
    job = load_job(out / "job.toml")
    assert job.erection == ErectionOptions(cable_stiffness=5000.0, cable_force=20.0)
    result = run("erect", out, "-f", "-q")  # the saved [erection] table is used again
    again = json.loads((out / "erect" / "erect.json").read_text())
    assert result.exit_code == 0 and again["deviation"] == data["deviation"]
    result = run("run", out / "job.toml", "-o", tmp_path / "rerun", "-q")
    assert result.exit_code == 0, result.stderr
    rerun = json.loads((tmp_path / "rerun" / "erect" / "erect.json").read_text())
    assert rerun["stress"] == data["stress"]


def test_run_with_erect_and_clear_errors(tmp_path):
    job = tmp_path / "job.toml"
    job.write_text('[input]\nexample = "hypar"\n[output]\ndirectory = "out"\n')
    result = run("run", job, "--erect", "-q")
    assert result.exit_code == 0, result.stderr
    assert json.loads((tmp_path / "out" / "erect" / "erect.json").read_text())["converged"]
    result = run("example", "hypar", "-o", tmp_path / "x", "--pressure", "1", "-q")
    assert result.exit_code == 2 and "--pressure is an erection option: add --erect" in (
        error_line(result)
    )
    result = run("erect", tmp_path / "nothing")
    assert result.exit_code == 2 and "no such directory" in error_line(result)
    (tmp_path / "empty").mkdir()
    result = run("erect", tmp_path / "empty")
    assert result.exit_code == 2 and "no job.toml" in error_line(result)
    result = run("erect", tmp_path / "out", "--cable-stiffness", "10", "--pressure", "1", "-f")
    assert result.exit_code == 2 and "not conservative" in error_line(result)
    result = run("erect", job)
    assert result.exit_code == 2 and "is a file" in error_line(result)
    (tmp_path / "out" / "pattern.vtu").write_text("not a mesh\n")  # a damaged output folder
    result = run("erect", tmp_path / "out", "-f")
    assert result.exit_code == 2 and "cannot read" in error_line(result)
    bad = tmp_path / "bad.toml"
    bad.write_text('[input]\nexample = "hypar"\n[erection]\npresure = 1.0\n')
    result = run("run", bad, "-q")
    assert result.exit_code == 2 and "did you mean 'pressure'" in error_line(result)


def test_every_erection_option_is_reachable_from_all_three_with_one_default():
    erect = inspect.signature(vares.erect).parameters
    for name, spec in ErectionOptions.specs().items():
        assert spec.section in SECTIONS and SECTIONS[spec.section] == "erection", name
        assert erect[name].default == ErectionOptions.defaults()[name], name
        flag = "--" + name.replace("_", "-")
        for command in ("pattern", "example", "panels", "erect"):
            assert flag in run(command, "--help").stdout, (name, command)


def test_optimise_writes_the_optimised_patterns_and_both_erections(tmp_path):
    """`vares panels --erect --optimise`: the written patterns are the optimised ones (they
    erect as erect.json says), erect.json keeps the VaReS patterns' erected figures under
    `optimisation`, and the optimised patterns carry the intended mean forces closer; the
    seams stay matched in structure.json; without --erect, --optimise is refused."""
    flags = ["--fabric", "pes-pvc-type-2", "--prestress", "2,1.5", "--warp-direction", "0,1,0"]
    out = tmp_path / "strips"
    result = run(
        "panels", "--example", "hypar-strips", "-o", out, *flags, "--erect", "--optimise", "-q"
    )
    assert result.exit_code == 0, result.stderr
    erected = json.loads((out / "erect" / "erect.json").read_text())
    optimisation = erected["optimisation"]
    assert optimisation["converged"] and optimisation["iterations"] >= 1
    start = optimisation["start_erected"]["stress"]
    for yarn, intended in (("warp", 2.0), ("fill", 1.5)):
        assert (
            abs(erected["stress"][yarn]["mean"] - intended) < abs(start[yarn]["mean"] - intended)
            or abs(erected["stress"][yarn]["mean"] - intended) < 1e-3 * intended
        )
    rms = [
        np.hypot(s["warp"]["rms_deviation"], s["fill"]["rms_deviation"])
        for s in (start, erected["stress"])
    ]
    assert rms[1] < rms[0]
    structure = json.loads((out / "structure.json").read_text())
    assert max(s["max_segment_mismatch_after"] for s in structure["seams"]) < 1e-9
    # structure.json: the VaReS and the optimised patterns, on the design shape and erected
    states = structure["erection"]["states"]
    assert structure["erection"]["optimised"]
    assert states["optimised_erected"]["stress"] == erected["stress"]
    assert states["optimised_erected"]["deviation"] == erected["deviation"]
    for key in ("stress", "wrinkled_area_fraction", "slack_area_fraction"):
        assert states["vares_erected"][key] == optimisation["start_erected"][key]
    assert states["vares_erected"]["deviation"] == optimisation["start_erected"]["deviation"]
    assert states["vares_design_shape"]["stress"]["warp"]["intended"] == pytest.approx(2.0)
    # the written patterns are the optimised ones: erected again, they give erect.json's forces
    again = run("erect", out, "-f", "-q")
    assert again.exit_code == 0, again.stderr
    plain = json.loads((out / "erect" / "erect.json").read_text())
    assert plain["stress"]["warp"]["mean"] == pytest.approx(
        erected["stress"]["warp"]["mean"], rel=1e-6
    )
    refused = run("panels", "--example", "hypar-strips", "-o", tmp_path / "x", *flags, "--optimise")
    assert refused.exit_code == 2 and "--erect" in error_line(refused)


def test_panels_take_their_intended_prestress_per_cell_from_the_input(tmp_path):
    """A structure in one VTU with a panel field and per-cell membrane forces (as form finding
    writes them): each panel is patterned for its own cells' rows, the erection is judged
    against them (erected.vtu: force minus the field), and `vares erect DIR` reads them again."""
    mesh, ids = vares.examples.hypar_strips(strips=4, cells_per_strip=3, n=12)
    centre = mesh.points[mesh.cells["triangle"]].mean(axis=1)
    warp, fill = 2.0 + 0.1 * centre[:, 0], 1.5 + 0.05 * centre[:, 1]
    source = tmp_path / "strips.vtu"
    meshio.write(
        source,
        meshio.Mesh(
            mesh.points,
            [("triangle", mesh.cells["triangle"])],
            cell_data={"panel": [ids], "n_warp": [warp], "n_fill": [fill]},
        ),
    )
    flags = ["--fabric", "pes-pvc-type-2", "--prestress-field", "n_warp,n_fill"]
    out = tmp_path / "out"
    result = run("panels", source, "-o", out, *flags, "--warp-direction", "0,1,0", "--erect", "-q")
    assert result.exit_code == 0, result.stderr
    erected = meshio.read(out / "erect" / "erected.vtu")
    data = {k: v[0] for k, v in erected.cell_data.items()}
    # the welded cells are the panels' cells in turn: find each cell's field row by its centre
    welded = erected.points[erected.cells_dict["triangle"]].mean(axis=1)
    design = mesh.points[mesh.cells["triangle"]].mean(axis=1)
    order = [int(np.argmin(np.linalg.norm(design - c, axis=1))) for c in welded]
    np.testing.assert_allclose(
        data["warp_stress"] - data["warp_stress_difference"], warp[order], atol=1e-12
    )
    np.testing.assert_allclose(
        data["fill_stress"] - data["fill_stress_difference"], fill[order], atol=1e-12
    )
    first = json.loads((out / "erect" / "erect.json").read_text())
    again = run("erect", out, "-f", "-q")
    assert again.exit_code == 0, again.stderr
    second = json.loads((out / "erect" / "erect.json").read_text())
    assert second["stress"] == first["stress"]


def test_a_cut_takes_its_intended_prestress_per_cell_and_erect_reads_it_again(tmp_path):
    """`vares cut FILE.vtu --prestress-field …`: the strips are patterned and erected for the
    rows of the cells they were cut from (the intended forces of erected.vtu span the field's
    range), and `vares erect DIR` finds the same rows from the saved strips."""
    mesh = vares.examples.hypar(size=6.0, rise=0.05, n=8)
    centre = mesh.points[mesh.cells["triangle"]].mean(axis=1)
    warp = 2.0 + 0.05 * centre[:, 0]
    source = tmp_path / "roof.vtu"
    meshio.write(
        source,
        meshio.Mesh(
            mesh.points,
            [("triangle", mesh.cells["triangle"])],
            cell_data={"n_warp": [warp], "n_fill": [np.full(len(warp), 1.5)]},
        ),
    )
    out = tmp_path / "cut"
    flags = ["--fabric", "pes-pvc-type-2", "--prestress-field", "n_warp,n_fill"]
    result = run(
        "cut", source, "-o", out, "--roll-width", "2", "--nest-time", "1", *flags, "--erect", "-q"
    )
    assert result.exit_code == 0, result.stderr
    erected = meshio.read(out / "erect" / "erected.vtu")
    data = {k: v[0] for k, v in erected.cell_data.items()}
    intended = data["warp_stress"] - data["warp_stress_difference"]
    assert intended.min() == pytest.approx(warp.min()) and intended.max() == pytest.approx(
        warp.max()
    )
    first = json.loads((out / "erect" / "erect.json").read_text())
    again = run("erect", out, "-f", "-q")
    assert again.exit_code == 0, again.stderr
    assert json.loads((out / "erect" / "erect.json").read_text())["stress"] == first["stress"]


def test_a_cut_with_optimise_nests_the_optimised_pieces_once(tmp_path, monkeypatch):
    """`vares cut --erect --optimise`: the pieces are nested once (they were nested before the
    optimisation and again after it), from the patterns written (a piece's extent is its
    pattern's with the allowances)."""
    from vares.structures import cutting

    nested, original = [], cutting.nest_pieces
    monkeypatch.setattr(
        cutting,
        "nest_pieces",
        lambda pieces, *a, **k: nested.append(pieces) or original(pieces, *a, **k),
    )
    mesh = vares.examples.hypar(size=6.0, rise=0.05, n=8)
    source = tmp_path / "roof.obj"
    meshio.write(source, meshio.Mesh(mesh.points, list(mesh.cells.items())))
    out = tmp_path / "cut"
    flags = ["--fabric", "pes-pvc-type-2", "--prestress", "2,1.5", "--nest-time", "1"]
    result = run(
        "cut", source, "-o", out, "--roll-width", "2", *flags, "--erect", "--optimise", "-q"
    )
    assert result.exit_code == 0, result.stderr
    assert len(nested) == 1
    erected = json.loads((out / "erect" / "erect.json").read_text())
    assert erected["optimisation"]["iterations"] >= 1
    structure = json.loads((out / "structure.json").read_text())
    first = structure["panels"][0]["name"]
    pattern = meshio.read(out / first / "pattern.obj").points[:, :2]
    ring = nested[0][0]  # the first piece's cut ring: its seam ring lies inside, allowance around
    assert np.ptp(ring, axis=0).max() == pytest.approx(np.ptp(pattern, axis=0).max(), rel=0.05)


class _Erection:
    """An erection's figures alone, as :func:`erection_comparison` reads them."""

    surface_area, erected_area = 10.0, 9.5

    def statistics(self, design=False):
        stress = {"intended": 2.0, "mean": 1.5 if design else 1.9, "min": 1.0, "max": 2.5}
        yarn = {**stress, "rms_deviation": 0.25}
        return {
            "stress": {"warp": yarn, "fill": yarn},
            "wrinkled_area_fraction": 0.125,
            "slack_area_fraction": 0.0 if design else 0.05,
        }

    def deviation(self):
        return {"max": 0.0123, "rms": 0.00456}


def test_erection_comparison_columns_design_shape_then_erected():
    """Column by column, the figures of each state: no deviation on the design shape, the
    erected surface's own after erection, and each state's area."""
    from vares.app.erection_outputs import erection_comparison

    titles, rows = erection_comparison(_Erection(), "m")
    assert titles == ["on the design shape", "after erection"]
    table = {label: values for label, *values in rows}
    assert table["warp: mean"] == ["1.5", "1.9"]
    assert table["slack area"] == ["0.0 %", "5.0 %"]
    assert table["normal deviation, max / RMS (m)"] == ["0 / 0", "0.0123 / 0.00456"]
    assert table["area (m²)"] == ["10", "9.5"]


def test_the_console_names_the_vares_patterns_erection_beside_the_optimisation(monkeypatch):
    """With --optimise the console's first erection line is the VaReS patterns' own erection
    (its iterations and time), and the optimisation's line counts the Newton iterations of its
    erections; the optimised patterns' final erection (finished from the last trial, an
    iteration or two) is not shown as if it were the structure's erection."""
    from rich.console import Console

    from vares.app.cli import common

    mesh = vares.examples.hypar(size=10.0, rise=0.06, n=12)
    solved = vares.solve(mesh, vares.materials.StVenantKirchhoff(E=600.0, nu=0.3), prestress=2.0)
    optimum = vares.optimise_for_erection(solved)
    assert optimum.start.iterations != optimum.erected.iterations  # else the test says nothing
    console = Console(record=True, width=300)
    monkeypatch.setattr(common, "console", console)
    common.show_erection(optimum.erected, "m", optimum)
    text = console.export_text()
    assert (
        f"erection of the VaReS patterns, 1 panel(s), {mesh.num_points} nodes" in text
        and f"converged in {optimum.start.iterations} iterations" in text
    )
    newton = sum(r.erection_iterations for r in optimum.history) + (optimum.tightening or 0)
    assert f"{optimum.iterations} steps, {newton} Newton iterations of their erections" in text
    # the report's key table says the same
    from vares.app.erection_report import erection_section

    html = "".join(erection_section(optimum.erected, "m", None, optimum))
    assert f'VaReS patterns</th><td class="num">{optimum.start.iterations} Newton' in html
    assert f"{newton} Newton iterations of their erections" in html
