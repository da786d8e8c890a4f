"""The files ``vares drape`` writes of a ply cut open along darts or into pieces along splices
(:mod:`vares.app.cli.drape`): the cut pieces' net and trim outlines
(:func:`~vares.structures.laminate_blanks.blank_outlines`, with the command's
:class:`~vares.structures.blank_options.BlankOptions`), ``drape.json``'s ``blank``, and the
darts' or splices' mesh, cutter file and figure."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..io.dxf import CutPiece, write_dxf
from ..io.meshes import write_surface
from ..structures.blank_options import BlankOptions
from ..structures.laminate_blanks import blank_outlines, ring_area
from ..structures.laminate_plies import BlankPiece

__all__ = ["blank_summary", "cut_outlines", "cut_pieces", "write_darts", "write_splices"]


def cut_pieces(darted, spliced):
    """The ply as cut (:class:`~vares.structures.laminate_plies.BlankPiece` each): the pieces
    along its splices, or its one blank, opened along its darts where they are kept."""
    if spliced is not None:
        return [
            BlankPiece(piece.name, piece.mesh, result)
            for piece, result in zip(spliced.pieces, spliced.results, strict=True)
        ]
    cut = darted.after if darted.kept else darted.before
    return [BlankPiece(None, cut.mesh, cut)]


def cut_outlines(darted, spliced, edges: BlankOptions, name: str):
    """Each cut piece's net and trim outlines
    (:func:`~vares.structures.laminate_blanks.blank_outlines`), None without darts or splices;
    an overlap as wide as half a piece is refused (exit 2) before anything is written."""
    if darted is None and spliced is None:
        return None
    kept = darted if darted is not None and darted.kept else None
    return blank_outlines(cut_pieces(darted, spliced), edges, spliced, kept, name)


def blank_summary(edges: BlankOptions, outlines, spliced) -> dict[str, Any]:
    """drape.json's ``blank``: the allowances and each cut piece's net and trim areas."""

    def area(rings):
        return float(sum(ring_area(r) for r in rings))

    names = [None] if spliced is None else [p.name for p in spliced.pieces]
    return {
        **edges.to_dict(),
        "pieces": [
            {"piece": name, "net_area": area(o.net), "trim_area": area(o.trim)}
            for name, o in zip(names, outlines, strict=True)
        ],
    }


def _edge_lines(edges: BlankOptions, units: str, joints: str = "") -> list[str]:
    """The cutter label's line on the blank's edges: the trim allowance, and how its
    ``joints`` (``"splices"``, ``"darts"`` or none) are cut."""
    line = f"trim +{edges.trim_allowance:g} {units}"
    if joints:
        overlap = edges.splice_overlap if joints == "splices" else edges.dart_overlap
        line += f", {joints} lap {overlap:g} {units}" if overlap else f", {joints} butt"
    return [line]


def write_darts(folder, paths: list[Path], darted, units: str, name: str, outlines, edges):
    """darts.vtu (the mould opened along the darts, the shear with them open), pattern.dxf (the
    pattern to cut: with its darts where they are kept, else the pattern without them; SEAM its
    net boundary, CUT its trim line from ``outlines``) and darts.png."""
    import matplotlib.pyplot as plt

    from ..io.dart_plots import plot_darts

    tried = darted.final
    fields = {"shear_angle": tried.fields["shear_angle"]}
    flat = tried.material_coordinates
    point_data = {"flat_u": flat[:, 0], "flat_v": flat[:, 1]}
    write_surface(folder.staged(paths[0]), tried.mesh, None, fields, point_data)
    summary = darted.summary()
    cut = darted.after if darted.kept else darted.before
    largest = float(np.nanmax(np.abs(cut.fields["shear_angle"])))
    if darted.kept or darted.after is None:
        label = [f"{summary['darts']} darts, largest shear {largest:.1f}°"]
    else:
        label = [
            f"no darts, largest shear {largest:.1f}°",
            f"darts tried, not kept: {summary['max_shear_after']:.1f}° with them",
        ]
    label += _edge_lines(edges, units, "darts" if darted.kept else "")
    lines = darted.dart_pattern_lines() if darted.kept else []
    (outline,) = outlines
    piece = CutPiece(
        name,
        cut.mesh,
        cut.material_coordinates,
        cut.fibres.warp,
        label,
        darts=lines,
        seams=outline.net,
        cut=outline.trim,
    )
    write_dxf(folder.staged(paths[1]), [piece], units=units, model_units=units)
    figure = plot_darts(darted)
    figure.savefig(folder.staged(paths[2]))
    plt.close(figure)


def write_splices(folder, paths: list[Path], spliced, units: str, name: str, outlines, edges):
    """splices.vtu, pieces.dxf (each piece: SEAM its net boundary, along a splice the line as
    drawn; CUT its trim line from ``outlines``) and splices.png."""
    import matplotlib.pyplot as plt

    from ..io.dart_plots import plot_splices

    cut = spliced.cut  # the pieces' flat patterns are pieces.dxf's (they share the splices' nodes)
    fields = {
        "piece": cut.panel_ids.astype(float),
        "shear_angle": spliced.cell_field("shear_angle"),
    }
    write_surface(folder.staged(paths[0]), cut.mesh, None, fields)
    pieces = []
    names = [p.name for p in spliced.pieces]
    for piece, result, outline in zip(spliced.pieces, spliced.results, outlines, strict=True):
        largest = float(np.nanmax(np.abs(result.fields["shear_angle"])))
        label = [f"{name} {piece.name}", f"largest shear {largest:.1f}°"]
        label += _edge_lines(edges, units, "splices")
        if outline.laps:
            label.append("laps over " + ", ".join(names[j] for j in outline.laps))
        warp = None if result.fibres is None else result.fibres.warp
        pieces.append(
            CutPiece(
                piece.name,
                result.mesh,
                result.material_coordinates,
                warp,
                label,
                seams=outline.net,
                cut=outline.trim,
            )
        )
    write_dxf(folder.staged(paths[1]), pieces, units=units, model_units=units)
    figure = plot_splices(spliced)
    figure.savefig(folder.staged(paths[2]))
    plt.close(figure)
