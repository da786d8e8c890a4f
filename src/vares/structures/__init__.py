"""Whole structures: panels, the seams between them, patterns whose seams match, a surface cut
into strips of roll width and nested on the roll, and laminates (stacks of plies on a mould)."""

from typing import TYPE_CHECKING

from .._lazy import lazy_exports

if TYPE_CHECKING:
    from .cutting import CutResult, cut
    from .laminate import Laminate, LaminateResult, Ply, drape_laminate
    from .laminate_options import LaminateOptions, PlyOptions
    from .matching import MatchingRecord, StructureResult, solve_structure
    from .options import CutOptions, StructureOptions
    from .panels import Panel, split_panels, width_across_warp
    from .seams import Seam, SeamReport, find_seams, seam_lengths, seam_marks, seam_reports

__getattr__, __dir__, __all__ = lazy_exports(__name__, __file__)
