"""What every command shares: the console, one-line errors and exit codes, running a job and
showing what it did."""

from __future__ import annotations

import dis
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.console import Console
from rich.table import Table

from .flags import InputError

if TYPE_CHECKING:  # the engine is imported when a command runs, not to build the command line
    import numpy as np

    from ...analysis.erection import ErectionResult
    from ...analysis.erection_optimum import OptimisedPatterns
    from ...solver.result import IterationRecord
    from ..job import Job
    from ..outcome import JobOutcome, PanelOutcome

__all__ = [
    "check_parallel",
    "console",
    "execute",
    "fail",
    "field_table",
    "guarded",
    "refused",
    "scheduler_option",
    "show_erection",
    "workers_option",
]

console = Console(stderr=True, highlight=False, soft_wrap=True)


def workers_option(what: str, default: str) -> typer.models.OptionInfo:
    """The ``--workers`` option of a command that runs ``what`` in parallel (``default`` when
    it is not given); :func:`check_parallel` checks it."""
    return typer.Option(
        "--workers", "-w", help=f"Local worker processes that run {what} (default: {default})."
    )


def scheduler_option(what: str) -> typer.models.OptionInfo:
    """The ``--scheduler`` option beside :func:`workers_option`."""
    return typer.Option(
        "--scheduler",
        help=f"A Dask distributed scheduler (tcp://host:port, e.g. tcp://10.0.0.5:8786) whose "
        f"workers run {what}, instead of local processes.",
    )


def check_parallel(workers: int | None, scheduler: str | None) -> None:
    """Refuse a worker count below 1, and workers beside a scheduler (as a laminate job's
    options do)."""
    if workers is not None and workers < 1:
        raise InputError(f"--workers must be > 0; got {workers}")
    if workers is not None and scheduler is not None:
        raise InputError("give --workers or --scheduler, not both")


def fail(message: str, code: int) -> int:
    """Print ``vares: error: message``; return the exit code."""
    console.print(f"vares: error: {message}", markup=False)
    return code


def guarded(body: Callable[[], None]) -> None:
    """Run a command body, turning known errors into one-line messages and exit codes (2: bad
    input or options, 1: the solve did not converge, 3: unexpected internal error).

    A ``ValueError`` is bad input when vares says so (:func:`refused`); one that escaped from
    numpy, scipy or another library is an internal error, whatever its type."""
    from ...io.files import OutputExistsError
    from ..job import JobError

    try:
        body()
    except typer.Exit:
        raise
    except (InputError, JobError, OutputExistsError, FileNotFoundError) as exc:
        raise typer.Exit(fail(str(exc), 2)) from None
    except ValueError as exc:
        if not refused(exc):
            raise typer.Exit(fail(f"internal error: {type(exc).__name__}: {exc}", 3)) from None
        raise typer.Exit(fail(str(exc), 2)) from None
    except OSError as exc:
        raise typer.Exit(fail(f"{exc.strerror or exc}: {exc.filename or ''}".strip(), 2)) from None
    except KeyboardInterrupt:
        raise typer.Exit(fail("interrupted", 130)) from None
    except Exception as exc:  # one line, never a traceback
        raise typer.Exit(fail(f"internal error: {type(exc).__name__}: {exc}", 3)) from None


def refused(exc: ValueError) -> bool:
    """Whether a ``ValueError`` is vares refusing an input: an error type of vares
    (``MeshError``, ``OptionsError``, ``CuttingError``, …), text that is no text
    (``UnicodeError``), or a ``ValueError`` raised by a ``raise`` statement in vares's own code.
    Not one raised inside a library, such as numpy's "operands could not be broadcast": that is
    vares handing it arrays it should not have (a bug), though it reaches vares's frame from C."""
    if type(exc).__module__.partition(".")[0] == "vares" or isinstance(exc, UnicodeError):
        return True
    if type(exc) is not ValueError or exc.__traceback__ is None:
        return False
    last = exc.__traceback__
    while last.tb_next is not None:
        last = last.tb_next
    frame = last.tb_frame
    if frame.f_globals.get("__name__", "").partition(".")[0] != "vares":
        return False
    return frame.f_code.co_code[last.tb_lasti] == dis.opmap["RAISE_VARARGS"]


def progress(quiet: bool) -> Callable[[IterationRecord], None] | None:
    """A callback that prints each Newton iteration (none when ``quiet``)."""
    if quiet:
        return None

    def show(record: IterationRecord) -> None:
        extra = f"  α={record.step_length:.3g} {record.tangent}" if record.iteration else ""
        if record.cg_iterations:  # a step solved with an earlier factorisation
            extra += f" ({record.cg_iterations} CG)"
        console.print(
            f"  {record.strategy:<18} step {record.step:>2}  τ={record.tau:6.4f}  "
            f"it {record.iteration:>2}  residual {record.relative_residual:9.3e}  "
            f"energy {record.energy: .6e}{extra}"
        )

    return show


def field_table(fields: dict[str, np.ndarray]) -> Table:
    from ...analysis.statistics import field_statistics
    from ...mechanics.fields import KEY_FIELDS

    table = Table(
        "field",
        "min",
        "mean",
        "max",
        title="per-cell results on the design shape (mean: area-weighted)",
    )
    statistics = field_statistics(fields)
    for name in KEY_FIELDS:
        s = statistics[name]
        table.add_row(name, f"{s['min']:.6g}", f"{s['mean']:.6g}", f"{s['max']:.6g}")
    return table


def _compensation_table(report) -> Table:
    table = Table(
        "",
        "warp",
        "fill",
        title="compensation and prestress on the design shape (force/length; area-weighted means)",
    )
    for row in report.rows():
        table.add_row(*row)
    return table


def _seconds(result) -> str:
    text = f"{result.elapsed:.2f} s"
    if result.warm_up >= 0.005:
        text += f" (+{result.warm_up:.2f} s loading compiled kernels)"
    return text


def _show_panel(panel: PanelOutcome, detail: bool) -> None:
    result = panel.result
    status = "[green]converged[/]" if result.converged else f"[red]failed[/]: {result.reason}"
    solves = len(result.steps)
    per = f", at most {result.options.max_iterations} in each of {solves}" if solves > 1 else ""
    console.print(
        f"{panel.name}: {status} in {result.iterations} Newton iterations "
        f"({' → '.join(result.strategy)}{per}), {_seconds(result)}; energy "
        f"{result.energy:.6e}; area 3D {result.surface_area:.6g}, pattern "
        f"{result.pattern_area:.6g}"
    )
    if result.converged and detail:
        console.print(field_table(result.fields))
        if result.prestress is not None and panel.compensation is not None:
            console.print(_compensation_table(panel.compensation))
        if result.warp_deviation is not None:
            console.print(
                f"mean deviation of the warp from the direction: {result.warp_deviation:.2e}°"
            )


def _show_structure(outcome: JobOutcome) -> None:
    structure = outcome.structure
    if structure.seams:
        console.print(_seam_table(structure))
    console.print(
        f"{len(outcome.panels)} panels, {len(structure.seams)} seams, "
        f"{structure.iterations} coupled iterations; energy {structure.energy:.6e}, price of "
        f"matching {structure.energy_price:.3e}; {structure.elapsed:.2f} s"
    )


def _seam_table(structure) -> Table:
    table = Table(
        "seam",
        "segments",
        "length A",
        "length B",
        "mismatch before",
        "mismatch after",
        title="seams (pattern lengths)",
    )
    for s in structure.seam_reports:
        table.add_row(
            f"{s.first} | {s.second}",
            str(s.segments),
            f"{s.length_first_after:.6f}",
            f"{s.length_second_after:.6f}",
            f"{s.mismatch_before:.2e}",
            f"{s.mismatch_after:.2e}",
        )
    return table


def _show_cut(outcome: JobOutcome) -> None:
    result, units = outcome.cut, outcome.units
    plan = result.plan
    lines = (
        f"between {len(plan.lines)} drawn curves"
        if result.options.seams == "curves"
        else f"of {result.options.seams} lines ({plan.evaluations} layouts tried)"
    )
    console.print(
        f"cut: {plan.counted} {lines}, widest {max(result.widths):.4g} {units} with "
        f"allowances (roll {result.options.roll_width:g}); worst cell angle "
        f"{plan.cut.worst_angle:.1f}° (surface {result.surface_worst_angle:.1f}°); area 3D "
        f"{result.panel_area:.6g} of {result.surface_area:.6g} {units}²"
    )
    for note in result.notes:
        console.print(f"  {note}")
    if result.nest is not None:
        nest = result.nest
        console.print(
            f"nest: {nest.length:.4g} {units} of roll, yield {100 * nest.yield_:.1f} % "
            f"(waste {100 * nest.waste:.1f} %), {nest.elapsed:.1f} s"
        )


def producibility_table(check) -> Table:
    """The area of a kinematic drape in each shear class of a
    :class:`~vares.analysis.producibility.Producibility`."""
    locking = check.locking_angle
    table = Table(
        "class",
        "shear",
        "area fraction",
        title=f"producibility (locking {locking:g}°, warn from {check.warn_angle:g}°)",
    )
    bands = {
        "ok": f"< {check.warn_angle:g}°",
        "warn": f"{check.warn_angle:g}–{locking:g}°",
        "limit": f"≥ {locking:g}°",
    }
    for name, band in bands.items():
        table.add_row(name, band, f"{100 * check.fractions[name]:.2f} %")
    return table


def net_line(check, nodes: int, spacing: float) -> str:
    """What the kinematic net reached: its nodes, the largest shear and the area draped."""
    return (
        f"net of {nodes} nodes at spacing {spacing:g}; largest shear {check.max_shear:.2f}°; "
        f"{100 * check.covered:.1f} % of the area draped"
    )


def _show_drape(panel: PanelOutcome) -> None:
    """A patterning job's kinematic drape beside its pattern: the net's producibility and the
    pattern's shear against the net's (``summary.json``'s ``kinematic_drape``)."""
    ply = panel.drape
    nodes = int(ply.drape.net.valid.sum())
    console.print("kinematic drape: " + net_line(ply.producibility, nodes, ply.spacing))
    console.print(producibility_table(ply.producibility))
    if not panel.result.converged:
        return
    against = ply.comparison(panel.result.fields["shear_angle"], panel.mesh.cell_areas())
    if against["cells"] < 2:
        console.print("the pattern and the kinematic drape share no cells to compare")
        return
    console.print(
        f"shear of the pattern against the kinematic drape on {against['cells']} cells: largest "
        f"{against['max_shear']:.2f}° against {against['max_kinematic_shear']:.2f}°; difference "
        f"{against['mean_abs_difference']:.2f}° on average (area-weighted), at most "
        f"{against['max_abs_difference']:.2f}°; correlation {against['correlation']:.3f}"
    )


def show_erection(
    result: ErectionResult, units: str, optimum: OptimisedPatterns | None = None
) -> None:
    """Print what an erection did: status, and design shape against erected (with ``optimum``,
    the VaReS patterns' erection beside the optimised patterns')."""
    # with an optimum, ``result`` is the optimised patterns' erection, finished from the
    # optimiser's last trial: the VaReS patterns' own erection is the one to report first
    first = result if optimum is None else optimum.start
    status = "[green]converged[/]" if first.converged else f"[red]failed[/]: {first.reason}"
    console.print(
        f"erection of {'the VaReS patterns, ' if optimum else ''}{len(first.panels)} panel(s), "
        f"{first.mesh.num_points} nodes ({int(first.held.sum())} held): {status} in "
        f"{first.iterations} iterations, {first.elapsed:.2f} s"
    )
    if optimum is not None:
        console.print(
            f"patterns optimised for the erected structure: {optimum.iterations} steps, "
            f"{optimum.newton_iterations} Newton iterations of their erections, "
            f"{optimum.elapsed:.2f} s"
            + ("" if optimum.converged else f" ([red]not optimised[/]: {optimum.reason})")
        )
    if not result.converged:
        return
    from ..erection_outputs import erection_comparison

    titles, rows = erection_comparison(result, units, optimum)
    table = Table(
        "",
        *titles,
        title="membrane forces (force/length; means and RMS weighted by the design area)",
    )
    for row in rows:
        table.add_row(*row)
    console.print(table)


def show(outcome: JobOutcome) -> None:
    """Print what a job did: per pattern its status (and figures), the structure's seams, the
    warnings and the files."""
    single = outcome.structure is None
    for panel in outcome.panels:
        _show_panel(panel, detail=single)
    if not single:
        _show_structure(outcome)
    if outcome.cut is not None:
        _show_cut(outcome)
    if single and outcome.panels[0].drape is not None:
        _show_drape(outcome.panels[0])
    warnings = outcome.panels[0].warnings if single else outcome.warnings
    if not single:
        warnings = warnings + [
            f"{p.name}: {w}" for p in outcome.panels for w in p.warnings if w not in warnings
        ]
    if outcome.erection is not None:
        show_erection(outcome.erection, outcome.units, outcome.optimum)
    for warning in warnings:
        console.print(f"[yellow]warning:[/] {warning}")
    for path in outcome.files:
        console.print(f"  wrote {path}")


def execute(job: Job, *, force: bool, quiet: bool, save_job: Path | None = None) -> None:
    """Run a job from the command line: progress, summary, ``--save-job``, exit status."""
    from ..runner import run_job

    if save_job is not None and save_job.suffix.lower() != ".toml":
        raise InputError(f"--save-job: a job file ends in .toml; got {save_job}")

    def starting(name, mesh, material) -> None:
        if not quiet:
            console.print(f"{name}: {mesh}; {material!r}, thickness {job.material.thickness:g}")

    outcome = run_job(
        job, force=force, callback=progress(quiet), on_solve_start=starting, save_job=save_job
    )
    if not quiet:
        show(outcome)
    if not outcome.patterned:
        what = "solve" if outcome.structure is None else "structure"
        raise typer.Exit(fail(f"the {what} did not converge: {outcome.reason}", 1))
    if not outcome.converged:
        raise typer.Exit(fail(f"the erection did not converge: {outcome.erection.reason}", 1))
    if outcome.unfit:  # patterned, but not on this roll: no nest
        raise typer.Exit(fail(outcome.unfit, 1))
