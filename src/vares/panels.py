"""The structure functions under the name they had in vares 0.1 (now :mod:`vares.structures`)."""

from .structures import (
    Panel,
    Seam,
    SeamReport,
    StructureResult,
    find_seams,
    solve_structure,
    split_panels,
)

__all__ = [
    "Panel",
    "Seam",
    "SeamReport",
    "StructureResult",
    "find_seams",
    "solve_structure",
    "split_panels",
]
