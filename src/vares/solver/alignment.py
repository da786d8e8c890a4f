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
    "ALIGNMENT_JUMP",
    "ALIGNMENT_TOLERANCE",
    "JUMP_ANGLE",
    "JUMP_RATIO",
    "MAX_TURNS",
    "SECANT_TURNS",
    "TURNED",
    "align_warp",
    "fibre_angle",
    "initial_fibres",
    "rotated",
]

#: The mean erected warp follows a prescribed direction to this angle (radians).
ALIGNMENT_TOLERANCE = 1e-10
#: Turns of the yarns by the secant iteration alone, and in all.
SECANT_TURNS = 15
MAX_TURNS = 40
#: Two warp angles this close (degrees) whose deviations have both signs and are both larger
#: than ``JUMP_RATIO`` times the angle between them are taken for a jump of the drape between
#: two patterns (a yarn turned by 1e-3° moves by 9 µm over 0.5 m; where the drape changes
#: smoothly, the deviation changes by about the angle the yarns turn, 16 times that on the
#: hemisphere's half spliced through its pole).
JUMP_ANGLE = 1e-3
JUMP_RATIO = 100.0
#: Across such a jump, the pattern whose mean warp deviates less is kept if it deviates by at
#: most this angle (degrees; the hemisphere's half spliced through its pole, stiff yarns:
#: +0.12° and −0.094° on either side of the jump).
ALIGNMENT_JUMP = 0.5
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
    warp), :data:`SECANT_TURNS` turns at most; each new angle is solved from the previous
    pattern, whose rotation stays held, by the attempts :data:`TURNED`
    (:func:`~vares.solver.strategies.follow_plan`). Where that does not align it and two of
    its angles bracket the alignment (deviations of both signs), the bracket is halved, a
    secant step taken instead where it stays inside and the last one halved the deviation, up
    to :data:`MAX_TURNS` turns in all. Where the bracket closes to :data:`JUMP_ANGLE` with the
    deviations at both ends still more than :data:`JUMP_RATIO` times its width, the drape
    jumps between two patterns there (the pattern a turn reaches depends on where its solve
    starts: stiff yarns on a piece of a sphere): the side whose mean warp deviates less is kept
    if that is within :data:`ALIGNMENT_JUMP`, else the alignment fails. Returns the pattern,
    the fibres and the final mean deviation (radians).
    """
    problem = make_problem(fibres)
    offset = _offset(fibres)
    theta = fibre_angle(fibres.warp)
    deviation, _ = warp_deviation(problem.mesh, coordinates, fibres.warp, direction)
    slope = 1.0
    sides: dict[bool, tuple[float, float, np.ndarray, Fibres]] = {}  # by the deviation's sign
    fast = True
    for outer in range(1, MAX_TURNS + 1):
        if abs(deviation) <= ALIGNMENT_TOLERANCE:
            break
        sides[deviation > 0] = (theta, deviation, coordinates, fibres)
        new_theta = theta - np.degrees(deviation / slope)
        if outer > SECANT_TURNS:
            if len(sides) < 2:
                break
            low, high = sorted((sides[True][0], sides[False][0]))
            nearest = min(abs(np.degrees(side[1])) for side in sides.values())
            if high - low <= JUMP_ANGLE and nearest > JUMP_RATIO * (high - low):
                return _across_jump(sides)
            if not (fast and low < new_theta < high):
                new_theta = 0.5 * (low + high)
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
        fast = abs(new_deviation) <= 0.5 * abs(deviation)
        theta, deviation = new_theta, new_deviation
    if abs(deviation) > ALIGNMENT_TOLERANCE:
        raise Failure(
            f"the warp could not be aligned with the direction (mean deviation "
            f"{np.degrees(deviation):.3g}°)",
            coordinates,
        )
    return coordinates, fibres, deviation


def _across_jump(sides: dict) -> tuple[np.ndarray, Fibres, float]:
    """The pattern of the bracket's side whose mean warp deviates less, where the deviation
    jumps across the bracket (:func:`align_warp`); a failure if it deviates by more than
    :data:`ALIGNMENT_JUMP`."""
    theta, deviation, coordinates, fibres = min(sides.values(), key=lambda side: abs(side[1]))
    plus, minus = (np.degrees(sides[key][1]) for key in (True, False))
    if abs(np.degrees(deviation)) > ALIGNMENT_JUMP:
        raise Failure(
            f"the warp could not be aligned with the direction: the drape jumps between two "
            f"patterns as the yarns turn through {theta:.6g}° in the pattern (mean deviation "
            f"{plus:+.3g}° on one side, {minus:+.3g}° on the other)",
            coordinates,
        )
    return coordinates, fibres, deviation
