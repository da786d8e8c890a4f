"""The ply book of a laminate (``plybook.html``): one HTML file, a summary of the laminate, then a
section per ply.

The summary: every ply's orientation, thickness, areas, mass, largest shear and producibility, the
stacking sequence with its thicknesses, the nest on the roll and the pair matrices of the
ply-stack check. Each ply's section: its flat blank with the net and extended boundaries and the
rosette (the 0° arrow along the warp, the 90° arrow along the fill, at the seed), its shear and
producibility maps (a darted ply's dart lines drawn on the blank and on both maps), its numbers,
and its darts: their lengths on the mould, the mouths' openings in the blank and the largest
shear before and after, or, without darts, how much of the ply is at or beyond the locking angle.
A spliced ply has a section per piece, with the splices instead of the darts; its first piece's
section shows the whole ply's shear on the mould beside the pieces' and the flat pieces.

Producibility here is that of the blank as cut (opened along its darts, if any): the mechanical
drape's shear angle against the ply's locking angle (its own, the laminate's or its fabric
kind's; warning from :class:`~vares.analysis.drape_options.
DrapeOptions`' ``warn_fraction`` of it); the kinematic net's fractions stand beside it.
"""

from __future__ import annotations

import html
from collections.abc import Sequence

import numpy as np

from ..analysis.drape_options import DrapeOptions
from ..analysis.producibility import CLASSES, Producibility, producibility
from ..structures.laminate import LaminateResult
from ..structures.laminate_blanks import PlyBlank
from ..structures.laminate_pairs import PAIR_TITLES
from ..structures.nesting import RollNest
from .html_parts import figure, number, page, report_drawing, status_text, table
from .ply_sections import (
    drape_figures,
    mass_text,
    optional_text,
    ply_section,
    splices_figure,
)

__all__ = ["BOOK_MATRICES", "ply_book", "ply_producibility"]

#: The pair matrices the book shows.
BOOK_MATRICES = ("warp_compressed_fraction", "largest_compression", "mean_deviation")


def ply_producibility(result: LaminateResult, name: str, piece: str | None = None) -> Producibility:
    """The producibility of ply ``name``'s blank as cut: its mechanical shear angle per cell of
    the blank's mesh (opened along its darts, if any; of its piece ``piece`` when spliced)
    against the ply's locking angle."""
    drape = result.drape(name)
    _, mesh, pattern = drape.piece(piece)
    return producibility(
        pattern.fields["shear_angle"],
        mesh.cell_areas(),
        drape.locking_angle,
        DrapeOptions().warn_fraction,
    )


def _summary_rows(result, blanks, checks, units) -> list[tuple]:
    rows = []
    for blank, check in zip(blanks, checks, strict=True):
        f = check.fractions
        rows.append(
            (
                blank.label,
                f"{blank.orientation:+g}°",
                blank.drape,
                optional_text(blank.thickness, "mm"),
                f"{number(blank.net_area)} {units}²",
                f"{number(blank.trim_area)} {units}²",
                mass_text(blank, blank.net_area, units),
                f"{number(check.max_shear, 3)}°",
                *(f"{100 * f[n]:.1f} %" for n in CLASSES[:3]),
            )
        )
    return rows


def _stacking(blanks: Sequence[PlyBlank], result: LaminateResult) -> list[str]:
    rows, height = [], 0.0
    first = {b.name: b for b in reversed(blanks)}  # a spliced ply's pieces: one layer
    for position, ply in enumerate(result.laminate.plies, 1):
        blank = first[ply.name]
        top = None if blank.thickness is None or height is None else height + blank.thickness
        drop = ply.options.drop_off
        region = ply.options.region or "whole mould"
        rows.append(
            (
                position,
                blank.name,
                f"{blank.orientation:+g}°",
                optional_text(blank.thickness, "mm"),
                optional_text(top, "mm"),
                region,
                "–" if drop is None else drop,
            )
        )
        height = top
    header = ("from the mould", "ply", "orientation", "thickness", "to", "region", "drop-off")
    total = "–" if height is None else f"{number(height, 4)} mm"
    return [
        "<h2>Stacking sequence</h2>",
        "<p>Bottom (mould side) first; thicknesses are the cured plies'.</p>",
        table(rows, header, ident="stacking"),
        f"<p id='total-thickness'>Total thickness: {total}.</p>",
    ]


def _matrix(result: LaminateResult, value: str) -> str:
    title, unit = PAIR_TITLES[value]
    scale = 100.0 if unit == "%" else 1.0
    rows = [
        (label, *("–" if not np.isfinite(v) else f"{scale * v:.2f}" for v in row))
        for label, row in zip(result.labels, result.pair_matrix(value), strict=True)
    ]
    caption = f"<p><b>{html.escape(title)}</b> [{unit}]; row: the blank of, column: used for</p>"
    return caption + table(rows, ("blank \\ ply", *result.labels), ident=f"pairs-{value}")


def _nest_section(nest: RollNest | None, blanks, units: str) -> list[str]:
    parts = ["<h2>Nest on the roll</h2>"]
    if nest is None:
        return [*parts, "<p id='nest'>Not nested: the laminate names no roll_width.</p>"]
    from ..io.dxf import NestedDrawing
    from ..io.plot import plot_nest

    rows = [
        ("roll width", f"{number(nest.roll_width)} {units}"),
        ("length used", f"{number(nest.length)} {units}"),
        ("net area of the plies", f"{number(nest.net_area)} {units}²"),
        ("yield (net area / roll used)", f"{100 * nest.yield_:.1f} %"),
        ("made", nest.how),
    ]
    drawings = []
    for piece in nest.pieces:
        blank = blanks[piece.index]
        angle = np.radians(piece.rotation)
        warp = np.array([np.cos(angle), np.sin(angle)])
        drawings.append(
            NestedDrawing(
                blank.label, piece.place(blank.net[0]), piece.place(blank.trim[0]), warp, ()
            )
        )
    fig = plot_nest(nest.roll_width, nest.length, drawings, units=units)
    return [
        *parts,
        table(rows, ident="nest"),
        figure(fig, "the plies on the roll (warp along the roll)", "figure-nest"),
    ]


def _summary_parts(result, blanks, nest, checks, units: str) -> list[str]:
    header = ("ply", "orientation", "drape", "thickness", "net area", "blank area", "mass",
              "largest shear", "ok", "warn", "limit")  # fmt: skip
    masses = [b.mass(b.net_area, units) for b in blanks]
    total = "–" if None in masses else f"{number(sum(masses), 5)} g"
    plies = len(result.laminate.plies)
    pieces = f" ({len(blanks)} blanks: spliced plies in pieces)" if len(blanks) > plies else ""
    return [
        "<h2>Laminate</h2>",
        f"<p>{plies} plies{pieces}, {len(result.drapes)} distinct drapes, reference direction "
        f"{tuple(result.laminate.options.reference)}; areas in {units}², masses of the flat "
        "nets.</p>",
        table(_summary_rows(result, blanks, checks, units), header, ident="laminate-summary"),
        f"<p id='total-mass'>Total mass of the nets: {total}.</p>",
        *_stacking(blanks, result),
        *_nest_section(nest, blanks, units),
        "<h2>Ply-stack check</h2>",
        *(_matrix(result, v) for v in BOOK_MATRICES),
    ]


def ply_book(
    result: LaminateResult,
    blanks: Sequence[PlyBlank],
    nest: RollNest | None,
    *,
    units: str,
    title: str = "laminate",
) -> str:
    """The ply book as one HTML page (module docs): ``blanks`` of :func:`~vares.structures.
    laminate_blanks.ply_blanks` (bottom first), ``nest`` of :func:`~vares.structures.
    laminate_blanks.nest_plies` or ``None``, in mesh ``units``."""
    checks = [ply_producibility(result, b.name, b.piece) for b in blanks]
    warnings = [
        f"drape {d.label} did not converge: {d.pattern.reason}"
        for d in result.drapes
        if not d.converged
    ]
    if any(b.areal_weight is None for b in blanks):
        warnings.append("no areal weight for some plies: their masses are not shown")
    status = status_text(result.converged, None if result.converged else "see the warnings")
    parts = page(title, f"Ply book: {title}", status, warnings)
    with report_drawing():
        parts += _summary_parts(result, blanks, nest, checks, units)
        figures: dict[tuple, list[str]] = {}
        for blank, check in zip(blanks, checks, strict=True):
            key = (blank.drape, blank.piece)
            if key not in figures:
                shear = result.drape(blank.name).piece(blank.piece).pattern.fields["shear_angle"]
                figures[key] = drape_figures(blank, shear, check, units)
            spliced = result.drape(blank.name).spliced
            if spliced is not None and (blank.drape, "splices") not in figures:
                figures[blank.drape, "splices"] = [splices_figure(spliced)]
            parts += ply_section(result, blank, check, units, figures)
    return "\n".join([*parts, "</body></html>"])
