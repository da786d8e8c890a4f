"""Running a job: read the input, solve (one surface, or a structure's panels), write the files.

The one runner behind ``vares pattern``, ``example``, ``run``, ``panels`` and ``batch``: every
command builds a :class:`vares.app.job.Job` and hands it here, so they all get the same outputs
(see :mod:`vares.app.outputs`).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

from ..analysis.checks import pattern_warnings
from ..analysis.compensation import compensation_report
from ..geometry.examples import EXAMPLE_PLANES
from ..geometry.mesh import SurfaceMesh
from ..io.files import check_writable
from ..materials import Hyperelastic
from ..solver import IterationRecord, PatternResult, solve
from ..structures.matching import solve_structure
from .cut_outputs import write_cut
from .inputs import Input, load_input
from .job import Job, JobError
from .outcome import JobOutcome, PanelOutcome
from .outputs import (
    panel_directory,
    planned_files,
    structure_marks,
    write_panel,
    write_structure,
)

__all__ = ["run_job"]


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
    check_writable(planned_files(job, Input([]) if job.cut is not None else source), force)
    options = job.solve
    if options.plane is None and job.input.example in EXAMPLE_PLANES:
        options = options.replace(plane=EXAMPLE_PLANES[job.input.example])
    first = source.panels[0]
    if on_solve_start is not None:
        on_solve_start(first.name, first.mesh, material)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if job.cut is not None:
            outcome = _solve_cut(job, source, material, options, callback, force)
        elif job.structure is None:
            outcome = _solve_one(job, source, material, options, callback)
        else:
            outcome = _solve_structure(job, source, material, options, callback)
    outcome.warnings = [str(w.message) for w in caught] + outcome.warnings
    for panel in outcome.panels:
        panel.warnings = outcome.warnings + panel.warnings
    marks = structure_marks(outcome) if outcome.structure and outcome.converged else None
    for index, panel in enumerate(outcome.panels):
        write_panel(panel, job, material.stiffness_scale, None if marks is None else marks[index])
        outcome.files += panel.files
    if outcome.structure is not None:
        write_structure(outcome, marks)
    if outcome.cut is not None:
        write_cut(outcome)
    if job.output.report:
        from .report import write_reports

        write_reports(outcome)
    return outcome


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


def _solve_cut(job, source: Input, material, options, callback, force: bool) -> JobOutcome:
    """Cut the surface into strips, pattern them, nest them (:func:`vares.structures.cut`);
    every plan's panel files are checked before its patterns are computed."""
    from ..structures.cutting import cut

    if job.prestress.field is not None:
        raise JobError("per-cell prestress is not available for cut jobs yet")
    curves = None
    if job.cut.seams == "curves":
        from ..io.curves import read_curves

        curves = read_curves(job.path(job.cut.curves), layer=job.cut.curves_layer)

    def check(plan) -> None:
        check_writable(planned_files(job, Input(plan.panels)), force)

    result = cut(
        source.panels[0].mesh,
        material,
        job.material.thickness,
        prestress=job.prestress.value({}),
        curves=curves,
        allowance=job.output.allowance,
        units=job.input.units,
        dxf_units=job.output.dxf_units,
        options=options,
        structure=job.structure,
        cutting=job.cut,
        callback=callback,
        before_solve=check,
    )
    panels = [
        _panel(job, p.name, p.mesh, r)
        for p, r in zip(result.plan.panels, result.structure.results, strict=True)
    ]
    units = job.input.units
    warnings = [
        f"{p.name} is {w:.4g} {units} wide across the warp with its allowances, more than the "
        f"roll width {job.cut.roll_width:g}"
        for p, w in zip(result.plan.panels, result.widths, strict=True)
        if w > job.cut.roll_width
    ]
    if warnings and result.structure.converged:
        warnings.append("no nest: a piece wider than the roll cannot be laid on it")
    return JobOutcome(
        job, material, panels, structure=result.structure, warnings=warnings, cut=result
    )
