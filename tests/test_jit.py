"""Kernels compiled at their first call, and their numpy form for small meshes (vares/_jit.py):
both paths give the same numbers, and a small job loads no numba."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from conftest import FIBRES, LAWS

from vares import _jit
from vares.geometry.elements import ELEMENTS
from vares.io.raster import rasterise
from vares.mechanics import Assembler
from vares.mechanics.kernels import block_energy, project_psd, projected_hessian

REFERENCE = {"triangle": [[0, 0], [1, 0], [0, 1]], "quad": [[0, 0], [1, 0], [1, 1], [0, 1]]}


def cells(cell_type: str, m: int, dtype=float):
    """``m`` curved 3D cells, their metrics and distorted (not inverted) patterns."""
    rng = np.random.default_rng(m)
    ref = np.array(REFERENCE[cell_type], float)
    element = ELEMENTS[cell_type]
    points = np.concatenate(
        [
            np.column_stack(
                [1.2 * ref + 0.05 * rng.normal(size=ref.shape), rng.normal(size=len(ref))]
            )
            for _ in range(m)
        ]
    )
    metric = element.metrics(points, np.arange(m * len(ref)).reshape(m, -1))
    pattern = np.array([ref + 0.08 * rng.normal(size=ref.shape) for _ in range(m)], dtype=dtype)
    return element, metric, pattern


def both_paths(function):
    """``function()`` run compiled and as numpy."""
    results = []
    for path in (True, False):
        with _jit.sized_for(path):
            results.append(function())
    return results


@pytest.mark.parametrize("cell_type", ["triangle", "quad"])
@pytest.mark.parametrize("law", LAWS, ids=lambda m: type(m).__name__)
def test_element_kernels_are_the_same_compiled_and_as_numpy(cell_type, law):
    element, metric, pattern = cells(cell_type, 7)
    fibres = FIBRES if law.needs_fibres else None
    prestress = np.array([[0.4, 0.1], [0.1, 0.25]])
    compiled, numpy = both_paths(
        lambda: block_energy(element, pattern, metric, law, 0.8, fibres=fibres, prestress=prestress)
    )
    for name in ("energy", "gradient", "hessian", "jacobian_hessian"):
        a, b = getattr(compiled, name), getattr(numpy, name)
        assert a.shape == b.shape and np.abs(a).max() > 0, name
        np.testing.assert_allclose(b, a, rtol=1e-13, atol=1e-13 * np.abs(a).max(), err_msg=name)
    projected = both_paths(lambda: projected_hessian(element, compiled.jacobian_hessian, 0.8))
    scale = np.abs(projected[0]).max()
    np.testing.assert_allclose(projected[1], projected[0], rtol=1e-12, atol=1e-12 * scale)


def test_the_positive_part_of_blocks_is_the_same_compiled_and_as_numpy():
    rng = np.random.default_rng(5)
    blocks = rng.normal(size=(30, 2, 4, 4))
    blocks[:10] += 20 * np.eye(4)  # diagonally dominant: left as they are
    compiled, numpy = both_paths(lambda: (lambda b: (project_psd(b), b)[1])(blocks.copy()))
    np.testing.assert_array_equal(numpy[:10], blocks[:10])
    np.testing.assert_allclose(numpy, compiled, rtol=1e-12, atol=1e-12)
    assert np.linalg.eigvalsh(numpy[10:]).min() > -1e-12
    assert np.linalg.eigvalsh(blocks[10:]).min() < -1  # there was something to take off


def test_the_numpy_path_keeps_complex_steps():
    """Complex-step differentiation runs through the numpy form as through the compiled one."""
    element, metric, pattern = cells("quad", 3, dtype=complex)
    pattern[1, 2, 0] += 1e-30j
    law = LAWS[1]
    compiled, numpy = both_paths(lambda: block_energy(element, pattern, metric, law, 1.0))
    assert np.iscomplexobj(numpy.gradient) and np.abs(numpy.energy.imag).max() > 0
    np.testing.assert_allclose(numpy.energy, compiled.energy, rtol=1e-14)
    np.testing.assert_allclose(numpy.hessian, compiled.hessian, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("d", [2, 3])
def test_the_assemblers_map_is_the_same_compiled_and_as_numpy(mixed_mesh, d):
    """The dof pattern and every element entry's slot, with held dofs in first, inner and last
    rows, for pattern (2) and erected (3) unknowns."""
    free = np.ones(d * mixed_mesh.num_points, bool)
    free[[0, 1, 7, 3 * d + 1, d * mixed_mesh.num_points - 1]] = False
    compiled, numpy = both_paths(lambda: Assembler(mixed_mesh, free, d))
    assert compiled.nnz == numpy.nnz
    for name in ("_indices", "_indptr", "_position", "_all_dofs"):
        np.testing.assert_array_equal(getattr(compiled, name), getattr(numpy, name))


def test_assembly_is_the_same_compiled_and_as_numpy(mixed_mesh):
    free = np.ones(2 * mixed_mesh.num_points, bool)
    free[[0, 1, 7]] = False
    rng = np.random.default_rng(3)
    hessians = [
        rng.normal(size=(len(c), c.shape[1], 2, c.shape[1], 2)) for c in mixed_mesh.cells.values()
    ]
    compiled, numpy = both_paths(lambda: Assembler(mixed_mesh, free).matrix(hessians))
    assert (compiled != numpy).nnz == 0
    np.testing.assert_array_equal(compiled.indices, numpy.indices)
    np.testing.assert_allclose(numpy.toarray(), compiled.toarray(), rtol=1e-15, atol=1e-15)
    jacobians = both_paths(
        lambda: ELEMENTS["quad"].jacobians(mixed_mesh.points, mixed_mesh.cells["quad"])
    )
    np.testing.assert_allclose(jacobians[1], jacobians[0], rtol=1e-15, atol=1e-15)


@pytest.mark.parametrize("seed", range(6))
def test_flat_rasterising_is_the_same_compiled_and_as_numpy(seed):
    """The runs of pixels along rows give every pixel the cell the compiled loop gives it,
    also where pixel centres fall on edges (whole-number corners) and for slivers."""
    rng = np.random.default_rng(seed)
    n = 40
    points = rng.uniform(-3, 43, size=(n, 2))
    if seed % 2 == 0:
        points = np.round(points)
    triangles = rng.integers(0, n, size=(150, 3))
    triangles[:5, 2] = triangles[:5, 1]  # degenerate ones
    images = both_paths(
        lambda: rasterise({"triangle": triangles}, points, grid=(0.0, 0.0, 1.0, 40, 37)).index
    )
    assert (images[0] >= 0).sum() > 100
    np.testing.assert_array_equal(images[1], images[0])


def test_a_small_job_loads_no_numba(tmp_path):
    """A solve of a small mesh runs without importing numba: nothing to compile on the first
    run after an install, nothing to load later."""
    code = (
        "import sys\n"
        "from vares import examples, solve, materials\n"
        "result = solve(examples.hypar(n=8), materials.NeoHooke(E=1000.0, nu=0.3))\n"
        "assert result.converged\n"
        "print('numba' in sys.modules)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["False"]


def test_which_path_a_call_takes():
    """By the call's size alone (the same numbers in every process), unless told."""
    assert not _jit.compiled(_jit.COMPILED_FROM - 1)
    assert _jit.compiled(_jit.COMPILED_FROM)
    with _jit.sized_for(10**6):
        assert _jit.compiled(1)
    with _jit.sized_for(False):
        assert not _jit.compiled(10**6)
