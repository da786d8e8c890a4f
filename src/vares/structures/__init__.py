"""Whole structures: panels, the seams between them, and patterns whose seams match."""

from .matching import MatchingRecord, StructureResult, solve_structure
from .options import StructureOptions
from .panels import Panel, split_panels, width_across_warp
from .seams import Seam, SeamReport, find_seams, seam_lengths, seam_marks, seam_reports

__all__ = [
    "MatchingRecord",
    "Panel",
    "Seam",
    "SeamReport",
    "StructureOptions",
    "StructureResult",
    "find_seams",
    "seam_lengths",
    "seam_marks",
    "seam_reports",
    "solve_structure",
    "split_panels",
    "width_across_warp",
]
