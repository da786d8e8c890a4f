"""The erection finds the equilibrium of the law itself: developable patterns erect back with no
stress on irregular meshes in any placement, taut states agree with the plain law's from starts
away from the solution, wrinkled and slack states are reached from such starts too, and a state
that is no equilibrium is never called converged."""

import numpy as np
import pytest
from conftest import rotation
from test_erection import flat_panel, jiggled

import vares
from vares.analysis import Pattern
from vares.analysis.erection import _not_in_equilibrium
from vares.geometry.examples import grid_cells, irregular_hypar_strips
from vares.materials import NeoHooke, StVenantKirchhoff
from vares.solver.newton import _stalled

PLACEMENT = (rotation(5), np.array([3.0, -2.0, 7.5]))


def placed(points: np.ndarray) -> np.ndarray:
    turn, shift = PLACEMENT
    return points @ turn.T + shift


def ruled_cylinder(radius=2.5, length=3.0, angle=160.0, n_around=24, n_along=10, seed=0):
    """A cylinder segment meshed between straight rulings at irregular angles, nodes at
    irregular heights on each: every triangle lies in the plane of two neighbouring rulings, so
    the mesh is exactly developable although no two cells are alike."""
    rng = np.random.default_rng(seed)
    theta = np.radians(np.linspace(-angle / 2, angle / 2, n_around + 1))
    theta[1:-1] += rng.uniform(-0.3, 0.3, n_around - 1) * (theta[1] - theta[0])
    y = np.linspace(0.0, length, n_along + 1)
    t, yy = np.meshgrid(theta, y, indexing="xy")
    yy[1:-1] += rng.uniform(-0.3, 0.3, yy[1:-1].shape) * (length / n_along)
    points = np.column_stack([radius * np.sin(t.ravel()), yy.ravel(), radius * np.cos(t.ravel())])
    return vares.SurfaceMesh(placed(points), grid_cells(n_around + 1, n_along + 1))


def test_a_developable_pattern_erects_back_with_no_stress_with_the_default_options():
    """A 160° cylinder segment on an irregular ruled mesh, rigidly moved, patterned without
    prestress: its pattern is isometric, so the erected structure is the design itself with no
    stress. With the default options (tension field, stabilised tangent) the erection stays
    there; a film tension in the energy would have moved it by ε^(1/3) of its span (10 mm)."""
    mesh = ruled_cylinder()
    law = StVenantKirchhoff(E=600.0, nu=0.3)
    pattern = vares.solve(mesh, law)
    assert pattern.converged
    result = vares.erect(pattern)
    assert result.converged
    size = np.ptp(mesh.points, axis=0).max()
    assert result.deviation()["max"] < 1e-9 * size
    assert np.abs(result.displacement).max() < 1e-9 * size
    for name in ("stress_max", "stress_min", "warp_stress", "fill_stress"):
        assert np.abs(result.fields[name]).max() < 1e-8 * law.E


def taut_hypar():
    """A rigidly moved hypar z = 0.04 x y over 10 m × 10 m on irregular columns with slivers,
    patterned for a uniform 2 kN/m, the erected state taut everywhere."""
    flat, _ = irregular_hypar_strips(strips=4, columns_per_strip=4, n=49, rise=0.04, seed=1)
    mesh = vares.SurfaceMesh(placed(flat.points), flat.cells)
    return vares.solve(mesh, StVenantKirchhoff(E=600.0, nu=0.3), prestress=2.0)


@pytest.mark.parametrize("amplitude", [0.0, 0.1, 0.2])
def test_a_taut_erection_reaches_the_plain_laws_equilibrium_from_far_starts(amplitude):
    """Where no cell wrinkles, the tension-field erection and the plain hyperelastic one have
    the same equilibrium: from the design and from starts pushed up to 0.2 m off it along the
    hypar's axis in waves, both converge to the same positions, every cell taut."""
    pattern = taut_hypar()
    plain = vares.erect(pattern, wrinkling=False)
    assert plain.converged and plain.fields["stress_min"].min() > 0.1
    local = (plain.mesh.points - PLACEMENT[1]) @ PLACEMENT[0]  # the hypar's own x, y, z
    wave = np.sin(0.9 * local[:, 0] + 0.3) * np.cos(0.6 * local[:, 1])
    start = plain.erected_points + amplitude * wave[:, None] * PLACEMENT[0][:, 2]
    for wrinkling in (True, False):
        result = vares.erect(pattern, start=start, wrinkling=wrinkling)
        assert result.converged, result.reason
        np.testing.assert_allclose(result.erected_points, plain.erected_points, atol=1e-8)
        assert not result.fields["state"].any()


def test_wrinkled_and_slack_states_are_reached_from_starts_away_from_them():
    """The panel stretched across and compressed along (wrinkled everywhere) and the panel cut
    too large (slack everywhere), erected from starts with the interior nodes moved off the
    plane and along it: the uniaxial force of the law's natural width, and no force (to the
    residual's tolerance)."""
    law = NeoHooke(E=1000.0, nu=0.3)
    uv, mesh, to_3d = flat_panel()
    rng = np.random.default_rng(4)
    interior = np.setdiff1d(np.arange(mesh.num_points), mesh.boundary_edges())
    start = to_3d(jiggled(mesh, uv, 0.1))
    start[interior] += rng.uniform(-0.1, 0.1, (interior.size, 3))
    from_design = vares.erect(Pattern(mesh, uv * [0.95, 1.05]), law)
    wrinkled = vares.erect(Pattern(mesh, uv * [0.95, 1.05]), law, start=start)
    assert from_design.converged and wrinkled.converged, wrinkled.reason
    assert wrinkled.statistics()["wrinkled_area_fraction"] == pytest.approx(1.0)
    np.testing.assert_allclose(
        wrinkled.fields["warp_stress"], from_design.fields["warp_stress"], rtol=1e-8
    )
    np.testing.assert_allclose(wrinkled.fields["fill_stress"], 0.0, atol=1e-9 * law.E)
    slack = vares.erect(Pattern(mesh, uv * 1.05), law, start=start)
    assert slack.converged and slack.statistics()["slack_area_fraction"] == pytest.approx(1.0)
    assert np.abs(slack.fields["stress_max"]).max() < 1e-9 * law.E  # the residual's tolerance


def test_a_state_that_is_no_equilibrium_is_named_so():
    """The equilibrium check on the design shape of a prestressed pattern (not in equilibrium
    there) names the law whose residual is too large; on the erected state it passes."""
    from vares.analysis.erection import _context
    from vares.analysis.erection_model import build_structure, patterns_of
    from vares.analysis.options import ErectionOptions
    from vares.mechanics.erection import ErectionProblem

    pattern = taut_hypar()
    erected = vares.erect(pattern)
    structure = build_structure(patterns_of(pattern), 1.0, ErectionOptions())
    problem = ErectionProblem(structure.mesh.points, structure.blocks, pattern.material)
    ctx = _context(problem, structure.held, pattern.options, None, 10)
    reason = _not_in_equilibrium(problem, structure.mesh.points, ctx, taut=True)
    assert reason is not None and "no equilibrium of the tension-field law" in reason
    assert _not_in_equilibrium(problem, erected.erected_points, ctx, taut=True) is None


def test_a_stalled_line_search_hands_over_to_damped_steps():
    """The least residual of the last ten iterations not below half the least before: stalled."""
    falling = list(np.geomspace(1.0, 1e-6, 25))
    assert not _stalled(falling, 10) and not _stalled(falling, None)
    circling = [*falling[:10], *([3e-5, 1e-5] * 6)]
    assert _stalled(circling, 10)
    assert not _stalled(circling[:12], 10)  # too few iterations to tell


def test_where_slack_regions_leave_no_isolated_equilibrium_the_regularised_one_is_found():
    """A hypar cut for an isotropic prestress whose pattern leaves a large part of the design
    in compression: erected, a quarter of it wrinkles and some hangs slack, where the tension
    field's equilibria are not isolated. Newton's method on the law stalls there and the
    equilibrium of the regularised energy (the film's tension in it) is returned, said so, and
    the law's residual there is no more than the film's forces."""
    from vares.analysis.erection import _film_residual

    mesh = vares.examples.hypar(n=16)
    pattern = vares.solve(mesh, NeoHooke(E=1000.0, nu=0.3), prestress=2.0)
    result = vares.erect(pattern)
    assert result.converged and result.regularised
    assert result.strategy[0] == "erection" and "regularised" in result.strategy[-1]
    stats = result.statistics()
    assert stats["wrinkled_area_fraction"] > 0.1 and stats["slack_area_fraction"] > 0.01
    problem, ctx = result.problem, result.context
    evaluation = problem.evaluate(result.erected_points, order=1)
    law = np.linalg.norm(ctx.residual(ctx.assembler.vector(evaluation.gradients)))
    film = _film_residual(problem, result.erected_points, ctx)
    assert 0 < law <= 1.01 * film + ctx.residual_tolerance
    assert result.to_dict()["regularised"] is True
    assert not vares.erect(taut_hypar()).regularised


def test_an_erection_result_keeps_no_factorisation():
    """The result keeps what the sensitivities need (problem, dof map, tolerances), not the last
    tangent's factors: SuperLU's of the solve are freed with its solver."""
    pattern = vares.solve(
        vares.examples.hypar(n=6),
        NeoHooke(E=600.0, nu=0.3),
        prestress=2.0,
        linear_solver="scipy-superlu",
    )
    result = vares.erect(pattern)
    assert result.converged and result.linear_solver == "scipy-superlu"
    assert result.context.linear_solver._lu is None
