"""Fibre orientation, anisotropic patterns and fibre results."""

import numpy as np
import pytest
from conftest import align_2d, rotation

import vares
from vares.geometry.examples import cylinder160, hypar, rib30
from vares.materials import (
    Fibres,
    MaterialError,
    NeoHooke,
    NonCrimpFabric,
    OrthotropicStVenantKirchhoff,
    StVenantKirchhoff,
)

ORTHO = OrthotropicStVenantKirchhoff(E1=800.0, E2=640.0, G12=40.0, nu12=0.4)
NCF = NonCrimpFabric.from_moduli(1000.0, 1000.0, 5.0)


def rotate(points, degrees):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return points @ np.array([[c, s], [-s, c]])


@pytest.mark.parametrize("law", [ORTHO, NCF], ids=lambda m: type(m).__name__)
def test_rotating_warp_and_pattern_together_leaves_the_energy_unchanged(law):
    mesh = hypar(size=4.0, rise=0.2, n=6)
    pattern = vares.projection_plane(mesh, "xy").project(mesh.points) * [1.01, 0.98]
    reference = vares.Problem(mesh, law, fibres=Fibres.from_angles(10.0)).energy(pattern)
    for turn in (17.0, -65.0, 180.0):
        turned = vares.Problem(mesh, law, fibres=Fibres.from_angles(10.0 + turn))
        assert turned.energy(rotate(pattern, turn)) == pytest.approx(reference, rel=1e-12)
    # turning only the fibres does change it: the check above is not vacuous
    assert vares.Problem(mesh, law, fibres=Fibres.from_angles(40.0)).energy(pattern) != (
        pytest.approx(reference, rel=1e-6)
    )


@pytest.mark.parametrize("orientation", ["held", "free"])
def test_orthotropic_with_isotropic_constants_gives_the_isotropic_pattern(orientation):
    mesh = hypar(size=4.0, rise=0.2, n=8, cell_type="quad")
    E, nu = 600.0, 0.3
    iso = vares.solve(mesh, StVenantKirchhoff(E, nu))
    ortho = vares.solve(
        mesh,
        OrthotropicStVenantKirchhoff(E, E, E / (2 * (1 + nu)), nu),
        warp_angle=23.0,
        orientation=orientation,
    )
    assert iso.converged and ortho.converged, ortho.reason
    assert ortho.energy == pytest.approx(iso.energy, rel=1e-9)
    a, b = iso.material_coordinates, ortho.material_coordinates
    assert np.abs(align_2d(a, b) - a).max() < 1e-9 * 4.0


@pytest.mark.parametrize("law", [ORTHO, NCF], ids=lambda m: type(m).__name__)
@pytest.mark.parametrize("angle", [0.0, 30.0, 45.0, 90.0])
@pytest.mark.parametrize("orientation", ["held", "free"])
def test_cylinder_unrolls_with_zero_energy_for_every_fibre_angle(law, angle, orientation):
    mesh = cylinder160(n_around=16, n_along=6)
    result = vares.solve(mesh, law, warp_angle=angle, orientation=orientation, plane="xy")
    assert result.converged, result.reason
    assert abs(result.energy) < 1e-12 * law.stiffness_scale * mesh.area
    assert result.pattern_area == pytest.approx(mesh.area, rel=1e-9)
    np.testing.assert_allclose(result.fields["warp_stretch"], 1.0, atol=1e-8)
    np.testing.assert_allclose(result.fields["shear_angle"], 0.0, atol=1e-5)


def test_free_orientation_never_costs_more_energy_than_held():
    mesh = hypar(size=4.0, rise=0.25, n=8)
    held = vares.solve(mesh, ORTHO, warp_angle=30.0)
    free = vares.solve(mesh, ORTHO, warp_angle=30.0, orientation="free")
    assert held.converged and free.converged
    assert free.energy < held.energy
    # the held solve kept the initial guess's rotation: the reaction is a pure torque, the
    # residual less that torque converged
    assert held.history[-1].relative_residual < 1e-10


def independent_mean_deviation(mesh, coordinates, warp, direction):
    """Area-weighted mean angle between F Φ₁ and the direction projected on each triangle."""
    total, weight = 0.0, 0.0
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    for tri in mesh.cells["triangle"]:
        x, X = mesh.points[tri], coordinates[tri]
        F = np.column_stack([x[1] - x[0], x[2] - x[0]]) @ np.linalg.inv(
            np.column_stack([X[1] - X[0], X[2] - X[0]])
        )
        n = np.cross(x[1] - x[0], x[2] - x[0])
        area = 0.5 * np.linalg.norm(n)
        n /= 2 * area
        a, t = F @ warp, d - (d @ n) * n
        total += area * np.arctan2(np.cross(t, a) @ n, t @ a)
        weight += area
    return np.degrees(total / weight)


@pytest.mark.parametrize(
    ("name", "mesh", "direction"),
    [
        ("saddle", hypar(size=10.0, rise=0.06, n=10), (1.0, 2.0, 0.3)),
        ("rib", rib30(spacing=0.02, fillet_segments=3), (-1.0, 1.0, 0.0)),
    ],
)
@pytest.mark.parametrize("law", [ORTHO, NCF], ids=lambda m: type(m).__name__)
def test_warp_follows_a_3d_direction(name, mesh, direction, law):
    result = vares.solve(mesh, law, warp_direction=direction)
    assert result.converged, result.reason
    np.testing.assert_allclose(result.fibres.warp, [1.0, 0.0], atol=1e-12)  # warp along +x
    deviation = independent_mean_deviation(
        mesh, result.material_coordinates, result.fibres.warp, direction
    )
    assert abs(deviation) < 0.1
    assert abs(result.warp_deviation) < 1e-6
    assert (
        abs(
            np.mean(result.fields["warp_deviation"] * result.fields["surface_area"])
            / np.mean(result.fields["surface_area"])
        )
        < 0.1
    )
    # without the prescription the warp would run elsewhere: the test is not vacuous
    other = vares.solve(mesh, law)
    assert (
        abs(
            independent_mean_deviation(
                mesh, other.material_coordinates, other.fibres.warp, direction
            )
        )
        > 1.0
    )


def test_warp_direction_with_an_isotropic_law_only_turns_the_fibres():
    mesh = hypar(size=10.0, rise=0.06, n=8)
    plain = vares.solve(mesh, NeoHooke(1000.0, 0.3))
    aligned = vares.solve(mesh, NeoHooke(1000.0, 0.3), warp_direction=(0.0, 1.0, 0.0))
    assert aligned.energy == pytest.approx(plain.energy, rel=1e-9)
    a, b = plain.material_coordinates, aligned.material_coordinates
    assert np.abs(align_2d(a, b) - a).max() < 1e-9


def test_fibre_fields_of_a_homogeneous_stretch():
    """Flat square, pattern shrunk by 1.1 along x and 1.05 along y: closed-form yarn results."""
    x, y = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 4))
    mesh = vares.SurfaceMesh(
        np.column_stack([x.ravel(), y.ravel(), 0 * x.ravel()]),
        vares.examples.grid_cells(4, 4, "quad"),
    )
    pattern = mesh.points[:, :2] / [1.1, 1.05]
    E, nu, angle = 100.0, 0.25, 30.0
    evaluation = vares.evaluate(mesh, pattern, StVenantKirchhoff(E, nu), warp_angle=angle)
    f = evaluation.fields
    U = np.diag([1.1, 1.05])
    warp = np.array([np.cos(np.radians(angle)), np.sin(np.radians(angle))])
    fill = np.array([-warp[1], warp[0]])
    Fw, Ff = U @ warp, U @ fill
    np.testing.assert_allclose(f["warp_stretch"], np.linalg.norm(Fw), rtol=1e-12)
    np.testing.assert_allclose(f["fill_stretch"], np.linalg.norm(Ff), rtol=1e-12)
    yarn_angle = np.degrees(np.arccos(Fw @ Ff / np.linalg.norm(Fw) / np.linalg.norm(Ff)))
    np.testing.assert_allclose(f["shear_angle"], 90.0 - yarn_angle, rtol=1e-10)
    Egl = 0.5 * (U @ U - np.eye(2))
    lam, mu = E * nu / (1 - nu**2), E / (2 * (1 + nu))
    S = lam * np.trace(Egl) * np.eye(2) + 2 * mu * Egl
    sigma = U @ S @ U / np.linalg.det(U)
    t = Fw / np.linalg.norm(Fw)
    np.testing.assert_allclose(f["warp_stress"], t @ sigma @ t, rtol=1e-12)
    np.testing.assert_allclose(f["warp_stress_pk2"], warp @ S @ warp, rtol=1e-12)
    np.testing.assert_allclose(f["stress_max"], np.linalg.eigvalsh(sigma).max(), rtol=1e-12)
    np.testing.assert_allclose(f["det_F"], 1.1 * 1.05, rtol=1e-12)
    assert not f["compressed_yarns"].any() and not f["wrinkling"].any()


def test_ply_check_flags_compressed_yarns_above_a_threshold():
    mesh = hypar(size=4.0, rise=0.25, n=8)
    result = vares.solve(mesh, NCF, warp_angle=45.0, orientation="free")
    check = vares.evaluate(mesh, result.material_coordinates, NCF, warp_angle=0.0)
    f = check.fields
    expected = np.flatnonzero((f["warp_stress"] < -1e-5) | (f["fill_stress"] < -1e-5))
    np.testing.assert_array_equal(check.compressed_cells, expected)
    assert check.compressed_area_fraction > 0
    strict = vares.evaluate(
        mesh,
        result.material_coordinates,
        NCF,
        warp_angle=0.0,
        compression_threshold=0.5 * -min(f["warp_stress"].min(), f["fill_stress"].min()),
    )
    assert 0 < strict.compressed_area_fraction < check.compressed_area_fraction


def test_orientation_options_are_validated():
    mesh = hypar(n=4)
    with pytest.raises(ValueError, match="cannot also be free"):
        vares.solve(mesh, ORTHO, warp_direction=(1, 0, 0), orientation="free")
    with pytest.raises(ValueError, match="orientation must be one of held, free"):
        vares.solve(mesh, ORTHO, orientation="sideways")
    with pytest.raises(ValueError, match="not all zero"):
        vares.solve(mesh, ORTHO, warp_direction=(0, 0, 0))
    with pytest.raises(MaterialError, match="yarns at 90°"):
        vares.solve(mesh, NCF, warp_angle=0.0, fill_angle=60.0)
    with pytest.raises(ValueError, match="normal to the surface everywhere"):
        vares.solve(mesh.transformed(mesh.points * [1, 1, 0]), ORTHO, warp_direction=(0, 0, 1))


def test_rib30_generator():
    mesh = rib30()
    # Pappus: area = profile length × arc angle × radius of the profile's centroid line; the
    # faceted mesh converges to it at second order in the cell size
    run = 0.05 / np.tan(np.radians(60.0))
    straight = 0.12 + 2 * np.hypot(run, 0.05) + 2 * 0.04
    turn, fillet = np.radians(60.0), 0.015  # four corners, each turning by 60°
    length = straight - 4 * (2 * fillet * np.tan(turn / 2) - fillet * turn)
    assert mesh.area == pytest.approx(length * np.radians(30.0) * 1.0, rel=2e-3)
    assert mesh.points[:, 2].min() == pytest.approx(0.0) and mesh.points[:, 2].max() == (
        pytest.approx(0.05)
    )
    quads = rib30(cell_type="quad")
    assert quads.area == pytest.approx(mesh.area, rel=1e-3)


def test_rigid_motion_invariance_with_a_prescribed_warp_direction():
    mesh = hypar(size=4.0, rise=0.2, n=8)
    R = rotation(3)
    direction = np.array([1.0, 1.0, 0.0])
    a = vares.solve(mesh, ORTHO, warp_direction=direction)
    b = vares.solve(mesh.transformed(mesh.points @ R.T + 5.0), ORTHO, warp_direction=R @ direction)
    assert a.converged and b.converged
    assert b.energy == pytest.approx(a.energy, rel=1e-9)
    pa, pb = a.material_coordinates, b.material_coordinates
    # both are returned with the warp along +x: equal up to a translation
    np.testing.assert_allclose(pb - pb.mean(axis=0), pa - pa.mean(axis=0), atol=1e-9)


def _fibre_torque(mesh, law, coordinates, fibres, delta=1e-5):
    """dE/dθ for the yarns turned by θ (radians) in a fixed pattern, by central differences."""
    warp, fill = (np.degrees(np.arctan2(d[1], d[0])) for d in (fibres.warp, fibres.fill))
    energy = [
        vares.Problem(mesh, law, fibres=Fibres.from_angles(warp + s, fill + s)).energy(coordinates)
        for s in (np.degrees(delta), -np.degrees(delta))
    ]
    return (energy[0] - energy[1]) / (2 * delta)


def test_a_free_pattern_turns_to_where_turning_the_yarns_costs_nothing():
    """A non-crimp fabric on a flat hypar whose energy turns the pattern some 25° from the
    held one: the free pattern is where the energy is stationary under turning the yarns
    (checked by differences of the energy, independently of the solver's residual), found
    by globalised Newton with the held rotation and then the rotation as an unknown (it took
    283 iterations and a pseudo-time fallback when the line search's steps turned the pattern
    linearly, 31 when they turned it by their least-squares turn)."""
    mesh = hypar(size=10.0, rise=0.06, n=24)
    held = vares.solve(mesh, NCF, warp_angle=20.0)
    free = vares.solve(mesh, NCF, warp_angle=20.0, orientation="free")
    assert held.converged and free.converged, free.reason
    assert free.strategy == ["globalised newton", "free rotation"]
    assert free.iterations <= held.iterations + 10  # 6 held, 15 free
    assert free.energy < 0.7 * held.energy
    scale = free.energy  # dE/dθ of the held pattern is of the energy's order
    assert abs(_fibre_torque(mesh, NCF, held.material_coordinates, held.fibres)) > 0.1 * scale
    assert abs(_fibre_torque(mesh, NCF, free.material_coordinates, free.fibres)) < 1e-6 * scale


def test_a_turning_step_path_leaves_along_the_step_and_turns_rigidly():
    from vares.solver.line_search import StepPath

    rng = np.random.default_rng(5)
    x = rng.uniform(0.0, 2.0, (12, 2))
    x[3] = [0.5, 0.5]
    across = np.column_stack([-(x[:, 1] - 0.5), x[:, 0] - 0.5])
    direction = 0.3 * across + 0.01 * rng.standard_normal((12, 2))
    direction[3] = 0.0
    path = StepPath(x, direction, pivot=3)
    assert path.turn == pytest.approx(0.3, rel=0.05)
    h = 1e-6
    np.testing.assert_allclose((path.at(h) - path.at(-h)) / (2 * h), direction, atol=1e-8)
    turned = StepPath(x, across, pivot=3).at(2.0)  # a pure turn by 2 rad: every distance kept
    distances = np.linalg.norm(x[:, None] - x[None], axis=-1)
    np.testing.assert_allclose(np.linalg.norm(turned[:, None] - turned[None], axis=-1), distances)
    np.testing.assert_allclose(StepPath(x, direction, pivot=None).at(0.7), x + 0.7 * direction)


def _hemisphere_half(rings: int):
    """The half (y < 0) of the irregular hemisphere R = 100 mm cut through its pole along x."""
    from vares.geometry.cutting import cut_mesh
    from vares.geometry.drawn_lines import curves_on_surface
    from vares.geometry.examples import irregular_cap
    from vares.structures.panels import split_panels

    t = np.linspace(-np.pi / 2 + 1e-3, np.pi / 2 - 1e-3, 200)
    line = np.column_stack([100.0 * np.sin(t), 0.0 * t, 100.0 * np.cos(t)])
    surface, lines = curves_on_surface(irregular_cap(100.0, 90.0, rings, 0.3, 1), [line], 0.4)
    cut = cut_mesh(surface, lines, 0.4)
    pieces = split_panels(cut.mesh, cut.panel_ids)
    return min(pieces, key=lambda p: p.mesh.points[:, 1].mean()).mesh


def test_a_warp_alignment_across_a_jump_of_the_drape_keeps_the_nearer_side(monkeypatch):
    """Stiff yarns on half a hemisphere (2,710 cells, the README's non-crimp fabric, the warp
    held along x): the pattern a turn of the yarns reaches depends on where its solve starts,
    and the mean warp deviation jumps (measured +0.120° and −0.095° at warp angles 9e-4°
    apart). The secant iteration alone failed there ("could not be aligned (mean deviation
    −0.0887°)", 104 iterations); bracketed, the side that deviates less is kept and reported;
    beyond ALIGNMENT_JUMP it is a failure that names the jump."""
    from vares.solver import alignment

    mesh = _hemisphere_half(30)
    ncf = NonCrimpFabric([-250.0, 250.0], [-250.0, 250.0], [0.5])
    result = vares.solve(mesh, ncf, warp_direction=(1.0, 0.0, 0.0))
    assert result.converged, result.reason
    assert 1e-6 < abs(result.warp_deviation) <= alignment.ALIGNMENT_JUMP
    independent = independent_mean_deviation(
        mesh, result.material_coordinates, result.fibres.warp, (1.0, 0.0, 0.0)
    )
    assert result.warp_deviation == pytest.approx(independent, abs=0.1 * abs(independent))
    monkeypatch.setattr(alignment, "ALIGNMENT_JUMP", 0.01)
    strict = vares.solve(mesh, ncf, warp_direction=(1.0, 0.0, 0.0))
    assert not strict.converged
    assert "the drape jumps between two patterns" in strict.reason
