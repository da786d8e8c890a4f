"""``vares pattern`` and ``vares example``: the cutting pattern of one surface."""

from pathlib import Path
from typing import Annotated, Any

import typer

from ...geometry.examples import EXAMPLES
from ..sections import InputOptions
from .common import execute, guarded
from .flags import (
    DRAPE_FLAG,
    DRAPE_FLAGS,
    JOB_FLAGS,
    flags,
    job_from_flags,
    option_parameter,
    with_flags,
)

__all__ = ["example", "pattern"]

RUN_FLAGS = [
    option_parameter(
        "save_job",
        None,
        Path | None,
        "--save-job",
        help="Write the job as TOML (rerun with 'vares run').",
        panel="Output",
    ),
    option_parameter(
        "force",
        False,
        bool,
        "--force",
        "-f",
        help="Overwrite existing output files.",
        panel="Output",
    ),
    option_parameter(
        "quiet", False, bool, "--quiet", "-q", help="Show no progress.", panel="Output"
    ),
]


@with_flags(
    flags(InputOptions, exclude=("cell_type", "panel_field")),
    JOB_FLAGS,
    DRAPE_FLAG,
    DRAPE_FLAGS,
    RUN_FLAGS,
)
def pattern(
    input: Annotated[Path, typer.Argument(help="Surface mesh (OBJ, STL, PLY, VTU, Gmsh, 3dm, …).")],
    **values: Any,
) -> None:
    """Compute the cutting pattern of a surface mesh.

    Writes pattern.obj, pattern.dxf, pattern.svg/.png, pattern.vtu, surface.vtu and summary.json
    (and report.html with --report) into the output directory.
    """

    def body() -> None:
        job = job_from_flags(values, mesh=str(input.resolve()))
        execute(job, force=values["force"], quiet=values["quiet"], save_job=values["save_job"])

    guarded(body)


@with_flags(
    flags(InputOptions, exclude=("panel_field",)), JOB_FLAGS, DRAPE_FLAG, DRAPE_FLAGS, RUN_FLAGS
)
def example(
    example_name: Annotated[
        str, typer.Argument(metavar="NAME", help="Example: " + ", ".join(EXAMPLES))
    ],
    **values: Any,
) -> None:
    """Write a shipped example surface (surface.obj) and compute its pattern."""

    def body() -> None:
        job = job_from_flags(values, example=example_name)
        execute(job, force=values["force"], quiet=values["quiet"], save_job=values["save_job"])

    guarded(body)
