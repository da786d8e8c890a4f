"""The options of a structure and of cutting a surface into strips, declared once (see
:mod:`vares.options`)."""

from __future__ import annotations

from dataclasses import dataclass

from ..geometry.cutting import SNAP
from ..geometry.line_families import LAYOUTS
from ..options import Options, OptionsError, option

__all__ = ["CROSS_SEAMS", "EDGE_TYPES", "INTERLOCK", "SEAM_LINES", "CutOptions", "StructureOptions"]

#: Kinds of cutting lines: computed, or the user's curves.
SEAM_LINES = ("geodesic", "planar", "curves")
#: Kinds of panel edge along the surface's boundary (each has its own allowance).
EDGE_TYPES = ("free", "cable", "clamp")
#: Whether strips are planned to lie in pairs on the roll (``auto``: where that saves roll).
INTERLOCK = ("auto", "always", "never")
CROSS_SEAMS = ("auto", "never")


@dataclass(frozen=True)
class StructureOptions(Options):
    """How the panels of a structure are patterned together."""

    title = "structure option"

    match_seams: bool = option(
        True,
        "bool",
        "Solve the panels together so that every seam has the same length on both sides.",
        section="structure",
        flags=("--match/--no-match",),
    )
    roll_width: float | None = option(
        None,
        "float",
        "Usable fabric roll width (mesh units): panels whose patterns (inside the seam lines) "
        "are wider across the warp are reported. A cut has its own (cut option roll_width).",
        section="structure",
        positive=True,
    )


def _allowance(help: str) -> object:
    return option(
        None, "float", help + " (DXF units; default: the seam allowance).", section="cut", minimum=0
    )


@dataclass(frozen=True)
class CutOptions(Options):
    """How a surface is cut into strips of roll width and nested on the roll."""

    title = "cut option"

    roll_width: float = option(
        None,
        "float",
        "Usable fabric roll width (mesh units): every strip's cut outline, allowances "
        "included, fits it.",
        section="cut",
        positive=True,
        optional=False,
    )
    seams: str = option(
        "geodesic",
        "str",
        "Cutting lines: geodesic, planar (plane sections), or curves (the curves file).",
        section="cut",
        choices=SEAM_LINES,
        flags=(),
    )
    curves: str | None = option(
        None,
        "path",
        "File of cutting lines: polylines (text, one 'x y z' per line, a blank line between "
        "curves) or a Rhino 3dm file.",
        section="cut",
        flags=(),
    )
    curves_layer: str | None = option(
        None, "str", "Layer of the 3dm file whose curves are the cutting lines.", section="cut"
    )
    layout: str = option(
        "auto",
        "str",
        "Strips side by side (parallel), running down from the high point (radial), or auto "
        "(radial when the highest boundary is a ring or the high point is inside).",
        section="cut",
        choices=LAYOUTS,
    )
    strip_direction: tuple[float, float, float] | None = option(
        None,
        "vector",
        "3D direction 'x,y,z' the parallel strips run along (default: the surface's longer side).",
        section="cut",
    )
    edge_type: str = option(
        "free",
        "str",
        "What the surface's boundary is: a free (hemmed) edge, a cable pocket or a clamp edge.",
        section="cut",
        choices=EDGE_TYPES,
    )
    high_edge_type: str | None = option(
        None,
        "str",
        "What the highest boundary loop (a tent's ring) is (default: edge type).",
        section="cut",
        choices=EDGE_TYPES,
    )
    free_allowance: float | None = _allowance("Allowance along free edges")
    cable_allowance: float | None = _allowance("Allowance along cable pockets")
    clamp_allowance: float | None = _allowance("Allowance along clamp edges")
    interlock: str = option(
        "auto",
        "str",
        "Plan tapered strips to lie in pairs on the roll, head to tail, the warp along one seam "
        "of each: auto (where that saves at least a tenth of the roll), always or never.",
        section="cut",
        choices=INTERLOCK,
    )
    cross_seams: str = option(
        "auto",
        "str",
        "Cut strips across into pieces, each with its warp along it, where whole strips fit no "
        "roll of this width however many there are (their flattened strips bow): auto or never.",
        section="cut",
        choices=CROSS_SEAMS,
    )
    allow_turn: bool = option(
        True,
        "bool",
        "Nesting may turn a piece by 180° (the warp stays along the roll).",
        section="cut",
        flags=("--turn/--no-turn",),
    )
    nest_time: float = option(
        10.0,
        "float",
        "Bound on the nesting search's time (seconds); a search that ends by itself within "
        "it gives the same nest for the same input (strips in pairs need no search).",
        section="cut",
        positive=True,
    )
    nest_seed: int = option(
        0,
        "int",
        "Seed of the nesting search (another seed, another search).",
        section="cut",
        minimum=0,
    )
    piece_gap: float = option(
        0.0, "float", "Gap between nested pieces (DXF units).", section="cut", minimum=0
    )
    snap: float = option(
        SNAP,
        "float",
        "Crossings of a cutting line closer than this fraction of the cell size to a node are "
        "moved onto it (fewer slivers, the line moves a little).",
        section="cut",
        minimum=0,
    )

    def check(self) -> None:
        if self.curves is not None and self.seams != "curves":
            raise OptionsError(None, "a curves file goes with seams = 'curves'")
        if self.curves_layer is not None and self.curves is None:
            raise OptionsError(None, "curves_layer needs a curves file")
        if self.seams == "curves" and self.interlock == "always":
            raise OptionsError(
                "interlock", "strips along your own curves are not planned: use auto or never"
            )
        if self.snap >= 0.5:
            raise OptionsError("snap", f"must be < 0.5; got {self.snap!r}")

    def allowance(self, edge: str, seam_allowance: float) -> float:
        """Allowance of an edge kind (``"seam"`` or one of :data:`EDGE_TYPES`), DXF units."""
        value = None if edge == "seam" else getattr(self, f"{edge}_allowance")
        return seam_allowance if value is None else value
