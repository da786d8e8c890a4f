"""Warnings about a solved pattern: what a pattern maker should look at before cutting."""

from __future__ import annotations

from ..solver.result import PatternResult
from .compensation import CompensationReport

__all__ = ["pattern_warnings"]


def pattern_warnings(result: PatternResult, report: CompensationReport | None) -> list[str]:
    """One sentence per concern: not converged; stopped at the round-off floor above the
    tolerance; compression (wrinkling risk); large area distortion; slack yarns under a
    prestress; the warp off its prescribed direction."""
    notes = []
    if not result.converged:
        notes.append(f"the solve did not converge: {result.reason}")
        return notes
    attained = result.final_relative_residual
    if attained is not None and attained > result.options.tolerance:
        notes.append(
            f"converged to the round-off floor of this mesh: relative residual {attained:.2g} "
            f"(tolerance {result.options.tolerance:g}); ill-shaped cells limit the accuracy"
        )
    fields = result.fields
    area = fields["surface_area"]
    total = area.sum()
    wrinkling = float(area[fields["wrinkling"] > 0].sum() / total)
    if wrinkling > 0:
        notes.append(
            f"compressive principal stress (wrinkling risk) on {100 * wrinkling:.1f} % of the area"
        )
    det_f = fields["det_F"]
    if det_f.min() < 0.95 or det_f.max() > 1.05:
        notes.append(f"large area distortion: det F from {det_f.min():.3f} to {det_f.max():.3f}")
    if report is not None:
        for yarn in ("warp", "fill"):
            y = getattr(report, yarn)
            if y.target_mean > 0 and y.slack_area_fraction > 0:
                notes.append(
                    f"{yarn} force below {report.slack_threshold:g} (slack risk) on "
                    f"{100 * y.slack_area_fraction:.1f} % of the area"
                )
    if result.warp_deviation is not None and abs(result.warp_deviation) > 0.1:
        notes.append(f"mean warp deviation {result.warp_deviation:.3g}° from the direction")
    return notes
