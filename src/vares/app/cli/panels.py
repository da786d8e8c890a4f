"""``vares panels``: the patterns of a structure of several panels, with matching seams."""

from pathlib import Path
from typing import Annotated, Any

import typer

from ...geometry.examples import STRUCTURE_EXAMPLES
from ...structures.options import StructureOptions
from ..sections import InputOptions
from .common import execute, guarded
from .flags import (
    JOB_FLAGS,
    InputError,
    example_flag,
    flags,
    job_from_flags,
    with_flags,
)
from .pattern import RUN_FLAGS

__all__ = ["panels"]

EXAMPLE_FLAG = example_flag(
    "Pattern a shipped structure instead: " + ", ".join(STRUCTURE_EXAMPLES) + "."
)


@with_flags(
    flags(InputOptions, exclude=("name",)),
    EXAMPLE_FLAG,
    JOB_FLAGS,
    flags(StructureOptions),
    RUN_FLAGS,
)
def panels(
    inputs: Annotated[
        list[Path] | None,
        typer.Argument(
            help="One mesh with a panel id per cell, a 3dm file with one object per "
            "panel, or one mesh file per panel."
        ),
    ] = None,
    **values: Any,
) -> None:
    """Pattern a structure of several panels with matching seams.

    Writes each panel's pattern files into a folder of its own (NAME/pattern.obj, .dxf, …, as
    'vares pattern' does), structure.dxf (all panels side by side, with match marks at the same
    places on both sides of every seam) and structure.json (panels, seam lengths before and after
    matching, the energy price of matching, roll width check).
    """

    def body() -> None:
        files = list(inputs or [])
        if bool(files) == bool(values["example"]):
            raise InputError("give input files or --example, not both and not neither")
        if values["example"] is not None:
            source: dict[str, Any] = {"example": values["example"]}
        elif len(files) == 1:
            source = {"mesh": str(files[0].resolve())}
        else:
            source = {"meshes": tuple(str(f.resolve()) for f in files)}
        job = job_from_flags(values, structure=True, **source)
        execute(job, force=values["force"], quiet=values["quiet"], save_job=values["save_job"])

    guarded(body)
