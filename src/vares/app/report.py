"""Self-contained HTML reports of a patterning job, for a person to read.

One file per pattern with everything inline (pictures as embedded PNG): the input, the material
and its parameters, the solver's path and convergence history, the pattern drawn with its yarn
directions, the result fields on the pattern and on the 3D surface, the key figures and the
warnings. A structure gets one more, for the whole: its panels, its seams before and after
matching, and links to the panels' reports.
"""

from __future__ import annotations

import base64
import datetime
import html
import io
import os
from pathlib import Path

import numpy as np

from .._version import __version__
from ..analysis.statistics import field_statistics
from ..io.files import atomic_path
from ..materials import Hyperelastic
from ..mechanics.fields import FIELD_DESCRIPTIONS, KEY_FIELDS
from .job import Job
from .outcome import JobOutcome, PanelOutcome
from .outputs import units_of

__all__ = ["html_report", "structure_report", "write_reports"]

_STYLE = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1100px; color: #222; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.2em; }
table { border-collapse: collapse; margin: 0.5em 0 1em; }
td, th { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; }
th { background: #f2f4f7; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
.status-ok { color: #17702a; font-weight: bold; } .status-bad { color: #b00020; font-weight: bold; }
.warning { background: #fff4d6; border-left: 4px solid #e0a800; padding: 0.4em 0.8em;
  margin: 0.3em 0; }
figure { display: inline-block; margin: 0.5em; vertical-align: top; }
figure img { max-width: 520px; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #555; }
"""

_FIGURE_FIELDS = ("det_F", "warp_stress", "fill_stress", "shear_angle", "stress_min")


def _png(fig) -> str:
    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    plt.close(fig)
    return base64.b64encode(buffer.getvalue()).decode("ascii")


def _figure(fig, caption: str, ident: str) -> str:
    return (
        f'<figure id="{ident}"><img alt="{html.escape(caption)}" '
        f'src="data:image/png;base64,{_png(fig)}"><figcaption>{html.escape(caption)}'
        "</figcaption></figure>"
    )


def _table(rows, header=None, ident: str | None = None) -> str:
    attr = f' id="{ident}"' if ident else ""
    out = [f"<table{attr}>"]
    if header:
        out.append("<tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header) + "</tr>")
    for row in rows:
        cells = []
        for k, cell in enumerate(row):
            text = html.escape(str(cell))
            cells.append(f"<th>{text}</th>" if k == 0 else f'<td class="num">{text}</td>')
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</table>")
    return "".join(out)


def _g(value: float, digits: int = 5) -> str:
    return f"{value:.{digits}g}"


def _page(title: str, heading: str, status: str, warnings: list[str]) -> list[str]:
    """The head of a report: title, version, date, status and the warnings."""
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>vares report: {html.escape(title)}</title><style>{_STYLE}</style>",
        "</head><body>",
        f"<h1>{html.escape(heading)}</h1>",
        f"<p>vares {__version__}, {datetime.datetime.now():%Y-%m-%d %H:%M}. Status: {status}</p>",
        "<h2>Warnings</h2>",
    ]
    if warnings:
        return parts + [f'<div class="warning">{html.escape(w)}</div>' for w in warnings]
    return [*parts, "<p id='no-warnings'>None.</p>"]


def _status(converged: bool, reason: str | None) -> str:
    if converged:
        return '<span class="status-ok">converged</span>'
    return f'<span class="status-bad">not converged: {html.escape(str(reason))}</span>'


def _input_section(outcome: PanelOutcome, job: Job) -> list[str]:
    mesh, units = outcome.mesh, outcome.units
    cells = ", ".join(f"{len(c)} {t}" for t, c in mesh.cells.items())
    source = ", ".join(job.input.paths) or f"example {job.input.example}"
    rows = [
        ("source", source),
        ("nodes", mesh.num_points),
        ("cells", cells),
        ("surface area", f"{_g(mesh.area)} {units}²"),
        ("extent (x, y, z)", " × ".join(_g(v, 4) for v in np.ptp(mesh.points, axis=0))),
    ]
    return ["<h2>Input</h2>", _table(rows, ident="input")]


def _material_section(result, job: Job, material: Hyperelastic) -> list[str]:
    rows = [("law", type(material).__name__)]
    rows += [(k, v) for k, v in material.parameters.items()]
    rows.append(("thickness", result.thickness))
    if job.material.fabric is not None:
        rows.append(("fabric preset", job.material.fabric))
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
                f"{_g(float(p[:, 0].mean()))} / {_g(float(p[:, 1].mean()))}{per_cell}",
            )
        )
    return ["<h2>Material and fibres</h2>", _table(rows, ident="material")]


def _key_figures(outcome: PanelOutcome, unit_names: dict[str, str]) -> list[str]:
    result, mesh = outcome.result, outcome.mesh
    units = unit_names["length"]
    key = [
        ("surface area", f"{_g(mesh.area)} {units}²"),
        ("pattern area", f"{_g(result.pattern_area)} {units}²"),
        ("pattern / surface area", f"{100 * (result.pattern_area / mesh.area - 1):+.3f} %"),
        ("energy", f"{_g(result.energy)} ({unit_names['energy']})"),
        ("Newton iterations", result.iterations),
        ("strategy", " → ".join(result.strategy)),
        ("initial guess", result.initial_guess),
        ("linear solver", result.linear_solver),
        ("time", f"{result.elapsed:.2f} s"),
    ]
    parts = ["<h2>Key figures</h2>", _table(key, ident="key-figures")]
    if not (result.converged or result.overlap is not None):
        return parts
    stats = field_statistics(result.fields)
    rows = []
    for name in KEY_FIELDS:
        s = stats[name]
        unit = _unit(name, unit_names)
        rows.append((f"{name}{unit}", _g(s["min"]), _g(s["mean"]), _g(s["max"])))
    parts += [
        "<h2>Results on the design shape</h2>",
        "<p>Stresses and stretches with the pattern forced exactly onto the design surface "
        "(area-weighted means).</p>",
        _table(rows, header=("field", "min", "mean", "max"), ident="fields"),
    ]
    if outcome.compensation is not None and result.prestress is not None:
        parts += [
            f"<h2>Compensation and prestress on the design shape ({unit_names['stress']})</h2>",
            _table(outcome.compensation.rows(), header=("", "warp", "fill"), ident="compensation"),
        ]
    return parts


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
        _figure(
            plot_convergence(result.history),
            "relative residual per Newton iteration",
            "figure-convergence",
        ),
        _table(
            steps,
            header=("strategy", "step", "τ", "iterations", "converged", "reason"),
            ident="steps",
        ),
    ]


def _pattern_figures(outcome: PanelOutcome, material: Hyperelastic) -> list[str]:
    from ..io.plot import plot_pattern, plot_surface

    result, mesh, fields = outcome.result, outcome.mesh, outcome.result.fields
    x = result.material_coordinates
    scale = material.stiffness_scale * result.thickness
    crossings = None if result.overlap is None else result.overlap.crossings
    caption = "the pattern with warp and fill"
    if crossings is not None:
        caption += f"; circled: where its outline crosses itself ({len(crossings)})"
    parts = [
        "<h2>Pattern</h2>",
        _figure(
            plot_pattern(mesh, x, fibres=result.fibres, title="pattern", marks=crossings),
            caption,
            "figure-pattern",
        ),
    ]
    for name in _FIGURE_FIELDS:
        figure = plot_pattern(
            mesh, x, fields[name], field=name, fibres=result.fibres, title=name, stress_scale=scale
        )
        caption = f"{name} on the pattern (on the design shape)"
        parts.append(_figure(figure, caption, f"figure-{name}"))
    surface_det_f = plot_surface(mesh, fields["det_F"], field="det_F", title="det F")
    surface_warp = plot_surface(
        mesh, fields["warp_stress"], field="warp_stress", title="warp stress", stress_scale=scale
    )
    return [
        *parts,
        "<h2>On the design surface</h2>",
        _figure(surface_det_f, "det F on the design surface", "figure-surface-det_F"),
        _figure(surface_warp, "warp stress on the design surface", "figure-surface-warp_stress"),
    ]


def html_report(panel: PanelOutcome, outcome: JobOutcome) -> str:
    """The report of one pattern of a job as one HTML document."""
    job, material = outcome.job, outcome.material
    result = panel.result
    parts = _page(
        panel.name,
        f"Cutting pattern: {panel.name}",
        _status(result.converged, result.reason),
        panel.warnings,
    )
    parts += _input_section(panel, job)
    parts += _material_section(result, job, material)
    parts += _key_figures(panel, units_of(outcome))
    parts += _convergence_section(result)
    if result.converged or result.overlap is not None:
        parts += _pattern_figures(panel, material)
    files = [(f.name, os.path.relpath(f, panel.directory)) for f in panel.files]
    parts += [
        "<h2>Files</h2>",
        _table(files, header=("file", "path"), ident="files"),
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
            f"{_g(p.mesh.area)} {units}²",
            f"{_g(p.result.pattern_area)} {units}²",
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
            _g(s.length_first_after, 8),
            _g(s.length_second_after, 8),
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
        ("energy, panels alone", _g(structure.energy_independent)),
        ("energy, seams matched", _g(structure.energy)),
        ("price of matching", f"{structure.energy_price:.3e}"),
        ("time", f"{structure.elapsed:.2f} s"),
    ]
    status = _status(structure.converged, structure.reason)
    parts = [
        *_page("structure", "Structure", status, outcome.warnings),
        "<h2>Key figures</h2>",
        _table(key, ident="key-figures"),
        "<h2>Panels</h2>",
        _table(
            panels,
            header=("panel", "cells", "surface area", "pattern area", "converged", "iterations"),
            ident="panels",
        ),
        f"<ul id='panel-reports'>{links}</ul>",
        "<h2>Seams (pattern lengths)</h2>",
        _table(
            seams,
            header=("seam", "segments", "length A", "length B", "mismatch before", "after"),
            ident="seams",
        ),
        *(_cut_section(outcome) if outcome.cut is not None else []),
        "</body></html>",
    ]
    return "\n".join(parts)


def _cut_section(outcome: JobOutcome) -> list[str]:
    """The cutting plan and the nest of a cut job: figures and pictures."""
    from ..io.plot import plot_cut_lines, plot_nest
    from .cut_outputs import nested_drawings

    result, units = outcome.cut, outcome.units
    plan, nest = result.plan, result.nest
    key = [
        ("roll width", f"{result.options.roll_width:g} {units}"),
        ("cutting lines", f"{result.options.seams}, {len(plan.lines)}"),
        ("strips", len(plan.panels)),
        ("widest pattern with allowances", f"{_g(max(result.widths))} {units}"),
        (
            "worst cell angle",
            f"{plan.cut.worst_angle:.1f}° (surface {result.surface_worst_angle:.1f}°)",
        ),
    ]
    if nest is not None:
        key += [
            ("roll length used", f"{_g(nest.length)} {units}"),
            ("yield", f"{100 * nest.yield_:.1f} % (waste {100 * nest.waste:.1f} %)"),
        ]
    parts = ["<h2>Cutting and nesting</h2>", _table(key, ident="cut-figures")]
    lines = plot_cut_lines(plan.cut.mesh, plan.cut.panel_ids, plan.cut.lines)
    parts.append(_figure(lines, "cutting lines on the surface", "cut-lines"))
    if nest is not None:
        drawing = plot_nest(nest.roll_width, nest.length, nested_drawings(outcome), units=units)
        parts.append(_figure(drawing, "the pieces on the roll", "nest"))
    return parts


def write_reports(outcome: JobOutcome) -> None:
    """Write each pattern's ``report.html`` (and the structure's), atomically; the paths go to
    the outcome's file lists."""
    for panel in outcome.panels:
        path = panel.directory / "report.html"
        _write_text(path, html_report(panel, outcome))
        panel.files.append(path)
        outcome.files.append(path)
    if outcome.structure is not None:
        path = outcome.directory / "report.html"
        _write_text(path, structure_report(outcome))
        outcome.files.append(path)


def _write_text(path: Path, text: str) -> None:
    with atomic_path(path) as temporary:
        temporary.write_text(text, encoding="utf-8")
