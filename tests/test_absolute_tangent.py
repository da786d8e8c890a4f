"""The projected tangent with the absolute values of the exact one's eigenvalues, which globalised
Newton takes after a shortened step on isotropic problems."""

import sys

import numpy as np
import pytest

import vares
from vares import examples
from vares.geometry.elements import ELEMENTS
from vares.mechanics.kernels import nodal_hessian
from vares.mechanics.problem import Problem
from vares.solver.newton import absolute_hessians

NEO_HOOKE = vares.materials.NeoHooke(1000.0, 0.3)


def test_absolute_hessians_have_the_absolute_eigenvalues_point_by_point():
    mesh = examples.hypar(size=10.0, rise=0.06, n=8)
    problem = Problem(mesh, NEO_HOOKE, 1.0)
    squeezed = mesh.points[:, :2] * np.array([1.0, 0.4])  # compressed across: indefinite blocks
    evaluation = problem.evaluate(squeezed, order=2)
    (point_wise,) = evaluation.jacobian_hessians
    values, vectors = np.linalg.eigh(0.5 * (point_wise + np.swapaxes(point_wise, -1, -2)))
    assert (values < -1e-9 * np.abs(values).max()).any()  # the case is one that matters
    mirrored = (vectors * np.abs(values)[..., None, :]) @ np.swapaxes(vectors, -1, -2)
    element = ELEMENTS["triangle"]
    expected = nodal_hessian(
        np.ascontiguousarray(mirrored),
        np.ascontiguousarray(element.shape_gradients),
        element.quadrature_weights,
    )
    (found,) = absolute_hessians(problem.projected_hessians(evaluation), evaluation.hessians)
    np.testing.assert_allclose(found, expected, atol=1e-9 * np.abs(expected).max())


def test_a_rough_start_reaches_the_same_optimum_with_absolute_tangents(monkeypatch):
    """From Tutte's embedding of a rough scan the first steps are shortened and take the
    absolute tangent; the optimum is the one the clamped tangents reach (the iterations are
    not always fewer: 9 here against 8; on libigl's camel head 13 against 16)."""
    newton = sys.modules["vares.solver.newton"]
    mesh = examples.scan_like(triangles=3000, noise=0.005)
    start = vares.geometry.flatten.tutte(mesh)
    calls = []

    def counted(projected, exact):
        calls.append(len(projected))
        return absolute_hessians(projected, exact)

    monkeypatch.setattr(newton, "absolute_hessians", counted)
    result = vares.solve(mesh, NEO_HOOKE, initial_guess=start)
    assert calls  # the mechanism was used
    monkeypatch.setattr(newton, "absolute_hessians", lambda projected, exact: projected)
    clamped = vares.solve(mesh, NEO_HOOKE, initial_guess=start)
    assert result.converged and clamped.converged
    assert result.energy == pytest.approx(clamped.energy, rel=1e-12)
    size = np.ptp(result.material_coordinates, axis=0).max()
    np.testing.assert_allclose(
        result.material_coordinates, clamped.material_coordinates, atol=1e-8 * size
    )
