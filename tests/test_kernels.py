"""Exact derivatives: element and global residual/tangent against complex-step differentiation."""

import numpy as np
import pytest
from conftest import FIBRES, LAWS

from vares.geometry.elements import ELEMENTS
from vares.materials import (
    Fibres,
    NeoHooke,
    StVenantKirchhoff,
)
from vares.mechanics import Assembler, Problem
from vares.mechanics.kernels import block_energy

PRESTRESS = np.array([[0.4, 0.1], [0.1, 0.25]])
H = 1e-30


def random_cell(cell_type, seed):
    """A curved 3D cell, its metric, and a distorted (non-inverted) pattern of it."""
    rng = np.random.default_rng(seed)
    ref = {"triangle": [[0, 0], [1, 0], [0, 1]], "quad": [[0, 0], [1, 0], [1, 1], [0, 1]]}
    ref = np.array(ref[cell_type], float)
    element = ELEMENTS[cell_type]
    points3d = np.column_stack(
        [1.2 * ref + 0.05 * rng.normal(size=ref.shape), 0.3 * rng.normal(size=len(ref))]
    )
    metric = element.metrics(points3d, np.arange(len(ref))[None])
    pattern = (ref + 0.08 * rng.normal(size=ref.shape))[None]
    return element, metric, pattern


@pytest.mark.parametrize("cell_type", ["triangle", "quad"])
@pytest.mark.parametrize("law", LAWS, ids=lambda m: type(m).__name__)
@pytest.mark.parametrize("prestress", [None, PRESTRESS], ids=["no-prestress", "prestress"])
def test_element_gradient_and_hessian_by_complex_step(cell_type, law, prestress):
    element, metric, pattern = random_cell(cell_type, seed=len(cell_type))
    fibres = FIBRES if law.needs_fibres else None
    exact = block_energy(element, pattern, metric, law, 0.8, fibres=fibres, prestress=prestress)
    nen = element.num_nodes
    gradient = np.zeros((nen, 2))
    hessian = np.zeros((nen, 2, nen, 2))
    for a in range(nen):
        for k in range(2):
            shifted = pattern.astype(complex)
            shifted[0, a, k] += 1j * H
            result = block_energy(
                element, shifted, metric, law, 0.8, fibres=fibres, prestress=prestress
            )
            gradient[a, k] = result.energy[0].imag / H
            hessian[:, :, a, k] = result.gradient[0].imag / H
    scale = np.abs(exact.gradient).max()
    np.testing.assert_allclose(exact.gradient[0], gradient, atol=1e-12 * scale)
    np.testing.assert_allclose(exact.hessian[0], hessian, atol=1e-12 * np.abs(hessian).max())
    h = exact.hessian[0].reshape(2 * nen, 2 * nen)
    np.testing.assert_allclose(h, h.T, atol=1e-13 * np.abs(h).max())


@pytest.mark.parametrize("cell_type", ["triangle", "quad"])
def test_gradient_is_the_eshelby_material_force(cell_type):
    """DESIGN.md eq. (2): ∂Π/∂X_a = t Σ_q w_q det J Σ J⁻ᵀ ∇N_a with Σ = Ψ̃ I − C S̃."""
    element, metric, pattern = random_cell(cell_type, seed=7)
    law, t = NeoHooke(E=4.0, nu=0.35), 0.6
    kernel = block_energy(element, pattern, metric, law, t, prestress=PRESTRESS)
    expected = np.zeros((element.num_nodes, 2))
    for q, w in enumerate(element.quadrature_weights):
        dN = element.shape_gradients[q]
        J = pattern[0].T @ dN
        K = np.linalg.inv(J)
        C = K.T @ metric[0, q] @ K
        response = law.response(C)
        E = 0.5 * (C - np.eye(2))
        psi = response.psi - np.sum(PRESTRESS * E)
        sigma = psi * np.eye(2) - C @ (response.stress - PRESTRESS)
        expected += t * w * np.linalg.det(J) * (sigma @ K.T @ dN.T).T
    np.testing.assert_allclose(kernel.gradient[0], expected, rtol=1e-12, atol=1e-14)


def test_global_residual_and_tangent_by_finite_differences(mixed_mesh):
    """Assembled over a mixed triangle/quad mesh with fixed dofs, against central differences."""
    problem = Problem(
        mixed_mesh,
        NeoHooke(E=5.0, nu=0.3),
        0.9,
        fibres=Fibres.from_angles(20.0),
        prestress=(0.4, 0.25, 0.1),
    )
    rng = np.random.default_rng(3)
    pattern = mixed_mesh.points[:, :2] * [1.05, 0.97] + 0.01 * rng.normal(size=(12, 2))
    free = np.ones(24, dtype=bool)
    free[[0, 1, 7]] = False
    assembler = Assembler(mixed_mesh, free)
    evaluation = problem.evaluate(pattern)
    gradient = assembler.vector(evaluation.gradients).ravel()
    matrix = assembler.matrix(evaluation.hessians).toarray()
    h = 1e-6
    fd_gradient = np.zeros(24)
    fd_matrix = np.zeros((24, 24))
    for dof in range(24):
        up, down = pattern.copy(), pattern.copy()
        up.ravel()[dof] += h
        down.ravel()[dof] -= h
        fd_gradient[dof] = (problem.energy(up) - problem.energy(down)) / (2 * h)
        g_up = assembler.vector(problem.evaluate(up).gradients).ravel()
        g_down = assembler.vector(problem.evaluate(down).gradients).ravel()
        fd_matrix[:, dof] = (g_up - g_down) / (2 * h)
    np.testing.assert_allclose(gradient, fd_gradient, atol=1e-8)
    np.testing.assert_allclose(matrix, fd_matrix[np.ix_(free, free)], atol=1e-7)
    assert np.abs(gradient).max() > 1e-3  # the check is not vacuous


def test_translation_invariance_of_the_residual(mixed_mesh):
    """The forces of any pattern sum to zero and have zero moment (rigid-mode invariance)."""
    problem = Problem(mixed_mesh, StVenantKirchhoff(E=5.0, nu=0.3))
    pattern = mixed_mesh.points[:, :2] * [1.1, 0.9]
    evaluation = problem.evaluate(pattern, order=1)
    force = Assembler(mixed_mesh, np.ones(24, bool)).vector(evaluation.gradients)
    assert np.abs(force).max() > 1e-2
    np.testing.assert_allclose(force.sum(axis=0), 0.0, atol=1e-13)
    moment = np.sum(pattern[:, 0] * force[:, 1] - pattern[:, 1] * force[:, 0])
    assert abs(moment) < 1e-13


def test_principal_values_keep_their_digits_where_they_are_close():
    """Principal stresses 1 and 1 + 1e-10 of a rotated S C: their difference to 1e-5 (the trace
    and determinant formula lost it to round-off), and an unsymmetric S C with a real spectrum."""
    from vares.mechanics.fields import principal_values

    angle = 0.3
    r = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    close = r @ np.diag([1.0, 1.0 + 1e-10]) @ r.T
    larger, smaller = principal_values(close)
    assert larger - smaller == pytest.approx(1e-10, rel=1e-5)
    S, C = np.array([[2.0, 0.3], [0.3, 1.0]]), np.array([[1.2, 0.1], [0.1, 0.9]])
    expected = np.sort(np.linalg.eigvals(S @ C).real)[::-1]
    np.testing.assert_allclose(principal_values(S @ C), expected, rtol=1e-14)
