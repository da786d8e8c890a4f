"""A stiff fibre law reached through softer ones: continuation in the yarn-to-shear ratio.

With yarns a million times stiffer than the shear (carbon fabrics, prepregs) Newton's method
from a pattern far from the solution crawls: the energy is a stiff penalty on the yarn
stretches, whose constraint surface is curved, and full steps along it raise the energy, so
the line search cuts them (docs/locking.md). The law's yarn part scaled down to softer ratios
(:class:`~vares.mechanics.yarn_laws.ScaledYarns`) is solved first, each stage from the last
pattern, the law itself last. The stages' patterns lie on a smooth path in ``ε = 1/ratio``
(``X(ε) = X₀ + ε X₁ + …``, the inextensible pattern and its first correction): from the third
stage on, the start is the linear extrapolation in ``ε`` of the two before, which takes out
the first-order change, and Newton begins next to the solution.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..geometry.flatten import inverted_cells
from ..geometry.mesh import SurfaceMesh
from ..materials import Hyperelastic, MaterialError
from ..mechanics.yarn_laws import ScaledYarns, yarn_to_shear_ratio
from ..options import OptionsError
from .options import SolveOptions
from .result import PatternResult

__all__ = [
    "AUTO_RATIO",
    "MAX_STAGE_SHARE",
    "ContinuationStage",
    "continuation_ratios",
    "solve_in_stages",
    "stage_label",
]

#: The share of a stage's yarn part kept per cell is at most this.
MAX_STAGE_SHARE = 0.5
#: ``yarn_continuation = "auto"``: laws of a higher yarn-to-shear ratio, with locking-free yarn
#: stretches, are solved through one stage at this ratio (docs/locking.md: on the shipped rib,
#: E/G 1e5 in 43 iterations through it against 204 directly, 1e6 in 43 against 1,903).
AUTO_RATIO = 1e4

#: Solves one stage: ``(law, options, initial pattern or None) → PatternResult``.
StageSolve = Callable[[Hyperelastic, SolveOptions, "np.ndarray | None"], PatternResult]


@dataclass(frozen=True)
class ContinuationStage:
    """One stage: its yarn-to-shear ratio, the share of its yarn part kept per cell, whether
    the warp was aligned (else the rotation of the stage before held), whether it started from
    the extrapolation of the two stages before, and how its solve went."""

    ratio: float
    stabilisation: float
    aligned: bool
    extrapolated: bool
    converged: bool
    iterations: int
    elapsed: float


def stage_label(ratio: float) -> str:
    """How a stage names its records: ``"E/G 1e+04"``."""
    return f"E/G {ratio:.3g}"


def checked_ratios(material: Hyperelastic, ratios: Sequence[float]) -> tuple[float, list[float]]:
    """The law's yarn-to-shear ratio and the continuation's ratios, or :class:`OptionsError`:
    the ratios must be positive, ascending and below the law's, the law one of ``(I4, I6, I8)``."""
    out = [float(r) for r in ratios]
    if any(not np.isfinite(r) or r <= 0.0 for r in out) or np.any(np.diff(out) <= 0.0):
        raise OptionsError("yarn_continuation", f"must be ascending positive ratios; got {out}")
    try:
        ratio = yarn_to_shear_ratio(material)
    except MaterialError as exc:
        raise OptionsError("yarn_continuation", f"needs a fibre law: {exc}") from None
    if out and out[-1] >= ratio:
        raise OptionsError(
            "yarn_continuation",
            f"ratios must lie below the law's yarn-to-shear ratio {ratio:.3g}; got {out[-1]:.3g}",
        )
    return ratio, out


def continuation_ratios(material: Hyperelastic, options: SolveOptions) -> tuple[float, ...]:
    """The stages ``options.yarn_continuation`` asks for: its ratios (``"none"``: none), or
    with ``"auto"`` one stage at :data:`AUTO_RATIO` for a law of ``(I4, I6, I8)`` stiffer than
    that whose yarn stretches are smoothed or paired, none else (cell by cell the stiff yarns
    lock the shear of linear triangles, and the stage would reach another pattern)."""
    if options.yarn_continuation == "none":
        return ()
    if options.yarn_continuation != "auto":
        return tuple(options.yarn_continuation)
    if options.yarn_strain == "element":
        return ()
    try:
        ratio = yarn_to_shear_ratio(material)
    except MaterialError:
        return ()
    return (AUTO_RATIO,) if ratio > AUTO_RATIO else ()


def solve_in_stages(
    solve_one: StageSolve,
    mesh: SurfaceMesh,
    material: Hyperelastic,
    options: SolveOptions,
    initial_guess: np.ndarray | None = None,
    *,
    align_up_to: float | None = None,
    extrapolate: bool = True,
) -> tuple[PatternResult, list[ContinuationStage]]:
    """The pattern of ``material`` through the ratios ``options.yarn_continuation``.

    Each stage solves ``ScaledYarns(material, ratio / law's ratio)`` with ``solve_one``, from the
    last stage's pattern, or from the extrapolation in ``1/ratio`` of the two before (where that
    inverts no cell); the first from ``initial_guess`` (or the options' start). Each stage keeps
    the law's per-cell yarn stiffness ``yarn_stabilisation × E`` (its share ``yarn_stabilisation
    × E / E_stage``, at most :data:`MAX_STAGE_SHARE`). With a warp direction the warp is aligned
    at the stages of ratio up to ``align_up_to`` (default: ``options.yarn_align_up_to``, else
    every stage); the later ones hold the yarn angle of the last (the pattern comes back with
    the warp along +x). ``extrapolate`` false: every stage from the last pattern (the
    comparison of docs/locking.md).

    Returns the law's result, its ``history``, ``steps`` and ``strategy`` those of every stage
    (each record's strategy led by :func:`stage_label`) before its own, ``elapsed`` their sum
    and ``options`` the given ones; and the stages, the law's last.
    """
    ratio, ratios = checked_ratios(material, options.yarn_continuation)
    if align_up_to is None:
        align_up_to = options.yarn_align_up_to
    base = options.replace(yarn_continuation=(), yarn_align_up_to=None)
    direction = options.warp_direction
    stages: list[ContinuationStage] = []
    history, steps, path = [], [], []
    solved: list[tuple[float, np.ndarray]] = []  # (1/ratio, pattern) of converged stages
    guess, held_angle, elapsed = initial_guess, None, 0.0
    for stage_ratio in [*ratios, ratio]:
        last = stage_ratio == ratio
        law = material if last else ScaledYarns(material, stage_ratio / ratio)
        share = options.yarn_stabilisation
        if not last:
            share = min(share * ratio / stage_ratio, MAX_STAGE_SHARE)
        aligned = direction is not None and (
            align_up_to is None or stage_ratio <= align_up_to or held_angle is None
        )
        stage_options = base.replace(yarn_stabilisation=share)
        if direction is not None and not aligned:
            stage_options = stage_options.replace(warp_direction=None, warp_angle=held_angle)
        start, extrapolated = _extrapolated(
            mesh, solved if extrapolate else [], 1.0 / stage_ratio, guess
        )
        result = solve_one(law, stage_options, start)
        stages.append(
            ContinuationStage(
                stage_ratio,
                share,
                aligned,
                extrapolated,
                result.converged,
                result.iterations,
                result.elapsed,
            )
        )
        elapsed += result.elapsed
        if last:
            break
        label = stage_label(stage_ratio)
        history += [replace(r, strategy=f"{label}: {r.strategy}") for r in result.history]
        steps += [replace(s, strategy=f"{label}: {s.strategy}") for s in result.steps]
        path += [f"{label}: {name}" for name in result.strategy]
        guess = result.material_coordinates
        if result.converged:
            solved.append((1.0 / stage_ratio, guess))
        else:  # no path to extrapolate along
            solved.clear()
        held_angle = float(np.degrees(np.arctan2(result.fibres.warp[1], result.fibres.warp[0])))
    result.history = history + result.history
    result.steps = steps + result.steps
    result.strategy = path + result.strategy
    result.elapsed = elapsed
    result.options = options
    return result, stages


def _extrapolated(
    mesh: SurfaceMesh, solved: list[tuple[float, np.ndarray]], eps: float, last: np.ndarray | None
) -> tuple[np.ndarray | None, bool]:
    """The start of a stage at ``eps = 1/ratio``: the linear extrapolation of the last two
    solved stages' patterns, unless fewer than two were solved or it inverts a cell (then the
    last pattern). ``(start, whether extrapolated)``."""
    if len(solved) < 2:
        return last, False
    (eps_a, a), (eps_b, b) = solved[-2:]
    start = b + (eps - eps_b) / (eps_b - eps_a) * (b - a)
    if inverted_cells(mesh, start).size:
        return last, False
    return start, True
