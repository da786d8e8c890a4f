"""What a pattern does: per-cell results of any pattern, the compensation report, statistics."""

from ..mechanics.fields import FIELD_DESCRIPTIONS, KEY_FIELDS, cell_fields
from .checks import pattern_warnings
from .compensation import CompensationReport, YarnReport, compensation_report
from .evaluate import PatternEvaluation, evaluate
from .statistics import field_statistics

__all__ = [
    "FIELD_DESCRIPTIONS",
    "KEY_FIELDS",
    "CompensationReport",
    "PatternEvaluation",
    "YarnReport",
    "cell_fields",
    "compensation_report",
    "evaluate",
    "field_statistics",
    "pattern_warnings",
]
