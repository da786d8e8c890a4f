"""Panels, seams, seam matching and the coupled problem's exact derivatives."""

import numpy as np
import pytest

import vares
from vares.assembly import Assembler
from vares.examples import grid_cells, hypar_strips
from vares.panels import (
    Panel,
    _Coupled,
    _kkt,
    find_seams,
    roll_width_check,
    solve_structure,
    split_panels,
)
from vares.solver import _rigid_modes

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
    problems, assemblers, rotations = [], [], []
    for r in results:
        problems.append(vares.Problem(r.mesh, FABRIC, fibres=r.fibres))
        free, rotation = _rigid_modes(r.material_coordinates, "held")
        assemblers.append(Assembler(r.mesh, free))
        rotations.append(rotation)
    offsets = np.concatenate([[0], np.cumsum([a.num_free for a in assemblers])])
    coupled = _Coupled(problems, assemblers, rotations, offsets, seams)
    rng = np.random.default_rng(0)
    x = [
        r.material_coordinates + 1e-3 * rng.normal(size=r.material_coordinates.shape)
        for r in results
    ]
    count = 2 + sum(s.segments for s in seams)
    lam = rng.normal(size=count)
    gradient, _, matrix, _, b = _kkt(coupled, x, lam)
    n = coupled.num_free
    matrix = matrix.toarray()

    def lagrangian(coords):
        _, c, _, e, _ = _kkt(coupled, coords, np.zeros(count))
        return e + lam @ c

    def shifted(dof, h):
        coords = [c.copy() for c in x]
        for p in range(2):
            index = coupled.free_index(p)
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
        rotation_part = b.toarray()[rotation_rows, dof] @ lam[rotation_rows]
        assert gradient[dof] - rotation_part == pytest.approx(fd, abs=1e-6)
        g_up = _kkt(coupled, up, lam)[0]
        g_down = _kkt(coupled, down, lam)[0]
        np.testing.assert_allclose(matrix[:n, dof], (g_up - g_down) / (2 * h), atol=1e-5)
        c_up, c_down = _kkt(coupled, up, lam)[1], _kkt(coupled, down, lam)[1]
        np.testing.assert_allclose(matrix[n + 2 :, dof], ((c_up - c_down) / (2 * h))[2:], atol=1e-7)


def test_roll_width_check(strips):
    structure = solve_structure(strips, FABRIC, match_seams=False, warp_direction=(0, 1, 0))
    names = [p.name for p in strips]
    lengths = [np.ptp(r.material_coordinates[:, 0]) for r in structure.results]
    assert roll_width_check(structure.results, names, 10.0) == []
    too_narrow = roll_width_check(structure.results, names, 1.6)
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
    with pytest.raises(vares.MeshError, match=r"panel patch: .*2 disconnected pieces"):
        split_panels(mesh, ids, {7: "patch"})


def test_panels_command_from_cell_data_3dm_and_files(tmp_path):
    import json

    import meshio
    from typer.testing import CliRunner

    from vares.cli import app
    from vares.rhino import NamedMesh, write_3dm

    runner = CliRunner()
    mesh, ids = hypar_strips(strips=3, cells_per_strip=3, n=9)
    source = tmp_path / "sail.vtu"
    meshio.write(
        source,
        meshio.Mesh(
            mesh.points, [("triangle", mesh.cells["triangle"])], cell_data={"strip": [ids]}
        ),
    )
    out = tmp_path / "cells"
    result = runner.invoke(
        app,
        [
            "panels",
            str(source),
            "--panel-field",
            "strip",
            "-o",
            str(out),
            "--fabric",
            "pes-pvc-type-2",
            "--prestress",
            "2,1.5",
            "--warp-direction",
            "0,1,0",
            "--mark-spacing",
            "2000",
            "--roll-width",
            "3.5",
            "-q",
        ],
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
    result = runner.invoke(
        app,
        ["panels", str(tmp_path / "sail.3dm"), "-o", str(tmp_path / "rhino"), "--no-match", "-q"],
    )
    assert result.exit_code == 0, result.stderr
    data = json.loads((tmp_path / "rhino" / "structure.json").read_text())
    assert [p["name"] for p in data["panels"]] == ["a", "b", "c"] and not data["matched"]
    assert max(s["mismatch_after"] for s in data["seams"]) > 1e-9  # not matched: not zero
    files = []
    for p in panels:
        files.append(tmp_path / f"{p.name}.obj")
        meshio.write(files[-1], meshio.Mesh(p.mesh.points, list(p.mesh.cells.items())))
    result = runner.invoke(app, ["panels", *map(str, files), "-o", str(tmp_path / "files"), "-q"])
    assert result.exit_code == 0, result.stderr
    result = runner.invoke(app, ["panels", str(files[0]), "-o", str(tmp_path / "one")])
    assert result.exit_code == 2 and "panel ids" in result.stderr
