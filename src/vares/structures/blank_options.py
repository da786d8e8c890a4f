"""The options of a ply's blank as cut, declared once (see :mod:`vares.options`): the excess along
the mould's edge and the overlaps at its joints. The flags of ``vares drape``
(``--trim-allowance``, ``--splice-overlap``, ``--dart-overlap``) and the laminate's keys
(:class:`~vares.structures.laminate_options.LaminateOptions` and each ply's overlaps reuse them);
:func:`vares.structures.laminate_blanks.blank_outlines` draws them."""

from __future__ import annotations

from dataclasses import dataclass

from ..options import Options, option

__all__ = ["BlankOptions"]


@dataclass(frozen=True)
class BlankOptions(Options):
    """How a ply's blank is cut round its net boundary (module docs)."""

    title = "blank option"

    trim_allowance: float = option(
        0.0,
        "float",
        "Excess round the ply's net boundary along the mould's edge, mesh length units: the "
        "extended (trim) boundary, the cut line of the cutter file (joints take their own).",
        section="drape",
        minimum=0.0,
    )
    splice_overlap: float = option(
        0.0,
        "float",
        "Overlap at the splices, mesh length units: each piece after the first laps over the "
        "pieces before it by this much (its edge along those splices moved out); 0: butt "
        "splices, every piece cut to the splice line.",
        section="drape",
        minimum=0.0,
    )
    dart_overlap: float = option(
        0.0,
        "float",
        "Overlap at the darts, mesh length units: a dart's left lip (as the dart runs in from "
        "its mouth) laps over the right one by this much when it closes; 0: the lips butt, both "
        "cut to the dart line.",
        section="drape",
        minimum=0.0,
    )
