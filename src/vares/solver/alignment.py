"""Warp alignment: turn the yarns in the pattern until the erected warp follows a 3D direction.

The yarns of a panel are straight in the pattern; erected, the warp runs along ``F Φ₁``. When the
designer names a 3D direction instead of an angle in the pattern, the warp angle becomes an
unknown fixed by one scalar condition: the 3D-area-weighted mean deviation of the erected warp
from the direction (:func:`vares.geometry.warp_deviation`) is zero.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..geometry.orientation import warp_deviation
from ..materials import Fibres
from ..mechanics.problem import Problem
from .newton import Failure, NewtonContext
from .strategies import Attempt, follow_plan

__all__ = [
    "ALIGNMENT_TOLERANCE",
    "TURNED",
    "align_warp",
    "fibre_angle",
    "initial_fibres",
    "rotated",
]

#: The mean erected warp follows a prescribed direction to this angle (radians).
ALIGNMENT_TOLERANCE = 1e-10
#: How each turn of the yarns is solved from the previous pattern: globalised Newton, then
#: damping from where it stopped.
TURNED = (
    Attempt("warp alignment", None, "line-search"),
    Attempt("warp alignment, damped", None, "damped"),
)


def fibre_angle(vector: np.ndarray) -> float:
    """Angle of a pattern direction from the x-axis, degrees."""
    return float(np.degrees(np.arctan2(vector[1], vector[0])))


def rotated(coordinates: np.ndarray, degrees: float) -> np.ndarray:
    """Points ``(n, 2)`` turned counter-clockwise by ``degrees`` about the origin."""
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return coordinates @ np.array([[c, s], [-s, c]])


def _offset(fibres: Fibres) -> float:
    """Angle from the warp to the fill, degrees."""
    return fibre_angle(fibres.fill) - fibre_angle(fibres.warp)


def initial_fibres(
    fibres: Fibres, warp_angle: float, start: np.ndarray, problem: Problem, direction: np.ndarray
) -> Fibres:
    """The yarns turned so that the initial guess meets the direction."""
    deviation, _ = warp_deviation(problem.mesh, start, fibres.warp, direction)
    theta = warp_angle - np.degrees(deviation)
    return Fibres.from_angles(theta, theta + _offset(fibres))


def align_warp(
    make_problem: Callable[[Fibres], Problem],
    coordinates: np.ndarray,
    fibres: Fibres,
    direction: np.ndarray,
    ctx: NewtonContext,
    damping: float,
) -> tuple[np.ndarray, Fibres, float]:
    """Turn the fibres in the pattern until the mean erected warp follows ``direction``.

    Secant iteration on the warp angle (the deviation changes by about the same angle as the
    warp); each new angle is solved from the previous pattern, whose rotation stays held, by
    the attempts :data:`TURNED` (:func:`~vares.solver.strategies.follow_plan`). Returns the
    pattern, the fibres and the final mean deviation (radians).
    """
    problem = make_problem(fibres)
    offset = _offset(fibres)
    theta = fibre_angle(fibres.warp)
    deviation, _ = warp_deviation(problem.mesh, coordinates, fibres.warp, direction)
    slope = 1.0
    for outer in range(1, 16):
        if abs(deviation) <= ALIGNMENT_TOLERANCE:
            break
        new_theta = theta - np.degrees(deviation / slope)
        fibres = Fibres.from_angles(new_theta, new_theta + offset)
        if problem.orientation_matters:
            problem = make_problem(fibres)
            coordinates, _, reason = follow_plan(
                problem, coordinates, None, TURNED, ctx, damping, step=outer
            )
            if reason is not None:
                raise Failure(reason, coordinates)
        new_deviation, _ = warp_deviation(problem.mesh, coordinates, fibres.warp, direction)
        if new_theta != theta and new_deviation != deviation:
            slope = (new_deviation - deviation) / np.radians(new_theta - theta)
        theta, deviation = new_theta, new_deviation
    if abs(deviation) > ALIGNMENT_TOLERANCE:
        raise Failure(
            f"the warp could not be aligned with the direction (mean deviation "
            f"{np.degrees(deviation):.3g}°)",
            coordinates,
        )
    return coordinates, fibres, deviation
