"""Globalised Newton, initial guesses and the robustness suite."""

import numpy as np
import pytest

import vares
from vares import examples
from vares.geometry.flatten import lscm, projection_distortion
from vares.materials import NeoHooke, NonCrimpFabric, OrthotropicStVenantKirchhoff

NEO_HOOKE = NeoHooke(1000.0, 0.3)
ORTHO = OrthotropicStVenantKirchhoff(800.0, 640.0, 40.0, 0.4)

SUITE = examples.robustness_suite()


@pytest.mark.parametrize("name", list(SUITE))
@pytest.mark.parametrize("law", [NEO_HOOKE, ORTHO], ids=["neo-hooke", "orthotropic"])
def test_robustness_suite_converges_with_the_default_strategy(name, law):
    mesh = SUITE[name]()
    result = vares.solve(mesh, law)
    assert result.converged, result.reason
    assert result.strategy[0] == "globalised newton"
    assert result.history[-1].relative_residual <= 1e-10
    assert (
        vares.Problem(mesh, law, fibres=result.fibres)
        .inverted_cells(result.material_coordinates)
        .size
        == 0
    )


@pytest.mark.parametrize("name", ["hemisphere", "deep cap 120°", "cylinder 220°"])
def test_steep_and_folding_surfaces_start_from_the_conformal_map(name):
    mesh = SUITE[name]()
    plane = vares.projection_plane(mesh)
    assert projection_distortion(mesh, plane) < 0.2
    result = vares.solve(mesh, NEO_HOOKE)
    assert result.initial_guess == "lscm" and result.converged


def test_mild_surfaces_start_from_the_projection():
    result = vares.solve(SUITE["hypar z = 0.06 xy, 10 m"](), NEO_HOOKE)
    assert result.initial_guess == "projection"
    assert vares.solve(SUITE["hemisphere"](), NEO_HOOKE, initial_guess="projection").converged


@pytest.mark.parametrize("name", ["cylinder 220°", "cone segment 120°"])
def test_lscm_flattens_developable_surfaces_isometrically(name):
    mesh = SUITE[name]()
    pattern = lscm(mesh)
    evaluation = vares.evaluate(mesh, pattern, NEO_HOOKE)
    assert evaluation.inverted_cells.size == 0
    np.testing.assert_allclose(evaluation.fields["det_F"], 1.0, atol=1e-8)
    assert abs(evaluation.energy) < 1e-10 * NEO_HOOKE.E * mesh.area


def test_globalised_newton_ends_quadratically():
    mesh = examples.cap_over_square(n=16)
    result = vares.solve(mesh, NEO_HOOKE, tolerance=1e-14)
    records = [r for r in result.history if r.strategy == "globalised newton"]
    residuals = [r.relative_residual for r in records]
    tail = [
        (a, b, c)
        for a, b, c in zip(residuals, residuals[1:], residuals[2:], strict=False)
        if b < 1e-3 and c > 1e-13
    ]
    assert tail, residuals
    orders = [np.log(c / b) / np.log(b / a) for a, b, c in tail]
    assert min(orders) > 1.8, (orders, residuals)
    assert records[-1].tangent == "exact" and records[-1].step_length == 1.0


def test_no_inverted_pattern_is_ever_accepted(monkeypatch):
    """Every iterate a strategy evaluates for a Newton step keeps det J > 0 in every cell."""
    seen = []
    original = vares.Problem.evaluate

    def checking(self, coordinates, order=2, **kwargs):
        if order == 2:
            seen.append(self.inverted_cells(coordinates).size)
        return original(self, coordinates, order, **kwargs)

    monkeypatch.setattr(vares.Problem, "evaluate", checking)
    mesh = examples.cylinder160(n_around=16, n_along=6)
    for strategy in ("auto", "damping", "pseudo-time"):
        result = vares.solve(
            mesh,
            NonCrimpFabric.from_moduli(1000.0, 1000.0, 5.0),
            warp_angle=30.0,
            strategy=strategy,
            plane="xy",
        )
        assert result.converged, (strategy, result.reason)
    assert len(seen) > 20 and max(seen) == 0


def test_step_bound_stops_at_the_first_collapsing_cell():
    mesh = examples.hypar(n=4)
    x = vares.projection_plane(mesh, "xy").project(mesh.points)
    problem = vares.Problem(mesh, NEO_HOOKE)
    rng = np.random.default_rng(2)
    direction = rng.normal(size=x.shape)
    bound = problem.admissible_step(x, direction)
    assert 0 < bound < np.inf
    assert problem.inverted_cells(x + 0.999 * bound * direction).size == 0
    assert problem.inverted_cells(x + 1.001 * bound * direction).size > 0


def test_projected_tangent_is_positive_semi_definite():
    mesh = examples.hypar(n=4)
    problem = vares.Problem(mesh, NEO_HOOKE)
    flat = vares.projection_plane(mesh, "xy").project(mesh.points)
    small = flat * 0.7  # a pattern much smaller than the surface: the tangent is indefinite
    exact = np.concatenate(problem.evaluate(small).hessians).reshape(-1, 6, 6)
    projected = np.concatenate(problem.evaluate(small, projected=True).hessians)
    projected = projected.reshape(-1, 6, 6)
    scale = np.abs(exact).max()
    assert np.linalg.eigvalsh(exact).min() < -1e-2 * scale
    assert np.linalg.eigvalsh(projected).min() > -1e-10 * scale
    near = flat * 1.1  # positive semi-definite already
    a = np.concatenate(problem.evaluate(near).hessians)
    b = np.concatenate(problem.evaluate(near, projected=True).hessians)
    np.testing.assert_allclose(a, b, atol=1e-9 * np.abs(a).max())  # PSD already: unchanged


@pytest.mark.parametrize("name", list(examples.EXAMPLES))
def test_every_shipped_example_patterns_with_the_default_strategy(name):
    mesh = examples.EXAMPLES[name]()
    plane = examples.EXAMPLE_PLANES.get(name)
    result = vares.solve(mesh, NEO_HOOKE, plane=plane)
    assert result.converged, result.reason
    assert abs(result.pattern_area / mesh.area - 1) < 0.05
