"""``vares erect``: build the structure from the patterns an earlier run wrote, and see what it
becomes."""

from pathlib import Path
from typing import Annotated, Any

import typer

from ...analysis.options import ErectionOptions
from ..job import load_job
from .common import console, fail, guarded, progress, show_erection
from .flags import InputError, build, flags, option_parameter, with_flags
from .pattern import RUN_FLAGS

__all__ = ["erect"]

REPORT_FLAG = [
    option_parameter(
        "report", False, bool, "--report", help="Also write erect/report.html.", panel="Output"
    )
]


#: The erection flags, unset unless given (then they override the job's [erection] table).
OVERRIDE_FLAGS = flags(ErectionOptions, defaults=dict.fromkeys(ErectionOptions.specs()))


@with_flags(OVERRIDE_FLAGS, REPORT_FLAG, RUN_FLAGS[1:])
def erect(
    directory: Annotated[
        Path,
        typer.Argument(
            metavar="DIR",
            help="Output directory of 'vares pattern', 'example', 'run' or 'panels'.",
        ),
    ],
    **values: Any,
) -> None:
    """Erect the structure from its patterns: weld the panels, stretch them onto the supports
    and solve for the shape and the membrane forces they settle into.

    Reads DIR/job.toml (material, prestress and the job's erection table) and each panel's
    surface.vtu, pattern.vtu and summary.json; writes DIR/erect/: erect.json, erected.vtu,
    erected.obj and drawings (deviation, warp and fill force, wrinkled/slack). Flags override
    the job's erection table.
    """

    def body() -> None:
        if directory.is_file():
            raise InputError(
                f"{directory} is a file: give the output directory of 'vares pattern', "
                "'example', 'run' or 'panels'"
            )
        if not directory.is_dir():
            raise InputError(f"no such directory: {directory}")
        from ..outputs import JOB_FILE  # the engine, when the command runs (common.py)
        from ..runner import run_erection

        job_file = directory / JOB_FILE
        saved = load_job(job_file).erection if job_file.is_file() else None
        given = {k: v for k, v in values.items() if k in ErectionOptions.specs() and v is not None}
        options = build(ErectionOptions, {**(saved or ErectionOptions()).to_dict(), **given})
        run = run_erection(
            directory,
            options,
            force=values["force"],
            report=values["report"],
            callback=progress(values["quiet"]),
        )
        if not values["quiet"]:
            show_erection(run.result, run.units)
            for path in run.files:
                console.print(f"  wrote {path}")
        if not run.result.converged:
            raise typer.Exit(fail(f"the erection did not converge: {run.result.reason}", 1))

    guarded(body)
