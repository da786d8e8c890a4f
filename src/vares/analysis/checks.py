"""Warnings about a solved pattern: what a pattern maker should look at before cutting.

The stresses of a pattern are those *on the design shape*: the pattern forced exactly onto the
surface. Where the surface cannot be made from the pattern without stress (double curvature),
they differ from the intended prestress by a *misfit*. Without a prestress the stresses are the
misfit alone, compressive about as much as tensile on any doubly curved surface: that is no
finding (the ply-stack check, ``vares evaluate``, looks at yarn compression of plies). With a
prestress the warnings are measured against it, so that round-off is not flagged:

- compression (wrinkling risk) where the smaller principal force is below
  −:data:`RELATIVE_COMPRESSION` × the prestress, reported above :data:`AREA_SHARE` of the area;
- the misfit (achieved minus intended yarn force) beyond the intended prestress itself:
  compensation alone cannot hold the design shape there;
- slack yarns, where the achieved force falls below the slack threshold by more than
  :data:`RELATIVE_COMPRESSION` × the prestress;
- a fabric compensated by measured values (``compensate_by = "measured"``) under a prestress
  other than the one they were measured at.
"""

from __future__ import annotations

import numpy as np

from ..materials.compensation_law import MeasuredCompensationLaw
from ..solver.result import PatternResult
from .compensation import CompensationReport

__all__ = ["AREA_SHARE", "RELATIVE_COMPRESSION", "pattern_warnings"]

#: Compression counts below this fraction of the reference stress (prestress, or RMS misfit).
RELATIVE_COMPRESSION = 0.1
#: Regions smaller than this share of the area are not warned of.
AREA_SHARE = 0.01


def pattern_warnings(result: PatternResult, report: CompensationReport | None) -> list[str]:
    """One sentence per concern: not converged; stopped at the round-off floor above the
    tolerance; compression (wrinkling risk); misfit beyond the prestress; slack yarns; large
    area distortion; the warp off its prescribed direction; measured compensation values used
    at another prestress."""
    if not result.converged:
        return [f"the solve did not converge: {result.reason}"]
    notes = []
    attained = result.final_relative_residual
    if attained is not None and attained > result.options.tolerance:
        notes.append(
            f"converged to the round-off floor of this mesh: relative residual {attained:.2g} "
            f"(tolerance {result.options.tolerance:g}); ill-shaped cells limit the accuracy"
        )
    fields = result.fields
    area = fields["surface_area"] / fields["surface_area"].sum()
    force = result.thickness * np.column_stack([fields["warp_stress"], fields["fill_stress"]])
    target = _target(result, len(area))
    if target is not None and float(target.min()) > 0:
        scale = target.min(axis=1)
        compressed = result.thickness * fields["stress_min"] < -RELATIVE_COMPRESSION * scale
        share = float(area[compressed].sum())
        if share > AREA_SHARE:
            notes.append(
                f"compression beyond {100 * RELATIVE_COMPRESSION:g} % of the prestress "
                f"(wrinkling risk) on {100 * share:.1f} % of the area, on the design shape"
            )
        notes += _misfit(force, target, area)
        notes += _slack(force, target, area, report)
    det_f = fields["det_F"]
    if det_f.min() < 0.95 or det_f.max() > 1.05:
        notes.append(f"large area distortion: det F from {det_f.min():.3f} to {det_f.max():.3f}")
    if result.warp_deviation is not None and abs(result.warp_deviation) > 0.1:
        notes.append(f"mean warp deviation {result.warp_deviation:.3g}° from the direction")
    notes += _measured_at(result, target)
    return notes


def _measured_at(result: PatternResult, target: np.ndarray | None) -> list[str]:
    """A law through measured compensation values holds them at the prestress they were
    measured at only (docs/fabrics.md)."""
    if not isinstance(result.material, MeasuredCompensationLaw):
        return []
    warp, fill = result.material.measured_at
    if target is None:
        return [
            f"the fabric's compensation values were measured at the prestress {warp:g}/{fill:g}, "
            "but this pattern has no prestress: it is not compensated"
        ]
    mean = target.mean(axis=0)
    if np.allclose(mean, (warp, fill), rtol=0.05):
        return []
    return [
        f"the fabric's compensation values were measured at the prestress {warp:g}/{fill:g}; "
        f"this pattern's is {mean[0]:.3g}/{mean[1]:.3g} on average: its compensation is the "
        "secant law's, not measured"
    ]


def _target(result: PatternResult, cells: int) -> np.ndarray | None:
    """Intended warp and fill force per cell ``(m, 2)``, or None without a prestress."""
    if result.prestress is None:
        return None
    return np.broadcast_to(result.prestress[:, :2], (cells, 2))


def _misfit(force: np.ndarray, target: np.ndarray, area: np.ndarray) -> list[str]:
    beyond = (np.abs(force - target) > target).any(axis=1)
    share = float(area[beyond].sum())
    if share <= AREA_SHARE:
        return []
    worst = float(np.max(np.abs(force - target) / target))
    return [
        f"the misfit stress exceeds the intended prestress on {100 * share:.1f} % of the area "
        f"(up to {worst:.3g} × it), on the design shape: compensation alone cannot hold the "
        "shape there; add seams (narrower panels) or change the surface"
    ]


def _slack(force, target, area, report: CompensationReport | None) -> list[str]:
    threshold = 0.0 if report is None else report.slack_threshold
    notes = []
    for k, yarn in enumerate(("warp", "fill")):
        slack = force[:, k] < threshold - RELATIVE_COMPRESSION * target[:, k]
        share = float(area[slack].sum())
        if share > AREA_SHARE:
            notes.append(
                f"{yarn} force below {threshold:g} by more than {100 * RELATIVE_COMPRESSION:g} % "
                f"of the prestress (slack risk) on {100 * share:.1f} % of the area, on the "
                "design shape"
            )
    return notes
