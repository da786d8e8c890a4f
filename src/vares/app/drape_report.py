"""The report's section on a ply draped kinematically beside the pattern (``--drape``): where it
was laid, its producibility, its shear against the pattern's and the net's shear on the surface;
and the report of ``vares drape --report`` (drape.html): the same drape and its darts, drawn on
the mould and on the flat pattern."""

from __future__ import annotations

from html import escape
from typing import TYPE_CHECKING

import numpy as np

from .html_parts import REPORT_DPI, figure, number, page, status_text, table
from .outcome import PanelOutcome

if TYPE_CHECKING:
    from ..analysis.darts import DartedPattern
    from ..analysis.drape import PlyDrape
    from ..analysis.splices import SplicedPly

__all__ = [
    "darts_section",
    "drape_page",
    "drape_section",
    "splice_piece_rows",
    "splices_section",
]


def _ply_rows(ply: PlyDrape, units: str) -> list[tuple[str, object]]:
    check = ply.producibility
    locking, source = ply.options.locking
    rows = [
        ("seed", " ".join(number(v, 6) for v in ply.seed)),
        ("warp at the seed", " ".join(number(v, 4) for v in ply.warp)),
        ("yarn spacing", f"{number(ply.spacing)} {units}"),
        ("net nodes", int(ply.drape.net.valid.sum())),
        ("fabric kind", ply.options.fabric_kind),
        ("locking angle", f"{number(locking, 4)}° ({source})"),
        ("warning from", f"{number(check.warn_angle, 4)}°"),
        ("largest shear of the net", f"{number(check.max_shear, 4)}°"),
        ("area with a shear value", f"{100 * check.covered:.1f} %"),
    ]
    rows += [(f"area {name}", f"{100 * value:.2f} %") for name, value in check.fractions.items()]
    return rows


def drape_section(panel: PanelOutcome) -> list[str]:
    """The HTML parts of the section (none without a drape)."""
    ply = panel.drape
    if ply is None:
        return []
    parts = [
        "<h2>Kinematic drape and producibility</h2>",
        table(_ply_rows(ply, panel.units), ident="drape"),
    ]
    result = panel.result
    if result.converged:
        against = ply.comparison(result.fields["shear_angle"], panel.mesh.cell_areas())
        if "correlation" in against:
            compared = [
                ("cells compared", against["cells"]),
                (
                    "mean |difference| (area-weighted)",
                    f"{number(against['mean_abs_difference'], 4)}°",
                ),
                ("largest |difference|", f"{number(against['max_abs_difference'], 4)}°"),
                ("largest shear of the pattern", f"{number(against['max_shear'], 4)}°"),
                ("correlation", number(against["correlation"], 4)),
            ]
            parts += [
                "<h3>The pattern's shear against the net's</h3>",
                table(compared, ident="drape-against-pattern"),
            ]
    from ..io.plot import plot_surface_fields  # when a report is written

    shear = np.where(np.isfinite(ply.drape.shear_angle), ply.drape.shear_angle, 0.0)
    titles = {"shear_angle": "shear angle of the kinematic net [°] (0 where it does not reach)"}
    for _, drawing in plot_surface_fields(
        panel.mesh, {"shear_angle": shear}, titles=titles, dpi=REPORT_DPI
    ):
        parts.append(figure(drawing, titles["shear_angle"], "figure-drape-shear", close=False))
    return parts


def darts_section(darted: DartedPattern, units: str) -> list[str]:
    """The HTML parts on a ply's darts: the largest shear before and after, every dart's length
    and mouth opening, every solve with darts, and the shear on the mould and the flat pattern
    with the dart lines."""
    summary = darted.summary()
    after = summary["max_shear_after"]
    rows = [
        ("locking angle", f"{number(darted.locking_angle, 4)}°"),
        ("largest shear without darts", f"{number(summary['max_shear_before'], 4)}°"),
        (
            "largest shear with the darts open",
            "no dart" if after is None else f"{number(after, 4)}°",
        ),
        ("below the locking angle", "yes" if darted.relieved else "no"),
        ("darts", summary["darts"]),
        (
            "cut with the darts",
            "yes"
            if darted.kept
            else "no dart opened"
            if darted.after is None
            else "no (they do not lower the largest shear)",
        ),
        ("pattern without darts", _state(darted.before)),
        (
            "pattern with the darts open",
            "not solved" if darted.after is None else _state(darted.after),
        ),
    ]
    shares = summary["over_locking_curvature"]
    if shares is not None:
        rows.append(
            (
                "area at or beyond the locking angle without darts: positively / negatively "
                "curved / flat",
                " / ".join(f"{100 * shares[k]:.0f} %" for k in ("positive", "negative", "flat")),
            )
        )
    parts = ["<h2>Darts</h2>", table(rows, ident="darts")]
    if darted.needs_splices:
        parts.append(
            "<p class='warning'>Most of the area at or beyond the locking angle is negatively "
            "curved: a dart takes out fabric the mould needs there. Draw darts that reach the "
            "positively curved part beside it (<code>--dart-lines</code>), or splice the ply "
            "(<code>--splice-lines</code>).</p>"
        )
    if summary["darts"]:
        darts = [
            (str(k), f"{number(length, 4)} {units}", f"{number(opening, 4)} {units}")
            for k, (length, opening) in enumerate(
                zip(summary["dart_lengths"], summary["mouth_openings"], strict=True), start=1
            )
        ]
        parts.append(table(darts, header=("dart", "length", "mouth opening"), ident="dart-lines"))
    rounds = [
        (
            str(k),
            r["rule"],
            "given" if r["tip_angle"] is None else f"{number(r['tip_angle'], 4)}°",
            f"{number(r['max_shear'], 4)}°",
            r["iterations"],
            f"{r['seconds']:.1f} s",
            "yes" if r["converged"] else "no",
        )
        for k, r in enumerate(summary["rounds"], start=1)
    ]
    if rounds:
        header = (
            "solve",
            "darts by",
            "dart tip",
            "largest shear",
            "iterations",
            "time",
            "converged",
        )
        parts.append(table(rounds, header=header, ident="dart-rounds"))
    from ..io.dart_plots import plot_darts  # when a report is written

    caption = "shear on the mould without and with the darts open, and the flat pattern"
    parts.append(figure(plot_darts(darted, dpi=REPORT_DPI), caption, "figure-darts"))
    return parts


def splices_section(spliced: SplicedPly, units: str, placed: str | None = None) -> list[str]:
    """The HTML parts on a spliced ply: the largest shear of the whole ply and of every piece,
    the pieces' yarn strains and solves, and the shear of the pieces on the mould; ``placed``:
    how the lines were placed (``vares drape --splices auto``'s line), if they were."""
    summary = spliced.summary()
    rows = [("placed", placed)] if placed is not None else []
    rows += [
        ("locking angle", f"{number(spliced.locking_angle, 4)}°"),
        ("largest shear of the whole ply", f"{number(summary['max_shear_before'], 4)}°"),
        ("largest shear of its pieces", f"{number(summary['max_shear_after'], 4)}°"),
        ("below the locking angle", "yes" if spliced.relieved else "no"),
        ("splice lines", summary["splices"]),
        (
            "their lengths",
            ", ".join(f"{number(v, 4)} {units}" for v in summary["splice_lengths"]),
        ),
        ("pattern of the whole ply", _state(spliced.before)),
    ]
    header, pieces = splice_piece_rows(summary, units)
    parts = [
        "<h2>Splices</h2>",
        table(rows, ident="splices"),
        table(pieces, header=header, ident="splice-pieces"),
    ]
    from ..io.dart_plots import plot_splices  # when a report is written

    caption = "shear on the mould of the whole ply and of its pieces, and the flat pieces"
    parts.append(figure(plot_splices(spliced, dpi=REPORT_DPI), caption, "figure-splices"))
    return parts


def splice_piece_rows(summary: dict, units: str) -> tuple[tuple[str, ...], list[tuple[str, ...]]]:
    """The header and one row per piece of a spliced ply's ``summary``
    (:meth:`~vares.analysis.splices.SplicedPly.summary`), as the report and ``vares drape``
    print them."""
    header = (
        "piece",
        "cells",
        f"area ({units}²)",
        "largest shear",
        "largest yarn strain (nodal mean)",
        "iterations",
        "converged",
        "net's largest shear",
    )
    rows = []
    for p in summary["pieces"]:
        strain, mean = p["max_yarn_strain"], p["max_yarn_strain_nodal_mean"]
        net = p.get("kinematic", {})
        rows.append(
            (
                p["name"],
                str(p["cells"]),
                number(p["area"], 6),
                f"{number(p['max_shear'], 4)}°",
                "" if strain is None else f"{100 * strain:.2f} % ({100 * mean:.2f} %)",
                str(p["iterations"]),
                "yes" if p["converged"] else "NO",
                f"{number(net['max_shear'], 4)}°" if "max_shear" in net else net.get("error", ""),
            )
        )
    return header, rows


def _state(result) -> str:
    return "converged" if result.converged else f"not converged: {result.reason}"


def drape_page(
    ply: PlyDrape,
    darted: DartedPattern | None,
    name: str,
    units: str,
    *,
    spliced: SplicedPly | None = None,
    placed: str | None = None,
) -> str:
    """The report of ``vares drape --report``: the drape and producibility of the ply on the
    mould ``name`` and, with darts, :func:`darts_section`; with splices,
    :func:`splices_section`; ``placed``: how splices were placed, or that none was needed
    (``vares drape --splices auto``)."""
    warnings = []
    if (darted is not None and not darted.relieved) or (
        spliced is not None and not spliced.relieved
    ):
        warnings.append("the largest shear is not below the locking angle")
    if darted is not None:
        status = status_text(darted.final.converged, darted.final.reason)
    elif spliced is not None:
        stuck = [
            p.name for p, r in zip(spliced.pieces, spliced.results, strict=True) if not r.converged
        ]
        status = status_text(spliced.converged, ", ".join(stuck))
    else:
        status = "drape"
    parts = page(name, f"Drape: {name}", status, warnings)
    parts += ["<h2>Kinematic drape and producibility</h2>", table(_ply_rows(ply, units))]
    if darted is not None:
        parts += darts_section(darted, units)
    if spliced is not None:
        parts += splices_section(spliced, units, placed)
    elif placed is not None:
        parts += ["<h2>Splices</h2>", f"<p>{escape(placed)}</p>"]
    parts.append("</body></html>")
    return "\n".join(parts)
