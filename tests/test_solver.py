import numpy as np
import pytest
from conftest import align_2d, rotation

import vares
from vares.geometry.examples import cylinder160, cylinder_arc_length, hypar
from vares.materials import IncompressibleNeoHooke, NeoHooke, StVenantKirchhoff
from vares.solver import api
from vares.solver.linear import SingularMatrixError

NEO_HOOKE = NeoHooke(E=1000.0, nu=0.3)


def developed_cylinder(mesh, n_around=32, radius=1.0, angle=160.0):
    """The exact development of the faceted cylinder: node (i, j) → (i × chord, y_j)."""
    chord = cylinder_arc_length(radius, angle, n_around) / n_around
    i = np.arange(mesh.num_points) % (n_around + 1)
    return np.column_stack([i * chord, mesh.points[:, 1]])


@pytest.mark.parametrize("cell_type", ["triangle", "quad"])
@pytest.mark.parametrize("strategy", ["pseudo-time", "damping", "auto"])
def test_cylinder160_unrolls_to_the_exact_rectangle(cell_type, strategy):
    """The seed's benchmark: zero energy, width = discrete arc length, area = 3D area."""
    mesh = cylinder160(cell_type=cell_type)
    result = vares.solve(mesh, NEO_HOOKE, strategy=strategy, steps=3, plane="xy")
    assert result.converged, result.reason
    assert result.steps[-1].converged and result.steps[-1].tau == 1.0
    x = result.material_coordinates
    width = np.linalg.norm(x[32] - x[0])  # corners θ = ±80° at y = 0
    assert width / cylinder_arc_length() - 1 == pytest.approx(0.0, abs=1e-8)
    assert result.pattern_area / mesh.area - 1 == pytest.approx(0.0, abs=1e-8)
    exact = developed_cylinder(mesh)
    assert np.abs(align_2d(exact, x) - exact).max() < 1e-8 * width
    energy_scale = NEO_HOOKE.E * mesh.area
    assert abs(result.energy) < 1e-12 * energy_scale
    np.testing.assert_allclose(result.fields["det_F"], 1.0, atol=1e-8)
    assert np.abs(result.fields["stress_max"]).max() < 1e-6 * NEO_HOOKE.E


def test_cylinder_pseudo_time_records_every_step():
    result = vares.solve(
        cylinder160(cell_type="quad"), NEO_HOOKE, strategy="pseudo-time", steps=3, plane="xy"
    )
    assert result.strategy == ["pseudo-time"]
    converged = [s for s in result.steps if s.converged]
    assert [s.tau for s in converged] == pytest.approx([1 / 3, 2 / 3, 1.0])
    assert sum(s.iterations for s in result.steps) == result.iterations
    assert all(0 < s.iterations < 30 for s in converged)
    # Every step ends below the tolerance, the iteration counts in the history agree.
    for step in converged:
        records = [r for r in result.history if r.step == step.step]
        assert records[-1].relative_residual <= 1e-10
        assert len(records) == step.iterations + 1


@pytest.mark.parametrize(
    "law",
    [NEO_HOOKE, StVenantKirchhoff(E=1000.0, nu=0.3), IncompressibleNeoHooke(mu=300.0)],
    ids=lambda m: type(m).__name__,
)
def test_cylinder_unrolls_for_every_isotropic_law(law):
    mesh = cylinder160(n_around=16, n_along=6, cell_type="quad")
    result = vares.solve(mesh, law, plane="xy")
    assert result.converged, result.reason
    assert result.pattern_area == pytest.approx(mesh.area, rel=1e-9)
    assert abs(result.energy) < 1e-12 * law.stiffness_scale * mesh.area


def quadratic_orders(residuals, floor):
    """Observed orders log(r_{k+1}/r_k) / log(r_k/r_{k-1}) in the asymptotic range."""
    r = np.asarray(residuals)
    orders = []
    for k in range(1, len(r) - 1):
        if r[k] < 1e-2 and r[k + 1] > floor:
            orders.append(np.log(r[k + 1] / r[k]) / np.log(r[k] / r[k - 1]))
    return orders


def test_newton_converges_quadratically_on_a_doubly_curved_surface():
    mesh = hypar(size=10.0, rise=0.06, n=16)
    result = vares.solve(mesh, NEO_HOOKE, strategy="newton", tolerance=1e-14)
    assert result.converged, result.reason
    residuals = [r.relative_residual for r in result.history]
    orders = quadratic_orders(residuals, floor=1e-13)
    assert orders, residuals
    assert min(orders) > 1.8, (orders, residuals)
    assert result.energy > 0  # the hypar is not developable


def test_rigid_motion_of_the_surface_moves_the_pattern_rigidly():
    mesh = hypar(size=4.0, rise=0.15, n=10, cell_type="quad")
    reference = vares.solve(mesh, NEO_HOOKE)
    moved = mesh.transformed(mesh.points @ rotation(5).T + [3.0, -7.0, 11.0])
    result = vares.solve(moved, NEO_HOOKE)
    assert reference.converged and result.converged
    a, b = reference.material_coordinates, result.material_coordinates
    assert np.abs(align_2d(a, b) - a).max() < 1e-9 * 4.0
    assert result.energy == pytest.approx(reference.energy, rel=1e-9)


def test_the_pattern_is_the_minimiser():
    """Perturbing the optimal pattern raises the energy (second-order, positive)."""
    mesh = hypar(size=4.0, rise=0.15, n=8)
    result = vares.solve(mesh, NEO_HOOKE)
    problem = vares.Problem(mesh, NEO_HOOKE)
    rng = np.random.default_rng(0)
    for _ in range(5):
        trial = result.material_coordinates + 1e-4 * rng.normal(size=(mesh.num_points, 2))
        assert problem.energy(trial) > result.energy


def test_plain_newton_reports_inverted_elements():
    result = vares.solve(cylinder160(), NEO_HOOKE, strategy="newton", plane="xy")
    assert not result.converged
    assert result.reason.startswith("inverted elements")
    assert (
        vares.Problem(result.mesh, NEO_HOOKE).inverted_cells(result.material_coordinates).size == 0
    )


def test_iteration_limit_is_reported():
    result = vares.solve(hypar(n=6), NEO_HOOKE, strategy="newton", max_iterations=1)
    assert not result.converged
    assert result.reason == "iteration limit (1) reached"


def test_singular_tangent_is_reported(monkeypatch):
    class Singular:
        name = "singular"
        reuse_iterations = 0

        def factorize(self, matrix, definite=False):
            raise SingularMatrixError("exactly singular")

    monkeypatch.setattr(api, "get_solver", lambda name: Singular())
    result = vares.solve(hypar(n=4), NEO_HOOKE, strategy="newton")
    assert not result.converged and result.reason.startswith("singular tangent")


def test_folding_projection_is_reported_or_passed_over():
    mesh = cylinder160(angle=220.0, n_around=22, n_along=2)
    result = vares.solve(mesh, NEO_HOOKE, plane="xy", initial_guess="projection")
    assert not result.converged
    assert "projection onto the plane inverts" in result.reason
    assert result.iterations == 0
    with pytest.warns(
        UserWarning, match="the projection folds 16 cell.*started from the conformal map"
    ):
        result = vares.solve(mesh, NEO_HOOKE, plane="xy")
    assert result.converged and result.initial_guess == "lscm"


def test_user_initial_guess_and_plane_normal():
    mesh = hypar(size=4.0, rise=0.15, n=8)
    reference = vares.solve(mesh, NEO_HOOKE, plane=[0.0, 0.0, 1.0])
    guess = reference.material_coordinates * 1.02 + [0.5, 0.1]
    result = vares.solve(mesh, NEO_HOOKE, initial_guess=guess)
    assert result.converged and result.strategy == ["globalised newton"]
    a, b = reference.material_coordinates, result.material_coordinates
    assert np.abs(align_2d(a, b) - a).max() < 1e-9


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"strategy": "magic"}, "strategy must be one of auto, newton"),
        ({"steps": 0}, "steps must be"),
        ({"tolerance": -1.0}, "tolerance"),
        ({"plane": "xq"}, "plane must be one of best-fit"),
        ({"plane": [0.0, 0.0, 0.0]}, "plane must be .*not all zero"),
        ({"initial_guess": np.zeros((3, 2))}, "initial_guess must be"),
        ({"initial_guess": np.zeros((25, 2)), "strategy": "pseudo-time"}, "projection"),
        ({"thickness": 0.0}, "thickness"),
        ({"linear_solver": "nope"}, "linear_solver must be one of pardiso"),
    ],
)
def test_bad_options_raise_clear_errors(kwargs, message):
    mesh = hypar(n=4)
    with pytest.raises(ValueError, match=message):
        vares.solve(mesh, NEO_HOOKE, **kwargs)


def test_evaluate_any_pattern():
    mesh = cylinder160(n_around=8, n_along=2)
    flat = vares.projection_plane(mesh, "xy").project(mesh.points)
    evaluation = vares.evaluate(mesh, flat, NEO_HOOKE)
    assert evaluation.energy > 0 and evaluation.inverted_cells.size == 0
    # The projection is shorter than the arc: the erected cells are stretched (det F > 1).
    assert evaluation.fields["det_F"].min() > 1.0
    np.testing.assert_allclose(
        evaluation.fields["det_F"],
        evaluation.fields["surface_area"] / evaluation.fields["pattern_area"],
        rtol=1e-12,
    )
    assert evaluation.fields["energy"].sum() == pytest.approx(evaluation.energy, rel=1e-12)


def test_a_minimum_beyond_a_fold_is_named_as_the_reason(monkeypatch):
    """When a globalised attempt finds the pattern squeezed flat at a cell (its minimum lies
    beyond a fold), that is the reason given, not the later attempt's iteration limit."""
    from vares.solver import strategies
    from vares.solver.newton import Failure

    calls = []

    def fake_newton(problem, x0, ctx, strategy, **_):
        calls.append(strategy)
        if strategy == "globalised newton":
            raise Failure("the pattern is being squeezed flat at 1 cell(s) (7)", x0, folding=True)
        raise Failure("iteration limit (50) reached", x0)

    class Context:
        def attempt(self, name, step, tau, run):
            return run()

    monkeypatch.setattr(strategies, "newton", fake_newton)
    plan = strategies.plan("auto", 4, have_plane=False)
    _, path, reason = strategies.follow_plan(None, np.zeros((3, 2)), None, plan, Context(), 1.0)
    assert calls == ["globalised newton", "damping"] and path == calls
    assert reason.startswith("the pattern is being squeezed flat at 1 cell(s) (7)")


def test_steps_held_back_by_a_fold_are_counted_only_while_they_shrink():
    from vares.solver.newton import _held_back

    class Search:
        bounded_by = np.array([7])

    assert _held_back(Search(), 0.03, [1.0, 0.3])
    assert not _held_back(Search(), 0.2, [1.0, 0.3])  # not short
    assert not _held_back(Search(), 0.03, [0.04])  # not shorter than half the one before
    Search.bounded_by = None
    assert not _held_back(Search(), 0.03, [1.0, 0.3])  # not held back by a fold
