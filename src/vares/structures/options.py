"""The options of a structure, declared once (see :mod:`vares.options`)."""

from __future__ import annotations

from dataclasses import dataclass

from ..options import Options, option

__all__ = ["StructureOptions"]


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
        "Usable fabric roll width (mesh units): panels wider across the warp are reported.",
        section="structure",
        positive=True,
    )
