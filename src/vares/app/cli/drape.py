"""``vares drape``: the kinematic drape of a woven ply on a mould, its producibility, and its
darts (``--darts auto`` or ``--dart-lines FILE``: the ply's pattern solved with its fabric, then
again with the darts open) or splices (``--splice-lines FILE``: the ply cut into pieces, each
piece's pattern solved). ``--example NAME`` drapes a shipped mould (:data:`DRAPE_EXAMPLES`)
from its own seed, warp and spacing."""

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer

from ...analysis.dart_options import DartOptions
from ...analysis.drape_options import DrapeOptions
from ...structures.blank_options import BlankOptions
from ...units import METRES
from ..sections import MaterialOptions
from .common import console, guarded, net_line, producibility_table
from .flags import InputError, build, example_flag, flags, option_parameter, with_flags
from .pattern import RUN_FLAGS

__all__ = [
    "DRAPE_EXAMPLES",
    "DrapeExample",
    "darts_verdict",
    "drape",
    "placed_verdict",
    "splices_verdict",
]


@dataclass(frozen=True)
class DrapeExample:
    """A shipped mould to drape: its mesh (``make()``), the seed ``(3,)`` (``seed()``; None: the
    node nearest the nodes' centroid), warp ``(3,)`` and yarn spacing it is draped with unless
    the flags say otherwise, and the units of its coordinates."""

    make: Callable[[], Any]
    seed: Callable[[], tuple[float, float, float] | None]
    warp: tuple[float, float, float]
    spacing: float
    units: str


def _hemisphere():
    from ...geometry.examples import irregular_cap

    return irregular_cap(100.0, 90.0, 30, 0.3, 1)


def _double_dome():
    from ...geometry.examples import double_dome

    return double_dome()


def _rib():
    from ...geometry.examples import rib30

    return rib30()


def _saddle_centre() -> tuple[float, float, float]:
    from ...geometry.examples import double_dome_height

    return (0.0, 0.0, float(double_dome_height(np.zeros(1), np.zeros(1))[0]))


#: The moulds ``vares drape --example`` takes (docs/composites.md): the hemisphere R = 100 mm to
#: the equator (30 rings of irregular triangles) from its pole, the double dome from the
#: saddle's centre (on both planes of symmetry), both with the warp along x; the seed's rib
#: (in metres) with the warp along it.
DRAPE_EXAMPLES: dict[str, DrapeExample] = {
    "hemisphere": DrapeExample(_hemisphere, lambda: (0.0, 0.0, 100.0), (1.0, 0.0, 0.0), 2.0, "mm"),
    "double-dome": DrapeExample(_double_dome, _saddle_centre, (1.0, 0.0, 0.0), 2.0, "mm"),
    "rib": DrapeExample(_rib, lambda: None, (0.0, 1.0, 0.0), 0.004, "m"),
}

OUTPUT_FLAGS = [
    option_parameter(
        "output",
        Path("drape-out"),
        Path,
        "--output",
        "-o",
        help="Output directory.",
        panel="Output",
    ),
    option_parameter(
        "report",
        False,
        bool,
        "--report",
        help="Also write drape.html: the producibility, the darts and their pictures.",
        panel="Output",
    ),
    option_parameter(
        "units",
        None,
        str | None,
        "--units",
        help="Units of the mould's coordinates, for pattern.dxf (" + ", ".join(METRES) + "; "
        "default mm, an example's own).",
        panel="Output",
    ),
]

EXAMPLE_FLAG = example_flag(
    "Drape a shipped mould instead, from its own seed, warp and spacing unless given: "
    + ", ".join(DRAPE_EXAMPLES)
    + "."
)


@with_flags(
    EXAMPLE_FLAG,
    flags(DrapeOptions),
    flags(DartOptions),
    flags(BlankOptions),
    flags(MaterialOptions),
    OUTPUT_FLAGS,
    RUN_FLAGS[1:],
)
def drape(
    surface: Annotated[
        Path | None, typer.Argument(help="The mould's surface mesh (or --example).")
    ] = None,
    **values: Any,
) -> None:
    """Drape a woven ply kinematically (pin-jointed net) and check its producibility.

    Writes drape.json (the producibility and the net) and drape.vtu (the mould with the shear
    angle, the producibility class, the yarn directions and the flat pattern per node) into the
    output directory. --example drapes a shipped mould (hemisphere, double-dome, rib). With
    --darts auto or --dart-lines the ply's pattern is solved with its
    fabric (--fabric, or --material and its parameters), darts are opened where its shear
    reaches the locking angle (or along the given lines) and it is solved again: drape.json
    gets the darts, and darts.vtu (the mould cut open), pattern.dxf (the pattern with layer
    DART) and darts.png (the shear before and after, the dart lines) are written. With
    --splice-lines the ply is cut into pieces along the lines and each piece's pattern is
    solved: drape.json gets the splices, and splices.vtu (the mould cut into pieces) and
    pieces.dxf (every piece's pattern) and splices.png (the shear of the whole ply and of the
    pieces, the flat pieces) are written; --splices auto places the splice itself, through the
    seed along the warp or the fill (the diagonals, or both axes, where that does not relieve
    the ply). In the DXF files the SEAM layer is the net boundary and the CUT layer the blank
    as cut: the net grown by --trim-allowance along the mould's edge, butt or lapping by
    --splice-overlap / --dart-overlap at the joints.
    """

    def body() -> None:
        from ...analysis.drape import drape_ply  # when the command runs
        from ...analysis.producibility import CLASSES
        from ...io.files import write_json
        from ...io.meshes import read_mesh, write_surface
        from ..drape_outputs import blank_summary, cut_outlines, write_darts, write_splices
        from ..staging import OutputFolder

        name = values["example"]
        if (surface is None) == (name is None):
            raise InputError("give a mould file or --example, not both and not neither")
        example = None
        if name is not None:
            if name not in DRAPE_EXAMPLES:
                known = ", ".join(DRAPE_EXAMPLES)
                raise InputError(f"--example must be one of {known}; got {name!r}")
            example = DRAPE_EXAMPLES[name]
        options = build(DrapeOptions, values)
        if example is not None:
            options = options.replace(
                seed=options.seed if options.seed is not None else example.seed(),
                warp=options.warp if options.warp is not None else example.warp,
                spacing=options.spacing if options.spacing is not None else example.spacing,
            )
        darting = build(DartOptions, values)
        material = _material(values, darting)
        edges = _edges(values, darting)
        units = values["units"] or (example.units if example is not None else "mm")
        if units not in METRES:
            raise InputError(f"--units must be one of {', '.join(METRES)}; got {units!r}")
        polylines = splice_lines = None
        if darting.dart_lines is not None or darting.splice_lines is not None:
            from ...io.curves import read_curves

            if darting.dart_lines is not None:
                polylines = read_curves(darting.dart_lines)
            if darting.splice_lines is not None:
                splice_lines = read_curves(darting.splice_lines)
        mesh = read_mesh(surface) if example is None else example.make()
        label = surface.stem if example is None else name
        output = values["output"]
        paths = [output / "drape.json", output / "drape.vtu"]
        dart_paths = [output / "darts.vtu", output / "pattern.dxf", output / "darts.png"]
        splice_paths = [output / "splices.vtu", output / "pieces.dxf", output / "splices.png"]
        if darting.wanted:
            paths += dart_paths
        if darting.splicing:
            paths += splice_paths
        if values["report"]:
            paths.append(output / "drape.html")
        inputs = [] if surface is None else [surface]
        inputs += [Path(f) for f in (darting.dart_lines, darting.splice_lines) if f is not None]
        folder = OutputFolder(output, paths, force=values["force"], inputs=inputs, command="drape")
        folder.check()
        ply = drape_ply(mesh, options)
        check, result = ply.producibility, ply.drape
        source = {"surface": str(surface)} if example is None else {"example": name}
        data = {**source, **ply.summary()}
        data["producibility_codes"] = {name: code for code, name in enumerate(CLASSES)}
        fields = {
            "shear_angle": result.shear_angle,
            "producibility": ply.fields()["producibility"],
            "warp": result.warp,
            "fill": result.fill,
        }
        point_data = {"flat_u": result.material_coordinates[:, 0]}
        point_data["flat_v"] = result.material_coordinates[:, 1]
        darted, spliced, placed = _solve_cuts(
            mesh, material, values["thickness"], options, darting, ply, polylines, splice_lines
        )
        outlines = cut_outlines(darted, spliced, edges, label)  # a lap too wide: refused here
        if darted is not None:
            data["darts"] = darted.summary()
        if spliced is not None:
            data["splices"] = spliced.summary()
        if placed is not None:
            data["splices"] = {**data.get("splices", {}), "placed": placed.summary()}
        if darting.splicing and spliced is None:  # placed: no splice needed, or none could be cut
            paths = [p for p in paths if p not in splice_paths]
        if outlines is not None:
            data["blank"] = blank_summary(edges, outlines, spliced)
        folder.start()
        try:
            write_surface(folder.staged(paths[1]), mesh, None, fields, point_data)
            write_json(folder.staged(paths[0]), data)
            if darted is not None:
                write_darts(folder, dart_paths, darted, units, label, outlines, edges)
            if spliced is not None:
                write_splices(folder, splice_paths, spliced, units, label, outlines, edges)
            if values["report"]:
                from ..drape_report import drape_page

                verdict = None if placed is None else placed_verdict(placed)
                html = drape_page(ply, darted, label, units, spliced=spliced, placed=verdict)
                folder.staged(paths[-1]).write_text(html, encoding="utf-8")
            folder.commit()
        finally:
            folder.discard()
        if not values["quiet"]:
            console.print(producibility_table(check))
            console.print(net_line(check, result.net.valid.sum(), ply.spacing))
            if darted is not None:
                _show_darts(darted)
            if placed is not None:
                console.print(placed_verdict(placed))
            if spliced is not None:
                _show_splices(spliced, units)
            for path in paths:
                console.print(f"  wrote {path}")
        if darted is not None and not darted.final.converged:
            raise typer.Exit(1)
        if spliced is not None and not spliced.converged:
            raise typer.Exit(1)
        if placed is not None and placed.needed and spliced is None:
            raise typer.Exit(1)

    guarded(body)


def _solve_cuts(mesh, material, thickness, options, darting, ply, polylines, splice_lines):
    """The ply's pattern with its darts open (a DartedPattern), or spliced along the given lines
    or through its seed (a SplicedPly with its pieces' kinematic nets; with ``--splices auto``
    also the PlacedSplices); None for what was not asked."""
    locking, _ = options.locking
    common = {"locking_angle": locking, "warp_direction": tuple(float(v) for v in ply.warp)}
    if darting.wanted:
        from ...analysis.darts import solve_with_darts

        darted = solve_with_darts(
            mesh, material, thickness, polylines=polylines, options=darting, **common
        )
        return darted, None, None
    if not darting.splicing:
        return None, None, None
    from ...analysis.splices import drape_pieces, solve_with_splices

    placed = None
    if splice_lines is not None:
        spliced = solve_with_splices(mesh, material, thickness, polylines=splice_lines, **common)
    else:
        from ...analysis.splice_lines import place_splices

        placed = place_splices(mesh, material, thickness, seed=ply.seed, **common)
        spliced = placed.spliced
    if spliced is not None:
        spliced = drape_pieces(spliced, options, ply.warp)
    return None, spliced, placed


def placed_verdict(placed) -> str:
    """The line ``vares drape --splices auto`` prints of a
    :class:`~vares.analysis.splice_lines.PlacedSplices`: whether a splice was needed, and the
    lines tried through the seed with the largest shear each gave
    (:func:`~vares.analysis.splice_lines.placed_text`)."""
    from ...analysis.splice_lines import placed_text

    if placed.needed:
        return f"splices placed {placed_text(placed.summary())}"
    whole = float(np.nanmax(np.abs(placed.before.fields["shear_angle"])))
    return f"no splice needed: the whole ply's largest shear is {whole:.2f}°"


def _edges(values: dict[str, Any], darting: DartOptions) -> BlankOptions:
    """The blank's allowances; each refused where there is no joint or cutter file for it."""
    edges = build(BlankOptions, values)
    given = [n for n, d in BlankOptions.defaults().items() if getattr(edges, n) != d]
    needs = {
        "trim_allowance": (darting.needs_fabric, "the cutter files of darts or splices: add "
                           "--darts auto, --dart-lines, --splice-lines or --splices auto"),
        "splice_overlap": (darting.splicing, "splices: add --splice-lines or --splices auto"),
        "dart_overlap": (darting.wanted, "darts: add --darts auto or --dart-lines"),
    }  # fmt: skip
    for name in given:
        wanted, what = needs[name]
        if not wanted:
            raise InputError(f"--{name.replace('_', '-')} is for {what}")
    return edges


def _material(values: dict[str, Any], darting: DartOptions):
    """The ply's fabric for the solves with darts (None without darts); material flags without
    darts are refused."""
    options = build(MaterialOptions, values)
    given = [n for n, d in MaterialOptions.defaults().items() if getattr(options, n) != d]
    if not darting.needs_fabric:
        if given:
            raise InputError(
                f"--{given[0].replace('_', '-')} is for darts or splices: add --darts auto "
                "or --splice-lines"
            )
        return None
    cuts = "darts" if darting.wanted else "splices"
    if options.law is None and options.fabric is None and options.presets is None:
        raise InputError(
            f"{cuts} need the ply's fabric: give --fabric, or --material and its moduli"
        )
    material = options.build(Path.cwd())
    if not material.needs_fibres:
        raise InputError(
            f"{cuts} need a fabric with yarns (an orthotropic or ncf law, or --fabric)"
        )
    return material


def _show_splices(spliced, units: str) -> None:
    from rich.table import Table

    from ..drape_report import splice_piece_rows

    header, rows = splice_piece_rows(spliced.summary(), units)
    table = Table(*header, title=f"splices (locking {spliced.locking_angle:g}°)")
    for row in rows:
        table.add_row(*row)
    console.print(table)
    console.print(splices_verdict(spliced))


def splices_verdict(spliced) -> str:
    """The line ``vares drape --splice-lines`` prints of a
    :class:`~vares.analysis.splices.SplicedPly`: the largest shear of the whole ply and of its
    pieces against the locking angle."""
    summary = spliced.summary()
    count = len(summary["pieces"])
    state = "below" if spliced.relieved else "NOT below"
    tail = "" if spliced.converged else " (a piece's pattern did NOT converge)"
    return (
        f"largest shear {summary['max_shear_before']:.2f}° of the whole ply, "
        f"{summary['max_shear_after']:.2f}° of its {count} pieces: {state} the locking angle"
        f"{tail}"
    )


def _show_darts(darted) -> None:
    from rich.table import Table

    summary = darted.summary()
    table = Table(
        "dart", "length", "mouth opening", title=f"darts (locking {darted.locking_angle:g}°)"
    )
    for k, (length, opening) in enumerate(
        zip(summary["dart_lengths"], summary["mouth_openings"], strict=True), start=1
    ):
        table.add_row(str(k), f"{length:.4g}", f"{opening:.4g}")
    console.print(table)
    console.print(darts_verdict(darted))


def darts_verdict(darted) -> str:
    """The line ``vares drape --darts`` prints of a :class:`~vares.analysis.darts.DartedPattern`:
    the largest shear without and with the darts against the locking angle, or that the pattern
    without darts did not converge (then no dart is placed)."""
    summary = darted.summary()
    before = summary["max_shear_before"]
    if not darted.before.converged:
        return (
            f"the pattern without darts did NOT converge ({darted.before.reason}): no darts "
            f"placed (its largest shear {before:.2f}° is not a result)"
        )
    after = summary["max_shear_after"]
    if after is None:
        tail = "no dart needed" if before < darted.locking_angle else "no dart placed"
    else:
        fall = summary["chosen_rule"] == "fall line"
        by = " (placed along the mould's fall lines)" if fall else ""
        tail = f"{after:.2f}° with the darts open{by}"
    state = "below" if darted.relieved else "NOT below"
    solves = len(darted.rounds)
    verdict = (
        f"largest shear of the pattern {before:.2f}° without darts, {tail}: {state} the "
        f"locking angle ({solves} {'solve' if solves == 1 else 'solves'} with darts)"
    )
    if darted.after is not None and not darted.kept:
        verdict += "; the darts are NOT kept (they do not lower it): pattern.dxf is without them"
    if darted.needs_splices:
        negative = summary["over_locking_curvature"]["negative"]
        verdict += (
            f"; {100 * negative:.0f} % of the area at or beyond it is negatively curved, where a "
            "dart takes out fabric the mould needs: draw darts that reach the positively curved "
            "part beside it (--dart-lines), or splice the ply (--splice-lines)"
        )
    return verdict
