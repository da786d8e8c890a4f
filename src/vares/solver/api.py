"""The cutting pattern of one surface: :func:`solve`.

It puts the pieces of this package together: the options, the initial guess, the rigid modes,
the strategy's attempts, and (for a prescribed 3D warp direction) the warp alignment; and it
returns a :class:`PatternResult` whether or not the solve converged.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from ..geometry.mesh import SurfaceMesh
from ..materials import Fibres, Hyperelastic
from ..mechanics.assembly import Assembler
from ..mechanics.problem import Problem
from ..mechanics.rigid import rigid_modes
from ..options import split_settings, takes_options
from .alignment import align_warp, fibre_angle, initial_fibres, rotated
from .linear import get_solver
from .newton import Failure, NewtonContext, describe_cells
from .options import SolveOptions
from .result import IterationRecord, PatternResult
from .start import Start, initial_guess
from .strategies import follow_plan, plan

__all__ = ["solve"]

#: Energy changes below this fraction of stiffness × thickness × area are round-off.
ENERGY_NOISE = 1e-13


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
        Always returned; ``converged`` and ``reason`` tell whether and why not.
    """
    given = settings.pop("initial_guess", None)
    if given is not None and isinstance(given, str):
        settings["initial_guess"], given = given, None
    (options,) = split_settings(settings, [options or SolveOptions()])
    started = time.perf_counter()
    fibres = Fibres.from_angles(options.warp_angle, options.fill_angle)

    def make_problem(fibres: Fibres) -> Problem:
        return Problem(mesh, material, thickness, fibres=fibres, prestress=prestress)

    problem = make_problem(fibres)
    start = initial_guess(mesh, options, given)
    direction = None if options.warp_direction is None else np.array(options.warp_direction)
    rotation = options.orientation if problem.orientation_matters else "fixed"
    free, constraint = rigid_modes(start.coordinates, rotation)
    ctx = NewtonContext(
        assembler=Assembler(mesh, free),
        linear_solver=get_solver(options.linear_solver),
        residual_tolerance=options.tolerance * problem.force_scale,
        energy_noise=ENERGY_NOISE * material.stiffness_scale * problem.thickness * mesh.area,
        force_scale=problem.force_scale,
        max_iterations=options.max_iterations,
        history=[],
        steps=[],
        callback=callback,
        constraint=constraint,
    )
    path: list[str] = []
    x, deviation = start.coordinates, None
    reason = _folded_start(problem, start)
    if reason is None:
        if direction is not None:
            fibres = initial_fibres(fibres, options.warp_angle, x, problem, direction)
            problem = make_problem(fibres)
        attempts = plan(options.strategy, options.steps, start.plane is not None)
        x, path, reason = follow_plan(problem, x, start.plane, attempts, ctx, options.damping)
        if reason is None and direction is not None:
            path.append("warp alignment")
            try:
                x, fibres, deviation = align_warp(
                    make_problem, x, fibres, direction, ctx, options.damping
                )
            except Failure as failure:
                reason, x = failure.reason, failure.coordinates
            x, fibres = _warp_along_x(x, fibres, ctx)
            problem = make_problem(fibres)
    return PatternResult(
        mesh=mesh,
        material=material,
        thickness=problem.thickness,
        material_coordinates=x,
        converged=reason is None,
        reason=reason,
        energy=problem.energy(x),
        history=ctx.history,
        steps=ctx.steps,
        strategy=path,
        linear_solver=ctx.linear_solver.name,
        elapsed=time.perf_counter() - started,
        options=options,
        fibres=fibres,
        prestress=problem.prestress,
        plane=start.plane,
        orientation="direction" if direction is not None else rotation,
        initial_guess=start.kind,
        warp_direction=direction,
        warp_deviation=None if deviation is None else float(np.degrees(deviation)),
    )


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
