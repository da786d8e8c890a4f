"""Panels, seams, seam matching and the coupled problem's exact derivatives."""

import numpy as np
import pytest
from conftest import run

import vares
from vares.geometry.examples import grid_cells, hypar_strips
from vares.structures import Panel, find_seams, solve_structure, split_panels
from vares.structures.matching import CoupledProblem

FABRIC = vares.materials.fabric("pes-pvc-type-2").material()


@pytest.fixture(scope="module")
def strips():
    mesh, ids = hypar_strips()
    return split_panels(mesh, ids, {i: f"strip-{i + 1}" for i in range(6)})


def test_strips_and_their_seams(strips):
    assert [p.name for p in strips] == [f"strip-{i}" for i in range(1, 7)]
    seams = find_seams(strips)
    assert [(s.first, s.second, s.segments) for s in seams] == [(i, i + 1, 24) for i in range(5)]
    for seam in seams:  # the two chains are the same points in 3D
        a = strips[seam.first].mesh.points[seam.nodes_first]
        b = strips[seam.second].mesh.points[seam.nodes_second]
        np.testing.assert_allclose(a, b, atol=1e-12)


def test_seams_of_separate_meshes_found_by_position():
    def grid(x0, permutation=None):
        x, y = np.meshgrid(np.linspace(x0, x0 + 1, 4), np.linspace(0, 1, 3))
        points = np.column_stack([x.ravel(), y.ravel(), 0.1 * x.ravel() ** 2])
        cells = grid_cells(4, 3, "quad")["quad"]
        if permutation is not None:  # the same surface, numbered differently
            points = points[permutation]
            cells = np.argsort(permutation)[cells]
        return vares.SurfaceMesh(points, {"quad": cells})

    order = np.random.default_rng(1).permutation(12)
    panels = [Panel("L", grid(0.0)), Panel("R", grid(1.0, order))]
    seams = find_seams(panels)
    assert len(seams) == 1 and seams[0].segments == 2
    np.testing.assert_allclose(
        panels[0].mesh.points[seams[0].nodes_first],
        panels[1].mesh.points[seams[0].nodes_second],
        atol=1e-12,
    )
    np.testing.assert_allclose(panels[0].mesh.points[seams[0].nodes_first][:, 0], 1.0)


def test_matching_makes_every_seam_equally_long(strips):
    independent = solve_structure(
        strips, FABRIC, match_seams=False, warp_direction=(0, 1, 0), prestress=(2.0, 1.5)
    )
    matched = solve_structure(strips, FABRIC, warp_direction=(0, 1, 0), prestress=(2.0, 1.5))
    assert independent.converged and matched.converged, matched.reason
    before = [r.mismatch_before for r in independent.seam_reports]
    assert max(before) > 1e-7  # without matching the sides differ
    for report in matched.seam_reports:
        assert report.mismatch_after < 1e-9
        assert report.max_segment_mismatch_after < 1e-9
    assert matched.energy_price > 0
    assert matched.energy_price < 1e-3 * abs(independent.energy_independent)
    for result in matched.results:
        assert (
            vares.Problem(result.mesh, FABRIC, fibres=result.fibres)
            .inverted_cells(result.material_coordinates)
            .size
            == 0
        )


def test_coupled_residual_and_tangent_by_finite_differences(strips):
    panels = strips[:2]
    results = [vares.solve(p.mesh, FABRIC, warp_angle=10.0) for p in panels]
    seams = find_seams(panels)
    coupled = CoupledProblem.build(results, FABRIC, 1.0, seams)
    assert coupled.num_rotations == 2  # anisotropic, rotation held: one row per panel
    rng = np.random.default_rng(0)
    x = [
        r.material_coordinates + 1e-3 * rng.normal(size=r.material_coordinates.shape)
        for r in results
    ]
    count = 2 + sum(s.segments for s in seams)
    lam = rng.normal(size=count)
    gradient, _, matrix, _ = coupled.kkt(x, lam)
    n = coupled.num_free
    matrix = matrix.toarray()
    b = matrix[n:, :n]

    def lagrangian(coords):
        _, c, _, e = coupled.kkt(coords, np.zeros(count))
        return e + lam @ c

    def shifted(dof, h):
        coords = [c.copy() for c in x]
        for p in range(2):
            index = coupled.free_index[p].ravel()
            hit = np.flatnonzero(index == dof)
            if hit.size:
                coords[p].ravel()[hit[0]] += h
        return coords

    h = 1e-6
    dofs = rng.choice(n, 40, replace=False)
    rotation_rows = [0, 1]
    for dof in dofs:
        up, down = shifted(dof, h), shifted(dof, -h)
        fd = (lagrangian(up) - lagrangian(down)) / (2 * h)
        # the rotation rows are linear in the displacement from the start: their value is not
        # part of c(X) above, but their gradient is, so compare without them
        rotation_part = b[rotation_rows, dof] @ lam[rotation_rows]
        assert gradient[dof] - rotation_part == pytest.approx(fd, abs=1e-6)
        g_up = coupled.kkt(up, lam).gradient
        g_down = coupled.kkt(down, lam).gradient
        np.testing.assert_allclose(matrix[:n, dof], (g_up - g_down) / (2 * h), atol=1e-5)
        c_up, c_down = coupled.kkt(up, lam).constraint, coupled.kkt(down, lam).constraint
        np.testing.assert_allclose(matrix[n + 2 :, dof], ((c_up - c_down) / (2 * h))[2:], atol=1e-7)


def test_the_coupled_tangent_does_not_depend_on_the_length_unit(strips):
    """The same panels in metres and in millimetres: the KKT matrix is the same (the energy's
    Hessian, the rotation rows and each seam segment's row are all free of the unit), the
    Lagrangian's gradient and the constraints a thousand times larger. With the squared lengths
    as constraints the seam rows were a thousand times longer in millimetres, and PARDISO
    solved the KKT system of the form-found sail cut at a 2.5 m roll to a relative residual of
    2.3 (its seam matching did not converge in 50 iterations; in metres, 2)."""
    from dataclasses import replace

    panels = strips[:2]
    results = [vares.solve(p.mesh, FABRIC, warp_angle=10.0) for p in panels]
    scaled = [  # the same patterns, every length in millimetres
        replace(
            r,
            mesh=vares.SurfaceMesh(1000.0 * r.mesh.points, r.mesh.cells),
            material_coordinates=1000.0 * r.material_coordinates,
        )
        for r in results
    ]
    seams = find_seams(panels)
    metre = CoupledProblem.build(results, FABRIC, 1.0, seams)
    mm = CoupledProblem.build(scaled, FABRIC, 1.0, seams)
    rng = np.random.default_rng(1)
    x = [
        r.material_coordinates + 1e-3 * rng.normal(size=r.material_coordinates.shape)
        for r in results
    ]
    lam = rng.normal(size=metre.num_constraints)
    a, b = metre.kkt(x, lam), mm.kkt([1000.0 * c for c in x], 1000.0 * lam)
    np.testing.assert_allclose(b.matrix.toarray(), a.matrix.toarray(), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(b.gradient, 1000.0 * a.gradient, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(b.constraint, 1000.0 * a.constraint, rtol=1e-9, atol=1e-12)


def test_roll_width_check(strips):
    names = [p.name for p in strips]
    wide = solve_structure(
        strips, FABRIC, match_seams=False, warp_direction=(0, 1, 0), roll_width=10.0
    )
    assert wide.too_wide == []
    structure = solve_structure(
        strips, FABRIC, match_seams=False, warp_direction=(0, 1, 0), roll_width=1.6
    )
    lengths = [np.ptp(r.material_coordinates[:, 0]) for r in structure.results]
    too_narrow = structure.too_wide
    assert [name for name, _ in too_narrow] == names  # strips are about 1.7 m wide
    assert all(w == pytest.approx(1.7, abs=0.02) for _, w in too_narrow)
    assert min(lengths) > 9.9  # the warp (+x in the pattern) runs along the strips


def test_split_panels_errors():
    mesh, ids = hypar_strips(strips=2, n=4)
    with pytest.raises(vares.MeshError, match="one value per cell"):
        split_panels(mesh, ids[:-1])
    with pytest.raises(vares.MeshError, match="integers"):
        split_panels(mesh, ids + 0.5)
    ids = ids.copy()
    ids[0] = 7  # one cell of its own: a valid panel
    panels = split_panels(mesh, ids, {7: "patch"})
    assert [p.name for p in panels] == ["panel-0", "panel-1", "patch"]
    assert sum(p.mesh.num_cells for p in panels) == mesh.num_cells
    assert panels[2].mesh.num_cells == 1
    ids[-1] = 7  # a second, far away cell: the panel falls apart
    with pytest.raises(vares.MeshError, match=r"panel patch: .*2 separate pieces"):
        split_panels(mesh, ids, {7: "patch"})


def test_panels_command_from_cell_data_3dm_and_files(tmp_path):
    import json

    import meshio

    from vares.io.rhino import NamedMesh, write_3dm

    mesh, ids = hypar_strips(strips=3, cells_per_strip=3, n=9)
    source = tmp_path / "sail.vtu"
    meshio.write(
        source,
        meshio.Mesh(
            mesh.points, [("triangle", mesh.cells["triangle"])], cell_data={"strip": [ids]}
        ),
    )
    out = tmp_path / "cells"
    result = run(
        "panels",
        source,
        "--panel-field",
        "strip",
        "-o",
        out,
        "--fabric",
        "pes-pvc-type-2",
        "--prestress",
        "2,1.5",
        "--warp-direction",
        "0,1,0",
        "--mark-spacing",
        2000,
        "--roll-width",
        3.5,
        "-q",
    )
    assert result.exit_code == 0, result.stderr
    data = json.loads((out / "structure.json").read_text())
    assert data["converged"] and data["matched"] and len(data["panels"]) == 3
    assert all(s["mismatch_after"] < 1e-9 for s in data["seams"]) and len(data["seams"]) == 2
    assert all(p["compensation"]["warp"]["compensation_mean"] > 0 for p in data["panels"])
    assert data["too_wide"] == [] and data["energy_price"] >= 0
    import ezdxf

    doc = ezdxf.readfile(out / "structure.dxf")
    marks = doc.modelspace().query("LINE[layer=='MARKS']")
    assert len(marks) == 2 * 2 * 4  # 2 seams × 2 sides × marks every 2 m on a 10 m seam
    # the same panels as a Rhino file and as separate files
    panels = split_panels(mesh, ids, {0: "a", 1: "b", 2: "c"})
    write_3dm(tmp_path / "sail.3dm", [NamedMesh(p.name, "membrane", p.mesh) for p in panels])
    result = run("panels", tmp_path / "sail.3dm", "-o", tmp_path / "rhino", "--no-match", "-q")
    assert result.exit_code == 0, result.stderr
    data = json.loads((tmp_path / "rhino" / "structure.json").read_text())
    assert [p["name"] for p in data["panels"]] == ["a", "b", "c"] and not data["matched"]
    assert max(s["mismatch_after"] for s in data["seams"]) > 1e-9  # not matched: not zero
    files = []
    for p in panels:
        files.append(tmp_path / f"{p.name}.obj")
        meshio.write(files[-1], meshio.Mesh(p.mesh.points, list(p.mesh.cells.items())))
    result = run("panels", *files, "-o", tmp_path / "files", "-q")
    assert result.exit_code == 0, result.stderr
    result = run("panels", files[0], "-o", tmp_path / "one")
    assert result.exit_code == 2 and "panel ids" in result.stderr


def test_the_iteration_limit_holds_for_every_panel_solve_and_the_matching(tmp_path):
    import json

    # from the projection, whose panels need more than the limit (from the automatic start, one
    # ARAP step further, they need 2)
    limited = ("--max-iterations", 2, "--initial-guess", "projection")
    result = run("panels", "--example", "hypar-strips", "-o", tmp_path, *limited, "-q")
    assert result.exit_code == 0, result.stderr
    data = json.loads((tmp_path / "structure.json").read_text())
    assert data["converged"] and 1 <= data["coupled_iterations"] <= 2
    assert data["options"]["max_iterations"] == 2
    for panel in data["panels"]:
        summary = json.loads((tmp_path / panel["name"] / "summary.json").read_text())
        assert summary["options"]["max_iterations"] == 2
        assert summary["converged"] and all(s["iterations"] <= 2 for s in summary["steps"])
    # with the default limit the same panels take 3 iterations in their first step
    structure = solve_structure(
        split_panels(*hypar_strips()),
        vares.materials.NeoHooke(1e3, 0.3),
        initial_guess="projection",
    )
    assert max(r.steps[0].iterations for r in structure.results) == 3


def test_a_structure_whose_matching_fails_says_so_everywhere(tmp_path, monkeypatch):
    import json

    from vares.structures import matching

    monkeypatch.setattr(matching, "ROUND_OFF", 0)  # seams can never match: the limit is hit
    mesh, ids = hypar_strips(strips=3, n=8)
    structure = solve_structure(split_panels(mesh, ids), FABRIC, max_iterations=3)
    assert not structure.converged and structure.matched
    assert structure.reason == "seam matching: iteration limit (3) reached"
    assert structure.iterations == 3
    assert all(not r.converged and r.reason == structure.reason for r in structure.results)
    result = run("panels", "--example", "hypar-strips", "-o", tmp_path, "--max-iterations", 3)
    assert result.exit_code == 1
    error = [line for line in result.stderr.splitlines() if line.startswith("vares: error:")]
    assert error == [
        "vares: error: the structure did not converge: seam matching: iteration limit (3) reached"
    ]
    data = json.loads((tmp_path / "structure.json").read_text())
    assert data["converged"] is False and data["reason"] == structure.reason
    assert [p["converged"] for p in data["panels"]] == [False] * 6
    for panel in data["panels"]:
        summary = json.loads((tmp_path / panel["name"] / "summary.json").read_text())
        assert summary["converged"] is False and summary["reason"] == structure.reason
        assert not (tmp_path / panel["name"] / "pattern.dxf").exists()
    assert not (tmp_path / "structure.dxf").exists()


@pytest.mark.parametrize("prestressed", [False, True])
def test_ten_strips_with_seams_through_cells_match_quadratically(prestressed):
    from vares.geometry.examples import irregular_hypar_strips

    mesh, ids = irregular_hypar_strips(strips=10, seed=3)
    panels = split_panels(mesh, ids)
    seams = find_seams(panels)
    assert len(panels) == 10 and len(seams) == 9
    segments = np.concatenate(
        [
            np.linalg.norm(np.diff(panels[s.first].mesh.points[s.nodes_first], axis=0), axis=1)
            for s in seams
        ]
    )
    assert segments.min() < 0.05 * segments.mean()  # short segments, as a cut through cells makes
    settings = {"warp_direction": (0, 1, 0), "prestress": (2.0, 1.5)} if prestressed else {}
    material = FABRIC if prestressed else vares.materials.NeoHooke(1e3, 0.3)
    structure = solve_structure(panels, material, seams=seams, **settings)
    assert structure.converged, structure.reason
    # the seams match to round-off within 5 iterations; the Lagrangian's gradient may then sit
    # at its round-off floor, which two more full steps that do not halve it show
    matched = next(h.iteration for h in structure.history if h.violation <= h.round_off)
    assert matched <= 5 and structure.iterations <= max(5, matched + 2)
    assert max(r.max_segment_mismatch_after for r in structure.seam_reports) < 1e-9
    assert max(r.mismatch_before for r in structure.seam_reports) > 1e-5
    violations = [h.violation for h in structure.history]
    assert violations[2] < 1e-3 * violations[1]  # quadratic, not linear, convergence


def test_panels_write_what_pattern_writes_per_panel_and_run_again_from_the_saved_job(tmp_path):
    import json

    import meshio

    mesh, ids = hypar_strips(strips=2, cells_per_strip=2, n=6)
    source = tmp_path / "sail.vtu"
    cells = [("triangle", mesh.cells["triangle"])]
    meshio.write(source, meshio.Mesh(mesh.points, cells, cell_data={"panel": [ids]}))
    out, saved = tmp_path / "out", tmp_path / "jobs" / "sail.toml"
    result = run(
        "panels", source, "-o", out, "--report", "--plot", "det_F", "--save-job", saved, "-q"
    )
    assert result.exit_code == 0, result.stderr
    single = run("pattern", source, "-o", tmp_path / "single", "--plot", "det_F", "-q")
    assert single.exit_code == 0, single.stderr
    expected = {p.name for p in (tmp_path / "single").iterdir()} | {"surface.obj", "report.html"}
    expected -= {".vares-run.json", "job.toml"}  # a run's manifest and job: in its folder only
    names = ["panel-0", "panel-1"]
    for name in names:
        assert {p.name for p in (out / name).iterdir()} == expected
    assert {p.name for p in out.iterdir()} == {
        *names,
        "structure.json",
        "structure.dxf",
        "report.html",
        ".vares-run.json",
        "job.toml",
    }
    report = (out / "report.html").read_text()
    assert all(f'href="{name}/report.html"' in report for name in names)
    # the saved job names its input and output relative to itself, and reruns elsewhere
    text = saved.read_text()
    assert (
        'mesh = "../sail.vtu"' in text and 'directory = "../out"' in text and "[structure]" in text
    )
    moved = tmp_path / "moved"
    result = run("run", saved, "-o", moved, "-q")
    assert result.exit_code == 0, result.stderr
    first = json.loads((out / "structure.json").read_text())
    again = json.loads((moved / "structure.json").read_text())
    assert again["energy"] == first["energy"] and again["converged"]
    result = run("run", saved, "-q")  # the job's own folder exists: nothing is overwritten
    assert result.exit_code == 2 and "output exists" in result.stderr
