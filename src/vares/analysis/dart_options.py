"""The options of a ply's darts and splices, declared once (see :mod:`vares.options`): the flags
of ``vares drape`` (``--darts auto``, ``--dart-lines FILE``, ``--splice-lines FILE``,
``--splices auto``) and the keywords of :func:`vares.analysis.darts.solve_with_darts`."""

from __future__ import annotations

from dataclasses import dataclass

from ..options import Options, OptionsError, option

__all__ = ["DartOptions"]


@dataclass(frozen=True)
class DartOptions(Options):
    """Whether and how darts are placed where a ply's shear reaches its locking angle (see
    :mod:`vares.analysis.darts`)."""

    title = "dart option"

    darts: str = option(
        "none",
        "str",
        "Darts where the pattern's shear reaches the locking angle: 'auto' places them, solves "
        "the pattern again with them open and lengthens them until the shear is below it.",
        section="drape",
        choices=("none", "auto"),
    )
    dart_lines: str | None = option(
        None,
        "path",
        "Dart lines of your own: a curves file (points 'x y z', a blank line between two "
        "lines, or a 3dm file), each from the boundary into the mould; replaces --darts auto.",
        section="drape",
    )
    splice_lines: str | None = option(
        None,
        "path",
        "Splice lines: a curves file (as --dart-lines), each from the boundary across the mould "
        "to the boundary; the ply is cut into pieces along them and each piece's pattern solved "
        "(for shear darts cannot relieve: where the mould is negatively curved).",
        section="drape",
    )
    splices: str = option(
        "none",
        "str",
        "Splices where the ply's shear reaches the locking angle: 'auto' cuts it through its "
        "seed along the warp or the fill (the diagonals where neither relieves it; both axes "
        "where one line does not) and solves the pieces.",
        section="drape",
        choices=("none", "auto"),
    )
    dart_tip: float = option(
        0.8,
        "float",
        "An automatic dart ends where the shear falls below this fraction (at most 1) of the "
        "locking angle.",
        section="drape",
        positive=True,
    )
    dart_step: float = option(
        0.1,
        "float",
        "Each further round lowers the darts' tip angle by this fraction of the locking angle.",
        section="drape",
        positive=True,
    )
    dart_rounds: int = option(
        4,
        "int",
        "At most this many solves with darts by each rule (the yarns' bisector, then fall lines),"
        " each with longer darts.",
        section="drape",
        positive=True,
    )
    dart_max_length: float | None = option(
        None,
        "float",
        "Longest automatic dart, mesh length units (default: half the mould's bounding-box "
        "diagonal).",
        section="drape",
        positive=True,
    )

    def check(self) -> None:
        if self.dart_tip > 1.0:
            raise OptionsError("dart_tip", f"must be at most 1; got {self.dart_tip}")
        if self.darts == "auto" and self.dart_lines is not None:
            raise OptionsError(None, "give --darts auto or --dart-lines, not both")
        if self.splice_lines is not None and self.wanted:
            raise OptionsError(None, "give darts or --splice-lines, not both")
        if self.splices == "auto" and self.splice_lines is not None:
            raise OptionsError(None, "give --splices auto or --splice-lines, not both")
        if self.splices == "auto" and self.wanted:
            raise OptionsError(None, "give darts or --splices auto, not both")

    @property
    def wanted(self) -> bool:
        """Whether darts are asked for (placed or given)."""
        return self.darts == "auto" or self.dart_lines is not None

    @property
    def splicing(self) -> bool:
        """Whether the ply is spliced: along given lines or placed ones."""
        return self.splices == "auto" or self.splice_lines is not None

    @property
    def needs_fabric(self) -> bool:
        """Whether the ply's pattern is solved: for darts or for splices."""
        return self.wanted or self.splicing
