"""The sparse linear solvers: same answers from every back end, PARDISO's upper triangle, BLAS
threads."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import vares
from vares.solver import linear


def _saddle_point_matrix(seed: int = 0) -> sp.csr_matrix:
    """A symmetric indefinite matrix bordered by constraints: its last two diagonal entries are
    not stored at all (as in the coupled problem's KKT matrix)."""
    rng = np.random.default_rng(seed)
    n, m = 40, 2
    a = sp.random(n, n, density=0.1, random_state=rng)
    stiffness = a @ a.T + sp.identity(n) * 4.0
    constraints = sp.random(m, n, density=0.3, random_state=rng) + sp.eye(m, n)
    return sp.bmat([[stiffness, constraints.T], [constraints, None]], format="csr")


def test_upper_triangle_map_adds_missing_diagonal_entries():
    matrix = _saddle_point_matrix()
    matrix.sort_indices()
    assert matrix.diagonal()[-1] == 0.0 and matrix[-1, -1] == 0.0
    index, indptr, indices = linear._upper_triangle_map(matrix)
    data = np.append(matrix.data, 0.0)[index]
    upper = sp.csr_matrix((data, indices, indptr), shape=matrix.shape)
    np.testing.assert_array_equal(upper.toarray(), np.triu(matrix.toarray()))
    rows = np.repeat(np.arange(matrix.shape[0]), np.diff(indptr))
    assert np.count_nonzero(indices == rows) == matrix.shape[0]  # every diagonal entry stored
    assert all(
        np.all(np.diff(indices[indptr[i] : indptr[i + 1]]) > 0) for i in range(matrix.shape[0])
    )


@pytest.mark.parametrize("name", linear.available_solvers())
def test_every_solver_solves_a_bordered_indefinite_system(name):
    matrix = _saddle_point_matrix(seed=1)
    solver = linear.get_solver(name)
    rng = np.random.default_rng(2)
    for _ in range(2):  # the second factorisation reuses the symbolic analysis
        matrix = matrix.copy()
        matrix.data[:] *= rng.uniform(0.9, 1.1)
        matrix = (matrix + matrix.T) * 0.5  # keep it exactly symmetric
        matrix.sort_indices()
        rhs = rng.standard_normal(matrix.shape[0])
        solver.factorize(matrix.tocsr())
        x = solver.solve(rhs)
        assert np.linalg.norm(matrix @ x - rhs) <= 1e-10 * np.linalg.norm(rhs)


def test_every_solver_gives_the_same_pattern():
    mesh = vares.examples.hypar(size=10.0, rise=0.06, n=24)
    material = vares.materials.StVenantKirchhoff(1000.0, 0.3)
    results = {
        name: vares.solve(mesh, material, linear_solver=name) for name in linear.available_solvers()
    }
    reference = results["scipy-superlu"]
    assert reference.converged
    for name, result in results.items():
        assert result.converged, (name, result.reason)
        assert result.linear_solver == name
        assert result.energy == pytest.approx(reference.energy, rel=1e-12)
        np.testing.assert_allclose(
            result.material_coordinates, reference.material_coordinates, atol=1e-10
        )


def test_quiet_blas_limits_openblas_to_one_thread_and_restores_it():
    from threadpoolctl import ThreadpoolController

    def openblas_threads():
        return [
            c.num_threads
            for c in ThreadpoolController().select(internal_api="openblas").lib_controllers
        ]

    before = openblas_threads()
    if not before:
        pytest.skip("NumPy and SciPy are not linked to OpenBLAS here")
    with linear.quiet_blas():
        assert openblas_threads() == [1] * len(before)
    assert openblas_threads() == before
