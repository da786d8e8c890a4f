"""Compensation report: how much smaller the pattern is, and the stress it delivers.

A membrane is cut smaller than its erected shape so that it carries the design prestress once
stretched into place. Per yarn direction the report gives

- the compensation ``1 − pattern length / erected length`` (%), from the yarn stretch;
- the achieved membrane force (thickness × Cauchy stress along the erected yarn, force per
  length) against the target prestress: mean, min, max and the RMS deviation;
- the slack-risk region: cells where the achieved force falls below a threshold.

Means are weighted by the 3D area of the cells.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..solver.result import PatternResult
from .statistics import stress_statistics

__all__ = ["CompensationReport", "YarnReport", "compensation_report"]


@dataclass(frozen=True)
class YarnReport:
    """Compensation and achieved force along one yarn direction (force per length, %)."""

    compensation_mean: float
    compensation_min: float
    compensation_max: float
    target_mean: float
    achieved_mean: float
    achieved_min: float
    achieved_max: float
    rms_deviation: float
    slack_area_fraction: float
    slack_cells: int


@dataclass(frozen=True)
class CompensationReport:
    """Warp and fill reports of one panel, and the slack threshold used."""

    warp: YarnReport
    fill: YarnReport
    slack_threshold: float

    def to_dict(self) -> dict[str, object]:
        return asdict(self)

    def rows(self) -> list[tuple[str, str, str]]:
        """The report as text rows ``(label, warp, fill)`` for tables."""
        formats = (
            ("compensation, mean", lambda y: f"{y.compensation_mean:.3f} %"),
            (
                "compensation, min … max",
                lambda y: f"{y.compensation_min:.3f} … {y.compensation_max:.3f} %",
            ),
            ("target prestress", lambda y: f"{y.target_mean:.4g}"),
            ("achieved, mean", lambda y: f"{y.achieved_mean:.4g}"),
            ("achieved, min … max", lambda y: f"{y.achieved_min:.4g} … {y.achieved_max:.4g}"),
            ("RMS deviation from target", lambda y: f"{y.rms_deviation:.3g}"),
            (
                f"slack: below {self.slack_threshold:g}",
                lambda y: f"{100 * y.slack_area_fraction:.1f} % ({y.slack_cells} cells)",
            ),
        )
        return [(label, text(self.warp), text(self.fill)) for label, text in formats]


def _yarn(fields, yarn: str, target: np.ndarray, thickness: float, threshold: float):
    weight = fields["surface_area"]
    compensation = fields[f"{yarn}_compensation"]
    achieved = thickness * fields[f"{yarn}_stress"]
    forces = stress_statistics(achieved, np.broadcast_to(target, achieved.shape), weight)
    slack = achieved < threshold
    return YarnReport(
        compensation_mean=float(compensation @ weight / weight.sum()),
        compensation_min=float(compensation.min()),
        compensation_max=float(compensation.max()),
        target_mean=forces["intended"],
        achieved_mean=forces["mean"],
        achieved_min=forces["min"],
        achieved_max=forces["max"],
        rms_deviation=forces["rms_deviation"],
        slack_area_fraction=float(weight[slack].sum() / weight.sum()),
        slack_cells=int(slack.sum()),
    )


def compensation_report(result: PatternResult, slack_threshold: float = 0.0) -> CompensationReport:
    """The compensation report of a solved pattern.

    ``slack_threshold`` is a force per length: cells whose achieved warp (or fill) force is
    below it are counted as slack risk (default 0: the yarn is in compression).
    """
    if not np.isfinite(slack_threshold):
        raise ValueError(f"slack_threshold must be finite; got {slack_threshold!r}")
    fields = result.fields
    components = result.prestress if result.prestress is not None else np.zeros((1, 3))
    return CompensationReport(
        warp=_yarn(fields, "warp", components[:, 0], result.thickness, slack_threshold),
        fill=_yarn(fields, "fill", components[:, 1], result.thickness, slack_threshold),
        slack_threshold=float(slack_threshold),
    )
