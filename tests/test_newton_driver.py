"""One Newton driver for every objective: patterns, the erection, seam matching's KKT system and
the warp alignment's turned yarns all iterate through :func:`vares.solver.newton.newton`."""

import numpy as np
import pytest
import scipy.sparse as sp

import vares
from vares.geometry.examples import hypar, hypar_strips
from vares.materials import OrthotropicStVenantKirchhoff
from vares.solver.linear import get_solver
from vares.solver.newton import AssembledDofs, Failure, NewtonContext, newton
from vares.structures import matching, solve_structure
from vares.structures.panels import split_panels

ORTHO = OrthotropicStVenantKirchhoff(E1=800.0, E2=640.0, G12=40.0, nu12=0.4)


class _Saddle:
    """``min ½ xᵀ A x − fᵀx`` subject to ``|x|² = r²`` as a KKT objective over ``(x, λ)``:
    its stationary point is a saddle of the Lagrangian, found by exact (bounded) steps."""

    def __init__(self, a, f, radius):
        self.a, self.f, self.radius = a, f, radius
        self.free = np.ones(a.shape[0] + 1, dtype=bool)

    def evaluate(self, state, order=2):
        x, lam = state[:-1], state[-1]
        gradient = self.a @ x - self.f + 2.0 * lam * x
        constraint = x @ x - self.radius**2
        matrix = sp.bmat(
            [
                [sp.csr_matrix(self.a + 2.0 * lam * np.eye(x.size)), sp.csr_matrix(2 * x[:, None])],
                [sp.csr_matrix(2 * x[None, :]), None],
            ],
            format="csr",
        )
        energy = 0.5 * x @ self.a @ x - self.f @ x

        class Evaluation:
            pass

        out = Evaluation()
        out.energy, out.gradients, out.hessians = energy, np.append(gradient, constraint), matrix
        return out

    def admissible_step(self, state, delta):
        return np.inf


def _context(objective, iterations=30, accepts=None):
    return NewtonContext(
        assembler=AssembledDofs(objective.free),
        linear_solver=get_solver("scipy-superlu"),
        residual_tolerance=1e-12,
        energy_noise=0.0,
        force_scale=1.0,
        max_iterations=iterations,
        history=[],
        steps=[],
        callback=None,
        accepts=accepts,
    )


def test_the_bounded_method_finds_a_lagrangians_saddle_quadratically():
    a = np.diag([1.0, 2.0, 4.0])
    objective = _Saddle(a, np.array([1.0, 1.0, 1.0]), radius=1.0)
    ctx = _context(objective)
    state = newton(objective, np.array([0.6, 0.6, 0.6, 0.0]), ctx, strategy="kkt", step=1,
                   tau=1.0, method="bounded")  # fmt: skip
    x, lam = state[:-1], state[-1]
    assert x @ x == pytest.approx(1.0, abs=1e-14)
    # stationary: A x − f = −2 λ x, i.e. x = (A + 2λ)⁻¹ f
    np.testing.assert_allclose(x, np.linalg.solve(a + 2 * lam * np.eye(3), objective.f), atol=1e-13)
    residuals = [r.relative_residual for r in ctx.history]
    assert len(residuals) <= 8
    assert residuals[-2] < 1e-3 * residuals[-3] or residuals[-1] < 1e-12  # quadratic end
    # a further condition of convergence is asked before it counts as converged
    refused = _context(objective, iterations=5, accepts=lambda state: False)
    with pytest.raises(Failure, match=r"iteration limit \(5\) reached"):
        newton(objective, np.array([0.6, 0.6, 0.6, 0.0]), refused, strategy="kkt", step=1,
               tau=1.0, method="bounded")  # fmt: skip


def test_seam_matching_iterates_through_the_newton_driver(monkeypatch):
    """The matching's records are the driver's (one per Newton iteration of the KKT system,
    bounded steps), and its seams match to round-off as they did with a loop of its own."""
    calls = []
    driver = matching.newton

    def counted(*args, **kwargs):
        calls.append(kwargs["method"])
        return driver(*args, **kwargs)

    monkeypatch.setattr(matching, "newton", counted)
    structure = solve_structure(split_panels(*hypar_strips()), vares.materials.NeoHooke(1e3, 0.3))
    assert calls == ["bounded"]
    assert structure.converged and structure.iterations == 2
    assert [h.iteration for h in structure.history] == [0, 1, 2]
    assert [h.step_length for h in structure.history] == [0.0, 1.0, 1.0]
    last = structure.history[-1]
    assert last.violation <= last.round_off and last.violation < 1e-14
    assert max(r.max_segment_mismatch_after for r in structure.seam_reports) < 1e-14


def test_each_turn_of_the_yarns_is_an_attempt_of_the_plan():
    """With a 3D warp direction every secant step of the alignment is a globalised Newton
    solve recorded under its step number."""
    mesh = hypar(size=4.0, rise=0.8, n=8)
    result = vares.solve(mesh, ORTHO, warp_direction=(1.0, 0.3, 0.0))
    assert result.converged, result.reason
    turned = [s for s in result.steps if s.strategy.startswith("warp alignment")]
    assert len(turned) >= 2 and all(s.converged for s in turned)
    assert [s.step for s in turned] == list(range(1, len(turned) + 1))
    assert {r.strategy for r in result.history} >= {"globalised newton", "warp alignment"}
    assert abs(result.warp_deviation) < 1e-8  # degrees


def test_an_isotropic_problem_takes_the_exact_tangent_from_a_relative_residual_of_5e_2():
    """The robustness suite's steep saddle (z = 2.5 x y, 800 cells, from Tutte's embedding),
    Neo-Hooke: the exact tangent from the second iteration on (relative residual 1.4e-2), 4
    iterations (with the switch at 1e-2: projected once more, 5)."""
    import warnings

    import vares
    from vares import examples

    mesh = examples.robustness_suite(fine=True)["steep saddle z = 2.5 xy"]()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # which start was passed over
        result = vares.solve(mesh, vares.materials.NeoHooke(1000.0, 0.3))
    assert result.converged
    tangents = [record.tangent for record in result.history[1:]]
    first_exact = tangents.index("exact")  # history[first_exact]: where that step started
    assert 1e-2 <= result.history[first_exact].relative_residual < 5e-2
    assert result.iterations <= 4
