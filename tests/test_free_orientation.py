"""A pattern free to turn: its rotation an explicit unknown of Newton's system."""

import numpy as np
import pytest

import vares
from vares.geometry.examples import hypar
from vares.materials import Fibres, OrthotropicStVenantKirchhoff
from vares.mechanics.assembly import Assembler
from vares.mechanics.problem import Problem
from vares.mechanics.rigid import rigid_modes
from vares.solver import turning
from vares.solver.linear import get_solver
from vares.solver.newton import Failure, NewtonContext
from vares.solver.turning import TurningSystem, quarter_turn

ORTHO = OrthotropicStVenantKirchhoff(E1=800.0, E2=640.0, G12=40.0, nu12=0.4)
#: the orthotropic hypar of tests/test_options.py, with the default strategy
OPTIONS = dict(
    warp_angle=15.0,
    fill_angle=105.0,
    initial_guess="projection",
    plane="xy",
    tolerance=1e-10,
    max_iterations=40,
)


def _turned(x, pivot, angle):
    c, s = np.cos(angle), np.sin(angle)
    return x[pivot] + (x - x[pivot]) @ np.array([[c, s], [-s, c]])


def _system(mesh, fibres, x):
    problem = Problem(mesh, ORTHO, fibres=fibres)
    free, _ = rigid_modes(x, "free")
    pivot = int(np.flatnonzero(~free.reshape(-1, 2).any(axis=1))[0])
    ctx = NewtonContext(
        Assembler(problem.connectivity, free), get_solver(None), 0.0, 0.0, 1.0, 1, [], [], None
    )
    ctx.turning_about, ctx.turning = pivot, True
    evaluation = problem.evaluate(x, order=2)
    gradient = ctx.assembler.vector(evaluation.gradients).ravel()[free]
    matrix = ctx.assembler.matrix(evaluation.hessians)
    return problem, ctx, pivot, TurningSystem(x, ctx, matrix, gradient), matrix, gradient


def test_the_turning_system_is_the_energys_derivatives_along_the_rotation():
    """Torque, curvature and coupling of the rotation against central differences of the
    energy of the pattern turned rigidly about its held node."""
    mesh = hypar(size=4.0, rise=0.5, n=6)
    x = vares.projection_plane(mesh, "xy").project(mesh.points) * [1.02, 0.99]
    problem, ctx, pivot, system, matrix, g = _system(mesh, Fibres.from_angles(20.0, 110.0), x)
    h = 1e-5

    def energy(y, angle):
        return problem.energy(_turned(y, pivot, angle))

    torque = (energy(x, h) - energy(x, -h)) / (2 * h)
    assert system.torque == pytest.approx(torque, rel=1e-7)
    free = ctx.assembler.free
    a = quarter_turn(x - x[pivot]).ravel()[free]
    curvature = float(a @ (matrix @ a) - g @ (x - x[pivot]).ravel()[free])
    second = (energy(x, h) - 2 * energy(x, 0.0) + energy(x, -h)) / h**2
    assert curvature == pytest.approx(second, rel=1e-4)
    # the coupling ∂²E/∂Y∂φ along a random change of the pattern, from the reduced gradient
    # identity ΔY = u + Δφ w: the torque's change along v is −vᵀH w (H w = −coupling)
    rng = np.random.default_rng(1)
    v = np.zeros(x.size)
    v[free] = rng.standard_normal(free.sum())
    v = v.reshape(-1, 2)
    e = 1e-5

    def torque_at(y):
        return (energy(y, h) - energy(y, -h)) / (2 * h)

    change = (torque_at(x + e * v) - torque_at(x - e * v)) / (2 * e)
    by_node = np.zeros(x.size)
    by_node[free] = g
    by_node = by_node.reshape(-1, 2)
    coupling = matrix @ a + np.column_stack([by_node[:, 1], -by_node[:, 0]]).ravel()[free]
    assert coupling @ v.ravel()[free] == pytest.approx(change, rel=1e-5)


def test_the_reduced_gradient_and_schur_complement_are_those_of_the_held_optimum():
    """Envelope theorem: at a pattern solved with its rotation held, the reduced gradient and
    the Schur complement are the first and second derivatives of the held optimum's energy
    with respect to the yarn angle (held solves at three angles, turned the other way)."""
    mesh = hypar(size=4.0, rise=0.5, n=8)
    step = 0.5
    solves = {
        t: vares.solve(mesh, ORTHO, warp_angle=-t, fill_angle=90.0 - t, tolerance=1e-12)
        for t in (36.0 - step, 36.0, 36.0 + step)
    }
    energies = [solves[t].energy for t in sorted(solves)]
    h = np.radians(step)
    first = (energies[2] - energies[0]) / (2 * h)
    second = (energies[2] - 2 * energies[1] + energies[0]) / h**2
    held = solves[36.0]
    *_, system, _, _ = _system(mesh, held.fibres, held.material_coordinates)
    # the yarns at −θ in a pattern held still are the pattern turned by +θ under fixed yarns
    assert system.reduced == pytest.approx(first, rel=1e-4)
    assert system.schur == pytest.approx(second, rel=1e-3)
    assert abs(system.schur) > 0.1 * abs(system.reduced)  # the check is not vacuous


def _fibre_torque(mesh, law, coordinates, fibres, delta=1e-5):
    """dE/dθ for the yarns turned by θ (radians) in a fixed pattern, by central differences."""
    warp, fill = (np.degrees(np.arctan2(d[1], d[0])) for d in (fibres.warp, fibres.fill))
    energy = [
        vares.Problem(mesh, law, fibres=Fibres.from_angles(warp + s, fill + s)).energy(coordinates)
        for s in (np.degrees(delta), -np.degrees(delta))
    ]
    return (energy[0] - energy[1]) / (2 * delta)


def test_free_orientation_takes_a_held_solves_iterations_and_a_few_more(monkeypatch):
    """The hypar that took 1,065 iterations: the held solve's iterations and four more; the
    same optimum as the globalised Newton whose steps turn by their least-squares turn (the
    turning steps made to fail, so that it runs instead), to round-off."""
    mesh = hypar(size=4.0, rise=0.15, n=8)
    held = vares.solve(mesh, ORTHO, 0.8, **OPTIONS)
    free = vares.solve(mesh, ORTHO, 0.8, orientation="free", **OPTIONS)
    assert held.converged and free.converged, free.reason
    assert free.strategy == ["globalised newton", "free rotation"]
    assert free.iterations <= held.iterations + 4, (free.iterations, held.iterations)
    assert free.energy < 0.75 * held.energy

    def fails(self):
        raise Failure("turning made to fail", self.x)

    monkeypatch.setattr(turning.TurningSearch, "step", fails)
    slow = vares.solve(mesh, ORTHO, 0.8, orientation="free", **OPTIONS)
    assert slow.converged, slow.reason
    assert slow.strategy == ["globalised newton", "free rotation", "globalised newton"]
    assert slow.iterations > free.iterations
    assert free.energy == pytest.approx(slow.energy, rel=1e-12)
    # the same pattern, held node and rotation included (no alignment)
    a, b = free.material_coordinates, slow.material_coordinates
    assert np.abs(a - b).max() < 1e-8 * 4.0
    # and stationary under turning the yarns, by differences of the energy alone
    scale = free.energy
    assert abs(_fibre_torque(mesh, ORTHO, a, free.fibres)) < 1e-6 * scale
    assert abs(_fibre_torque(mesh, ORTHO, held.material_coordinates, held.fibres)) > 0.1 * scale


def test_a_pattern_held_at_a_rotation_of_greatest_energy_turns_away():
    """With the warp along the symmetric hypar's axis the held pattern is stationary in its
    rotation (torque zero by symmetry) but at the energy's greatest: the free pattern turns
    away from it, some 45°, to the minimum (the stationary point is not taken for it)."""
    mesh = hypar(size=4.0, rise=0.5, n=16)
    held = vares.solve(mesh, ORTHO, warp_angle=0.0)
    free = vares.solve(mesh, ORTHO, warp_angle=0.0, orientation="free")
    assert held.converged and free.converged, free.reason
    scale = held.energy
    assert abs(_fibre_torque(mesh, ORTHO, held.material_coordinates, held.fibres)) < 1e-8 * scale
    assert free.energy < 0.9 * held.energy
    assert abs(_fibre_torque(mesh, ORTHO, free.material_coordinates, free.fibres)) < 1e-7 * scale
    a, b = held.material_coordinates, free.material_coordinates
    u, _, vt = np.linalg.svd((b - b.mean(axis=0)).T @ (a - a.mean(axis=0)))
    turn = abs(np.degrees(np.arctan2((u @ vt)[0, 1], (u @ vt)[0, 0])))
    assert 35.0 < turn < 55.0, turn
    assert free.iterations <= held.iterations + 12  # 36 with least-squares turns


def test_a_symmetric_panel_free_to_turn_leaves_its_stationary_rotation():
    """A strip of the symmetric sail: held with the warp along its axis, its rotation is
    stationary (by symmetry) but no minimum; free, it turns some 48° to one that is (the
    globalised Newton with least-squares turns stayed at the stationary one: 0.00406)."""
    from vares.geometry.examples import hypar_strips
    from vares.structures.panels import split_panels

    panel = split_panels(*hypar_strips(strips=3, n=8))[0]
    held = vares.solve(panel.mesh, ORTHO)
    free = vares.solve(panel.mesh, ORTHO, orientation="free")
    assert held.converged and free.converged, free.reason
    assert free.energy < 0.7 * held.energy
    x, fibres = free.material_coordinates, free.fibres
    assert abs(_fibre_torque(panel.mesh, ORTHO, x, fibres)) < 1e-6 * free.energy
    warp = np.degrees(np.arctan2(fibres.warp[1], fibres.warp[0]))
    for turn in (-1.0, 1.0):  # turning the yarns either way in the free pattern costs energy
        turned = Fibres.from_angles(warp + turn, warp + 90.0 + turn)
        assert Problem(panel.mesh, ORTHO, fibres=turned).energy(x) > free.energy


def test_turning_from_a_stationary_rotation_of_greatest_energy_does_not_stop_there():
    """Started at the symmetric strip's held pattern, solved to round-off (so that its residual
    meets any tolerance), the turning Newton asks whether the rotation is a minimum and,
    finding the curvature negative, turns away."""
    from vares.geometry.examples import hypar_strips
    from vares.solver.strategies import FREE_ROTATION, turn_free
    from vares.structures.panels import split_panels

    panel = split_panels(*hypar_strips(strips=3, n=8))[0]
    held = vares.solve(panel.mesh, ORTHO, tolerance=1e-13)
    problem, ctx, _, system, *_ = _system(panel.mesh, held.fibres, held.material_coordinates)
    assert system.schur < 0 and abs(system.torque) < 1e-10 * held.energy
    ctx.residual_tolerance = 1e-10 * problem.force_scale
    ctx.max_iterations = 40
    x, path, reason = turn_free(problem, held.material_coordinates, ctx, damping=1.0)
    assert reason is None and path == [FREE_ROTATION]
    assert ctx.history[0].relative_residual < 1e-10  # it had met the tolerance at the start
    assert problem.energy(x) < 0.7 * held.energy
