"""Self-contained HTML reports of a patterning job, for a person to read.

One file per pattern with everything inline (pictures as embedded PNG): the input, the material
and its parameters, the solver's path and convergence history, the pattern drawn with its yarn
directions, the result fields on the pattern and on the 3D surface, the key figures and the
warnings. A structure gets one more, for the whole: its panels, its seams before and after
matching, and links to the panels' reports. A job that erects its structure adds the erection
section (:mod:`vares.app.erection_report`) to the pattern's report (the structure's, for a
structure); one that drapes a ply, the drape's (:mod:`vares.app.drape_report`); one with
``[scatter]``, the band of its patterns under the fabric's scatter (:mod:`vares.app.run_band`).
"""

from __future__ import annotations

import html
import os

import numpy as np

from ..analysis.statistics import field_statistics
from ..io.files import write_text
from ..materials import Hyperelastic
from ..mechanics.fields import FIELD_DESCRIPTIONS, KEY_FIELDS
from ..solver.linear import solver_choice
from .drape_report import drape_section
from .erection_report import erection_section
from .html_parts import (
    REPORT_DPI,
    figure,
    number,
    page,
    picture,
    report_drawing,
    status_text,
    table,
)
from .job import Job
from .outcome import JobOutcome, PanelOutcome
from .outputs import units_of

__all__ = ["html_report", "scatter_section", "structure_report", "write_reports"]

_FIGURE_FIELDS = ("det_F", "warp_stress", "fill_stress", "shear_angle", "stress_min")


def _input_section(outcome: PanelOutcome, job: Job) -> list[str]:
    mesh, units = outcome.mesh, outcome.units
    cells = ", ".join(f"{len(c)} {t}" for t, c in mesh.cells.items())
    source = ", ".join(job.input.paths) or f"example {job.input.example}"
    rows = [
        ("source", source),
        ("nodes", mesh.num_points),
        ("cells", cells),
        ("surface area", f"{number(mesh.area)} {units}²"),
        ("extent (x, y, z)", " × ".join(number(v, 4) for v in np.ptp(mesh.points, axis=0))),
    ]
    return ["<h2>Input</h2>", table(rows, ident="input")]


def _material_section(result, job: Job, material: Hyperelastic) -> list[str]:
    rows = [("law", type(material).__name__)]
    rows += [(k, v) for k, v in material.parameters.items()]
    rows.append(("thickness", result.thickness))
    if job.material.fabric is not None:
        rows.append(("fabric preset", job.material.fabric))
    rows += _fabric_file_rows(job)
    rows.append(("fibre orientation", result.orientation))
    warp, fill = (np.round(v, 4).tolist() for v in (result.fibres.warp, result.fibres.fill))
    rows.append(("warp / fill in the pattern", f"{warp} / {fill}"))
    if result.warp_direction is not None:
        rows.append(("warp direction (3D)", np.round(result.warp_direction, 4).tolist()))
        rows.append(("mean warp deviation", f"{result.warp_deviation:.2e}°"))
    if result.prestress is not None:
        p = result.prestress
        per_cell = " (per cell)" if len(p) > 1 else ""
        rows.append(
            (
                "prestress warp / fill",
                f"{number(float(p[:, 0].mean()))} / {number(float(p[:, 1].mean()))}{per_cell}",
            )
        )
    return ["<h2>Material and fibres</h2>", table(rows, ident="material")]


def _fabric_file_rows(job: Job) -> list[tuple[str, object]]:
    """Where a fabric from biaxial tests came from and what it measured (docs/fabrics.md)."""
    if job.material.presets is None:
        return []
    from ..materials.presets import fabric, file_fabric

    path = job.path(job.material.presets)
    name = job.material.fabric
    preset = file_fabric(path) if name is None else fabric(name, path)
    rows: list[tuple[str, object]] = [("fabric file", str(path)), ("source", preset.source)]
    c = preset.compensation
    if c is not None:
        rows.append(("compensated by", job.material.compensate_by or preset.compensate_by))
        rows.append(
            (
                f"measured compensation at {number(c.prestress[0])} / {number(c.prestress[1])}",
                f"warp {100 * c.warp:.3f} ± {100 * c.warp_std:.3f} %, "
                f"fill {100 * c.fill:.3f} ± {100 * c.fill_std:.3f} % "
                + ("(one specimen: no scatter)" if c.specimens == 1 else "(mean ± std)"),
            )
        )
    return rows


def _key_figures(outcome: PanelOutcome, unit_names: dict[str, str]) -> list[str]:
    result, mesh = outcome.result, outcome.mesh
    units = unit_names["length"]
    key = [
        ("surface area", f"{number(mesh.area)} {units}²"),
        ("pattern area", f"{number(result.pattern_area)} {units}²"),
        ("pattern / surface area", f"{100 * (result.pattern_area / mesh.area - 1):+.3f} %"),
        ("energy", f"{number(result.energy)} ({unit_names['energy']})"),
        ("Newton iterations", result.iterations),
        ("strategy", " → ".join(result.strategy)),
        ("initial guess", result.initial_guess),
        ("linear solver", solver_choice(result.options.linear_solver, result.linear_solver)),
        (
            "factorisations, CG iterations",
            f"{result.factorisations}, {result.cg_iterations}",
        ),
        ("time", _time(result)),
    ]
    parts = ["<h2>Key figures</h2>", table(key, ident="key-figures")]
    if not (result.converged or result.uncuttable):
        return parts
    stats = field_statistics(result.fields)
    rows = []
    for name in KEY_FIELDS:
        s = stats[name]
        unit = _unit(name, unit_names)
        rows.append((f"{name}{unit}", number(s["min"]), number(s["mean"]), number(s["max"])))
    parts += [
        "<h2>Results on the design shape</h2>",
        "<p>Stresses and stretches with the pattern forced exactly onto the design surface "
        "(area-weighted means).</p>",
        table(rows, header=("field", "min", "mean", "max"), ident="fields"),
    ]
    if outcome.compensation is not None and result.prestress is not None:
        parts += [
            f"<h2>Compensation and prestress on the design shape ({unit_names['stress']})</h2>",
            table(outcome.compensation.rows(), header=("", "warp", "fill"), ident="compensation"),
        ]
    return parts


def _time(result) -> str:
    """The solve's wall time, and the kernels' loading before it when there was any."""
    text = f"{result.elapsed:.2f} s"
    if result.warm_up >= 0.005:
        text += f" (and {result.warm_up:.2f} s before it loading the compiled kernels)"
    return text


def _unit(field: str, unit_names: dict[str, str]) -> str:
    kind = FIELD_DESCRIPTIONS[field][1]
    text = {"stress": unit_names["stress"], "degree": "°", "%": "%"}.get(kind)
    return f" [{text}]" if text else ""


def _convergence_section(result) -> list[str]:
    from ..io.plot import plot_convergence

    steps = [
        (
            s.strategy,
            s.step,
            f"{s.tau:.4g}",
            s.iterations,
            "yes" if s.converged else "no",
            s.reason or "",
        )
        for s in result.steps
    ]
    return [
        "<h2>Convergence</h2>",
        figure(
            plot_convergence(result.history),
            "relative residual per Newton iteration",
            "figure-convergence",
        ),
        table(
            steps,
            header=("strategy", "step", "τ", "iterations", "converged", "reason"),
            ident="steps",
        ),
    ]


def _pattern_figures(outcome: PanelOutcome, material: Hyperelastic) -> list[str]:
    from ..io.plot import pattern_image, plot_pattern, plot_pattern_fields, plot_surface_fields

    result, mesh, fields = outcome.result, outcome.mesh, outcome.result.fields
    x = result.material_coordinates
    image = pattern_image(mesh, x, REPORT_DPI)  # the cells rasterised once for every picture of x
    scale = material.stiffness_scale * result.thickness
    crossings = None if result.overlap is None else result.overlap.crossings
    caption = "the pattern with warp and fill"
    if crossings is not None:
        caption += f"; circled: where its outline crosses itself ({len(crossings)})"
    preview = outcome.directory / "pattern.png"  # the same picture, written already
    parts = [
        "<h2>Pattern</h2>",
        picture(preview, caption, "figure-pattern")
        if preview.is_file()
        else figure(
            plot_pattern(
                mesh, x, fibres=result.fibres, title="pattern", marks=crossings, image=image
            ),
            caption,
            "figure-pattern",
        ),
    ]
    drawings = plot_pattern_fields(
        mesh,
        x,
        {name: fields[name] for name in _FIGURE_FIELDS},
        fibres=result.fibres,
        stress_scale=scale,
        image=image,
    )
    for name, drawing in drawings:
        caption = f"{name} on the pattern (on the design shape)"
        parts.append(figure(drawing, caption, f"figure-{name}", close=False))
    titles = {"det_F": "det F", "warp_stress": "warp stress"}
    surfaces = plot_surface_fields(
        mesh,
        {name: fields[name] for name in titles},
        titles=titles,
        stress_scale=scale,
        dpi=REPORT_DPI,
    )
    parts.append("<h2>On the design surface</h2>")
    for name, drawing in surfaces:
        caption = f"{titles[name]} on the design surface"
        parts.append(figure(drawing, caption, f"figure-surface-{name}", close=False))
    return parts


def html_report(panel: PanelOutcome, outcome: JobOutcome) -> str:
    """The report of one pattern of a job as one HTML document."""
    job, material = outcome.job, outcome.material
    result = panel.result
    parts = page(
        panel.name,
        f"Cutting pattern: {panel.name}",
        status_text(result.converged, result.reason),
        panel.warnings,
    )
    parts += _input_section(panel, job)
    parts += _material_section(result, job, material)
    parts += _key_figures(panel, units_of(outcome))
    parts += _convergence_section(result)
    if result.converged or result.uncuttable:
        parts += _pattern_figures(panel, material)
    parts += drape_section(panel)
    if outcome.erection is not None and outcome.structure is None:
        parts += erection_section(
            outcome.erection, outcome.units, outcome.directory / "erect", outcome.optimum
        )
    if outcome.structure is None:
        parts += scatter_section(outcome)
    files = [(f.name, os.path.relpath(f, panel.directory)) for f in panel.files]
    parts += [
        "<h2>Files</h2>",
        table(files, header=("file", "path"), ident="files"),
        "</body></html>",
    ]
    return "\n".join(parts)


def structure_report(outcome: JobOutcome) -> str:
    """The report of a structure: status, panels (with links to their reports), seams."""
    structure = outcome.structure
    units = outcome.units
    panels = [
        (
            p.name,
            p.mesh.num_cells,
            f"{number(p.mesh.area)} {units}²",
            f"{number(p.result.pattern_area)} {units}²",
            "yes" if p.result.converged else "no",
            p.result.iterations,
        )
        for p in outcome.panels
    ]
    links = "".join(
        f'<li><a href="{html.escape(p.directory.name)}/report.html">{html.escape(p.name)}</a></li>'
        for p in outcome.panels
    )
    seams = [
        (
            f"{s.first} | {s.second}",
            s.segments,
            number(s.length_first_after, 8),
            number(s.length_second_after, 8),
            f"{s.mismatch_before:.2e}",
            f"{s.mismatch_after:.2e}",
        )
        for s in structure.seam_reports
    ]
    key = [
        ("panels", len(outcome.panels)),
        ("seams", len(structure.seams)),
        ("seam matching", "yes" if structure.matched else "no"),
        ("coupled iterations", structure.iterations),
        ("energy, panels alone", number(structure.energy_independent)),
        ("energy, seams matched", number(structure.energy)),
        ("price of matching", f"{structure.energy_price:.3e}"),
        ("time", f"{structure.elapsed:.2f} s"),
    ]
    status = status_text(structure.converged, structure.reason)
    parts = [
        *page("structure", "Structure", status, outcome.warnings),
        "<h2>Key figures</h2>",
        table(key, ident="key-figures"),
        "<h2>Panels</h2>",
        table(
            panels,
            header=("panel", "cells", "surface area", "pattern area", "converged", "iterations"),
            ident="panels",
        ),
        f"<ul id='panel-reports'>{links}</ul>",
        "<h2>Seams (pattern lengths)</h2>",
        table(
            seams,
            header=("seam", "segments", "length A", "length B", "mismatch before", "after"),
            ident="seams",
        ),
        *(_cut_section(outcome) if outcome.cut is not None else []),
        *(
            erection_section(outcome.erection, units, outcome.directory / "erect", outcome.optimum)
            if outcome.erection is not None
            else []
        ),
        *scatter_section(outcome),
        "</body></html>",
    ]
    return "\n".join(parts)


def scatter_section(outcome: JobOutcome) -> list[str]:
    """The band of the run's patterns under the fabric's scatter (none without ``[scatter]``):
    the fabric and its samples, the band of every figure and its plot, or why there is none."""
    if outcome.scatter is None:
        return []
    from .fabric_report import band_section

    run = outcome.scatter
    parts = [f"<h2>Fabric scatter: the band of the patterns ({html.escape(str(run.path))})</h2>"]
    if run.band is None:
        return [*parts, f"<p>No band: {html.escape(run.reason or '')}</p>"]
    parts.append(
        "<p>The nominal case is the run's own patterns solved again with the same law and "
        f"options (its figures differ from the run's by at most {run.nominal_difference:.1e} "
        f"{html.escape(outcome.units)}); the samples were solved in this process.</p>"
    )
    return parts + band_section(run.band, outcome.units, level=3)


def _cut_section(outcome: JobOutcome) -> list[str]:
    """The cutting plan and the nest of a cut job: figures and pictures."""
    from ..io.plot import plot_cut_lines, plot_nest
    from .cut_outputs import nested_drawings

    result, units = outcome.cut, outcome.units
    plan, nest = result.plan, result.nest
    key = [
        ("roll width", f"{result.options.roll_width:g} {units}"),
        ("cutting lines", f"{result.options.seams}, {len(plan.lines)}"),
        ("strips", plan.counted),
        ("widest pattern with allowances", f"{number(max(result.widths))} {units}"),
        (
            "worst cell angle",
            f"{plan.cut.worst_angle:.1f}° (surface {result.surface_worst_angle:.1f}°)",
        ),
    ]
    if nest is not None:
        key += [
            ("roll length used", f"{number(nest.length)} {units}"),
            ("yield", f"{100 * nest.yield_:.1f} % (waste {100 * nest.waste:.1f} %)"),
            ("nest made", nest.how),
        ]
    parts = ["<h2>Cutting and nesting</h2>", table(key, ident="cut-figures")]
    lines = plot_cut_lines(plan.cut.mesh, plan.cut.panel_ids, plan.cut.lines, dpi=REPORT_DPI)
    parts.append(figure(lines, "cutting lines on the surface", "cut-lines"))
    if nest is not None:
        drawing = plot_nest(nest.roll_width, nest.length, nested_drawings(outcome), units=units)
        parts.append(figure(drawing, "the pieces on the roll", "nest"))
    return parts


def write_reports(outcome: JobOutcome) -> None:
    """Write each pattern's ``report.html`` (and the structure's), atomically; the paths go to
    the outcome's file lists."""
    with report_drawing():
        for panel in outcome.panels:
            path = panel.directory / "report.html"
            write_text(path, html_report(panel, outcome))
            panel.files.append(path)
            outcome.files.append(path)
        if outcome.structure is not None:
            path = outcome.directory / "report.html"
            write_text(path, structure_report(outcome))
            outcome.files.append(path)
