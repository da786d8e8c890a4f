"""The erection section of the HTML reports: the stresses on the design shape (what the
patterning reports: the patterns forced onto the surface) against those after erection (what the
structure really carries), the deviation from the design and where the membrane wrinkles.

It goes into a job's ``report.html`` (the pattern's, or the structure's) when the job erects, and
``vares erect DIR --report`` writes it on its own as ``DIR/erect/report.html``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..analysis.erection import ErectionResult
from ..io.files import write_text
from .erection_outputs import erected_pictures, erection_comparison
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

if TYPE_CHECKING:
    from ..analysis.erection_optimum import OptimisedPatterns

__all__ = ["erection_section", "write_erection_report"]


def _figures(result: ErectionResult, units: str, pictures: Path | None) -> list[str]:
    """The section's pictures; those the erection wrote into ``pictures`` are embedded, the
    others drawn, those of each shape on one figure (:func:`~vares.io.plot.plot_surface_fields`)."""
    from ..io.plot import plot_surface_fields

    scale = result.material.stiffness_scale * result.thickness
    written = erected_pictures(result, units)  # (file, values, title) by field
    design = {
        yarn: (None, result.design_fields[yarn], f"{yarn[:4]} force on the design shape")
        for yarn in ("warp_stress", "fill_stress")
    }
    order = [  # (shape, field): the design shape's yarn forces beside the erected ones
        ("erected", "normal_deviation"),
        ("design", "warp_stress"),
        ("erected", "warp_stress"),
        ("design", "fill_stress"),
        ("erected", "fill_stress"),
        ("erected", "state"),
    ]
    drawings = [
        (*(written if shape == "erected" else design)[field], shape, field)
        for shape, field in order
    ]
    embedded, fields, titles = {}, {"design": {}, "erected": {}}, {"design": {}, "erected": {}}
    for k, (name, values, caption, shape, field) in enumerate(drawings):
        if pictures is not None and name is not None and (pictures / name).is_file():
            embedded[k] = picture(pictures / name, caption, f"figure-erection-{k}")
        else:  # a shape's fields are distinct
            fields[shape][field], titles[shape][field] = values, caption
    drawn = {
        shape: plot_surface_fields(
            mesh,
            fields[shape],
            titles=titles[shape],
            stress_unit="force/length",
            stress_scale=scale,
            dpi=REPORT_DPI,
        )
        for shape, mesh in (("design", result.mesh), ("erected", result.erected_mesh))
    }
    out = []
    for k, (_, _, _, shape, field) in enumerate(drawings):
        if k in embedded:
            out.append(embedded[k])
            continue
        _, drawing = next(drawn[shape])  # the pictures of a shape come in the order asked
        out.append(figure(drawing, titles[shape][field], f"figure-erection-{k}", close=False))
    for pictures_of_a_shape in drawn.values():
        pictures_of_a_shape.close()  # and its figure
    return out


def erection_section(
    result: ErectionResult,
    units: str,
    pictures: Path | None = None,
    optimum: OptimisedPatterns | None = None,
) -> list[str]:
    """The section: status, comparison table (force per length; with ``optimum``, the VaReS
    patterns' erection beside the optimised patterns'), figures (those in ``pictures``, the
    erection's folder, embedded as they are)."""
    key = [
        ("status", "converged" if result.converged else f"not converged: {result.reason}"),
        ("panels welded", len(result.panels)),
        ("nodes / cells", f"{result.mesh.num_points} / {result.mesh.num_cells}"),
        ("supports", f"{int(result.held.sum())} nodes held"),
        ("wrinkling", "tension field (no compression)" if result.options.wrinkling else "off"),
        ("pressure", number(result.options.pressure)),
    ]
    if optimum is None:
        key += [("Newton iterations", result.iterations), ("time", f"{result.elapsed:.2f} s")]
    else:  # ``result`` is the optimum's erection, finished from the optimiser's last trial
        start = optimum.start
        key.append(
            (
                "erection of the VaReS patterns",
                f"{start.iterations} Newton iterations, {start.elapsed:.2f} s",
            )
        )
        key.append(
            (
                "patterns optimised for the erected structure",
                f"{optimum.iterations} steps, {optimum.newton_iterations} Newton iterations of "
                f"their erections, {optimum.elapsed:.2f} s (shape weight "
                f"{optimum.shape_weight:g}, shape bound {optimum.shape_bound}"
                + ("" if optimum.converged else f"; not optimised: {optimum.reason}")
                + ")",
            )
        )
    if result.cables is not None:
        key.append(
            (
                "edge cables",
                f"{len(result.cables.segments)} segments, EA "
                f"{number(result.cables.stiffness)}, force {number(result.cable_tension.min())} … "
                f"{number(result.cable_tension.max())}",
            )
        )
    parts = [
        "<h2>Erection: on the design shape and after erection</h2>",
        "<p>The panels welded along their seams, stretched onto the supports and left to settle "
        "(the same law and yarns; the membrane carries no compression). Membrane forces are "
        "force per length along the erected yarns; means and RMS are weighted by the design "
        "area.</p>",
        table(key, ident="erection"),
    ]
    if result.converged:
        titles, rows = erection_comparison(result, units, optimum)
        parts += [
            table(rows, header=("", *titles), ident="erection-comparison"),
            *_figures(result, units, pictures),
        ]
    return parts


def write_erection_report(result: ErectionResult, directory: Path, units: str) -> Path:
    """``report.html`` of an erection on its own, in ``directory``."""
    parts = page(
        "erection",
        "Erection analysis",
        status_text(result.converged, result.reason),
        [],
    )
    with report_drawing():
        parts += [*erection_section(result, units, Path(directory)), "</body></html>"]
    path = Path(directory) / "report.html"
    write_text(path, "\n".join(parts))
    return path
