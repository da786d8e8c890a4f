"""The cutting pattern of one surface: :func:`solve`.

It puts the pieces of this package together: the options, the initial guess, the rigid modes,
the strategy's attempts, and (for a prescribed 3D warp direction) the warp alignment; and it
returns a :class:`PatternResult` whether or not the solve converged.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .._jit import compiled, sized_for
from ..geometry.flatten import tutte
from ..geometry.injectivity import AreaMisfit, Overlap, pattern_area_misfit, pattern_overlap
from ..geometry.mesh import SurfaceMesh
from ..materials import Fibres, Hyperelastic
from ..mechanics.assembly import Assembler
from ..mechanics.problem import Problem
from ..mechanics.rigid import rigid_modes
from ..options import split_settings, takes_options
from .alignment import align_warp, fibre_angle, initial_fibres, rotated
from .continuation import continuation_ratios, solve_in_stages
from .linear import get_solver, quiet_blas, unsymmetric_factorizer
from .newton import Failure, NewtonContext, describe_cells, exact_tangent_below
from .options import SolveOptions
from .result import IterationRecord, PatternResult
from .start import Start, initial_guess
from .strategies import follow_plan, plan, turn_free

__all__ = ["solve"]

#: Energy changes below this fraction of stiffness × thickness × area are round-off.
ENERGY_NOISE = 1e-13
#: A pattern free to turn is solved with its rotation held to this relative residual (or the
#: solve's tolerance, if looser) before it is let turn: where the globalised Newton's exact
#: tangents take over (closer, its steps gain little that the turn does not undo; from
#: further, the turning steps start off the valley floor; benchmarks/free_orientation.py).
HELD_FIRST = 1e-2


@takes_options(SolveOptions)
def solve(
    mesh: SurfaceMesh,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    prestress: float | Sequence[float] | np.ndarray | None = None,
    options: SolveOptions | None = None,
    callback: Callable[[IterationRecord], None] | None = None,
    **settings: Any,
) -> PatternResult:
    """Compute the cutting pattern of ``mesh`` that minimises the erection energy.

    Parameters
    ----------
    mesh
        The 3D surface.
    material, thickness
        Hyperelastic law and membrane thickness (use 1 for laws given as force per length).
    prestress
        Intended prestress along the yarns, force per length (e.g. kN/m): a number
        (isotropic), ``(warp, fill)``, ``(warp, fill, shear)``, or one such row per cell. It
        enters the energy as ``− S_pre : E`` and is ramped with the pseudo-time steps.
    options
        A :class:`SolveOptions` to start from; keyword ``settings`` (below) change it.
    callback
        Called with every :class:`IterationRecord` as the solve proceeds (progress display).
    settings
        Any option of :class:`SolveOptions` (listed below). ``initial_guess`` may also be
        pattern coordinates ``(n, 2)``. With ``warp_direction`` the fibres are turned in the
        pattern until the 3D-area-weighted mean angle between the erected warp ``F Φ₁`` and
        this direction (projected on the surface) is zero, and the pattern is returned with
        the warp along +x. ``orientation`` matters for anisotropic laws or a prestress
        (whenever the energy depends on the yarn directions): ``"held"`` keeps the pattern's
        rotation that of the initial guess, so the yarns run at ``warp_angle`` to the
        initial-guess plane's axes; ``"free"`` lets the energy choose the rotation.

    Returns
    -------
    PatternResult
        Always returned; ``converged`` and ``reason`` tell whether and why not. A pattern that
        overlaps itself (its outline crosses itself) is not converged: ``overlap`` says where;
        nor is one whose area is not within a factor 1.5 of the surface's (no fabric can be
        erected from it): ``area_misfit`` says by how much.
    """
    given = settings.pop("initial_guess", None)
    if given is not None and isinstance(given, str):
        settings["initial_guess"], given = given, None
    (options,) = split_settings(settings, [options or SolveOptions()])
    with quiet_blas():
        warm_up = _load_kernels(mesh, material, options.linear_solver)
        ratios = continuation_ratios(material, options)
        if ratios:  # the law's yarns reached through softer ones
            result, _ = solve_in_stages(
                lambda law, stage, start: _solve(
                    mesh, law, thickness, prestress, stage, callback, start
                ),
                mesh,
                material,
                options.replace(yarn_continuation=ratios),
                given,
            )
        else:
            result = _solve(mesh, material, thickness, prestress, options, callback, given)
    result.warm_up = warm_up
    return result


#: What this process has solved before: ``(cell type, material class, linear solver)``.
_WARM: set[tuple[str, type, str | None]] = set()


def _load_kernels(mesh: SurfaceMesh, material: Hyperelastic, solver: str | None) -> float:
    """Load (or compile) every compiled kernel a solve of ``mesh`` needs, by solving one cell of
    each of its cell types, once per process; the seconds it took (0 when nothing was new).
    Compiled kernels are cached on disk (numba), so only the first process compiles; later ones
    load them. Kept out of a solve's ``elapsed``."""
    started = time.perf_counter()
    if not compiled(mesh.num_cells):  # a small mesh's kernels run as numpy: nothing to load
        return 0.0
    loaded = False
    for cell_type, cells in mesh.cells.items():
        key = (cell_type, type(material), solver)
        if key in _WARM:
            continue
        _WARM.add(key)
        loaded = True
        nodes = cells[0]
        single = SurfaceMesh(mesh.points[nodes], {cell_type: np.arange(len(nodes))[None, :]})
        try:
            with sized_for(True):  # the compiled kernels, as the mesh's own solve runs them
                _solve(single, material, 1.0, None, SolveOptions(linear_solver=solver), None, None)
        except Exception:  # a warm-up only: the real solve reports any trouble
            pass
    return time.perf_counter() - started if loaded else 0.0


def _solve(mesh, material, thickness, prestress, options, callback, given) -> PatternResult:
    started = time.perf_counter()
    run = _Run(mesh, material, thickness, prestress, options, callback)
    # an energy blind to the pattern's rotation: the automatic start is taken one ARAP step on
    isotropic = not material.needs_fibres and prestress is None
    start = initial_guess(mesh, options, given, isotropic=isotropic)
    attempt = run.attempt(start)
    may_restart = options.initial_guess == "auto" and options.strategy != "pseudo-time"
    if attempt.overlap is not None and may_restart and start.kind != "tutte":
        # a start that is not one-to-one can lead to a minimum whose outline laps over itself;
        # Tutte's embedding starts on the right side of every fold (not for pseudo-time, whose
        # steps start from a projection)
        conformal = start.coordinates if start.kind == "lscm" else None  # its boundary's shape
        lu = unsymmetric_factorizer(options.linear_solver)
        retry = run.attempt(Start(tutte(mesh, conformal, lu), "tutte", None), restart=True)
        if retry.reason is None or retry.energy < attempt.energy:
            attempt = retry
    return PatternResult(
        mesh=mesh,
        material=material,
        thickness=attempt.problem.thickness,
        material_coordinates=attempt.coordinates,
        converged=attempt.reason is None,
        reason=attempt.reason,
        energy=attempt.energy,
        history=run.history,
        steps=run.steps,
        strategy=run.path,
        linear_solver=run.solver_name,
        elapsed=time.perf_counter() - started,
        options=options,
        fibres=attempt.fibres,
        prestress=attempt.problem.prestress,
        plane=attempt.start.plane,
        orientation="direction" if options.warp_direction is not None else attempt.rotation,
        initial_guess=attempt.start.kind,
        warp_direction=None if options.warp_direction is None else np.array(options.warp_direction),
        warp_deviation=attempt.deviation,
        overlap=attempt.overlap,
        area_misfit=attempt.area_misfit,
    )


@dataclass
class _Attempt:
    """A solve from one start: where it ended and how."""

    start: Start
    coordinates: np.ndarray
    problem: Problem
    fibres: Fibres
    rotation: str
    reason: str | None
    deviation: float | None
    overlap: Overlap | None
    area_misfit: AreaMisfit | None = None

    @property
    def energy(self) -> float:
        return self.problem.energy(self.coordinates)


@dataclass
class _Run:
    """What the attempts of one solve share: the problem's data, the options, and the records
    of every iteration and step."""

    mesh: SurfaceMesh
    material: Hyperelastic
    thickness: float
    prestress: object
    options: SolveOptions
    callback: Callable[[IterationRecord], None] | None
    history: list[IterationRecord] = field(default_factory=list)
    steps: list = field(default_factory=list)
    path: list[str] = field(default_factory=list)
    solver_name: str = ""

    def problem(self, fibres: Fibres) -> Problem:
        return Problem(
            self.mesh,
            self.material,
            self.thickness,
            fibres=fibres,
            prestress=self.prestress,
            yarn_strain=self.options.yarn_strain,
            yarn_stabilisation=self.options.yarn_stabilisation,
        )

    def attempt(self, start: Start, restart: bool = False) -> _Attempt:
        """Solve from ``start``: the strategy's plan, then the warp alignment, then the check
        that the pattern is one-to-one."""
        options = self.options
        fibres = Fibres.from_angles(options.warp_angle, options.fill_angle)
        problem = self.problem(fibres)
        rotation = options.orientation if problem.orientation_matters else "fixed"
        ctx = self._context(problem, start, rotation)
        if restart:
            self.path.append("restart from Tutte's embedding")
        x, deviation = start.coordinates, None
        reason = _folded_start(problem, start)
        if reason is None:
            direction = options.warp_direction
            if direction is not None:
                direction = np.array(direction)
                fibres = initial_fibres(fibres, options.warp_angle, x, problem, direction)
                problem = self.problem(fibres)
            attempts = plan(options.strategy, options.steps, start.plane is not None)
            if rotation == "free":
                x, path, reason = self._free(problem, start, attempts, ctx)
            else:
                x, path, reason = follow_plan(
                    problem, x, start.plane, attempts, ctx, options.damping
                )
            self.path += path
            if reason is None and direction is not None:
                self.path.append("warp alignment")
                try:
                    x, fibres, deviation = align_warp(
                        self.problem, x, fibres, direction, ctx, options.damping
                    )
                    deviation = float(np.degrees(deviation))
                except Failure as failure:
                    reason, x = failure.reason, failure.coordinates
                x, fibres = _warp_along_x(x, fibres, ctx)
                problem = self.problem(fibres)
        overlap = None if reason is not None else pattern_overlap(self.mesh, x)
        if overlap is not None:
            reason = overlap.describe(self.mesh)
        misfit = None if reason is not None else pattern_area_misfit(self.mesh, x)
        if misfit is not None:
            reason = misfit.describe()
        return _Attempt(start, x, problem, fibres, rotation, reason, deviation, overlap, misfit)

    def _free(self, problem: Problem, start: Start, attempts, ctx: NewtonContext):
        """A pattern free to turn: solved first with the rotation of ``start`` held, then let
        turn (:func:`~vares.solver.strategies.turn_free`); where the held solve fails, the
        attempts free to turn from ``start``. ``(pattern, names tried, reason or None)``."""
        damping = self.options.damping
        held = self._context(problem, start, "held")
        held.residual_tolerance = max(held.residual_tolerance, HELD_FIRST * held.force_scale)
        x, path, reason = follow_plan(
            problem, start.coordinates, start.plane, attempts, held, damping
        )
        if reason is None:
            x, more, reason = turn_free(problem, x, ctx, damping)
            return x, path + more, reason
        x, more, reason = follow_plan(
            problem, start.coordinates, start.plane, attempts, ctx, damping
        )
        return x, path + more, reason

    def _context(self, problem: Problem, start: Start, rotation: str) -> NewtonContext:
        free, constraint = rigid_modes(start.coordinates, rotation)
        solver = get_solver(self.options.linear_solver)
        self.solver_name = solver.name
        scale = self.material.stiffness_scale * problem.thickness * self.mesh.area
        return NewtonContext(
            assembler=Assembler(problem.connectivity, free),
            linear_solver=solver,
            residual_tolerance=self.options.tolerance * problem.force_scale,
            energy_noise=ENERGY_NOISE * scale,
            force_scale=problem.force_scale,
            max_iterations=self.options.max_iterations,
            history=self.history,
            steps=self.steps,
            callback=self.callback,
            constraint=constraint,
            turning_about=_held_node(free) if rotation == "free" else None,
            # isotropic problems only: on the robustness suite's orthotropic deep cap and
            # steep saddle the absolute tangents led to other minima (docs/benchmarks.md)
            absolute_after_short_steps=not problem.orientation_matters,
            exact_tangent_below=exact_tangent_below(
                _softness(problem), isotropic=not problem.orientation_matters
            ),
        )


def _softness(problem: Problem) -> float:
    """The softness of the problem's shear modes relative to its stiffness scale
    (:func:`~vares.solver.newton.exact_tangent_below`): the law's
    (:meth:`~vares.materials.Hyperelastic.softness`) where the yarn strains are locking-free
    (``"smoothed"``, ``"paired"``); unknown (``nan``) cell by cell, where stiff yarns lock the
    shear of linear triangles and the discrete problem is stiffer along it than the law (the
    2,400-cell hemisphere at E/G = 1e6 from the default start: with the law's softness the
    projected steps crept at relative residuals of 1e-5–1e-6 and the warp alignment failed)."""
    if problem.yarn_strain == "element":
        return float("nan")
    return problem.material.softness(problem.fibres)


def _held_node(free: np.ndarray) -> int:
    """The node whose translation is held (both its dofs fixed)."""
    return int(np.flatnonzero(~free.reshape(-1, 2).any(axis=1))[0])


def _folded_start(problem: Problem, start: Start) -> str | None:
    """Why the start cannot be used (it inverts cells), or ``None``."""
    inverted = problem.inverted_cells(start.coordinates)
    if not inverted.size:
        return None
    source = {"projection": "the projection onto the plane", "lscm": "the conformal map"}.get(
        start.kind, "the initial guess"
    )
    return (
        f"{source} inverts {describe_cells(inverted)}; choose another plane or supply an "
        "initial guess that does not fold"
    )


def _warp_along_x(x: np.ndarray, fibres: Fibres, ctx: NewtonContext) -> tuple[np.ndarray, Fibres]:
    """The pattern (and every recorded step) turned so the warp runs along +x, as it comes off
    the roll, and the fibres turned with it."""
    turn = fibre_angle(fibres.warp)
    for index, record in enumerate(ctx.steps):
        if record.coordinates is not None:
            ctx.steps[index] = replace(record, coordinates=rotated(record.coordinates, -turn))
    return rotated(x, -turn), Fibres.from_angles(0.0, fibre_angle(fibres.fill) - turn)
