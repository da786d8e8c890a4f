"""Summaries: the key figures of a solve as JSON-ready dictionaries."""

from __future__ import annotations

from ..analysis.statistics import field_statistics
from ..solver.linear import solver_choice
from ..solver.result import PatternResult

__all__ = ["summary"]


def summary(result: PatternResult, **extra: object) -> dict:
    """The key figures of a solve as a JSON-ready dictionary.

    Field statistics are min, max and pattern-area-weighted mean over the cells.
    """
    from .._version import __version__

    mesh = result.mesh
    last = result.history[-1] if result.history else None
    out: dict[str, object] = {
        "vares_version": __version__,
        **extra,
        "converged": result.converged,
        "reason": result.reason,
        "energy": result.energy,
        "iterations": result.iterations,
        "final_relative_residual": None if last is None else last.relative_residual,
        "strategy": result.strategy,
        "options": result.options.to_dict(),
        "linear_solver": result.linear_solver,
        "linear_solver_choice": solver_choice(result.options.linear_solver, result.linear_solver),
        "factorisations": result.factorisations,
        "cg_iterations": result.cg_iterations,
        "elapsed_seconds": result.elapsed,
        "warm_up_seconds": result.warm_up,
        "mesh": {
            "points": mesh.num_points,
            "cells": {t: len(c) for t, c in mesh.cells.items()},
        },
        "material": {"law": type(result.material).__name__, **result.material.parameters},
        "thickness": result.thickness,
        "surface_area": result.surface_area,
        "pattern_area": result.pattern_area,
        "steps": [
            {
                "strategy": s.strategy,
                "step": s.step,
                "tau": s.tau,
                "iterations": s.iterations,
                "converged": s.converged,
                "reason": s.reason,
            }
            for s in result.steps
        ],
    }
    out["fibres"] = {
        "orientation": result.orientation,
        "warp": result.fibres.warp,
        "fill": result.fibres.fill,
        "warp_direction": result.warp_direction,
        "warp_deviation_degrees": result.warp_deviation,
    }
    if result.converged:
        out["fields_on"] = "the design shape: the pattern forced exactly onto the surface"
        out["fields"] = field_statistics(result.fields)
    out["history"] = [
        {
            "strategy": r.strategy,
            "step": r.step,
            "tau": r.tau,
            "iteration": r.iteration,
            "residual": r.residual,
            "relative_residual": r.relative_residual,
            "energy": r.energy,
            "damping": r.damping,
            "factorisations": r.factorisations,
            "cg_iterations": r.cg_iterations,
        }
        for r in result.history
    ]
    return out
