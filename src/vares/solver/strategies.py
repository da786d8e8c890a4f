"""Solution strategies: the paths from the initial guess to the optimal pattern.

All strategies minimise the same energy (:class:`vares.mechanics.Problem`) with the consistent
tangent; they differ in the path they take:

``"newton"``
    Full Newton steps on the final surface from the initial guess.
``"pseudo-time"``
    The homotopy of the method (docs/method.md): the surface is raised from its projection onto
    the initial-guess plane (where the projection is the exact solution) to its true shape in
    ``steps`` equal steps, prestress ramped alike; each step is solved by Newton from the
    previous pattern. A step that fails is halved (cut back) and retried.
``"damping"``
    Newton with a proximal term ``(c/2)‖X − X_k‖²`` (Levenberg–Marquardt): steps that would
    raise the energy or invert a cell are rejected and ``c`` grows; ``c`` shrinks with the
    residual so the final convergence stays quadratic.
``"auto"`` (default)
    Globalised Newton (step bound, line search, projected tangent far from the solution); if it
    fails, pseudo-time stepping with it from the projection, then damped pseudo-time stepping
    (or, from a conformal start, damping resumed where the globalised Newton stopped).

Inverted pattern cells (``det J ≤ 0``) are never accepted.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..geometry.flatten import ProjectionPlane
from ..mechanics.problem import Problem
from .newton import Failure, NewtonContext, newton

__all__ = ["FREE_ROTATION", "Attempt", "follow_plan", "plan", "pseudo_time", "turn_free"]

#: The name of the step that lets a pattern solved with its rotation held turn freely.
FREE_ROTATION = "free rotation"

#: Pseudo-time steps are not cut back below this length.
MIN_STEP = 1.0 / 1024


@dataclass(frozen=True)
class Attempt:
    """One attempt of a strategy: its name, its pseudo-time targets (``None``: the whole surface
    at once) and the Newton method of :func:`vares.solver.newton.newton`."""

    name: str
    taus: tuple[float, ...] | None
    method: str


def plan(strategy: str, steps: int, have_plane: bool) -> list[Attempt]:
    """The sequence of attempts of a strategy (the next one runs when one fails)."""
    uniform = tuple(np.arange(1, steps + 1) / steps)
    if strategy == "newton":
        return [Attempt("newton", None, "full")]
    if strategy == "damping":
        return [Attempt("damping", None, "damped")]
    if strategy == "pseudo-time":
        return [Attempt("pseudo-time", uniform, "full")]
    quarters = (0.25, 0.5, 0.75, 1.0)
    if have_plane:  # auto
        return [
            Attempt("globalised newton", None, "line-search"),
            Attempt("pseudo-time", quarters, "line-search"),
            Attempt("damped pseudo-time", quarters, "damped"),
        ]
    return [Attempt("globalised newton", None, "line-search"), Attempt("damping", None, "damped")]


def follow_plan(
    problem: Problem,
    start: np.ndarray,
    plane: ProjectionPlane | None,
    attempts: Sequence[Attempt],
    ctx: NewtonContext,
    damping: float,
    step: int = 1,
) -> tuple[np.ndarray, list[str], str | None]:
    """Run the attempts until one converges: ``(pattern, names tried, reason of the last
    failure or None)``. A whole-surface attempt goes on from where the last one stopped (never
    inverted, lower energy than the start); pseudo-time stepping starts again from ``start``.
    ``step`` numbers the whole-surface attempts' records (the warp alignment's secant step)."""
    path: list[str] = []
    reason = folding = None
    x = resume = start
    for attempt in attempts:
        path.append(attempt.name)
        try:
            if attempt.taus is None:
                x = ctx.attempt(
                    attempt.name,
                    step,
                    1.0,
                    lambda a=attempt, x0=resume: newton(
                        problem,
                        x0,
                        ctx,
                        strategy=a.name,
                        step=step,
                        tau=1.0,
                        method=a.method,
                        damping=damping,
                    ),
                )
            else:
                x = pseudo_time(problem, plane, start, attempt, ctx, damping)
            return x, path, None
        except Failure as failure:
            reason, x = failure.reason, failure.coordinates
            if failure.folding:
                folding = failure.reason
            if attempt.taus is None:
                resume = x
    # a minimum beyond a fold explains the later attempts' failures better than they do
    return x, path, folding or reason


def pseudo_time(
    base: Problem,
    plane: ProjectionPlane,
    start: np.ndarray,
    attempt: Attempt,
    ctx: NewtonContext,
    damping: float,
) -> np.ndarray:
    """Pseudo-time stepping over the planned targets with cut-back on failure."""
    planned = [float(t) for t in attempt.taus]
    x, tau = start, 0.0
    step = 0
    while planned:
        target = planned[0]
        step += 1
        problem = (
            base
            if target == 1.0
            else base.with_surface(plane.lift(base.points, target), prestress_factor=target)
        )
        try:
            x = ctx.attempt(
                attempt.name,
                step,
                target,
                lambda p=problem, x0=x, s=step, t=target: newton(
                    p,
                    x0,
                    ctx,
                    strategy=attempt.name,
                    step=s,
                    tau=t,
                    method=attempt.method,
                    damping=damping,
                ),
            )
        except Failure as failure:
            if target - tau <= MIN_STEP:
                raise Failure(
                    f"{failure.reason} at τ = {target:.4g}; step size fell below {MIN_STEP:.3g}",
                    x,
                ) from None
            planned.insert(0, 0.5 * (tau + target))
            continue
        tau = planned.pop(0)
    return x


def turn_free(
    problem: Problem, coordinates: np.ndarray, ctx: NewtonContext, damping: float
) -> tuple[np.ndarray, list[str], str | None]:
    """From a pattern solved with its rotation held, the pattern free to turn (``ctx`` holds
    only its translation and names the held node in ``turning_about``): globalised Newton with
    the rotation as an explicit unknown (:mod:`vares.solver.turning`); should that fail,
    globalised Newton whose steps turn by their least-squares turn, then damping, from where
    it stopped. ``(pattern, names tried, reason of the last failure or None)``."""
    ctx.turning = True
    try:
        x = ctx.attempt(
            FREE_ROTATION,
            1,
            1.0,
            lambda: newton(problem, coordinates, ctx, strategy=FREE_ROTATION, step=1, tau=1.0),
        )
        return x, [FREE_ROTATION], None
    except Failure as failure:
        resume = failure.coordinates
    finally:
        ctx.turning = False
    attempts = [
        Attempt("globalised newton", None, "line-search"),
        Attempt("damping", None, "damped"),
    ]
    x, path, reason = follow_plan(problem, resume, None, attempts, ctx, damping)
    return x, [FREE_ROTATION, *path], reason
