"""The sparse linear solvers: same answers from every back end, PARDISO's upper triangle, BLAS
threads."""

from __future__ import annotations

import gc
import itertools

import numpy as np
import pytest
import scipy.sparse as sp

import vares
from vares import examples
from vares.materials import OrthotropicStVenantKirchhoff
from vares.solver import linear, pardiso
from vares.solver.linear import SingularMatrixError, available_solvers, get_solver
from vares.structures import matching

ORTHO = OrthotropicStVenantKirchhoff(800.0, 640.0, 40.0, 0.4)


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
    index, indptr, indices = pardiso._upper_triangle_map(matrix)
    data = np.append(matrix.data, 0.0)[index]
    upper = sp.csr_matrix((data, indices, indptr), shape=matrix.shape)
    np.testing.assert_array_equal(upper.toarray(), np.triu(matrix.toarray()))
    rows = np.repeat(np.arange(matrix.shape[0]), np.diff(indptr))
    assert np.count_nonzero(indices == rows) == matrix.shape[0]  # every diagonal entry stored
    assert all(
        np.all(np.diff(indices[indptr[i] : indptr[i + 1]]) > 0) for i in range(matrix.shape[0])
    )


def test_upper_triangle_map_of_a_matrix_with_its_whole_diagonal():
    """Every diagonal entry stored: the map keeps the upper entries in their CSR order."""
    matrix = _saddle_point_matrix() + sp.identity(_saddle_point_matrix().shape[0]) * 1e-3
    matrix = sp.csr_matrix(matrix)
    matrix.sort_indices()
    index, indptr, indices = pardiso._upper_triangle_map(matrix)
    assert np.all(index >= 0) and np.all(np.diff(index) > 0)
    upper = sp.csr_matrix((matrix.data[index], indices, indptr), shape=matrix.shape)
    np.testing.assert_array_equal(upper.toarray(), np.triu(matrix.toarray()))
    # the same matrix with its columns out of order in every row: the map sorts them
    shuffled = sp.csr_matrix(
        (matrix.data.copy(), matrix.indices.copy(), matrix.indptr.copy()), shape=matrix.shape
    )
    for a, b in zip(shuffled.indptr[:-1], shuffled.indptr[1:], strict=True):
        shuffled.indices[a:b], shuffled.data[a:b] = (
            shuffled.indices[a:b][::-1],
            shuffled.data[a:b][::-1],
        )
    shuffled.has_sorted_indices = False
    index, indptr, indices = pardiso._upper_triangle_map(shuffled)
    assert all(np.all(np.diff(indices[a:b]) > 0) for a, b in itertools.pairwise(indptr))
    upper = sp.csr_matrix((shuffled.data[index], indices, indptr), shape=matrix.shape)
    np.testing.assert_array_equal(upper.toarray(), np.triu(matrix.toarray()))


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


def test_quiet_blas_limits_openblas_to_one_thread_and_restores_it(monkeypatch):
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
        with linear.quiet_blas():  # nested: the outer context gives the threads back
            assert openblas_threads() == [1] * len(before)
        assert openblas_threads() == [1] * len(before)
    assert openblas_threads() == before
    # the erection and the structure solve run quietly too (their Newton iterations' callbacks)
    seen = []
    mesh = examples.cylinder160(n_around=8, n_along=4)
    result = vares.solve(mesh, vares.materials.NeoHooke(E=1000.0, nu=0.3), prestress=(1.0, 1.0))
    vares.erect(result, callback=lambda record: seen.append(openblas_threads()))
    assert seen and all(threads == [1] * len(before) for threads in seen)
    assert openblas_threads() == before
    # the seam matching's own Newton iterations, between the panels' solves
    seen.clear()
    original = matching.newton
    monkeypatch.setattr(
        matching, "newton", lambda *a, **k: (seen.append(openblas_threads()), original(*a, **k))[1]
    )
    apart = (mesh.points[mesh.cells["triangle"]].mean(axis=1)[:, 0] > 0.3).astype(int)
    vares.solve_structure(
        vares.split_panels(mesh, apart),
        vares.materials.NeoHooke(E=1000.0, nu=0.3),
        prestress=(1.0, 0.5),
        match_seams=True,
    )
    assert seen and all(threads == [1] * len(before) for threads in seen)
    assert openblas_threads() == before


def test_the_run_says_which_solver_it_used_and_why():
    from vares.io.summary import summary

    mesh = vares.examples.hypar(n=6)
    material = vares.materials.NeoHooke(1000.0, 0.3)
    chosen = summary(vares.solve(mesh, material))
    fastest = linear.available_solvers()[0]
    assert chosen["linear_solver"] == fastest
    assert chosen["linear_solver_choice"].startswith(f"{fastest}, the fastest installed")
    asked = summary(vares.solve(mesh, material, linear_solver="scipy-superlu"))
    assert asked["linear_solver_choice"] == "scipy-superlu, as asked"
    # a small mesh's kernels run as numpy: nothing is loaded, nothing is timed apart
    assert asked["warm_up_seconds"] == 0.0 and asked["elapsed_seconds"] > 0.0


def test_loading_the_compiled_kernels_is_timed_apart_once_per_process_and_kind():
    from vares._jit import COMPILED_FROM
    from vares.solver import api

    small = vares.examples.hypar(n=6)
    large = vares.examples.hypar(n=32)
    assert small.num_cells < COMPILED_FROM <= large.num_cells
    key = ("triangle", vares.materials.StVenantKirchhoff, "scipy-superlu")
    api._WARM.discard(key)
    svk = vares.materials.StVenantKirchhoff(1000.0, 0.3)
    assert api._load_kernels(small, svk, "scipy-superlu") == 0.0
    assert key not in api._WARM
    assert api._load_kernels(large, svk, "scipy-superlu") > 0.0
    assert key in api._WARM
    assert api._load_kernels(large, svk, "scipy-superlu") == 0.0  # once per process


@pytest.mark.parametrize("name", available_solvers())
def test_linear_solvers_solve_definite_and_bordered_systems(name):
    rng = np.random.default_rng(4)
    n = 60
    m = sp.random(n, n, density=0.08, random_state=4)
    spd = (m @ m.T + sp.identity(n)).tocsr()
    solver = get_solver(name)
    for matrix in (spd, (spd * 2.0).tocsr()):
        solver.factorize(matrix)
        rhs = rng.normal(size=n)
        np.testing.assert_allclose(matrix @ solver.solve(rhs), rhs, atol=1e-10)
    column = sp.csr_matrix(rng.normal(size=(n, 1)))
    bordered = sp.bmat([[spd, column], [column.T, None]], format="csr")
    solver.factorize(bordered)
    rhs = rng.normal(size=n + 1)
    np.testing.assert_allclose(bordered @ solver.solve(rhs), rhs, atol=1e-9)


@pytest.mark.parametrize("name", available_solvers())
def test_every_linear_solver_gives_the_same_pattern(name):
    mesh = examples.hypar(n=10)
    reference = vares.solve(mesh, ORTHO, warp_angle=20.0, linear_solver="scipy-superlu")
    result = vares.solve(mesh, ORTHO, warp_angle=20.0, linear_solver=name)
    assert result.linear_solver == name and result.converged
    assert result.energy == pytest.approx(reference.energy, rel=1e-10)
    np.testing.assert_allclose(
        result.material_coordinates, reference.material_coordinates, atol=1e-9
    )


@pytest.mark.parametrize("name", available_solvers())
def test_a_new_sparsity_pattern_of_the_same_size_is_analysed_again(name):
    """Two definite matrices of one size and one number of entries, their off-diagonal pairs in
    different places: a solver keeping its analysis per pattern solves both exactly."""
    rhs = np.arange(1.0, 7.0)
    solver = get_solver(name)
    for pairs in (((0, 1), (2, 3)), ((0, 5), (1, 4))):
        dense = 4.0 * np.eye(6)
        for i, j in pairs:
            dense[i, j] = dense[j, i] = 1.0
        matrix = sp.csr_matrix(dense)
        solver.factorize(matrix)
        np.testing.assert_allclose(matrix @ solver.solve(rhs), rhs, rtol=0, atol=1e-12)


def test_singular_matrices_are_reported():
    singular = sp.csr_matrix(np.array([[1.0, 1.0], [1.0, 1.0]]))
    solver = get_solver("scipy-superlu")
    with pytest.raises(SingularMatrixError):
        solver.factorize(singular)
        solver.solve(np.ones(2))


def test_solver_choice_errors(monkeypatch):
    with pytest.raises(ValueError, match="unknown linear solver"):
        get_solver("gauss")
    monkeypatch.setattr(linear, "_importable", lambda module: False)
    assert available_solvers() == ["scipy-superlu"]
    with pytest.raises(ValueError, match="not installed"):
        get_solver("pardiso")
    assert get_solver().name == "scipy-superlu"


def test_superlu_frees_its_factors_before_making_the_next(monkeypatch):
    """Two factorisations alive at once were the peak of a 1M-triangle solve (4.7 GiB, 3.4
    without): the solver must hold no factors when the next splu starts."""
    import scipy.sparse.linalg as spla

    n = 50
    matrix = sp.diags([-np.ones(n - 1), 4 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]).tocsr()
    solver = linear.SuperLUSolver()
    solver.factorize(matrix)
    held_at_next = []
    splu = spla.splu

    def watching(*args, **kwargs):
        held_at_next.append(solver._lu is not None)
        return splu(*args, **kwargs)

    monkeypatch.setattr(linear.spla, "splu", watching)
    solver.factorize(2.0 * matrix)
    assert held_at_next == [False]
    rhs = np.ones(n)
    np.testing.assert_allclose(2.0 * matrix @ solver.solve(rhs), rhs, rtol=1e-12)


@pytest.mark.parametrize("name", available_solvers())
def test_two_solvers_factorise_and_solve_in_turn(name):
    """A solver keeps its own factors whatever other solvers do in between (PARDISO's solvers
    share one handle: a solver whose factors were replaced factorises its matrix again)."""
    rng = np.random.default_rng(1)
    matrices = []
    for size in (30, 40):
        a = sp.random(size, size, density=0.2, random_state=rng)
        matrices.append((a @ a.T + size * sp.identity(size)).tocsr())
    solvers = [get_solver(name) for _ in matrices]
    for solver, matrix in zip(solvers, matrices, strict=True):
        solver.factorize(matrix)
    for _ in range(2):
        for solver, matrix in zip(solvers, matrices, strict=True):
            rhs = rng.normal(size=matrix.shape[0])
            np.testing.assert_allclose(matrix @ solver.solve(rhs), rhs, atol=1e-10)


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="PARDISO is not installed")
def test_pardiso_maps_a_sparsity_pattern_to_its_upper_triangle_once(monkeypatch):
    """New solvers of the thread factorising matrices of one pattern (an erection's, then an
    optimiser's states) reuse the upper-triangle map of the last pattern; another pattern is
    mapped afresh, and every solve is right."""
    calls = []
    original = pardiso._upper_triangle_map
    monkeypatch.setattr(
        pardiso, "_upper_triangle_map", lambda matrix: (calls.append(1), original(matrix))[1]
    )
    monkeypatch.setattr(pardiso._PARDISO_STATE, "upper", None)
    rng = np.random.default_rng(3)
    a = sp.random(40, 40, density=0.2, random_state=rng)
    first = (a @ a.T + 40 * sp.identity(40)).tocsr()
    same = first.copy()
    same.data = same.data * 2.0
    b = sp.random(40, 40, density=0.3, random_state=rng)
    other = (b @ b.T + 40 * sp.identity(40)).tocsr()
    for matrix, mapped in ((first, 1), (same, 1), (other, 2)):
        solver = get_solver("pardiso")
        solver.factorize(matrix)
        rhs = rng.normal(size=40)
        np.testing.assert_allclose(matrix @ solver.solve(rhs), rhs, atol=1e-10)
        assert len(calls) == mapped


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="PARDISO is not installed")
def test_a_pardiso_solver_with_its_own_factors_keeps_them_while_others_factorise(monkeypatch):
    """``own_factors``: a handle of its own, so solving between another solver's factorisations
    does not factorise again (the shared handle's solvers would); its memory is given back."""
    rng = np.random.default_rng(2)
    matrices = []
    for size in (30, 40):
        a = sp.random(size, size, density=0.2, random_state=rng)
        matrices.append((a @ a.T + size * sp.identity(size)).tocsr())
    numeric = []
    original = linear.PardisoSolver._numeric
    monkeypatch.setattr(
        linear.PardisoSolver, "_numeric", lambda self: (numeric.append(self), original(self))
    )
    own, shared = get_solver("pardiso", own_factors=True), get_solver("pardiso")
    assert own._solver is not shared._solver
    own.factorize(matrices[0])
    for _ in range(3):
        shared.factorize(matrices[1])
        rhs = rng.normal(size=30)
        np.testing.assert_allclose(matrices[0] @ own.solve(rhs), rhs, atol=1e-10)
    assert numeric.count(own) == 1 and numeric.count(shared) == 3
    release = own._state.release  # the handle's memory given back with the solver
    assert release.alive
    numeric.clear()
    del own
    gc.collect()
    assert not release.alive


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="PARDISO is not installed")
def test_a_family_of_pardiso_solvers_shares_one_analysis_apart_from_other_solvers(monkeypatch):
    """``solver_family``: the states an optimiser linearises one after another share one handle
    of their own, ordered by nested dissection (``many_solves``): the pattern is analysed once
    for the family, a thread solver factorising between them disturbs neither the family's
    analysis nor its factors, each member factorises its own matrix again where another member
    has since, and every solve is right."""
    rng = np.random.default_rng(5)
    base = sp.random(60, 60, density=0.1, random_state=rng)
    base = (base + base.T + 60 * sp.identity(60)).tocsr()
    matrices = [base + k * sp.diags(rng.uniform(1, 2, 60)) for k in range(3)]
    other = (base @ base.T + sp.identity(60)).tocsr()  # another pattern, the thread's handle
    phases = []
    original = linear.PardisoSolver._phase
    monkeypatch.setattr(
        linear.PardisoSolver,
        "_phase",
        lambda self, phase, rhs: (phases.append((self, phase)), original(self, phase, rhs))[1],
    )
    family = linear.solver_family("pardiso", many_solves=True)
    members = [family() for _ in matrices]
    thread = get_solver("pardiso")
    for member, matrix in zip(members, matrices, strict=True):
        member.factorize(matrix)
        thread.factorize(other)
        assert tuple(member._solver.iparm[[1, 23]]) == (2, 1)
        assert tuple(thread._solver.iparm[[1, 23]]) == (0, 0)
    assert members[0]._solver is members[2]._solver and members[0]._solver is not thread._solver
    analyses = [s for s, phase in phases if phase == 11]
    assert sum(s in members for s in analyses) == 1  # one analysis for the whole family
    for index in (2, 2, 0):  # the last member holds the family's factors; the first not
        rhs = rng.normal(size=60)
        np.testing.assert_allclose(matrices[index] @ members[index].solve(rhs), rhs, atol=1e-10)
    numeric = [s for s, phase in phases if phase == 22]
    assert numeric.count(members[2]) == 1 and numeric.count(members[0]) == 2
    # the default ordering and nested dissection on one handle: each analyses its own
    default, nested = get_solver("pardiso"), get_solver("pardiso", many_solves=True)
    for solver in (default, nested, default):
        solver.factorize(matrices[0])
        rhs = rng.normal(size=60)
        np.testing.assert_allclose(matrices[0] @ solver.solve(rhs), rhs, atol=1e-10)
    assert [s for s, phase in phases if phase == 11][-3:] == [default, nested, default]
    release = members[0]._state.release  # the family's handle given back with its last solver
    assert release.alive
    del family, members, member, analyses, numeric
    phases.clear()
    gc.collect()
    assert not release.alive


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="PARDISO is not installed")
def test_factors_for_many_solves_give_the_same_bits_at_every_factorisation():
    """An erection tangent (the isotropic hypar's, 2,187 unknowns) factorised eight times for
    many solves (nested dissection, two-level factorisation) solves to the same bits each time,
    as the default factors do, and to the same solution as they do to round-off. (With nested
    dissection and PARDISO's classic factorisation two different results came out of 4–8
    factorisations, and an optimisation's steps differed from run to run.)"""
    mesh = examples.hypar(size=10.0, rise=0.06, n=28)
    law = vares.materials.StVenantKirchhoff(E=600.0, nu=0.3)
    erected = vares.erect(vares.solve(mesh, law, prestress=2.0, linear_solver="pardiso"))
    hessians = erected.problem.evaluate(erected.erected_points, order=2).hessians
    K = erected.context.assembler.matrix(hessians).tocsr()
    rhs = np.random.default_rng(0).normal(size=K.shape[0])
    solutions = {}
    for many in (True, False):
        runs = []
        for _ in range(8):
            solver = get_solver("pardiso", own_factors=True, many_solves=many)
            solver.factorize(K)
            runs.append(solver.solve(rhs))
        assert all(np.array_equal(runs[0], x) for x in runs[1:]), many
        solutions[many] = runs[0]
    np.testing.assert_allclose(K @ solutions[True], rhs, atol=1e-9 * np.abs(rhs).max())
    scale = np.abs(solutions[False]).max()
    np.testing.assert_allclose(solutions[True], solutions[False], rtol=0, atol=1e-11 * scale)


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="PARDISO is not installed")
def test_pardiso_solves_in_two_threads_at_once_as_each_alone():
    """Each thread has its own PARDISO handle (analysis and factors): two solves of different
    meshes running at once in two threads give exactly the patterns each gives alone (with one
    handle shared by the process, they overwrote each other's factors, or crashed)."""
    import threading

    meshes = [examples.hypar(n=n) for n in (20, 23)]
    material = vares.materials.StVenantKirchhoff(1000.0, 0.3)
    alone = [vares.solve(m, material, linear_solver="pardiso").material_coordinates for m in meshes]
    together: list[list[np.ndarray]] = [[], []]

    def work(i: int) -> None:
        for _ in range(3):
            result = vares.solve(meshes[i], material, linear_solver="pardiso")
            together[i].append(result.material_coordinates)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for i in range(2):
        assert len(together[i]) == 3
        for coordinates in together[i]:
            np.testing.assert_array_equal(coordinates, alone[i])


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="PARDISO is not installed")
def test_pardiso_lu_solves_unsymmetric_systems_and_falls_back_where_it_is_inaccurate(monkeypatch):
    """The unsymmetric factoriser: PARDISO's LU on a diagonally dominant unsymmetric matrix
    (as Tutte's mean-value Laplacian) to round-off, two right-hand sides at once; a solve it
    gets wrong is redone by SuperLU with partial pivoting; its handle's memory is given back."""
    rng = np.random.default_rng(3)
    n = 60
    off = sp.random(n, n, density=0.1, random_state=rng, format="csr")
    matrix = (sp.diags(np.asarray(abs(off).sum(axis=1)).ravel() + 1.0) - off).tocsr()
    assert abs(matrix - matrix.T).max() > 0.1  # really unsymmetric
    rhs = rng.normal(size=(n, 2))
    factorize = linear.unsymmetric_factorizer("pardiso")
    np.testing.assert_allclose(matrix @ factorize(matrix)(rhs), rhs, atol=1e-12)
    assert linear.unsymmetric_factorizer("scipy-superlu") is None  # the caller keeps SuperLU
    lu = linear.PardisoLU(matrix)
    release = lu._release
    del lu
    gc.collect()
    assert not release.alive
    # a handle whose solve is off: the check finds it and SuperLU answers instead
    lu = linear.PardisoLU(matrix)
    monkeypatch.setattr(lu._handle, "solve", lambda a, b: b * 0.5)
    np.testing.assert_allclose(matrix @ lu.solve(rhs), rhs, atol=1e-12)
    assert lu._fallback is not None and not lu._release.alive
    np.testing.assert_allclose(matrix @ lu.solve(rhs[:, 0]), rhs[:, 0], atol=1e-12)


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="PARDISO is not installed")
def test_tutte_by_pardiso_lu_is_tutte_by_superlu(monkeypatch):
    """The solve's Tutte start is factorised by PARDISO's LU where the solve runs PARDISO, by
    SuperLU where it runs SuperLU, and it is the same embedding either way."""
    import warnings

    from vares.geometry import flatten

    mesh = examples.hypar(size=2.0, rise=2.5, n=20)  # the steep saddle: LSCM folds it
    by_superlu = flatten.tutte(mesh)
    by_pardiso = flatten.tutte(mesh, factorize=linear.unsymmetric_factorizer("pardiso"))
    np.testing.assert_allclose(by_pardiso, by_superlu, atol=1e-12 * np.abs(by_superlu).max())
    made = []
    original = linear.PardisoLU.__init__

    def counted(self, matrix):
        made.append(matrix.shape)
        original(self, matrix)

    monkeypatch.setattr(linear.PardisoLU, "__init__", counted)
    material = vares.materials.NeoHooke(1000.0, 0.3)
    results = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the conformal map folds: started from Tutte's
        for name in ("scipy-superlu", "pardiso"):
            results[name] = vares.solve(mesh, material, linear_solver=name)
            assert results[name].initial_guess == "tutte"
            assert len(made) == (name == "pardiso")
    np.testing.assert_allclose(
        results["pardiso"].material_coordinates,
        results["scipy-superlu"].material_coordinates,
        atol=1e-9 * np.abs(by_superlu).max(),
    )


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="PARDISO not installed")
def test_a_pardiso_solve_with_perturbed_pivots_is_checked(monkeypatch):
    """A KKT system (two strips' seam matching: a zero block, whose pivots PARDISO perturbs)
    is solved to round-off and the solve accepted; a solve whose residual is far off (as the
    seam matching's in millimetres was, 2.3, before its rows were scaled) is refused with its
    residual instead of being handed to Newton's method."""
    from vares.geometry.examples import hypar_strips
    from vares.structures import find_seams, split_panels
    from vares.structures.matching import CoupledProblem

    fabric = vares.materials.fabric("pes-pvc-type-2").material()
    mesh, ids = hypar_strips()
    strips = split_panels(mesh, ids)[:2]
    results = [vares.solve(p.mesh, fabric, warp_angle=10.0) for p in strips]
    coupled = CoupledProblem.build(results, fabric, 1.0, find_seams(strips))
    kkt = coupled.kkt([r.material_coordinates for r in results], np.zeros(coupled.num_constraints))
    rhs = np.random.default_rng(0).normal(size=kkt.matrix.shape[0])
    solver = get_solver("pardiso")
    solver.factorize(kkt.matrix)
    assert solver._solver.iparm[13] > 0  # perturbed pivots: the first solve is checked
    x = solver.solve(rhs)
    assert np.linalg.norm(kkt.matrix @ x - rhs) < 1e-9 * np.linalg.norm(rhs)
    phase = pardiso.PardisoSolver._phase

    def astray(self, number, vector):  # a solve gone wrong, as on the badly scaled system
        out = phase(self, number, vector)
        return out * (1.0 + np.arange(out.size) % 3) if number == 33 else out

    monkeypatch.setattr(pardiso.PardisoSolver, "_phase", astray)
    solver.factorize(kkt.matrix)
    with pytest.raises(SingularMatrixError, match="perturbed pivots has a relative residual of"):
        solver.solve(rhs)
