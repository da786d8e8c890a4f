"""``vares cut``: one surface cut into strips of roll width, patterned with matched seams and
nested on the roll."""

from pathlib import Path
from typing import Annotated, Any

import typer

from ...geometry.examples import CUT_EXAMPLES, EXAMPLES
from ...structures.options import CutOptions, StructureOptions
from ..sections import InputOptions
from .common import execute, guarded
from .flags import (
    JOB_FLAGS,
    SEAMS_FLAG,
    InputError,
    example_flag,
    flags,
    job_from_flags,
    with_flags,
)
from .pattern import RUN_FLAGS

__all__ = ["cut"]

EXAMPLE_FLAG = example_flag(
    "Cut a shipped surface instead: " + ", ".join([*CUT_EXAMPLES, *EXAMPLES]) + "."
)


@with_flags(
    flags(InputOptions, exclude=("name", "panel_field")),
    EXAMPLE_FLAG,
    flags(CutOptions),
    SEAMS_FLAG,
    JOB_FLAGS,
    flags(StructureOptions, exclude=("roll_width",)),
    RUN_FLAGS,
)
def cut(
    surface: Annotated[
        Path | None,
        typer.Argument(help="The design surface (OBJ, STL, PLY, VTU, Gmsh, 3dm, …)."),
    ] = None,
    **values: Any,
) -> None:
    """Cut a surface into strips that fit the roll, pattern them with matched seams, nest them.

    The cutting lines (geodesics, plane sections or your curves) are placed so that every
    strip's pattern, allowances included, fits --roll-width (mesh units) with the least number
    of strips; the warp runs along each strip (or along --warp-direction). Tapered strips (a
    conic tent's) are planned in pairs, head to tail, the warp along one seam of each, and laid
    on the roll in pairs (--interlock). Writes cut.json
    (panels, widths, seams, nesting), nest.dxf (the pieces on the roll, for the cutter),
    nest.svg/.png, cut_lines.png, panels.vtu, structure.json and every strip's pattern files in
    a folder of its own.
    """

    def body() -> None:
        if (surface is None) == (values["example"] is None):
            raise InputError("give a surface file or --example, not both and not neither")
        if values["example"] is not None:
            source: dict[str, Any] = {"example": values["example"]}
        else:
            source = {"mesh": str(surface.resolve())}
        job = job_from_flags(values, cut=True, **source)
        execute(job, force=values["force"], quiet=values["quiet"], save_job=values["save_job"])

    guarded(body)
