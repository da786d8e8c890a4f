"""Inexact Newton: forcing terms, conjugate gradients preconditioned by an earlier
factorisation, and what that does to a solve."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import vares
from vares import examples
from vares.solver import linear
from vares.solver.reuse import (
    CAUTIOUS_BELOW,
    ETA_MAX,
    ETA_MAX_KINKED,
    ReusingSolver,
    forcing_term,
    preconditioned_cg,
)

NEO_HOOKE = vares.materials.NeoHooke(1000.0, 0.3)


def _laplacian(n: int, shift: float = 0.1) -> sp.csr_matrix:
    """A 2D grid Laplacian plus ``shift`` on the diagonal: positive definite, size n²."""
    one = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    return (sp.kronsum(one, one) + shift * sp.identity(n * n)).tocsr()


def test_forcing_term_follows_eisenstat_walker_and_the_tolerance():
    assert forcing_term([1.0], 1e-10) == ETA_MAX  # first iteration: the loosest
    # 0.9 (r_k / r_{k-1})^2
    assert forcing_term([1.0, 0.01], 1e-12) == pytest.approx(0.9e-4)
    assert forcing_term([3.0, 1.0, 0.2], 1e-12) == pytest.approx(0.9 * 0.04)
    # never tighter than half of what the tolerance asks of the next iterate
    assert forcing_term([1.0, 1e-6], 1e-10) == pytest.approx(0.5e-10 / 1e-6)
    # a residual that grew, or fell little: the loosest
    assert forcing_term([1.0, 2.0], 1e-10) == ETA_MAX
    assert forcing_term([1.0, 0.5], 1e-10) == ETA_MAX
    # an energy with kinks: a tighter cap, the same formula below it
    assert forcing_term([1.0, 0.5], 1e-10, ETA_MAX_KINKED) == ETA_MAX_KINKED
    assert forcing_term([1.0, 0.01], 1e-12, ETA_MAX_KINKED) == pytest.approx(0.9e-4)


def test_cg_with_the_exact_inverse_takes_one_iteration():
    matrix = _laplacian(12)
    rhs = np.random.default_rng(0).standard_normal(matrix.shape[0])
    lu = sp.linalg.splu(matrix.tocsc())
    x, iterations = preconditioned_cg(matrix, rhs, lu.solve, 1e-12, budget=5)
    assert iterations == 1
    np.testing.assert_allclose(matrix @ x, rhs, atol=1e-10 * np.linalg.norm(rhs))


def test_cg_with_a_nearby_factorisation_reaches_the_tolerance_asked():
    matrix = _laplacian(20)
    rng = np.random.default_rng(1)
    changed = matrix + sp.diags(rng.uniform(0.0, 0.3, matrix.shape[0]))  # a later tangent
    lu = sp.linalg.splu(matrix.tocsc())
    rhs = rng.standard_normal(matrix.shape[0])
    for rtol in (1e-2, 1e-6, 1e-10):
        x, iterations = preconditioned_cg(changed, rhs, lu.solve, rtol, budget=40)
        assert x is not None and iterations >= 2
        assert np.linalg.norm(rhs - changed @ x) <= rtol * np.linalg.norm(rhs)


def test_cg_gives_up_on_an_indefinite_matrix_and_beyond_its_budget():
    matrix = _laplacian(10)
    rhs = np.ones(matrix.shape[0])
    indefinite = (matrix - 2.0 * sp.identity(matrix.shape[0])).tocsr()
    x, _ = preconditioned_cg(indefinite, rhs, lambda r: r, 1e-8, budget=200)
    assert x is None  # negative curvature met, not iterated through
    # unpreconditioned CG on a Laplacian converges slowly: its rate shows it early
    x, iterations = preconditioned_cg(_laplacian(30, 1e-3), np.ones(900), lambda r: r, 1e-10, 8)
    assert x is None and iterations <= 3  # given up once the rate shows it, not at the budget
    zero, iterations = preconditioned_cg(matrix, np.zeros(matrix.shape[0]), lambda r: r, 1e-8, 5)
    assert iterations == 0 and not zero.any()


def test_reusing_solver_factorises_only_when_it_must():
    solver = ReusingSolver(linear.get_solver("scipy-superlu"))
    assert solver.budget > 0
    matrix = _laplacian(16)
    rng = np.random.default_rng(3)
    rhs = rng.standard_normal(matrix.shape[0])
    solver.solve(matrix, rhs, rtol=1e-3)  # nothing to reuse yet
    assert (solver.factorisations, solver.cg_iterations) == (1, 0)
    later = (matrix + sp.diags(rng.uniform(0.0, 0.05, matrix.shape[0]))).tocsr()
    x = solver.solve(later, rhs, rtol=1e-8)
    assert solver.factorisations == 1 and solver.cg_iterations > 0
    assert np.linalg.norm(rhs - later @ x) <= 1e-8 * np.linalg.norm(rhs)
    solver.solve(later, rhs)  # an exact solve asked: factorised
    assert solver.factorisations == 2
    smaller = _laplacian(15)  # another size: the factorisation cannot precondition it
    solver.solve(smaller, rhs[: smaller.shape[0]], rtol=1e-3)
    assert solver.factorisations == 3
    # the same size as the last, but nothing like it: CG gives up and the matrix is factorised
    far = (smaller + sp.diags(rng.uniform(0.0, 40.0, smaller.shape[0]))).tocsr()
    iterations = solver.cg_iterations
    x = solver.solve(far, rhs[: far.shape[0]], rtol=1e-10)
    assert solver.factorisations == 4 and solver.cg_iterations > iterations
    np.testing.assert_allclose(far @ x, rhs[: far.shape[0]], atol=1e-9 * np.linalg.norm(rhs))


class _Cautious(linear.SuperLUSolver):
    """SuperLU that reuses its factorisation as PARDISO does: cautiously, within 3 iterations."""

    reuse_iterations = 3
    cautious_reuse = True


def test_a_cautious_solver_reuses_only_at_newtons_end_for_the_same_kind_and_until_it_fails():
    """A back end whose factorisation is cheap (PARDISO) reuses it only for steps asked to
    better than CAUTIOUS_BELOW, only for a tangent of the kind it factorised (Newton's exact
    tangents come with ``definite=True``), and not again once conjugate gradients failed."""
    solver = ReusingSolver(_Cautious())
    matrix = _laplacian(16)
    rng = np.random.default_rng(4)
    rhs = rng.standard_normal(matrix.shape[0])
    near = (matrix + sp.diags(rng.uniform(0.0, 0.01, matrix.shape[0]))).tocsr()
    solver.solve(matrix, rhs, rtol=1e-3, definite=True)
    assert (solver.factorisations, solver.cg_iterations) == (1, 0)
    solver.solve(near, rhs, rtol=2 * CAUTIOUS_BELOW, definite=True)  # a loose, early step
    assert (solver.factorisations, solver.cg_iterations) == (2, 0)
    x = solver.solve(near, rhs, rtol=1e-6, definite=True)  # Newton's end: reused
    assert solver.factorisations == 2 and 0 < solver.cg_iterations <= 3
    assert np.linalg.norm(rhs - near @ x) <= 1e-6 * np.linalg.norm(rhs)
    solver.solve(near, rhs, rtol=1e-6, definite=False)  # a projected tangent after an exact one
    assert solver.factorisations == 3
    used = solver.cg_iterations
    far = (matrix + sp.diags(rng.uniform(0.0, 40.0, matrix.shape[0]))).tocsr()
    solver.solve(far, rhs, rtol=1e-10, definite=False)  # too far: CG gives up, factorised
    assert solver.factorisations == 4 and solver.cg_iterations > used
    used = solver.cg_iterations
    solver.solve(far, rhs, rtol=1e-3, definite=False)  # would reuse, but no longer tries
    assert (solver.factorisations, solver.cg_iterations) == (5, used)


def test_pardiso_reuses_its_factorisation_at_newtons_end_for_the_same_pattern():
    """On the 100k race's hypar, smaller (20k triangles): the last Newton steps by conjugate
    gradients preconditioned by the first exact tangent's factorisation, the same optimum as
    with every tangent factorised."""
    if "pardiso" not in linear.available_solvers():
        pytest.skip("PARDISO is not installed")
    mesh = examples.hypar(size=10.0, rise=0.06, n=100)
    law = vares.materials.StVenantKirchhoff(1000.0, 0.3)
    reused = vares.solve(mesh, law, tolerance=1e-10, linear_solver="pardiso")
    every = linear.PardisoSolver.reuse_iterations
    try:
        linear.PardisoSolver.reuse_iterations = 0
        reference = vares.solve(mesh, law, tolerance=1e-10, linear_solver="pardiso")
    finally:
        linear.PardisoSolver.reuse_iterations = every
    assert reference.factorisations == reference.iterations and reference.cg_iterations == 0
    assert reused.iterations == reference.iterations
    assert reused.factorisations < reference.factorisations and reused.cg_iterations > 0
    assert reused.energy == pytest.approx(reference.energy, rel=1e-12)
    np.testing.assert_allclose(
        reused.material_coordinates, reference.material_coordinates, atol=1e-9 * 10.0
    )


def test_a_solver_that_never_reuses_factorises_every_system():
    solver = ReusingSolver(linear.get_solver("scipy-superlu"))
    solver.budget = 0
    matrix = _laplacian(8)
    for _ in range(3):
        solver.solve(matrix, np.ones(matrix.shape[0]), rtol=0.1)
    assert (solver.factorisations, solver.cg_iterations) == (3, 0)


def test_inexact_newton_finds_the_same_pattern_with_one_factorisation():
    """SuperLU reuses its first factorisation: the same optimum as exact Newton (every tangent
    factorised) to round-off, in as many Newton iterations, ending superlinearly. From the
    projection (the automatic start, one ARAP step further, is two iterations from the optimum
    here: too few to show the rate)."""
    mesh = examples.hypar(size=10.0, rise=0.06, n=40)
    inexact = vares.solve(
        mesh, NEO_HOOKE, linear_solver="scipy-superlu", initial_guess="projection"
    )
    exact_solver = linear.SuperLUSolver()
    exact_solver.reuse_iterations = 0
    reference = _solve_with(mesh, exact_solver, initial_guess="projection")
    assert inexact.converged and reference.converged
    assert reference.factorisations == reference.iterations and reference.cg_iterations == 0
    assert inexact.factorisations == 1 and inexact.cg_iterations >= inexact.iterations - 1
    assert inexact.iterations <= reference.iterations + 1
    assert inexact.energy == pytest.approx(reference.energy, rel=1e-12)
    np.testing.assert_allclose(
        inexact.material_coordinates, reference.material_coordinates, atol=1e-10 * 10.0
    )
    residuals = [r.relative_residual for r in inexact.history]
    assert residuals[-1] <= 1e-10
    # superlinear, not linear: the contraction itself shrinks tenfold (the last step is solved
    # only as accurately as the tolerance asks, so it is the one before that shows the rate)
    contractions = np.array(residuals[1:]) / np.array(residuals[:-1])
    assert contractions[-2] < 0.1 * contractions[-3] and residuals[-2] < 1e-2 * residuals[-3]


def _solve_with(mesh, solver, **settings):
    """A solve whose context gets ``solver`` (an instance) instead of a new one by name."""
    original = linear._SOLVERS["scipy-superlu"]
    linear._SOLVERS["scipy-superlu"] = lambda: solver
    try:
        return vares.solve(mesh, NEO_HOOKE, linear_solver="scipy-superlu", **settings)
    finally:
        linear._SOLVERS["scipy-superlu"] = original


def test_the_history_counts_the_linear_work():
    mesh = examples.hypar(n=12)
    result = vares.solve(mesh, NEO_HOOKE, linear_solver="scipy-superlu")
    assert result.history[0].factorisations == 0 and result.history[0].cg_iterations == 0
    # every step solved something, by a factorisation or CG with an earlier one; after the
    # first, CG stood in for at least one factorisation
    assert all(r.factorisations + r.cg_iterations > 0 for r in result.history[1:])
    assert result.history[1].factorisations >= 1
    assert result.factorisations < result.iterations
    from vares.io.summary import summary

    written = summary(result)
    assert written["factorisations"] == result.factorisations
    assert written["cg_iterations"] == result.cg_iterations


def test_a_definite_only_solver_refuses_an_indefinite_matrix_when_asked():
    pytest.importorskip("sksparse")
    solver = linear.get_solver("cholmod")
    indefinite = (_laplacian(6) - 0.5 * sp.identity(36)).tocsr()
    rhs = np.ones(36)
    with pytest.raises(linear.IndefiniteMatrixError):
        solver.factorize(indefinite, definite=True)
    solver.factorize(indefinite)  # passed on to SuperLU
    np.testing.assert_allclose(indefinite @ solver.solve(rhs), rhs, atol=1e-10)


class _DefiniteOnly(linear.SuperLUSolver):
    """SuperLU that refuses every matrix it is asked to factorise as a definite one (and
    factorises every tangent)."""

    refused = 0
    reuse_iterations = 0

    def factorize(self, matrix, definite=False):
        if definite:
            _DefiniteOnly.refused += 1
            raise linear.IndefiniteMatrixError("refused")
        super().factorize(matrix)


def test_globalised_newton_takes_the_projected_tangent_where_the_exact_one_is_refused():
    mesh = examples.hypar(size=10.0, rise=0.06, n=16)
    reference = vares.solve(mesh, NEO_HOOKE, linear_solver="scipy-superlu")
    _DefiniteOnly.refused = 0
    result = _solve_with(mesh, _DefiniteOnly())
    assert result.converged and _DefiniteOnly.refused > 0
    tangents = {r.tangent for r in result.history[1:]}
    assert "exact" not in tangents and "projected" in tangents
    assert result.energy == pytest.approx(reference.energy, rel=1e-10)


def test_the_command_shows_and_reports_the_linear_work(tmp_path):
    import json

    from conftest import run

    out = tmp_path / "out"
    result = run("example", "hypar", "-o", out, "--linear-solver", "scipy-superlu", "--report")
    assert result.exit_code == 0, result.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["factorisations"] >= 1 and summary["cg_iterations"] > 0
    shown = [line for line in result.stderr.splitlines() if " CG)" in line]
    assert shown and len(shown) == sum(1 for h in summary["history"] if h["cg_iterations"])
    report = (out / "report.html").read_text()
    expected = f"{summary['factorisations']}, {summary['cg_iterations']}"
    assert f'<th>factorisations, CG iterations</th><td class="num">{expected}</td>' in report


def test_constrained_cg_keeps_the_constraint_and_solves_the_bordered_system():
    matrix = _laplacian(12)
    n = matrix.shape[0]
    rng = np.random.default_rng(7)
    c = rng.standard_normal(n)
    c /= np.linalg.norm(c)
    rhs = rng.standard_normal(n)
    rhs -= c * (c @ rhs)  # a Newton residual less its constraint component
    later = (matrix + sp.diags(rng.uniform(0.0, 0.05, n))).tocsr()
    solver = ReusingSolver(linear.get_solver("scipy-superlu"))
    solver.solve(matrix, rhs, rtol=1e-3, constraint=c)  # factorises the bordered matrix
    assert solver.factorisations == 1
    x = solver.solve(later, rhs, rtol=1e-10, constraint=c)
    assert solver.factorisations == 1 and solver.cg_iterations > 0
    column = sp.csr_matrix(c[:, None])
    bordered = sp.bmat([[later, column], [column.T, None]], format="csc")
    exact = sp.linalg.spsolve(bordered, np.append(rhs, 0.0))[:-1]
    assert abs(c @ x) < 1e-12 * np.linalg.norm(x)
    np.testing.assert_allclose(x, exact, atol=1e-8 * np.linalg.norm(exact))


def test_a_held_anisotropic_solve_reuses_its_bordered_factorisation():
    """Orthotropic fabric, rotation held (the tangent bordered by the rotation constraint):
    SuperLU factorises once and reaches exact Newton's pattern."""
    mesh = examples.hypar(size=10.0, rise=0.06, n=24)
    law = vares.materials.OrthotropicStVenantKirchhoff(800.0, 640.0, 40.0, 0.4)
    inexact = vares.solve(mesh, law, warp_angle=20.0, linear_solver="scipy-superlu")
    exact = (
        vares.solve(mesh, law, warp_angle=20.0, linear_solver="pardiso")
        if ("pardiso" in linear.available_solvers())
        else None
    )
    assert inexact.converged and inexact.factorisations == 1 and inexact.cg_iterations > 0
    if exact is not None:
        assert exact.factorisations == exact.iterations
        assert inexact.energy == pytest.approx(exact.energy, rel=1e-12)
        np.testing.assert_allclose(
            inexact.material_coordinates, exact.material_coordinates, atol=1e-10 * 10.0
        )


def test_a_primed_solver_solves_by_the_primer_until_it_needs_more_or_factorises():
    from scipy.sparse.linalg import splu

    matrix = _laplacian(15)  # 225 unknowns
    nearby = splu((matrix * 1.02).tocsc())  # a nearby matrix's factorisation
    rhs = np.random.default_rng(0).standard_normal(matrix.shape[0])
    systems = ReusingSolver(linear.get_solver("scipy-superlu"))
    systems.prime(nearby.solve, 6)
    x = systems.solve(matrix, rhs, rtol=1e-8)
    assert np.linalg.norm(matrix @ x - rhs) <= 1e-8 * np.linalg.norm(rhs)
    assert systems.factorisations == 0 and 0 < systems.cg_iterations <= 6
    # a primer too far off for its budget gives way to a factorisation, and is dropped
    far = splu((matrix * 3.0 + sp.identity(matrix.shape[0])).tocsc())
    systems.prime(far.solve, 1)
    x = systems.solve(matrix, rhs, rtol=1e-12)
    assert systems.factorisations == 1
    assert np.linalg.norm(matrix @ x - rhs) <= 1e-10 * np.linalg.norm(rhs)
    assert systems._primer is None
