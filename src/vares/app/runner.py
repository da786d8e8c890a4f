"""Running a job: read the input, solve (one surface, or a structure's panels), erect the
structure from its patterns if asked, write the files.

The one runner behind ``vares pattern``, ``example``, ``run``, ``panels``, ``batch`` and
``erect``: every command builds a :class:`vares.app.job.Job` and hands it here, so they all get
the same outputs (see :mod:`vares.app.outputs`). :func:`run_erection` erects the patterns an
earlier run wrote (``vares erect DIR``).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from ..analysis.checks import pattern_warnings
from ..analysis.compensation import compensation_report
from ..analysis.erection import ErectionResult, erect
from ..analysis.erection_model import Pattern
from ..analysis.options import ErectionOptions
from ..geometry.examples import EXAMPLE_PLANES
from ..geometry.mesh import SurfaceMesh
from ..io.files import check_writable
from ..materials import Hyperelastic
from ..solver import IterationRecord, PatternResult, solve
from ..structures.matching import solve_structure
from .inputs import Input, load_input, saved_patterns
from .job import Job, JobError, load_job
from .outcome import JobOutcome, PanelOutcome
from .outputs import (
    JOB_FILE,
    erection_directory,
    erection_files,
    panel_directory,
    planned_files,
    structure_marks,
    write_erection,
    write_job_file,
    write_panel,
    write_structure,
)

__all__ = ["ErectionRun", "run_erection", "run_job"]


def run_job(
    job: Job,
    *,
    force: bool = False,
    callback: Callable[[IterationRecord], None] | None = None,
    on_solve_start: Callable[[str, SurfaceMesh, Hyperelastic], None] | None = None,
) -> JobOutcome:
    """Run a job and write its files; returns what it did (also when the solve fails).

    Every target is checked before the solve: an existing file is an error unless ``force``.
    ``on_solve_start`` is told the name, mesh (the first panel's) and material before solving.
    """
    material = job.material.build(job.base)
    source = load_input(job)
    check_writable(planned_files(job, source), force)
    options = job.solve
    if options.plane is None and job.input.example in EXAMPLE_PLANES:
        options = options.replace(plane=EXAMPLE_PLANES[job.input.example])
    first = source.panels[0]
    if on_solve_start is not None:
        on_solve_start(first.name, first.mesh, material)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if job.structure is None:
            outcome = _solve_one(job, source, material, options, callback)
        else:
            outcome = _solve_structure(job, source, material, options, callback)
    outcome.warnings = [str(w.message) for w in caught] + outcome.warnings
    for panel in outcome.panels:
        panel.warnings = outcome.warnings + panel.warnings
    marks = structure_marks(outcome) if outcome.structure and outcome.patterned else None
    for index, panel in enumerate(outcome.panels):
        write_panel(panel, job, material.stiffness_scale, None if marks is None else marks[index])
        outcome.files += panel.files
    if outcome.structure is not None:
        write_structure(outcome, marks)
    outcome.files.append(write_job_file(job))
    if job.erection is not None:
        _erect(outcome, options, callback)
    if job.output.report:
        from .report import write_reports

        write_reports(outcome)
    return outcome


def _erect(outcome: JobOutcome, options, callback) -> None:
    """Erect the structure from the job's patterns and write ``erect/`` (patterns that did not
    converge are not erected: a warning says so)."""
    job = outcome.job
    if not outcome.patterned:
        outcome.warnings.append("not erected: the patterns did not converge")
        return
    patterns = [Pattern.of(p.result, p.name) for p in outcome.panels]
    outcome.erection = erect(
        patterns,
        outcome.material,
        job.material.thickness,
        solver=options,
        options=job.erection,
        callback=callback,
    )
    outcome.files += write_erection(outcome.erection, erection_directory(job), job.input.units)


@dataclass
class ErectionRun:
    """What ``vares erect DIR`` did: the job it read, the erection and the files written."""

    job: Job
    result: ErectionResult
    files: list[Path] = field(default_factory=list)


def run_erection(
    directory: str | Path,
    options: ErectionOptions | None = None,
    *,
    force: bool = False,
    report: bool = False,
    callback: Callable[[IterationRecord], None] | None = None,
) -> ErectionRun:
    """Erect the patterns that a run wrote into ``directory`` (from its ``job.toml``, the panels'
    ``surface.vtu``, ``pattern.vtu`` and ``summary.json``) and write ``directory/erect/``.

    ``options`` default to the job's ``[erection]`` table (or the defaults); the tolerance,
    iteration limit and linear solver are the job's.
    """
    directory = Path(directory)
    job_file = directory / JOB_FILE
    if not job_file.is_file():
        raise FileNotFoundError(
            f"no {JOB_FILE} in {directory}: erect an output directory written by "
            "'vares pattern', 'example', 'run' or 'panels'"
        )
    job = load_job(job_file)
    options = options or job.erection or ErectionOptions()
    material = job.material.build(job.base)
    patterns = saved_patterns(job)
    target = directory / "erect"
    check_writable(erection_files(target, report), force)
    result = erect(
        patterns,
        material,
        job.material.thickness,
        solver=job.solve,
        options=options,
        callback=callback,
    )
    run = ErectionRun(job, result, write_erection(result, target, job.input.units))
    if report:
        from .erection_report import write_erection_report

        run.files.append(write_erection_report(run.result, target, job.input.units))
    return run


def _panel(job: Job, name: str, mesh: SurfaceMesh, result: PatternResult) -> PanelOutcome:
    slack = job.prestress.slack_threshold
    report = compensation_report(result, slack) if result.converged else None
    panel = PanelOutcome(name, mesh, result, report, panel_directory(job, name))
    panel.warnings = pattern_warnings(result, report)
    return panel


def _solve_one(job, source: Input, material, options, callback) -> JobOutcome:
    panel = source.panels[0]
    result = solve(
        panel.mesh,
        material,
        job.material.thickness,
        prestress=job.prestress.value(source.cell_data),
        options=options,
        callback=callback,
    )
    return JobOutcome(job, material, [_panel(job, panel.name, panel.mesh, result)])


def _solve_structure(job, source: Input, material, options, callback) -> JobOutcome:
    if job.prestress.field is not None:
        raise JobError("per-cell prestress is not available for structures yet")
    structure = solve_structure(
        source.panels,
        material,
        job.material.thickness,
        prestress=job.prestress.value({}),
        options=options,
        structure=job.structure,
        callback=callback,
    )
    panels = [
        _panel(job, p.name, p.mesh, r)
        for p, r in zip(source.panels, structure.results, strict=True)
    ]
    too_wide = [
        f"{name} is {width:.4g} {job.input.units} wide across the warp, more than the roll width "
        f"{structure.structure_options.roll_width:g}"
        for name, width in structure.too_wide
    ]
    return JobOutcome(job, material, panels, structure=structure, warnings=too_wide)
