"""Kernels compiled at their first call, and their numpy form for small meshes (vares/_jit.py):
both paths give the same numbers, and a small job loads no numba."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import FIBRES, LAWS

from vares import _jit
from vares.geometry.elements import ELEMENTS
from vares.io.raster import rasterise
from vares.materials import Hyperelastic
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


class _SquaredFibreLaw(Hyperelastic):
    """A law of every kind of invariant derivative: constant (I1), per point (I3, I5, I7),
    with constant second derivatives (I3, I5, I7), coupled (I1 with I5)."""

    invariants = ("I1", "I3", "I5", "I7")
    stiffness_scale = 1.0

    def psi_invariants(self, inv):
        i1, i3, i5, i7 = np.moveaxis(inv, -1, 0)
        return 0.5 * (i1 - 2) ** 2 - np.log(i3) + 0.3 * i5 * i1 + 0.2 * i7**2

    def dpsi_invariants(self, inv):
        i1, i3, i5, i7 = np.moveaxis(inv, -1, 0)
        return np.stack([i1 - 2 + 0.3 * i5, -1 / i3, 0.3 * i1, 0.4 * i7], axis=-1)

    def d2psi_invariants(self, inv):
        out = np.zeros((*inv.shape, 4), dtype=inv.dtype)
        out[..., 0, 0], out[..., 1, 1] = 1.0, 1 / inv[..., 1] ** 2
        out[..., 0, 2] = out[..., 2, 0] = 0.3
        out[..., 3, 3] = 0.4
        return out


@pytest.mark.parametrize(
    "law", [*LAWS, _SquaredFibreLaw()], ids=lambda m: type(m).__name__.strip("_")
)
def test_the_material_response_is_the_same_compiled_and_as_numpy(law):
    """``S`` and ``ℂ`` from the invariants' derivatives: the compiled sums are the numpy
    form's, in the same order, to the bit (cells on the leading axis, quadrature points next)."""
    rng = np.random.default_rng(4)
    A = np.eye(2) + 0.1 * rng.normal(size=(2500, 3, 2, 2))
    C = np.swapaxes(A, -1, -2) @ A
    fibres = FIBRES if law.needs_fibres else None
    for tangent in (True, False):
        compiled, numpy = both_paths(lambda t=tangent: law.response(C, fibres, tangent=t))
        assert compiled.stress.shape == C.shape and np.abs(compiled.stress).max() > 0
        np.testing.assert_array_equal(compiled.psi, numpy.psi)
        np.testing.assert_array_equal(compiled.stress, numpy.stress)
        if tangent:
            assert compiled.tangent.shape == (*C.shape, 2, 2)
            np.testing.assert_array_equal(compiled.tangent, numpy.tangent)
        else:
            assert compiled.tangent is None and numpy.tangent is None


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


def test_parallel_kernels_give_the_same_numbers_on_any_number_of_threads():
    """The element kernels share their cells among the cores (``prange``): each cell's results
    are written by one thread, so one thread and all give the same bits, in the pattern's
    kernels (energy, gradient, Hessian, projection) and the erection's."""
    import numba

    from vares.mechanics import forward

    element, metric, pattern = cells("triangle", 3000)
    gradients = np.random.default_rng(1).normal(size=(3000, 1, 3, 2))
    weights = np.abs(np.random.default_rng(2).normal(size=(3000, 1)))
    nodes = np.random.default_rng(3).normal(size=(3000, 3, 3))
    law = LAWS[0]

    def run():
        with _jit.sized_for(True):
            block = block_energy(element, pattern, metric, law, 0.8)
            projected = projected_hessian(element, block.jacobian_hessian, 0.8)
        F = forward.deformation_gradients(nodes, gradients)
        hessian = forward._nodal_hessian(np.ones((3000, 1, 6, 6)), gradients, weights)
        return [block.energy, block.gradient, block.hessian, projected, F, hessian]

    default = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        single = run()
    finally:
        numba.set_num_threads(default)
    for a, b in zip(single, run(), strict=True):
        assert np.array_equal(a, b) and np.abs(a).max() > 0


def test_parallel_kernels_called_from_several_threads_at_once():
    """A script or a plug-in may solve from several Python threads. Numba's own thread pool
    (``workqueue``, where neither TBB nor OpenMP is installed) ends the process when two threads
    launch parallel kernels at once; the kernels take turns, and every thread gets its result."""
    script = """
import threading, sys
sys.path.insert(0, {tests!r})
from test_jit import cells
from conftest import LAWS
from vares import _jit
from vares.mechanics.kernels import block_energy
element, metric, pattern = cells("triangle", 4000)
out = []
def work():
    with _jit.sized_for(True):
        for _ in range(20):
            block = block_energy(element, pattern, metric, LAWS[0], 0.8)
    out.append(float(block.energy.sum()))
threads = [threading.Thread(target=work) for _ in range(4)]
[t.start() for t in threads]
[t.join() for t in threads]
import numba
print(numba.threading_layer(), len(out), len(set(out)))
"""
    tests = str(Path(__file__).parent)
    env = {**os.environ, "NUMBA_THREADING_LAYER": "workqueue"}
    done = subprocess.run(
        [sys.executable, "-c", script.format(tests=tests)],
        capture_output=True, text=True, env=env, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["workqueue", "4", "1"]
