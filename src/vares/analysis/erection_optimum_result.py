"""What :func:`~vares.analysis.erection_optimum.optimise_for_erection` returns: the optimised
patterns, the erections of the starting and the optimised patterns and the record of every
iteration; and the solves' results with the optimised patterns in their place."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..mechanics.problem import Problem
from ..solver.result import PatternResult
from .erection import ErectionResult
from .erection_model import Pattern

__all__ = ["OptimisedPatterns", "OptimumRecord", "optimised_results"]


@dataclass(frozen=True)
class OptimumRecord:
    """One iteration: the objective ``J`` and its force and shape parts, the erected RMS force
    deviation, the largest and RMS shape deviation, the largest seam mismatch (length units),
    the damping ``μ``, LSQR's iterations, whether the step was taken, the Newton iterations
    of its trial erection, the gain ratio (the decrease of ``J`` against the Gauss–Newton
    model's) and the step's largest edge strain."""

    iteration: int
    objective: float
    force_part: float
    shape_part: float
    force_rms: float
    deviation_max: float
    deviation_rms: float
    seam_mismatch: float
    damping: float
    lsqr_iterations: int
    accepted: bool
    erection_iterations: int = 0
    gain: float = 0.0
    step_strain: float = 0.0


@dataclass
class OptimisedPatterns:
    """The optimised patterns (one :class:`Pattern` per panel, as given), the erections of the
    starting and of the optimised patterns, the iterations and why it stopped; ``tightening``:
    the Newton iterations of erecting the optimum again to the full tolerance (None where its
    trial's erection already met it, or nothing was optimised)."""

    patterns: list[Pattern]
    start: ErectionResult
    erected: ErectionResult
    history: list[OptimumRecord]
    converged: bool
    reason: str | None
    shape_weight: float
    shape_bound: float | None = None
    elapsed: float = 0.0
    tightening: int | None = None

    @property
    def iterations(self) -> int:
        return sum(1 for r in self.history if r.iteration > 0)

    @property
    def newton_iterations(self) -> int:
        """The Newton iterations of the erections made after the start's: the trials' and the
        optimum's final one."""
        return sum(r.erection_iterations for r in self.history) + (self.tightening or 0)

    def to_dict(self) -> dict[str, object]:
        """What ``erect.json`` holds under ``optimisation``: the optimiser's settings and
        iterations, and the erected figures of the starting (VaReS) patterns beside which the
        file's own figures are those of the optimised ones."""
        return {
            "converged": self.converged,
            "reason": self.reason,
            "iterations": self.iterations,
            "newton_iterations": self.newton_iterations,
            "shape_weight": self.shape_weight,
            "shape_bound": self.shape_bound,
            "elapsed_seconds": self.elapsed,
            "start_erected": {
                "deviation": self.start.deviation(),
                **self.start.statistics(),
            },
            "history": [
                {
                    "iteration": r.iteration,
                    "objective": r.objective,
                    "force_rms": r.force_rms,
                    "deviation_max": r.deviation_max,
                    "seam_mismatch": r.seam_mismatch,
                    "accepted": r.accepted,
                }
                for r in self.history
            ],
        }


def optimised_results(
    results: list[PatternResult], optimum: OptimisedPatterns
) -> list[PatternResult]:
    """The solves' results with the optimised patterns in place of theirs (energy on the design
    shape and per-cell fields of the new patterns; the rest, history included, as solved)."""
    out = []
    for result, pattern in zip(results, optimum.patterns, strict=True):
        coordinates = np.asarray(pattern.material_coordinates, dtype=float)
        problem = Problem(
            result.mesh,
            result.material,
            result.thickness,
            fibres=result.fibres,
            prestress=result.prestress,
        )
        out.append(
            replace(
                result,
                material_coordinates=coordinates,
                energy=float(problem.energy(coordinates)),
                _fields=None,
            )
        )
    return out
