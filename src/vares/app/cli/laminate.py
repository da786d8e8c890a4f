"""``vares laminate``: drape every ply of a laminate job and check every pair of plies."""

from dataclasses import replace
from pathlib import Path
from typing import Annotated, Any

import typer

from ...structures.laminate_options import LaminateOptions
from .common import console, guarded
from .flags import build, flags, with_flags

__all__ = ["laminate"]


#: The options of the job's ``[laminate]`` table that the command line may replace.
REPLACED = ("workers", "scheduler", "darts")


@with_flags(
    flags(
        LaminateOptions,
        exclude=[name for name in LaminateOptions.specs() if name not in REPLACED],
        defaults=dict.fromkeys(REPLACED),
    )
)
def laminate(
    job_file: Annotated[Path, typer.Argument(metavar="JOB", help="Laminate job file (TOML).")],
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", help="Write the outputs here instead of the job's folder."),
    ] = None,
    force: Annotated[bool, typer.Option("--force", "-f", help="Overwrite output files.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Show no progress.")] = False,
    **values: Any,
) -> None:
    """Drape every ply of a laminate (mechanical pattern and kinematic net) and check every pair.

    Writes laminate.json, laminate.md (the pair matrices), laminate.vtu (the draped warp and
    fill per cell and ply), orientations.inp (Abaqus, one *ORIENTATION per ply),
    orientations.csv, patterns/drape_ANGLEdeg.vtu, plybook.html (the ply book), plies/PLY.dxf
    (each ply's cutter file, its darts on layer DART, a spliced ply's pieces side by side)
    and, with a roll_width, nest.dxf (every blank nested on the roll) into the output
    directory. --workers, --scheduler and --darts replace the values of the job's laminate
    table. Exit status 1 when a ply did not converge.
    """

    def body() -> None:
        from ..laminate_job import load_laminate_job
        from ..laminate_outputs import laminate_files, run_laminate_job

        job = load_laminate_job(job_file)
        given = {name for name in REPLACED if values.get(name) is not None}
        kept = {n: getattr(job.laminate, n) for n in LaminateOptions.specs() if n not in given}
        job = replace(job, laminate=build(LaminateOptions, values, **kept))
        if output is not None:
            job = job.with_output(output)

        def progress(drape) -> None:
            if not quiet:
                state = "converged" if drape.converged else f"NOT converged: {drape.pattern.reason}"
                dart_text = ""
                if drape.is_darted:
                    dart_text = (
                        f", {len(drape.darted.dart_lines)} dart(s): largest shear "
                        f"{drape.darted.max_shear_before:.2f}° -> "
                        f"{drape.darted.max_shear_after:.2f}°"
                    )
                elif drape.is_spliced:
                    dart_text = (
                        f", {len(drape.spliced.pieces)} pieces: largest shear "
                        f"{drape.spliced.max_shear_before:.2f}° -> "
                        f"{drape.spliced.max_shear_after:.2f}°"
                    )
                console.print(
                    f"  {drape.label} ({', '.join(drape.plies)}): {state}, "
                    f"{drape.pattern.iterations} iterations, {drape.seconds:.2f} s{dart_text}"
                )

        run = run_laminate_job(job, force=force, callback=progress)
        result = run.result
        if not quiet:
            _show(result)
            _show_cutting(run)
            for path in laminate_files(job, result.labels, nested=run.nest is not None):
                console.print(f"  wrote {path}")
        if not result.converged:
            raise typer.Exit(1)

    guarded(body)


def _show(result) -> None:
    from rich.table import Table

    labels = result.labels
    for value, title in (
        ("warp_compressed_fraction", "area with compressed warp [%]"),
        ("largest_compression", "largest yarn compression [%]"),
        ("mean_deviation", "mean fibre-angle deviation [°]"),
    ):
        matrix = result.pair_matrix(value)
        table = Table("blank \\ ply", *labels, title=f"ply-stack check: {title}")
        for label, row in zip(labels, matrix, strict=True):
            scale = 1.0 if value == "mean_deviation" else 100.0
            table.add_row(label, *("–" if v != v else f"{scale * v:.2f}" for v in row))
        console.print(table)
    console.print(
        f"{len(result.laminate.plies)} plies, {len(result.drapes)} distinct drapes in "
        f"{result.seconds:.2f} s on {result.workers} worker(s)"
    )


def _show_cutting(run) -> None:
    from rich.table import Table

    units = run.units
    table = Table(
        "ply", "orientation", f"net area [{units}²]", f"blank area [{units}²]", "mass [g]",
        title=f"plies as cut (trim allowance {run.result.laminate.options.trim_allowance:g} "
        f"{units})",
    )  # fmt: skip
    for blank in run.blanks:
        mass = blank.mass(blank.net_area, units)
        table.add_row(
            blank.label,
            f"{blank.orientation:+g}°",
            f"{blank.net_area:.6g}",
            f"{blank.trim_area:.6g}",
            "–" if mass is None else f"{mass:.4g}",
        )
    console.print(table)
    nest = run.nest
    if nest is not None:
        console.print(
            f"nest: {len(nest.pieces)} blanks on a roll {nest.roll_width:g} {units} wide, "
            f"{nest.length:.6g} {units} long, yield {100 * nest.yield_:.1f} % "
            f"({nest.elapsed:.1f} s)"
        )
        if nest.stopped:
            console.print(f"  {nest.stopped}")
    elif run.nest_error is not None:
        console.print(f"not nested: {run.nest_error}")
