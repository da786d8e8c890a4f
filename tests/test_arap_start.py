"""ARAP flattening and the ARAP-refined start: isometric where the surface is developable, and
the same optimum as the plain start, reached in fewer Newton iterations on a rough scan."""

import warnings

import numpy as np
import pytest
import scipy.linalg

import vares
from vares.geometry.arap import ArapFlattening, arap, nearest_rotations
from vares.geometry.flatten import inverted_cells, lscm, tutte
from vares.mechanics.rigid import rigid_modes
from vares.solver.options import SolveOptions
from vares.solver.start import arap_refined, initial_guess

NEO_HOOKE = vares.materials.NeoHooke(1000.0, 0.3)


def edge_lengths(points, mesh):
    tris = mesh.cells["triangle"]
    return np.concatenate(
        [
            np.linalg.norm(points[tris[:, (k + 1) % 3]] - points[tris[:, k]], axis=1)
            for k in range(3)
        ]
    )


def test_nearest_rotations_are_the_polar_factors():
    rng = np.random.default_rng(3)
    j = rng.normal(size=(50, 2, 2))
    j[np.linalg.det(j) < 0, 0] *= -1  # proper maps: the polar factor is a rotation
    expected = np.array([scipy.linalg.polar(m)[0] for m in j])
    assert np.allclose(nearest_rotations(j), expected, atol=1e-12)


def test_arap_flattens_a_developable_cone_isometrically_from_tutte():
    mesh = vares.examples.cone_segment()
    start = tutte(mesh)
    flat = ArapFlattening(mesh)
    before = flat.energy(start)
    pattern = arap(mesh, start, 200, flat)
    assert before > 0.5  # Tutte's embedding is far from isometric here
    assert flat.energy(pattern) < 1e-20 * mesh.area
    relative = edge_lengths(pattern, mesh) / edge_lengths(mesh.points, mesh) - 1.0
    assert np.abs(relative).max() < 1e-11
    assert not inverted_cells(mesh, pattern).size


def test_an_isometric_pattern_is_a_fixed_point_of_the_step():
    mesh = vares.examples.cone_segment()
    pattern = lscm(mesh)  # conformal on a developable surface, scaled to its area: isometric
    step = ArapFlattening(mesh).step(pattern)
    assert np.abs(step - pattern).max() < 1e-10 * np.sqrt(mesh.area)


def aligned(x, target):
    """``x`` moved rigidly onto ``target`` in least squares."""
    centre, target_centre = x.mean(axis=0), target.mean(axis=0)
    u, _, vt = np.linalg.svd((x - centre).T @ (target - target_centre))
    return target_centre + (x - centre) @ (u @ vt)


def solved(mesh, start):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return vares.solve(mesh, NEO_HOOKE, initial_guess=start)


def starts(mesh):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = initial_guess(mesh, SolveOptions())
        return plain, initial_guess(mesh, SolveOptions(), isotropic=True)


def test_refined_start_reaches_the_same_optimum_on_a_rough_scan_in_fewer_iterations():
    mesh = vares.examples.scan_like(6000)
    plain, refined = starts(mesh)
    assert refined.refinement == "arap" and refined.kind == plain.kind
    before, after = solved(mesh, plain.coordinates), solved(mesh, refined.coordinates)
    assert before.converged and after.converged
    assert after.iterations < before.iterations
    assert after.energy == pytest.approx(before.energy, rel=1e-12)
    size = np.ptp(before.material_coordinates, axis=0).max()
    moved = aligned(after.material_coordinates, before.material_coordinates)
    assert np.abs(moved - before.material_coordinates).max() < 1e-8 * size


def test_refined_start_keeps_the_held_nodes_and_ends_at_the_very_pattern():
    mesh = vares.examples.spherical_cap()
    plain, refined = starts(mesh)
    held = rigid_modes(plain.coordinates, "fixed")[0]
    assert np.array_equal(rigid_modes(refined.coordinates, "fixed")[0], held)
    assert np.array_equal(
        refined.coordinates[~held.reshape(-1, 2)], plain.coordinates[~held.reshape(-1, 2)]
    )
    before, after = solved(mesh, plain.coordinates), solved(mesh, refined.coordinates)
    size = np.ptp(before.material_coordinates, axis=0).max()
    assert np.abs(after.material_coordinates - before.material_coordinates).max() < 1e-8 * size


def test_refined_start_is_the_start_where_the_step_folds():
    # a unit square with a spike of height 1 at its centre: far from developable, and one ARAP
    # step from the conformal map folds cells around the spike
    n = 11
    xs, ys = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    points = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(n * n)])
    points[(n * n) // 2, 2] = 1.0
    quads = np.array(
        [
            [i * n + j, i * n + j + 1, (i + 1) * n + j + 1, (i + 1) * n + j]
            for i in range(n - 1)
            for j in range(n - 1)
        ]
    )
    mesh = vares.SurfaceMesh(points, {"triangle": np.vstack([quads[:, :3], quads[:, [0, 2, 3]]])})
    start = initial_guess(mesh, SolveOptions())
    assert not inverted_cells(mesh, start.coordinates).size
    assert inverted_cells(mesh, ArapFlattening(mesh).step(start.coordinates)).size
    assert arap_refined(mesh, start) is start


def test_no_refinement_unless_isotropic_nor_for_pseudo_time_or_a_named_plane():
    mesh = vares.examples.spherical_cap()
    assert initial_guess(mesh, SolveOptions()).refinement == ""
    assert initial_guess(mesh, SolveOptions(plane="xy"), isotropic=True).refinement == ""
    pseudo = initial_guess(mesh, SolveOptions(strategy="pseudo-time"), isotropic=True)
    assert pseudo.refinement == "" and pseudo.kind == "projection"
