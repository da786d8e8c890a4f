"""What a pattern does: per-cell results of any pattern, the compensation report, statistics,
the erection analysis (the structure built from its patterns) and patterns optimised for it,
and the producibility of a
draped ply and its darts."""

from typing import TYPE_CHECKING

from .._lazy import lazy_exports

if TYPE_CHECKING:
    from ..mechanics.fields import FIELD_DESCRIPTIONS, KEY_FIELDS, cell_fields
    from .checks import pattern_warnings
    from .compensation import CompensationReport, YarnReport, compensation_report
    from .dart_options import DartOptions
    from .darts import DartedPattern, solve_with_darts
    from .drape import PlyDrape, drape_ply
    from .drape_options import DrapeOptions
    from .erection import ErectionResult, erect
    from .erection_model import Pattern
    from .erection_optimum import OptimisedPatterns, optimise_for_erection, optimised_results
    from .evaluate import PatternEvaluation, evaluate
    from .options import ErectionOptions
    from .producibility import Producibility, producibility
    from .statistics import field_statistics

__getattr__, __dir__, __all__ = lazy_exports(__name__, __file__)
