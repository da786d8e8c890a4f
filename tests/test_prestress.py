"""Prestress, compensation and fabric presets."""

import meshio
import numpy as np
import pytest
from conftest import rotation
from scipy.optimize import root

import vares
from vares.analysis import compensation_report
from vares.geometry.examples import conic_tent, four_point_sail, grid_cells
from vares.materials import (
    Fibres,
    MaterialError,
    NeoHooke,
    OrthotropicStVenantKirchhoff,
    StVenantKirchhoff,
    fabric,
    load_presets,
    presets,
)
from vares.mechanics import Assembler
from vares.mechanics.prestress import PrestressWarning, prestress_components


# ---- closed form: a flat rectangle with uniform biaxial prestress ---------------------------
def psi_svk(E11, E22, E, nu):
    lam, mu = E * nu / (1 - nu**2), E / (2 * (1 + nu))
    return lam / 2 * (E11 + E22) ** 2 + mu * (E11**2 + E22**2)


def psi_neo_hooke(E11, E22, E, nu):
    lam, mu = E * nu / (1 - nu**2), E / (2 * (1 + nu))
    c11, c22 = 1 + 2 * E11, 1 + 2 * E22
    log_j = np.log(c11 * c22)
    return mu / 2 * (c11 + c22 - 2 - log_j) + lam / 8 * log_j**2


def psi_ortho(E11, E22, E1, E2, nu12):
    d = 1 - nu12**2 * E2 / E1
    return 0.5 * (E1 / d * E11**2 + 2 * nu12 * E2 / d * E11 * E22 + E2 / d * E22**2)


def homogeneous_stretches(psi, p1, p2, t):
    """Stationary point of Π(λ₁, λ₂) = (A/λ₁λ₂) t [Ψ − S_pre:E] (A = 1), found independently."""

    def energy(lam):
        E11, E22 = (lam[0] ** 2 - 1) / 2, (lam[1] ** 2 - 1) / 2
        return t * (psi(E11, E22) - (p1 * E11 + p2 * E22) / t) / (lam[0] * lam[1])

    def gradient(lam):  # complex step: exact to round-off
        h = 1e-30
        return np.array([energy(lam + 1j * h * e).imag / h for e in np.eye(2)])

    solution = root(gradient, [1.0, 1.0], tol=1e-14)
    assert np.abs(gradient(solution.x)).max() < 1e-12  # stationary to round-off
    return solution.x


@pytest.mark.parametrize(
    ("material", "psi"),
    [
        (StVenantKirchhoff(600.0, 0.3), lambda a, b: psi_svk(a, b, 600.0, 0.3)),
        (NeoHooke(600.0, 0.45), lambda a, b: psi_neo_hooke(a, b, 600.0, 0.45)),
        (
            OrthotropicStVenantKirchhoff(800.0, 500.0, 30.0, 0.35),
            lambda a, b: psi_ortho(a, b, 800.0, 500.0, 0.35),
        ),
    ],
    ids=["svk", "neo-hooke", "orthotropic"],
)
@pytest.mark.parametrize("thickness", [1.0, 0.8])
def test_prestressed_flat_rectangle_matches_the_closed_form(material, psi, thickness):
    a, b, p1, p2 = 3.0, 2.0, 12.0, 7.0  # large prestress: stretches of a few per cent
    x, y = np.meshgrid(np.linspace(0, a, 7), np.linspace(0, b, 5))
    flat = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    R = rotation(11)
    mesh = vares.SurfaceMesh(flat @ R.T + [1.0, 2.0, 3.0], grid_cells(7, 5, "quad"))
    result = vares.solve(mesh, material, thickness, prestress=(p1, p2), warp_direction=R[:, 0])
    assert result.converged, result.reason
    lam1, lam2 = homogeneous_stretches(psi, p1, p2, thickness)
    assert lam1 > 1.01 and lam2 > 1.002  # the prestress matters
    pattern = result.material_coordinates
    width = np.linalg.norm(pattern[6] - pattern[0])  # corner nodes along a
    depth = np.linalg.norm(pattern[28] - pattern[0])  # corner nodes along b
    assert width == pytest.approx(a / lam1, rel=1e-8)
    assert depth == pytest.approx(b / lam2, rel=1e-8)
    # the report: compensation and achieved membrane force of the homogeneous state
    report = compensation_report(result)
    assert report.warp.compensation_mean == pytest.approx(100 * (1 - 1 / lam1), rel=1e-7)
    assert report.fill.compensation_min == pytest.approx(100 * (1 - 1 / lam2), rel=1e-7)
    E11, E22 = (lam1**2 - 1) / 2, (lam2**2 - 1) / 2
    h = 1e-30
    S11 = psi(E11 + 1j * h, E22).imag / h  # ∂Ψ/∂E11
    assert report.warp.achieved_mean == pytest.approx(thickness * lam1 * S11 / lam2, rel=1e-7)
    assert report.warp.target_mean == pytest.approx(p1)
    assert report.fill.target_mean == pytest.approx(p2)
    assert report.warp.slack_cells == 0


def test_prestress_residual_and_tangent_by_finite_differences(mixed_mesh):
    rng = np.random.default_rng(8)
    per_cell = np.column_stack(
        [rng.uniform(1, 3, 8), rng.uniform(0.5, 2, 8), rng.uniform(-0.3, 0.3, 8)]
    )
    problem = vares.Problem(
        mixed_mesh, NeoHooke(50.0, 0.3), 0.7, fibres=Fibres.from_angles(-15.0), prestress=per_cell
    )
    pattern = mixed_mesh.points[:, :2] * [0.97, 1.02] + 0.01 * rng.normal(size=(12, 2))
    free = np.ones(24, bool)
    assembler = Assembler(mixed_mesh, free)
    evaluation = problem.evaluate(pattern)
    gradient = assembler.vector(evaluation.gradients).ravel()
    matrix = assembler.matrix(evaluation.hessians).toarray()
    h = 1e-6
    for dof in range(24):
        up, down = pattern.copy(), pattern.copy()
        up.ravel()[dof] += h
        down.ravel()[dof] -= h
        fd = (problem.energy(up) - problem.energy(down)) / (2 * h)
        assert gradient[dof] == pytest.approx(fd, abs=1e-7)
        column = (
            assembler.vector(problem.evaluate(up).gradients).ravel()
            - assembler.vector(problem.evaluate(down).gradients).ravel()
        ) / (2 * h)
        np.testing.assert_allclose(matrix[:, dof], column, atol=1e-6)
    # the prestress term is really there: without it the gradient differs
    bare = vares.Problem(mixed_mesh, NeoHooke(50.0, 0.3), 0.7, fibres=Fibres.from_angles(-15.0))
    assert np.abs(assembler.vector(bare.evaluate(pattern).gradients).ravel() - gradient).max() > 0.1


def test_prestress_is_ramped_with_pseudo_time():
    mesh = four_point_sail(n=8)
    material = fabric("pes-pvc-type-2").material()
    problem = vares.Problem(mesh, material, fibres=Fibres.from_angles(0.0), prestress=(2.0, 1.5))
    half = problem.with_surface(mesh.points, prestress_factor=0.5)
    np.testing.assert_allclose(half.prestress, [[1.0, 0.75, 0.0]])
    stepped = vares.solve(mesh, material, prestress=(2.0, 1.5), strategy="pseudo-time", steps=4)
    direct = vares.solve(mesh, material, prestress=(2.0, 1.5))
    assert stepped.converged and direct.converged
    np.testing.assert_allclose(stepped.material_coordinates, direct.material_coordinates, atol=1e-9)


def test_sail_pattern_with_prestress_is_compensated():
    mesh = four_point_sail()
    material = fabric("pes-pvc-type-2").material()
    plain = vares.solve(mesh, material, warp_direction=(1, 1, 0))
    stressed = vares.solve(mesh, material, warp_direction=(1, 1, 0), prestress=(2.0, 1.5))
    assert plain.converged and stressed.converged
    assert stressed.pattern_area < plain.pattern_area < mesh.area * 1.001
    without, report = compensation_report(plain), compensation_report(stressed)
    assert report.warp.compensation_mean > 0.1 and report.fill.compensation_mean > 0.1
    assert report.warp.compensation_min > 0 and report.fill.compensation_min > 0
    assert abs(without.warp.compensation_mean) < 0.01
    assert report.warp.achieved_mean == pytest.approx(2.0, rel=0.01)
    assert report.fill.achieved_mean == pytest.approx(1.5, rel=0.01)
    assert 0 < report.warp.rms_deviation < 1.0
    assert report.warp.slack_cells == 0
    strict = compensation_report(stressed, slack_threshold=1.9)
    assert 0 < strict.warp.slack_area_fraction < 1


def test_conic_tent_panel():
    mesh = conic_tent()
    assert mesh.points[:, 2].max() == pytest.approx(6.0)
    assert mesh.points[:, 2].min() == pytest.approx(0.0, abs=1e-12)
    result = vares.solve(
        mesh, fabric("pes-pvc-type-1").material(), warp_direction=(1, 0, 0), prestress=(2.0, 1.5)
    )
    assert result.converged, result.reason
    report = compensation_report(result)
    assert report.warp.compensation_mean > 0 and report.fill.compensation_mean > 0
    whole = conic_tent(panels=1, n_around=6)
    assert len(whole.boundary_edges()) == 2 * 24  # two rings: the tent has no seam


@pytest.mark.parametrize(
    ("prestress", "message"),
    [
        ((1.0, np.nan), "not finite"),
        (np.ones((3, 2)), "one such row per cell"),
        (np.ones((2, 2, 2)), "one such row per cell"),
        ((1.0, 2.0, 3.0, 4.0), "one such row per cell"),
    ],
)
def test_bad_prestress_is_rejected(prestress, message):
    with pytest.raises(ValueError, match=message):
        prestress_components(prestress, 8)


def test_compressive_prestress_warns_but_solves():
    mesh = four_point_sail(n=6)
    with pytest.warns(PrestressWarning, match="compressive"):
        result = vares.solve(mesh, fabric("pes-pvc-type-2").material(), prestress=(2.0, -0.5))
    assert result.converged
    np.testing.assert_allclose(prestress_components(3.0, 5), [[3.0, 3.0, 0.0]])


def test_prestress_field_from_cell_data(tmp_path):
    mesh = four_point_sail(n=6)
    field = np.column_stack([np.linspace(1.5, 2.5, mesh.num_cells), np.full(mesh.num_cells, 1.5)])
    path = tmp_path / "sail.vtu"
    meshio.write(
        path,
        meshio.Mesh(
            mesh.points,
            [("triangle", mesh.cells["triangle"])],
            cell_data={"n": [field], "n_warp": [field[:, 0]]},
        ),
    )
    read, data = vares.read_mesh_data(path)
    np.testing.assert_allclose(data["n"], field)
    material = fabric("pes-pvc-type-2").material()
    per_cell = vares.solve(read, material, prestress=data["n"])
    uniform = vares.solve(read, material, prestress=(2.0, 1.5))
    assert per_cell.converged
    assert not np.allclose(per_cell.material_coordinates, uniform.material_coordinates, atol=1e-6)


def test_shipped_presets_say_where_their_numbers_come_from():
    catalogue = presets()
    assert {
        "pes-pvc-type-1",
        "pes-pvc-type-2",
        "pes-pvc-type-3",
        "pes-pvc-type-4",
        "glass-ptfe",
    } <= set(catalogue)
    for preset in catalogue.values():
        assert "typical value" in preset.source
        material = preset.material()
        assert material.E1 >= material.E2 > material.G12 > 0


def test_user_presets(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text(
        '[roll-4711]\ndescription = "tested"\nE1 = 780\nE2 = 590\nG12 = 25\n'
        'nu12 = 0.38\nsource = "our biaxial test"\n'
    )
    assert load_presets(path)["roll-4711"].material().E2 == 590.0
    assert fabric("roll-4711", path).nu12 == 0.38
    assert fabric("glass-ptfe", path).E1 == 1400.0
    bad = tmp_path / "bad.toml"
    for text, message in [
        ("[x]\nE1 = 1\nE2 = 1\nG12 = 1\n", "lacks nu12"),
        ("[x]\nE1 = 1\nE2 = 1\nG12 = 1\nnu12 = 0.3\n", "where its numbers come from"),
        ('[x]\nE1 = 1\nE2 = 100\nG12 = 1\nnu12 = 0.3\nsource = "s"\n', "positive definite"),
        ('[x]\nE1 = 1\nE2 = 1\nG12 = 1\nnu12 = 0.3\nsource = "s"\ncolour = 2\n', "unknown keys"),
        ("[x\n", "not valid TOML"),
    ]:
        bad.write_text(text)
        with pytest.raises(MaterialError, match=message):
            load_presets(bad)
    with pytest.raises(MaterialError, match="unknown fabric preset"):
        fabric("pes-pvc-type-9")
