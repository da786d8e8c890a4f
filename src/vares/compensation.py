"""The compensation report under the name it had in vares 0.1 (now :mod:`vares.analysis`)."""

from .analysis.compensation import CompensationReport, YarnReport, compensation_report

__all__ = ["CompensationReport", "YarnReport", "compensation_report"]
