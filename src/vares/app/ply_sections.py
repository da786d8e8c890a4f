"""A ply's section of the ply book (:mod:`.ply_book`): its flat blank with the net and extended
boundaries and the rosette, its shear and producibility maps, its numbers, and its darts or, for
a spliced ply's piece, its splices."""

from __future__ import annotations

import html

import numpy as np

from ..analysis.producibility import CLASSES, Producibility
from ..analysis.splice_lines import placed_text
from ..structures.laminate import PlyDrapeResult
from ..structures.laminate_blanks import PlyBlank
from .html_parts import REPORT_DPI, figure, number, status_text, table

__all__ = [
    "curvature_advice",
    "drape_figures",
    "mass_text",
    "optional_text",
    "ply_section",
    "splices_figure",
]

#: Colours of the producibility classes (ok, warn, limit, none).
_CLASS_COLOURS = ("#4caf50", "#ffb300", "#d32f2f", "#bdbdbd")


def _draw_darts(ax, blank: PlyBlank) -> None:
    for index, dart in enumerate(blank.darts):
        label = "darts" if index == 0 else None
        ax.plot(dart[:, 0], dart[:, 1], color="#6a1b9a", lw=1.6, label=label)


def _polygons(blank: PlyBlank) -> list[np.ndarray]:
    return [blank.coordinates[c] for cells in blank.mesh.cells.values() for c in cells]


def _outline(ax, blank: PlyBlank) -> None:
    for rings, style in ((blank.trim, dict(color="#c62828", ls="--")), (blank.net, {})):
        for ring in rings:
            closed = np.vstack([ring, ring[:1]])
            ax.plot(closed[:, 0], closed[:, 1], lw=1.0, **({"color": "black"} | style))
    ax.set_aspect("equal")


def _blank_figure(blank: PlyBlank, units: str):
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection

    fig, ax = plt.subplots(figsize=(6.5, 5.0))
    fig.subplots_adjust(left=0.12, right=0.97, bottom=0.1, top=0.92)
    ax.add_collection(
        PolyCollection(_polygons(blank), facecolor="#e3e8ef", edgecolor="none", antialiased=False)
    )
    _outline(ax, blank)
    _draw_darts(ax, blank)
    size = float(np.ptp(blank.trim[0], axis=0).max())
    for direction, text, colour in (
        (blank.warp, "0° warp", "#1565c0"),
        (blank.fill, "90° fill", "#2e7d32"),
    ):
        d = 0.2 * size * direction / np.linalg.norm(direction)
        ax.annotate(
            "",
            xy=tuple(blank.origin + d),
            xytext=tuple(blank.origin),
            arrowprops=dict(arrowstyle="-|>", color=colour, lw=2.0),
        )
        u = d / np.linalg.norm(d)
        ha = "left" if u[0] > 0.3 else "right" if u[0] < -0.3 else "center"
        va = "bottom" if u[1] > 0.3 else "top" if u[1] < -0.3 else "center"
        ax.text(*(blank.origin + 1.05 * d), text, color=colour, ha=ha, va=va)
    ax.plot(*blank.origin, "o", color="black", ms=4)
    darts = f", {len(blank.darts)} dart(s) (purple)" if blank.darts else ""
    ax.set_title(
        f"{blank.label}: flat blank, net (black) and trim (red, +{blank.allowance:g}){darts}"
    )
    ax.set_xlabel(f"along the warp [{units}]")
    ax.set_ylabel(f"[{units}]")
    return fig


def _producibility_figure(blank: PlyBlank, check: Producibility):
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Patch

    colours = {name: c for name, c in zip(CLASSES, _CLASS_COLOURS, strict=True)}
    fig, ax = plt.subplots(figsize=(6.5, 5.0))
    fig.subplots_adjust(left=0.12, right=0.97, bottom=0.1, top=0.92)
    faces = [colours[c] for c in check.classes]
    ax.add_collection(
        PolyCollection(_polygons(blank), facecolor=faces, edgecolor="none", antialiased=False)
    )
    _outline(ax, blank)
    _draw_darts(ax, blank)
    labels = {
        "ok": f"ok (< {check.warn_angle:g}°)",
        "warn": f"warn ({check.warn_angle:g}–{check.locking_angle:g}°)",
        "limit": f"limit (≥ {check.locking_angle:g}°)",
    }
    handles = [
        Patch(color=colours[n], label=f"{labels[n]}: {100 * check.fractions[n]:.1f} %")
        for n in CLASSES[:3]
    ]
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.06), ncols=3, fontsize=8)
    ax.set_title(f"{blank.label}: producibility (shear against the locking angle)")
    return fig


def mass_text(blank: PlyBlank, area: float, units: str) -> str:
    mass = blank.mass(area, units)
    return "–" if mass is None else f"{number(mass, 4)} g"


def optional_text(value: float | None, unit: str) -> str:
    return "–" if value is None else f"{number(value, 4)} {unit}"


def _splices_text(blank, units: str) -> str:
    """How a spliced piece meets the others: cut to the splice lines (butt), or lapping over
    the pieces laid before it."""
    if not blank.laps_over:
        if blank.splice_overlap > 0:
            return (
                f"cut to its splice lines; the pieces after it lap over it by "
                f"{number(blank.splice_overlap)} {units} (lay it first)"
            )
        return "butt: cut to its splice lines (no trim allowance there)"
    them = "them" if len(blank.laps_over) > 1 else "it"
    return (
        f"laps {number(blank.splice_overlap)} {units} over {', '.join(blank.laps_over)} (lay "
        f"it after {them}); cut to its splice lines with the pieces after it"
    )


def ply_section(result, blank, check, units, figures: dict[tuple, list[str]]) -> list[str]:
    drape: PlyDrapeResult = result.drape(blank.name)
    ply = next(p for p in result.laminate.plies if p.name == blank.name)
    pattern = drape.pattern
    rows = [
        ("orientation", f"{blank.orientation:+g}° from the reference"),
        ("drape", f"{drape.label} (plies {', '.join(drape.plies)})"),
        ("material", type(ply.material).__name__),
        ("state", status_text(pattern.converged, pattern.reason)),
        ("seed", " ".join(number(v, 6) for v in drape.seed)),
        ("warp at the seed", " ".join(number(v, 4) for v in drape.warp_direction)),
        ("thickness", optional_text(blank.thickness, "mm")),
        ("areal weight", optional_text(blank.areal_weight, "g/m²")),
        ("area on the mould", f"{number(blank.surface_area)} {units}²"),
        ("net area (flat)", f"{number(blank.net_area)} {units}²"),
        (f"blank area (trim +{blank.allowance:g} {units})", f"{number(blank.trim_area)} {units}²"),
        *([("splices", _splices_text(blank, units))] if blank.piece is not None else []),
        *([("splices placed", placed_text(drape.placed))] if drape.placed is not None else []),
        ("mass of the net", mass_text(blank, blank.net_area, units)),
        ("mass of the blank as cut", mass_text(blank, blank.trim_area, units)),
        ("largest shear", f"{number(check.max_shear, 4)}°"),
        ("locking angle", f"{number(check.locking_angle, 4)}°"),
    ]
    rows += [(f"area {n}", f"{100 * check.fractions[n]:.2f} %") for n in CLASSES[:3]]
    net = drape.kinematic.producibility if drape.kinematic is not None else None
    if drape.spliced is not None and drape.spliced.nets is not None:  # the piece's own net
        own = drape.spliced.nets[[p.name for p in drape.spliced.pieces].index(blank.piece)]
        net = own.producibility if own is not None else None
    if net is not None:
        rows.append(
            (
                "kinematic net: ok / warn / limit",
                " / ".join(f"{100 * net.fractions[n]:.1f} %" for n in CLASSES[:3]),
            )
        )
    state = rows.pop(3)  # its cell holds markup: not escaped
    ident = html.escape(blank.name if blank.piece is None else f"{blank.name}-{blank.piece}")
    heading = html.escape(blank.name)
    if blank.piece is not None:
        heading += f", {html.escape(blank.piece)} of {blank.pieces}"
    if drape.spliced is not None:
        lines = ["<h3>Splices</h3>", *_splices_part(drape, blank, check, ident, units)]
        if blank.piece == drape.spliced.pieces[0].name:  # the whole ply's picture, once
            lines += [part.replace("{ply}", ident) for part in figures[drape.label, "splices"]]
    else:
        lines = ["<h3>Darts</h3>", *_darts_part(drape, check, ident, units, blank.dart_overlap)]
    return [
        f"<section class='ply' id='ply-{ident}'>",
        f"<h2>Ply {heading}: {blank.orientation:+g}°</h2>",
        f"<p>{html.escape(state[0])}: {state[1]}</p>",
        table(rows, ident=f"ply-table-{ident}"),
        *(part.replace("{ply}", ident) for part in figures[drape.label, blank.piece]),
        *lines,
        "</section>",
    ]


def _splices_part(
    drape: PlyDrapeResult, blank: PlyBlank, check: Producibility, ident: str, units: str
) -> list[str]:
    """A spliced ply's piece: the splices' lengths, the piece's largest shear against the
    ply's cut whole, how much of the piece is at or beyond the locking angle."""
    spliced = drape.spliced
    data = spliced.summary()
    lengths = ", ".join(number(v, 4) for v in data["splice_lengths"])
    whole = number(data["max_shear_before"], 4)
    state = "below" if check.max_shear < check.locking_angle else "still at or beyond"
    text = (
        f"The ply is cut into {len(spliced.pieces)} pieces along {data['splices']} splice(s) "
        f"({lengths} {units} on the mould): the largest shear {whole}° cut whole, "
        f"{number(check.max_shear, 4)}° on this piece, {state} the locking angle "
        f"({number(check.locking_angle, 4)}°); {100 * check.fractions['limit']:.1f} % of the "
        "piece's area is at or beyond it."
    )
    return [f"<p id='splices-{ident}'>{html.escape(text)}</p>"]


def splices_figure(spliced) -> str:
    """The spliced ply's shear on the mould, whole and in its pieces (the splice lines in
    black), and its flat pieces (:func:`vares.io.dart_plots.plot_splices`)."""
    from ..io.dart_plots import plot_splices

    caption = (
        f"the ply's shear on the mould, whole (largest {spliced.max_shear_before:.1f}°) and in "
        f"its {len(spliced.pieces)} pieces ({spliced.max_shear_after:.1f}°; the splice lines in "
        "black), and the flat pieces"
    )
    return figure(plot_splices(spliced, dpi=REPORT_DPI), caption, "figure-{ply}-splices")


def curvature_advice(darted) -> str:
    """Where darts leave the shear at or beyond the locking angle on mostly negatively curved
    surface (:attr:`~vares.analysis.darts.DartedPattern.needs_splices`), what relieves it."""
    if not darted.needs_splices:
        return ""
    negative = darted.summary()["over_locking_curvature"]["negative"]
    return (
        f" {100 * negative:.0f} % of the area at or beyond the locking angle is negatively "
        "curved, where a dart takes out fabric the mould needs: dart lines drawn to the "
        "positively curved part beside it, or a splice, relieve it (docs/composites.md)."
    )


def _darts_part(
    drape: PlyDrapeResult, check: Producibility, ident: str, units: str, overlap: float = 0.0
) -> list[str]:
    """The ply's darts: a table of their lengths and openings, the largest shear before and
    after and how the lips meet (``overlap``: the left lip's over the right one, 0: butt); or,
    without darts, how much of the ply is at or beyond the locking angle."""
    limit = 100 * check.fractions["limit"]
    darted = drape.darted
    if darted is not None and darted.after is not None and not drape.is_darted:
        lengths = ", ".join(number(v, 4) for v in darted.summary()["dart_lengths"])
        after = "did not converge" if not darted.after.converged else (
            f"{number(darted.max_shear_after, 4)}° with them open"
        )  # fmt: skip
        text = (
            f"Darts tried and not cut: {len(darted.dart_lines)} dart(s) ({lengths} {units} on "
            f"the mould), the largest shear {number(darted.max_shear_before, 4)}° without them, "
            f"{after}: they do not lower it, so the ply is cut whole. {limit:.1f} % of the "
            "ply's area is at or beyond the locking angle."
        )
        return [f"<p id='darts-{ident}'>{html.escape(text + curvature_advice(darted))}</p>"]
    if darted is None or darted.after is None:
        if darted is None:
            why = "No darts (none asked for: darts = 'auto' or dart_lines)."
        elif not darted.before.converged:
            why = "No darts: the ply without darts did not converge."
        else:
            why = (
                f"No darts needed: the largest shear, {number(darted.max_shear_before, 4)}°, "
                f"is below the locking angle ({number(darted.locking_angle, 4)}°)."
                if darted.max_shear_before < darted.locking_angle
                else "No dart could be placed."
            )
        extra = " (a dart or another seed or orientation is needed there)." if limit > 0 else "."
        text = f"{why} {limit:.1f} % of the ply's area is at or beyond the locking angle{extra}"
        if darted is not None:
            text += curvature_advice(darted)
        return [f"<p id='darts-{ident}'>{html.escape(text)}</p>"]
    data = darted.summary()
    rows = [
        (k + 1, f"{number(length, 4)}", f"{number(opening, 4)}")
        for k, (length, opening) in enumerate(
            zip(data["dart_lengths"], data["mouth_openings"], strict=True)
        )
    ]
    after = data["max_shear_after"]
    state = "below" if darted.relieved else "still at or beyond"
    text = (
        f"{len(rows)} dart(s), {len(darted.rounds)} solve(s) with darts: the largest shear "
        f"{number(darted.max_shear_before, 4)}° without darts, {number(after, 4)}° with them "
        f"open, {state} the locking angle ({number(darted.locking_angle, 4)}°); "
        f"{limit:.1f} % of the blank's area is at or beyond it. "
        + (
            f"Each dart's left lip (from its mouth in) laps {number(overlap)} {units} over the "
            "right one."
            if overlap > 0
            else "The lips butt: both cut to the dart line."
        )
    )
    return [
        f"<p id='darts-{ident}'>{html.escape(text)}</p>",
        table(
            rows,
            ("dart", f"length on the mould [{units}]", f"mouth opening [{units}]"),
            ident=f"darts-table-{ident}",
        ),
    ]


def drape_figures(
    blank: PlyBlank, shear: np.ndarray, check: Producibility, units: str
) -> list[str]:
    """The three pictures of a drape's blank, their ids holding ``{ply}``."""
    from ..io.plot import plot_pattern_fields

    parts = [figure(_blank_figure(blank, units), "flat blank and rosette", "figure-{ply}-blank")]
    titles = {"shear_angle": "shear angle [°]"}
    for _, drawing in plot_pattern_fields(
        blank.mesh, blank.coordinates, {"shear_angle": shear}, titles=titles, dpi=REPORT_DPI
    ):
        if blank.darts:
            _draw_darts(drawing.axes[0], blank)
        parts.append(figure(drawing, "shear angle of the blank", "figure-{ply}-shear", close=False))
    parts.append(
        figure(_producibility_figure(blank, check), "producibility", "figure-{ply}-producibility")
    )
    return parts
