"""``vares run``: run a job file."""

from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer

from ...analysis.options import ErectionOptions
from ..job import load_job
from .common import execute, guarded

__all__ = ["run"]


def run(
    job_file: Annotated[Path, typer.Argument(metavar="JOB", help="Job file (TOML).")],
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", help="Write the outputs here instead of the job's folder."),
    ] = None,
    force: Annotated[bool, typer.Option("--force", "-f", help="Overwrite output files.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Show no progress.")] = False,
    erect: Annotated[
        bool,
        typer.Option(
            "--erect",
            help="Erect the structure from its patterns afterwards (the job's [erection] table, "
            "or the defaults).",
        ),
    ] = False,
) -> None:
    """Run a job file: input, material, fibres, prestress, solver and outputs in one TOML."""

    def body() -> None:
        job = load_job(job_file)
        if erect and job.erection is None:
            job = replace(job, erection=ErectionOptions())
        execute(job if output is None else job.with_output(output), force=force, quiet=quiet)

    guarded(body)
