"""Running a job: read the input, solve (one surface, or a structure's panels), erect the
structure from its patterns if asked, write the files.

The one runner behind ``vares pattern``, ``example``, ``run``, ``panels``, ``cut``, ``batch`` and
``erect``: every command builds a :class:`vares.app.job.Job` and hands it here, so they all get
the same outputs (see :mod:`vares.app.outputs`). Everything that can be checked is checked before
the solve; the files of a run are staged and put in place as one set (:mod:`vares.app.staging`).
:func:`run_erection` (:mod:`vares.app.erection_run`) erects the patterns an earlier run wrote
(``vares erect DIR``).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..analysis.checks import pattern_warnings
from ..analysis.compensation import compensation_report
from ..analysis.erection_model import Pattern
from ..geometry.examples import EXAMPLE_PLANES
from ..geometry.mesh import SurfaceMesh
from ..io.files import check_writable, write_text
from ..materials import Hyperelastic
from ..solver import IterationRecord, PatternResult, SolveOptions, solve
from .erection_outputs import write_erection
from .erection_run import ErectionRun, run_erection
from .inputs import Input, load_input
from .job import Job, JobError
from .outcome import JobOutcome, PanelOutcome
from .outputs import (
    JOB_FILE,
    check_mark_spacing,
    panel_directory,
    planned_files,
    structure_marks,
    write_job_file,
    write_panel,
    write_structure,
)
from .run_band import check_run_band, run_band
from .staging import OutputFolder, listed

__all__ = ["ErectionRun", "run_erection", "run_job"]


def run_job(
    job: Job,
    *,
    force: bool = False,
    callback: Callable[[IterationRecord], None] | None = None,
    on_solve_start: Callable[[str, SurfaceMesh, Hyperelastic], None] | None = None,
    save_job: Path | None = None,
) -> JobOutcome:
    """Run a job and write its files; returns what it did (also when the solve fails).

    Before the solve: the material, the input and every target are checked (an existing run is
    replaced only with ``force``; nothing else in the folder is ever lost). ``save_job``: also
    write the job as TOML there (paths relative to it). ``on_solve_start`` is told the name,
    mesh (the first panel's) and material before solving.
    """
    if job.drape is not None and job.structure is not None:
        raise JobError("[drape] drapes a ply on a single surface, not on a structure's panels")
    material = job.material.build(job.base)
    band_inputs = check_run_band(job)
    source = load_input(job)
    check_mark_spacing(job, source)
    folder = OutputFolder(
        job.directory,
        planned_files(job, source, save_job),
        force=force,
        inputs=_inputs(job),
    )
    folder.check()
    if save_job is not None and save_job.resolve() not in folder.planned:
        if save_job.resolve() in folder.inputs:
            raise JobError(f"--save-job {save_job} is an input of the run")
        if save_job.resolve() in {p.resolve() for p in listed(save_job.parent)}:
            raise JobError(f"--save-job {save_job} belongs to another run's folder")
        check_writable([save_job], force)
    first = source.panels[0]
    if on_solve_start is not None:
        on_solve_start(first.name, first.mesh, material)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        outcome = _solve(job, source, material, _options(job), callback)
        if job.erection is not None:
            _erect(outcome, _options(job), callback)
    outcome.warnings = source.warnings + [str(w.message) for w in caught] + outcome.warnings
    if band_inputs is not None:
        if outcome.patterned:
            outcome.scatter = run_band(outcome, band_inputs, _options(job))
        else:
            outcome.warnings.append("no scatter band: the patterns did not converge")
    root = folder.start()
    try:
        _write(outcome, root, save_job, folder)
        folder.commit()
    finally:
        folder.discard()
    _moved(outcome, folder.directory, root)
    if save_job is not None and save_job.resolve() not in folder.planned:
        _save_job(job, save_job)
        outcome.files.append(save_job)
    return outcome


def _inputs(job: Job) -> list[Path]:
    paths = [job.path(p) for p in job.input.paths]
    curves = None if job.cut is None else job.cut.curves
    for extra in (job.material.presets, job.input.initial_pattern, curves):
        if extra is not None:
            paths.append(job.path(extra))
    own_file = (job.directory / JOB_FILE).resolve()
    if job.location is not None and job.location.resolve() != own_file:
        paths.append(job.location)  # a run's own job.toml is rewritten with the same job
    return paths


def _options(job: Job) -> SolveOptions:
    options = job.solve
    if options.plane is None and job.input.example in EXAMPLE_PLANES:
        options = options.replace(plane=EXAMPLE_PLANES[job.input.example])
    return options


def _solve(job: Job, source: Input, material, options, callback) -> JobOutcome:
    if job.cut is not None:
        return _solve_cut(job, source, material, options, callback)
    if job.structure is None:
        return _solve_one(job, source, material, options, callback)
    return _solve_structure(job, source, material, options, callback)


def _write(outcome: JobOutcome, root: Path, save_job: Path | None, folder: OutputFolder) -> None:
    """Every file of the run, into ``root`` (the staging folder)."""
    job = outcome.job
    outcome.directory = root
    for panel in outcome.panels:
        panel.directory = panel_directory(job, panel.name, root)
        panel.warnings = outcome.warnings + panel.warnings
    marks = None
    if outcome.structure is not None and all(
        p.result.converged or p.result.uncuttable for p in outcome.panels
    ):
        marks = structure_marks(outcome)
    for index, panel in enumerate(outcome.panels):
        write_panel(panel, outcome, None if marks is None else marks[index])
        outcome.files += panel.files
    if outcome.structure is not None:
        write_structure(outcome, marks)
    if outcome.cut is not None:
        from .cut_outputs import write_cut

        write_cut(outcome)
    outcome.files.append(write_job_file(job, root))
    if outcome.erection is not None:
        outcome.files += write_erection(
            outcome.erection, root / "erect", outcome.units, outcome.optimum
        )
    if job.output.report:
        from .report import write_reports

        write_reports(outcome)
    if save_job is not None and save_job.resolve() in folder.planned:
        staged = folder.staged(save_job)
        _save_job(job, staged, location=save_job)
        outcome.files.append(staged)


def _save_job(job: Job, path: Path, location: Path | None = None) -> None:
    text = job.to_toml(location or path)
    write_text(path, text)


def _moved(outcome: JobOutcome, directory: Path, root: Path) -> None:
    """Point the outcome's paths from the staging folder to the output folder."""

    def final(path: Path) -> Path:
        return directory / Path(path).relative_to(root)

    outcome.directory = directory
    outcome.files = [final(p) for p in outcome.files]
    for panel in outcome.panels:
        panel.directory = final(panel.directory)
        panel.files = [final(p) for p in panel.files]


def _erect(outcome: JobOutcome, options, callback) -> None:
    """Erect the structure from the job's patterns (patterns that did not converge are not
    erected: a warning says so); with ``[erection] optimise``, optimise the patterns for the
    erected structure first and erect those (the job's patterns are then the optimised ones)."""
    job = outcome.job
    if not outcome.patterned:
        outcome.warnings.append("not erected: the patterns did not converge")
        return
    patterns = [Pattern.of(p.result, p.name) for p in outcome.panels]
    if job.erection.optimise:
        _optimise(outcome, patterns, options)
        return
    from ..analysis.erection import erect  # imported by a job that erects

    outcome.erection = erect(
        patterns,
        outcome.material,
        job.material.thickness,
        solver=options,
        options=job.erection,
        callback=callback,
    )


def _optimise(outcome: JobOutcome, patterns: list[Pattern], options) -> None:
    """Patterns optimised for the erected structure in place of the job's (the erection of the
    VaReS patterns kept beside it)."""
    from ..analysis.erection_optimum import optimise_for_erection

    job = outcome.job
    optimum = optimise_for_erection(
        patterns, outcome.material, job.material.thickness, solver=options, options=job.erection
    )
    outcome.optimum, outcome.erection = optimum, optimum.erected
    if not optimum.converged:
        outcome.warnings.append(f"the patterns were not optimised: {optimum.reason}")
    else:
        _take_patterns(outcome, optimum)
    if outcome.cut is not None:  # the pieces' outlines and the nest of the patterns cut
        from ..structures.cutting import with_patterns

        outcome.cut = with_patterns(outcome.cut, outcome.structure)


def _optimising(job: Job) -> bool:
    return job.erection is not None and job.erection.optimise


def _take_patterns(outcome: JobOutcome, optimum) -> None:
    """The optimised patterns in place of the job's (reports and seams of the new ones)."""
    from ..analysis.erection_optimum import optimised_results

    job = outcome.job
    results = optimised_results([p.result for p in outcome.panels], optimum)
    for k, (panel, result) in enumerate(zip(outcome.panels, results, strict=True)):
        fresh = _panel(job, outcome.units, panel.name, panel.mesh, result)
        panel.result, panel.compensation, panel.warnings = (
            result,
            fresh.compensation,
            fresh.warnings,
        )
        if outcome.structure is not None:
            outcome.structure.results[k] = result
    if outcome.structure is not None:
        outcome.structure.seam_reports = _seam_reports_after(outcome.structure)


def _seam_reports_after(structure):
    """The structure's seam reports with the lengths of its (optimised) patterns as those after
    matching."""
    from dataclasses import replace

    from ..structures.seams import seam_lengths

    coordinates = [r.material_coordinates for r in structure.results]
    out = []
    for report, seam in zip(structure.seam_reports, structure.seams, strict=True):
        first, second = seam_lengths(coordinates, seam)
        out.append(
            replace(
                report,
                length_first_after=float(first.sum()),
                length_second_after=float(second.sum()),
                max_segment_mismatch_after=float(np.max(np.abs(first - second) / first)),
            )
        )
    return out


def _panel(
    job: Job, units: str, name: str, mesh: SurfaceMesh, result: PatternResult
) -> PanelOutcome:
    slack = job.prestress.slack_threshold
    report = compensation_report(result, slack) if result.converged else None
    panel = PanelOutcome(name, mesh, result, report, job.directory, units)
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
        initial_guess=source.initial_pattern,
    )
    patterned = _panel(job, source.units, panel.name, panel.mesh, result)
    if job.drape is not None:
        from ..analysis.drape import drape_ply
        from ..geometry.orientation import erected_warp

        # the ply laid as the pattern's warp runs: the direction asked for, or where it went
        warp = job.solve.warp_direction
        if warp is None:
            warp = tuple(erected_warp(panel.mesh, result.material_coordinates, result.fibres.warp))
        patterned.drape = drape_ply(panel.mesh, job.drape, warp_direction=warp)
    return JobOutcome(job, material, [patterned], units=source.units, repairs=source.repairs)


def _solve_structure(job, source: Input, material, options, callback) -> JobOutcome:
    per_panel = None
    if job.prestress.field is not None:  # each panel's cells' own rows of the field
        per_panel = [job.prestress.value(data) for data in source.panel_cell_data]
        if len(per_panel) != len(source.panels):  # a Rhino model's objects carry no cell data
            raise JobError("per-cell prestress needs the panels' cell data (a mesh file's)")
    from ..structures.matching import solve_structure  # imported by a structure's job

    structure = solve_structure(
        source.panels,
        material,
        job.material.thickness,
        prestress=None if per_panel is not None else job.prestress.value({}),
        panel_prestress=per_panel,
        options=options,
        structure=job.structure,
        callback=callback,
    )
    pairs = zip(source.panels, structure.results, strict=True)
    panels = [_panel(job, source.units, p.name, p.mesh, r) for p, r in pairs]
    too_wide = [
        f"{name} is {width:.4g} {source.units} wide across the warp, more than the roll width "
        f"{structure.structure_options.roll_width:g}"
        for name, width in structure.too_wide
    ]
    return JobOutcome(
        job,
        material,
        panels,
        structure=structure,
        warnings=too_wide,
        units=source.units,
        repairs=source.repairs,
    )


def _solve_cut(job, source: Input, material, options, callback) -> JobOutcome:
    """Cut the surface into strips, pattern them, nest them (:func:`vares.structures.cut`)."""
    from ..structures.cutting import cut

    lines = None
    if job.cut.seams == "curves":
        from ..io.curves import read_curves

        if job.cut.curves is None:
            raise JobError("[cut] seams = 'curves' needs a curves file: curves = \"FILE\"")
        lines = read_curves(job.path(job.cut.curves), layer=job.cut.curves_layer)
    result = cut(
        source.panels[0].mesh,
        material,
        job.material.thickness,
        prestress=job.prestress.value(source.cell_data),
        lines=lines,
        allowance=job.output.allowance,
        units=source.units,
        dxf_units=job.output.dxf_units,
        options=options,
        structure=job.structure,
        cutting=job.cut,
        callback=callback,
        nest=not _optimising(job),  # nested once the patterns are optimised
    )
    pairs = zip(result.plan.panels, result.structure.results, strict=True)
    panels = [_panel(job, source.units, p.name, p.mesh, r) for p, r in pairs]
    warnings = [
        f"{result.plan.panels[k].name} is {result.widths[k]:.6g} {source.units} wide across the "
        f"warp with its allowances; the roll ({job.cut.roll_width:g}) takes at most "
        f"{result.usable_width:.6g}"
        for k in result.too_wide
    ]
    if warnings and result.structure.converged:
        warnings.append("no nest: a piece wider than the roll cannot be laid on it")
    return JobOutcome(
        job,
        material,
        panels,
        structure=result.structure,
        warnings=warnings,
        units=source.units,
        repairs=source.repairs,
        cut=result,
    )
