"""Erection analysis: derivatives of the forward problem, and structures whose erected state is
known in closed form."""

import numpy as np
import pytest
from conftest import FIBRES, LAWS, rotation
from scipy.optimize import brentq, fsolve

import vares
from vares.analysis import Pattern
from vares.geometry.elements import ELEMENTS
from vares.geometry.examples import grid_cells
from vares.materials import (
    Fibres,
    NeoHooke,
    OrthotropicStVenantKirchhoff,
)
from vares.mechanics import Assembler
from vares.mechanics.erection import Cables, ErectionProblem, membrane_block
from vares.mechanics.forward import deformation_gradients, forward_block, reference_block
from vares.mechanics.loads import pressure_terms
from vares.mechanics.wrinkling import relaxed_response

H = 1e-30
TIGHT = vares.SolveOptions(tolerance=1e-14)


def plain(law, fibres):
    def respond(C, tangent):
        r = law.response(C, fibres, tangent=tangent)
        return r.psi, r.stress, r.tangent

    return respond


@pytest.mark.parametrize("cell_type", ["triangle", "quad"])
@pytest.mark.parametrize("law", LAWS, ids=lambda m: type(m).__name__)
def test_forward_element_gradient_and_hessian_by_complex_step(cell_type, law):
    rng = np.random.default_rng(len(cell_type))
    ref = {"triangle": [[0, 0], [1, 0], [0, 1]], "quad": [[0, 0], [1, 0], [1, 1], [0, 1]]}
    ref = np.array(ref[cell_type], float)
    element = ELEMENTS[cell_type]
    pattern = (ref + 0.08 * rng.normal(size=ref.shape))[None]
    nodes = np.column_stack([1.1 * ref, 0.3 * rng.normal(size=len(ref))])[None]
    reference = reference_block(element, pattern, 0.7)
    respond = plain(law, FIBRES if law.needs_fibres else None)
    exact = forward_block(reference, nodes, respond)
    nen = element.num_nodes
    gradient = np.zeros((nen, 3))
    hessian = np.zeros((nen, 3, nen, 3))
    for a in range(nen):
        for k in range(3):
            shifted = nodes.astype(complex)
            shifted[0, a, k] += 1j * H
            result = forward_block(reference, shifted, respond)
            gradient[a, k] = result.energy[0].imag / H
            hessian[:, :, a, k] = result.gradient[0].imag / H
    np.testing.assert_allclose(exact.gradient[0], gradient, atol=1e-12 * np.abs(gradient).max())
    np.testing.assert_allclose(exact.hessian[0], hessian, atol=1e-12 * np.abs(hessian).max())


def _problem_with_everything(wrinkling: bool):
    """A curved quad/triangle mesh with a pattern that leaves cells taut, wrinkled and slack,
    pressure, and edge cables of which some are taut and some slack."""
    mesh = vares.examples.hypar(n=4, cell_type="quad")
    rng = np.random.default_rng(0)
    pattern = vares.solve(mesh, NeoHooke(E=10.0, nu=0.3)).material_coordinates
    blocks = [
        membrane_block(ELEMENTS[t], c, pattern[c], mesh.points, 1.0, None)
        for t, c in mesh.cells.items()
    ]
    segments = mesh.boundary_edges()
    length = np.linalg.norm(np.diff(mesh.points[segments], axis=1)[:, 0], axis=1)
    cables = Cables(segments, length * rng.uniform(0.97, 1.03, len(length)), 50.0)
    problem = ErectionProblem(
        mesh.points,
        blocks,
        NeoHooke(E=10.0, nu=0.3),
        wrinkling=wrinkling,
        regularisation=0.0,
        cables=cables,
        pressure=0.3,
    )
    x = mesh.points + 0.15 * rng.normal(size=mesh.points.shape)
    return problem, x


@pytest.mark.parametrize("wrinkling", [True, False], ids=["relaxed", "plain"])
def test_assembled_forward_residual_and_tangent_by_central_differences(wrinkling):
    problem, x = _problem_with_everything(wrinkling)
    states = np.concatenate(
        [relaxed_response(problem.material, _C(b, x)).state.ravel() for b in problem.blocks]
    )
    assert set(states) == {0, 1, 2}  # taut, wrinkled and slack points
    evaluation = problem.evaluate(x)
    tension = evaluation.cable_tension
    assert (tension > 0).any() and (tension == 0).any()
    assembler = Assembler(problem.connectivity, np.ones(x.size, bool), dofs_per_node=3)
    gradient = assembler.vector(evaluation.gradients).ravel()
    tangent = assembler.matrix(evaluation.hessians).toarray()
    h = 1e-6
    for i in range(x.size):
        plus, minus = x.copy(), x.copy()
        plus.ravel()[i] += h
        minus.ravel()[i] -= h
        e_plus, e_minus = problem.evaluate(plus, 1), problem.evaluate(minus, 1)
        assert abs((e_plus.energy - e_minus.energy) / (2 * h) - gradient[i]) < 1e-7
        column = assembler.vector(e_plus.gradients) - assembler.vector(e_minus.gradients)
        np.testing.assert_allclose(tangent[:, i], column.ravel() / (2 * h), atol=2e-6)
    np.testing.assert_allclose(tangent, tangent.T, atol=1e-12)


def _C(block, x):
    F = deformation_gradients(x[block.cells], block.reference.gradients)
    return np.einsum("mqia,mqib->mqab", F, F)


def test_pressure_is_the_consistent_follower_load_at_interior_nodes():
    """At interior nodes the gradient of −pV is −p Σ A n / 3 (the consistent load of a uniform
    pressure on linear triangles), wherever the origin lies."""
    mesh = vares.examples.hypar(n=5)
    interior = np.setdiff1d(np.arange(mesh.num_points), mesh.boundary_edges())
    triangles = mesh.cells["triangle"]
    for shift in (np.zeros(3), np.array([3.0, -2.0, 5.0])):
        nodes = mesh.points[triangles] + shift
        _, gradient, _ = pressure_terms(nodes, 0.7, order=1)
        force = np.zeros((mesh.num_points, 3))
        for a in range(3):
            np.add.at(force, triangles[:, a], -gradient[:, a])
        area_vector = 0.5 * np.cross(nodes[:, 1] - nodes[:, 0], nodes[:, 2] - nodes[:, 0])
        expected = np.zeros((mesh.num_points, 3))
        for a in range(3):
            np.add.at(expected, triangles[:, a], 0.7 * area_vector / 3)
        np.testing.assert_allclose(force[interior], expected[interior], atol=1e-13)


def flat_panel(nx=8, ny=6, size=(4.0, 3.0), seed=1):
    """A rectangle in a tilted plane: its (u, v) grid, the 3D mesh and the map to 3D."""
    u, v = np.meshgrid(np.linspace(0, size[0], nx + 1), np.linspace(0, size[1], ny + 1))
    uv = np.column_stack([u.ravel(), v.ravel()])
    frame = rotation(seed)[:, :2]
    origin = np.array([1.0, -2.0, 0.5])
    mesh = vares.SurfaceMesh(origin + uv @ frame.T, grid_cells(nx + 1, ny + 1))
    return uv, mesh, lambda w: origin + w @ frame.T


def jiggled(mesh, coordinates, amount, seed=2):
    """The coordinates with interior nodes moved at random (boundary kept)."""
    out = coordinates.copy()
    interior = np.setdiff1d(np.arange(mesh.num_points), mesh.boundary_edges())
    out[interior] += amount * np.random.default_rng(seed).uniform(-1, 1, (interior.size, 2))
    return out


def test_flat_membrane_with_closed_form_compensation_erects_to_the_intended_prestress():
    """Orthotropic fabric, yarns at 30° to the edges, rectangle in a tilted plane: the pattern
    is the design shrunk by the stretches at which the membrane forces along the yarns are the
    intended ones (solved here from the law's formula), interior nodes jiggled. Erected, the
    deformation is homogeneous: every node where the stretch puts it, forces as intended."""
    E1, E2, G12, nu12 = 840.0, 640.0, 32.0, 0.3
    fabric = OrthotropicStVenantKirchhoff(E1=E1, E2=E2, G12=G12, nu12=nu12)
    n_warp, n_fill = 2.0, 1.5
    d = 1 - nu12**2 * E2 / E1
    Q11, Q22, Q12 = E1 / d, E2 / d, nu12 * E2 / d

    def forces(stretches):
        l1, l2 = stretches
        e1, e2 = (l1**2 - 1) / 2, (l2**2 - 1) / 2
        return [l1 / l2 * (Q11 * e1 + Q12 * e2) - n_warp, l2 / l1 * (Q12 * e1 + Q22 * e2) - n_fill]

    l1, l2 = fsolve(forces, [1.0, 1.0], xtol=1e-13)
    fibres = Fibres.from_angles(30.0)
    U = l1 * np.outer(fibres.warp, fibres.warp) + l2 * np.outer(fibres.fill, fibres.fill)
    uv, mesh, to_3d = flat_panel()
    pattern = jiggled(mesh, uv @ np.linalg.inv(U), 0.1)
    result = vares.erect(Pattern(mesh, pattern, fibres, (n_warp, n_fill)), fabric, solver=TIGHT)
    assert result.converged and result.iterations >= 2
    np.testing.assert_allclose(result.erected_points, to_3d(pattern @ U.T), atol=1e-10)
    for yarn, target in (("warp", n_warp), ("fill", n_fill)):
        np.testing.assert_allclose(result.fields[f"{yarn}_stress"], target, rtol=1e-9)
        stats = result.statistics()["stress"][yarn]
        assert stats["rms_deviation"] < 1e-9 and stats["intended"] == pytest.approx(target)
    assert result.deviation()["max"] < 1e-10
    assert result.statistics()["wrinkled_area_fraction"] == 0.0


@pytest.mark.parametrize("cell_type", ["triangle", "quad"])
def test_flat_panel_cut_too_small_carries_the_analytic_uniform_stress(cell_type):
    """A pattern scaled 0.9 (interior jiggled), Neo-Hooke: erected, the stretch is 1/0.9 in
    every direction and the membrane force t σ with σ = μ + (2λ* ln λ − μ)/λ²."""
    E, nu, t = 1000.0, 0.3, 0.8
    uv, mesh, to_3d = flat_panel()
    if cell_type == "quad":
        mesh = vares.SurfaceMesh(mesh.points, grid_cells(9, 7, "quad"))
    pattern = jiggled(mesh, 0.9 * uv, 0.08)
    result = vares.erect(Pattern(mesh, pattern), NeoHooke(E=E, nu=nu), t, solver=TIGHT)
    assert result.converged
    lam, mu, lame = 1 / 0.9, E / (2 * (1 + nu)), E * nu / (1 - nu**2)
    sigma = mu + (2 * lame * np.log(lam) - mu) / lam**2
    np.testing.assert_allclose(result.erected_points, to_3d(pattern / 0.9), atol=1e-10)
    for name in ("warp_stress", "fill_stress", "stress_max", "stress_min"):
        np.testing.assert_allclose(result.fields[name], t * sigma, rtol=1e-9)
    np.testing.assert_allclose(result.fields["state"], 0.0)


def test_a_trial_point_whose_state_is_not_found_is_stepped_back_from(monkeypatch):
    """The first trial of the line search raises (a wrinkled state not found there): the step
    is shortened as at a fold and the erection still reaches the analytic solution."""
    from vares.mechanics.wrinkling import WrinklingError

    uv, mesh, to_3d = flat_panel()
    pattern = jiggled(mesh, 0.9 * uv, 0.08)
    evaluate, calls = ErectionProblem.evaluate, []

    def once_unfound(self, x, order=2, relaxed=None):
        if order == 2:
            calls.append(1)
            if len(calls) == 2:  # the first trial point: the first call is at the start
                raise WrinklingError("the wrinkled state was not found (injected)")
        return evaluate(self, x, order, relaxed)

    monkeypatch.setattr(ErectionProblem, "evaluate", once_unfound)
    result = vares.erect(Pattern(mesh, pattern), NeoHooke(E=1000.0, nu=0.3), 0.8, solver=TIGHT)
    assert len(calls) > 2 and result.converged and result.iterations > 1
    assert result.strategy == ["erection"]  # the line search stepped back: no damped fallback
    assert result.history[1].step_length < 1.0
    np.testing.assert_allclose(result.erected_points, to_3d(pattern / 0.9), atol=1e-10)


def test_uniaxially_stretched_panel_wrinkles_with_the_uniaxial_force():
    """Pattern 0.95 × the design across, 1.05 × along: erected, the panel is stretched across
    and compressed along. Relaxed, it wrinkles everywhere and carries the uniaxial tension of
    the stretch 1/0.95 with the transverse stress free (natural width from the law); the plain
    law carries compression instead. Cut 1.05 × in both directions it is slack."""
    E, nu = 1000.0, 0.3
    law = NeoHooke(E=E, nu=nu)
    uv, mesh, _ = flat_panel()
    result = vares.erect(Pattern(mesh, uv * [0.95, 1.05]), law)
    mu, lame = E / (2 * (1 + nu)), E * nu / (1 - nu**2)
    l1, l2 = 1 / 0.95, 1 / 1.05

    def S(a, b):  # principal 2nd P-K stresses of C = diag(a², b²)
        c = lame / 2 * np.log(a**2 * b**2) - mu
        return mu + c / a**2, mu + c / b**2

    natural = brentq(lambda b: S(l1, b)[1], 0.5, 1.0)
    force = l1 * S(l1, natural)[0] / l2  # per unit length of the (averaged) erected panel
    assert result.converged
    np.testing.assert_allclose(result.fields["warp_stress"], force, rtol=1e-9)
    np.testing.assert_allclose(result.fields["fill_stress"], 0.0, atol=1e-9 * E)
    assert result.statistics()["wrinkled_area_fraction"] == pytest.approx(1.0)
    compressed = vares.erect(Pattern(mesh, uv * [0.95, 1.05]), law, wrinkling=False)
    np.testing.assert_allclose(compressed.fields["fill_stress"], l2 * S(l1, l2)[1] / l1, rtol=1e-9)
    slack = vares.erect(Pattern(mesh, uv * 1.05), law)
    assert slack.statistics()["slack_area_fraction"] == pytest.approx(1.0)
    assert np.abs(slack.fields["stress_max"]).max() == 0.0


@pytest.mark.parametrize(
    "surface",
    [
        lambda: vares.examples.cylinder160(n_around=16, n_along=8),
        lambda: vares.examples.cylinder160(n_around=16, n_along=8, cell_type="quad"),
        lambda: vares.examples.cone_segment(n_radial=8, n_around=12),
    ],
    ids=["cylinder", "cylinder-quads", "cone"],
)
def test_developable_surface_erects_back_onto_the_design(surface):
    """Patterned without prestress, a developable surface erects back with no stress and no
    deviation (the forward and the pattern problem agree). Without the regularising tension: a
    stress-free membrane has no stiffness against it."""
    mesh = surface()
    law = NeoHooke(E=1000.0, nu=0.3)
    pattern = vares.solve(mesh, law)
    assert pattern.converged
    for wrinkling in (True, False):
        result = vares.erect(pattern, wrinkling=wrinkling, regularisation=0.0)
        size = np.ptp(mesh.points, axis=0).max()
        assert result.converged and result.deviation()["max"] < 1e-9 * size
        assert np.abs(result.displacement).max() < 1e-9 * size
        for name in ("stress_max", "stress_min", "warp_stress", "fill_stress"):
            assert np.abs(result.fields[name]).max() < 1e-8 * law.E


def square_membrane(n: int, size: float = 2.0):
    u, v = np.meshgrid(np.linspace(0, size, n + 1), np.linspace(0, size, n + 1))
    uv = np.column_stack([u.ravel(), v.ravel()])
    return uv, vares.SurfaceMesh(np.column_stack([uv, np.zeros(len(uv))]), grid_cells(n + 1, n + 1))


def isotropic_compensation(law: NeoHooke, force: float) -> float:
    """The stretch λ at which a Neo-Hooke membrane (t = 1) stretched equally in every direction
    carries the membrane force ``force``: μ + (2λ* ln λ − μ)/λ² = force."""
    mu, lame = law.E / (2 * (1 + law.nu)), law.E * law.nu / (1 - law.nu**2)
    return brentq(lambda s: mu + (2 * lame * np.log(s) - mu) / s**2 - force, 1.0, 2.0)


def test_pressurised_square_membrane_deflects_as_the_prestressed_membrane_equation_says():
    """A flat square membrane cut for a uniform prestress N, under a small pressure p (centre
    deflection 1e-4 of the span, so the change of N is negligible): the centre deflection
    converges at second order in the mesh size to the series solution of N ∇²w = −p (without the
    regularising tension, which would add 5e-4 of N)."""
    law, N, a = NeoHooke(E=1000.0, nu=0.3), 2.0, 2.0
    stretch = isotropic_compensation(law, N)
    p = 1e-4 * N / (0.0737 * a)
    odd = np.arange(1, 400, 2)
    m, n = np.meshgrid(odd, odd)
    signs = (-1.0) ** ((m - 1) // 2 + (n - 1) // 2)
    exact = np.sum(16 * p * a**2 * signs / (np.pi**4 * N * m * n * (m**2 + n**2)))
    errors = []
    for cells in (10, 20):
        uv, mesh = square_membrane(cells, a)
        result = vares.erect(Pattern(mesh, uv / stretch), law, pressure=p, regularisation=0.0)
        centre = np.argmin(np.linalg.norm(uv - a / 2, axis=1))
        assert result.converged
        assert result.normal_deviation[centre] == pytest.approx(result.erected_points[centre, 2])
        errors.append(abs(result.erected_points[centre, 2] / exact - 1))
    assert errors[1] < 1e-3 and errors[0] / errors[1] > 3.0


def test_edge_cables_on_circular_arcs_hold_a_uniformly_prestressed_membrane():
    """A flat membrane bounded by four circular-arc edge cables with uniform isotropic prestress
    N is in equilibrium when each cable carries T = N R cos(Δθ/2) (R the radius, Δθ the angle
    between its nodes): cut for N (interior jiggled), with cables of that force, it erects with
    every node where the uniform stretch puts it, the boundary on the design arcs; the cables
    carry T and the membrane N (without the regularising tension, which the cables would carry
    too)."""
    law, N, a, sag, n = NeoHooke(E=1000.0, nu=0.3), 2.0, 2.0, 0.15, 12
    R = (a**2 / 4 + sag**2) / (2 * sag)
    half = np.arcsin(a / (2 * R))
    theta = np.linspace(-half, half, n + 1)
    arc = np.column_stack([a / 2 + R * np.sin(theta), R * np.cos(theta) - R * np.cos(half)])
    bottom, top = arc, arc * [1, -1] + [0, a]
    left = np.column_stack([arc[:, 1], arc[:, 0]])
    right = np.column_stack([a - arc[:, 1], arc[:, 0]])
    s = np.linspace(0, 1, n + 1)
    u, v = (w.ravel() for w in np.meshgrid(s, s))
    i, j = (np.rint(w * n).astype(int) for w in (u, v))
    corners = [bottom[0], bottom[-1], top[0], top[-1]]
    plane = (
        (1 - v)[:, None] * bottom[i]
        + v[:, None] * top[i]
        + (1 - u)[:, None] * left[j]
        + u[:, None] * right[j]
        - ((1 - u) * (1 - v))[:, None] * corners[0]
        - (u * (1 - v))[:, None] * corners[1]
        - ((1 - u) * v)[:, None] * corners[2]
        - (u * v)[:, None] * corners[3]
    )  # Coons patch of the four arcs
    frame = rotation(4)[:, :2]
    mesh = vares.SurfaceMesh(plane @ frame.T, grid_cells(n + 1, n + 1))
    stretch = isotropic_compensation(law, N)
    tension = N * R * np.cos((theta[1] - theta[0]) / 2)
    pattern = jiggled(mesh, plane / stretch, 0.2 * a / n)
    result = vares.erect(
        Pattern(mesh, pattern),
        law,
        cable_stiffness=500.0,
        cable_force=tension,
        regularisation=0.0,
        solver=TIGHT,
    )
    assert result.converged and result.iterations >= 2
    assert result.held.sum() == 4 and len(result.cables.segments) == 4 * n
    np.testing.assert_allclose(result.erected_points, (stretch * pattern) @ frame.T, atol=1e-10)
    np.testing.assert_allclose(result.cable_tension, tension, rtol=1e-9)
    np.testing.assert_allclose(result.fields["stress_min"], N, rtol=1e-9)
    np.testing.assert_allclose(result.fields["stress_max"], N, rtol=1e-9)


def test_panels_welded_along_their_seams_erect_as_the_whole_surface():
    """Cutting a pattern into strips (each cell keeps its reference) and welding them again is
    the same structure: the erected positions agree with those of the uncut pattern."""
    mesh, ids = vares.examples.hypar_strips(strips=3, cells_per_strip=3, n=9)
    fabric = OrthotropicStVenantKirchhoff(E1=840.0, E2=640.0, G12=32.0, nu12=0.3)
    whole = vares.solve(mesh, fabric, warp_direction=(0, 1, 0), prestress=(2.0, 1.5))
    uncut = vares.erect(whole)
    panels = vares.split_panels(mesh, ids)
    patterns = []
    for panel in panels:
        nodes = [int(np.flatnonzero((mesh.points == p).all(axis=1))[0]) for p in panel.mesh.points]
        coordinates = whole.material_coordinates[nodes]
        patterns.append(Pattern(panel.mesh, coordinates, whole.fibres, whole.prestress, panel.name))
    welded = vares.erect(patterns, fabric)
    assert uncut.converged and welded.converged
    assert welded.mesh.num_points == mesh.num_points and len(welded.panels) == 3
    order = [
        int(np.flatnonzero((uncut.mesh.points == p).all(axis=1))[0]) for p in welded.mesh.points
    ]
    np.testing.assert_allclose(welded.erected_points, uncut.erected_points[order], atol=1e-12)
    assert uncut.deviation()["max"] > 1e-4  # the erected shape does differ from the design
    a, b = uncut.to_dict(), welded.to_dict()
    assert a["stress"]["warp"]["mean"] == pytest.approx(b["stress"]["warp"]["mean"], rel=1e-10)
    # every panel's cells and nodes are found in the welded structure
    for panel, node_map, cells in zip(panels, welded.node_maps, welded.cell_ids, strict=True):
        np.testing.assert_array_equal(welded.mesh.points[node_map], panel.mesh.points)
        assert len(cells) == panel.mesh.num_cells


def test_erect_json_contract_and_clear_errors():
    mesh = vares.examples.four_point_sail(n=6)
    fabric = OrthotropicStVenantKirchhoff(E1=840.0, E2=640.0, G12=32.0, nu12=0.3)
    result = vares.erect(vares.solve(mesh, fabric, warp_direction=(1, 1, 0), prestress=(2, 1.5)))
    data = result.to_dict(units="m")
    assert data["converged"] is True and data["iterations"] == result.iterations > 0
    assert data["units"] == "m"
    # every figure again from the result's per-cell and per-node values, weighted by the
    # design surface's areas
    area = mesh.cell_areas()
    assert data["surface_area"] == pytest.approx(area.sum(), rel=1e-12)
    assert data["erected_area"] == pytest.approx(result.erected_mesh.area, rel=1e-12)
    deviation, weight = result.normal_deviation, result.node_areas
    assert data["deviation"]["max"] == pytest.approx(np.abs(deviation).max(), rel=1e-12)
    rms = np.sqrt(deviation**2 @ weight / weight.sum())
    assert data["deviation"]["rms"] == pytest.approx(rms, rel=1e-12)
    for k, yarn in enumerate(("warp", "fill")):
        force, intended = result.fields[f"{yarn}_stress"], result.intended[:, k]
        stats = data["stress"][yarn]
        assert stats["mean"] == pytest.approx(force @ area / area.sum(), rel=1e-12)
        assert (stats["min"], stats["max"]) == (force.min(), force.max())
        assert stats["intended"] == pytest.approx((2.0, 1.5)[k], rel=1e-12)
        rms = np.sqrt((force - intended) ** 2 @ area / area.sum())
        assert stats["rms_deviation"] == pytest.approx(rms, rel=1e-12)
    state = result.fields["state"]
    assert data["wrinkled_area_fraction"] == pytest.approx(area[state == 1].sum() / area.sum())
    assert data["slack_area_fraction"] == pytest.approx(area[state == 2].sum() / area.sum())
    plain = vares.solve(mesh, fabric)
    with pytest.raises(vares.OptionsError, match="not conservative"):
        vares.erect(plain, pressure=1.0, cable_stiffness=10.0)
    with pytest.raises(ValueError, match="three corners"):
        vares.erect(plain, cable_stiffness=10.0, corner_angle=179.0)
    with pytest.raises(ValueError, match="start must have shape"):
        vares.erect(plain, start=np.zeros((3, 3)))


@pytest.mark.parametrize("wrinkling", [True, False])
def test_the_tension_field_solves_newton_steps_tighter(monkeypatch, wrinkling):
    """With the tension field's kinks, Newton steps are solved to at most 1e-3 (loose steps
    took 1.3–2× the iterations through them); a smooth erection keeps the usual cap."""
    import importlib

    from vares.solver.reuse import ETA_MAX, ETA_MAX_KINKED, forcing_term

    newton = importlib.import_module("vares.solver.newton")
    caps = []

    def recording(residuals, tolerance, loosest):
        caps.append(loosest)
        return forcing_term(residuals, tolerance, loosest)

    monkeypatch.setattr(newton, "forcing_term", recording)
    uv, mesh, _ = flat_panel()
    pattern = jiggled(mesh, 0.95 * uv, 0.08)
    result = vares.erect(
        Pattern(mesh, pattern), NeoHooke(E=1000.0, nu=0.3), 1.0, wrinkling=wrinkling
    )
    assert result.converged and caps
    assert set(caps) == {ETA_MAX_KINKED if wrinkling else ETA_MAX}
