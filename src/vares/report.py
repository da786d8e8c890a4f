"""A self-contained HTML report of a patterning job, for a person to read.

One file with everything inline (pictures as embedded PNG): the input, the material and its
parameters, the solver's path and convergence history, the pattern drawn with its yarn
directions, the result fields on the pattern and on the 3D surface, the key figures and the
warnings.
"""

from __future__ import annotations

import base64
import datetime
import html
import io
from pathlib import Path

import numpy as np

from .analysis import KEY_FIELDS
from .io import atomic_path, field_statistics
from .runner import JobOutcome

__all__ = ["html_report", "write_report"]

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


def html_report(outcome: JobOutcome) -> str:
    """The report of a job as one HTML document."""
    from . import __version__
    from .plot import plot_convergence, plot_pattern, plot_surface

    result, mesh, job = outcome.result, outcome.mesh, outcome.job
    fields = result.fields if result.converged else {}
    units = job.input.get("units", "m")
    status = (
        '<span class="status-ok">converged</span>'
        if result.converged
        else f'<span class="status-bad">not converged: {html.escape(str(result.reason))}</span>'
    )
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>vares report: {html.escape(outcome.name)}</title><style>{_STYLE}</style>",
        "</head><body>",
        f"<h1>Cutting pattern: {html.escape(outcome.name)}</h1>",
        f"<p>vares {__version__}, {datetime.datetime.now():%Y-%m-%d %H:%M}. Status: {status}</p>",
        "<h2>Warnings</h2>",
    ]
    if outcome.warnings:
        parts += [f'<div class="warning">{html.escape(w)}</div>' for w in outcome.warnings]
    else:
        parts.append("<p id='no-warnings'>None.</p>")

    cells = ", ".join(f"{len(c)} {t}" for t, c in mesh.cells.items())
    source = job.input.get("mesh") or f"example {job.input.get('example')}"
    parts += [
        "<h2>Input</h2>",
        _table(
            [
                ("source", source),
                ("nodes", mesh.num_points),
                ("cells", cells),
                ("surface area", f"{_g(mesh.area)} {units}²"),
                ("extent (x, y, z)", " × ".join(_g(v, 4) for v in np.ptp(mesh.points, axis=0))),
            ],
            ident="input",
        ),
    ]

    material = outcome.material
    rows = [("law", type(material).__name__)]
    rows += [(k, v) for k, v in material.parameters.items()]
    rows.append(("thickness", result.thickness))
    if "fabric" in job.material:
        rows.append(("fabric preset", job.material["fabric"]))
    rows.append(("fibre orientation", result.orientation))
    rows.append(
        (
            "warp / fill in the pattern",
            f"{np.round(result.fibres.warp, 4).tolist()} / "
            f"{np.round(result.fibres.fill, 4).tolist()}",
        )
    )
    if result.warp_direction is not None:
        rows.append(("warp direction (3D)", np.round(result.warp_direction, 4).tolist()))
        rows.append(("mean warp deviation", f"{result.warp_deviation:.2e}°"))
    if result.prestress is not None:
        p = result.prestress
        rows.append(
            (
                "prestress warp / fill",
                f"{_g(float(p[:, 0].mean()))} / "
                f"{_g(float(p[:, 1].mean()))}" + (" (per cell)" if len(p) > 1 else ""),
            )
        )
    parts += ["<h2>Material and fibres</h2>", _table(rows, ident="material")]

    key = [
        ("surface area", f"{_g(mesh.area)} {units}²"),
        ("pattern area", f"{_g(result.pattern_area)} {units}²"),
        ("pattern / surface area", f"{100 * (result.pattern_area / mesh.area - 1):+.3f} %"),
        ("energy", _g(result.energy)),
        ("Newton iterations", result.iterations),
        ("strategy", " → ".join(result.strategy)),
        ("initial guess", result.initial_guess),
        ("linear solver", result.linear_solver),
        ("time", f"{result.elapsed:.2f} s"),
    ]
    if fields:
        stats = field_statistics(fields)
        for name in KEY_FIELDS:
            s = stats[name]
            key.append(
                (f"{name} (min / mean / max)", f"{_g(s['min'])} / {_g(s['mean'])} / {_g(s['max'])}")
            )
        key.append(("wrinkling area", f"{100 * stats['wrinkling']['mean']:.1f} %"))
    parts += ["<h2>Key figures</h2>", _table(key, ident="key-figures")]

    if outcome.compensation is not None and result.prestress is not None:
        rows = outcome.compensation.rows()
        parts += [
            "<h2>Compensation and prestress</h2>",
            _table(rows, header=("", "warp", "fill"), ident="compensation"),
        ]

    parts += [
        "<h2>Convergence</h2>",
        _figure(
            plot_convergence(result.history),
            "relative residual per Newton iteration",
            "figure-convergence",
        ),
    ]
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
    parts.append(
        _table(
            steps,
            header=("strategy", "step", "τ", "iterations", "converged", "reason"),
            ident="steps",
        )
    )

    if result.converged:
        x = result.material_coordinates
        scale = material.stiffness_scale * result.thickness
        parts += [
            "<h2>Pattern</h2>",
            _figure(
                plot_pattern(mesh, x, fibres=result.fibres, title="pattern"),
                "the pattern with warp and fill",
                "figure-pattern",
            ),
        ]
        for name in _FIGURE_FIELDS:
            parts.append(
                _figure(
                    plot_pattern(
                        mesh,
                        x,
                        fields[name],
                        field=name,
                        fibres=result.fibres,
                        title=name,
                        stress_scale=scale,
                    ),
                    f"{name} on the pattern",
                    f"figure-{name}",
                )
            )
        parts += [
            "<h2>On the surface</h2>",
            _figure(
                plot_surface(mesh, fields["det_F"], field="det_F", title="det F"),
                "det F on the 3D surface",
                "figure-surface-det_F",
            ),
            _figure(
                plot_surface(
                    mesh,
                    fields["warp_stress"],
                    field="warp_stress",
                    title="warp stress",
                    stress_scale=scale,
                ),
                "warp stress on the 3D surface",
                "figure-surface-warp_stress",
            ),
        ]
    files = [(f.name, str(f)) for f in outcome.files]
    parts += [
        "<h2>Files</h2>",
        _table(files, header=("file", "path"), ident="files"),
        "</body></html>",
    ]
    return "\n".join(parts)


def write_report(path: str | Path, outcome: JobOutcome) -> None:
    """Write :func:`html_report` atomically."""
    text = html_report(outcome)
    with atomic_path(Path(path)) as temporary:
        temporary.write_text(text, encoding="utf-8")
