"""The files of a cut job, besides every strip's own files and ``structure.json``.

``cut.json``        roll width; per panel its 3D area, width across the warp with allowances and
                    warp (pattern frame); per seam its panels, 3D length and pattern lengths; the
                    nest's roll width, length and yield (lengths in the mesh's units)
``nest.dxf``        the pieces on the roll, for the cutter (one drawing per roll)
``nest.svg/.png``   the nest drawn
``cut_lines.png``   the cutting lines on the surface, the strips coloured
``panels.vtu``      the cut surface with the strip of every cell (cell data ``panel``)
"""

from __future__ import annotations

import numpy as np

from ..io.dxf import NestedDrawing, write_nest_dxf
from ..io.files import atomic_path, write_json
from ..io.meshes import write_surface
from ..structures.seams import named_seam_marks
from ..units import unit_factor
from .outcome import JobOutcome

__all__ = ["cut_summary", "cutting_details", "nested_drawings", "write_cut"]


def cut_summary(outcome: JobOutcome) -> dict:
    """``cut.json``: exactly the figures a cutting plan is judged by (module docs)."""
    result = outcome.cut
    nest = result.nest
    return {
        "roll_width": result.options.roll_width,
        "panels": [
            {
                "name": panel.name,
                "area": panel.mesh.area,
                "width": width,
                "warp": [float(v) for v in r.fibres.warp],
            }
            for panel, width, r in zip(
                result.plan.panels, result.widths, result.structure.results, strict=True
            )
        ],
        "seams": [
            {"panels": list(s.panels), "length_3d": s.length_3d, "length_2d": list(s.length_2d)}
            for s in result.seams
        ],
        "nesting": None
        if nest is None
        else {"roll_width": nest.roll_width, "length": nest.length, "yield": nest.yield_},
    }


def cutting_details(outcome: JobOutcome) -> dict:
    """What ``structure.json`` adds for a cut job: lines, cut mesh, rounds, seams, nest."""
    result = outcome.cut
    plan, nest = result.plan, result.nest
    return {
        "seams_kind": result.options.seams,
        "layout": None if plan.family is None else plan.family.kind,
        "strips": len(plan.panels),
        "layouts_tried": plan.evaluations,
        "strips_tried": [{"strips": n, "widest_flattened": w} for n, w in plan.history],
        "widest_pattern_per_round": result.rounds,
        "refinements": plan.refinements,
        "input_cells": plan.input_cells,
        "refined_cells": plan.refined_cells,
        "replaced_geodesics": plan.replaced_geodesics,
        "interlock": plan.interlock,
        "cross_seams": {
            "strips_cut": plan.cross_cut,
            "pieces_each": plan.pieces if plan.cross_cut else 1,
        },
        "roll_estimates": {
            kind: {"strips": strips, "length": length}
            for kind, (strips, length) in plan.compared.items()
        },
        "notes": result.notes,
        "worst_angle_degrees": plan.cut.worst_angle,
        "input_worst_angle_degrees": result.surface_worst_angle,
        "surface_area": result.surface_area,
        "panels_area": result.panel_area,
        "seam_lines": [
            {
                "panels": list(s.panels),
                "length_3d": s.length_3d,
                "line_length": s.line_length,
                "excess": s.length_3d / s.line_length - 1.0,
            }
            for s in result.seams
        ],
        "nest": None
        if nest is None
        else {
            "length": nest.length,
            "yield": nest.yield_,
            "waste": nest.waste,
            "net_area": nest.net_area,
            "seconds": nest.elapsed,
            "method": nest.method,
            "search_seconds": nest.search_time,
            "time_limit": nest.time_limit,
            "seed": nest.seed,
            "finished": nest.finished,
            "pieces": [
                {
                    "panel": result.plan.panels[p.index].name,
                    "rotation": p.rotation,
                    "translation": p.translation.tolist(),
                }
                for p in nest.pieces
            ],
        },
        "elapsed_seconds": result.elapsed,
    }


def write_cut(outcome: JobOutcome) -> None:
    """The cut job's own files (module docs); paths to ``outcome.files``."""
    job, result = outcome.job, outcome.cut
    directory = outcome.directory

    def wrote(name: str) -> None:
        outcome.files.append(directory / name)

    write_json(directory / "cut.json", cut_summary(outcome))
    wrote("cut.json")
    cut = result.plan.cut
    write_surface(
        directory / "panels.vtu", cut.mesh, fields={"panel": cut.panel_ids}, units=outcome.units
    )
    wrote("panels.vtu")
    _write_figure(directory / "cut_lines.png", _lines_figure(outcome))
    wrote("cut_lines.png")
    if result.nest is None:
        return
    drawings = nested_drawings(outcome)
    nest = result.nest
    write_nest_dxf(
        directory / "nest.dxf",
        [(nest.roll_width, nest.length, drawings)],
        units=job.output.dxf_units,
        model_units=outcome.units,
    )
    wrote("nest.dxf")
    from ..io.plot import plot_nest

    figure = plot_nest(nest.roll_width, nest.length, drawings, units=outcome.units)
    for name in ("nest.svg", "nest.png"):
        _write_figure(directory / name, figure, close=name == "nest.png")
        wrote(name)


def nested_drawings(outcome: JobOutcome) -> list[NestedDrawing]:
    """Every piece as laid on the roll, with its label and named match marks."""
    job, result = outcome.job, outcome.cut
    structure, nest = result.structure, result.nest
    to_model = unit_factor(job.output.dxf_units, outcome.units)
    spacing = outcome.mark_spacing()
    coordinates = [r.material_coordinates for r in structure.results]
    marks = named_seam_marks(coordinates, structure.seams, spacing)
    units = outcome.units
    drawings = []
    for placed in nest.pieces:
        index = placed.index
        outline, panel = result.outlines[index], result.plan.panels[index]
        named = []
        for seam, points in marks[index]:
            for number, point in enumerate(points, start=1):
                normal = _outward(outline.seam, point)
                turned = placed.place(np.vstack([point, point + normal]))
                named.append((f"S{seam + 1}.{number}", turned[0], turned[1] - turned[0]))
        warp = placed.place(np.vstack([[0.0, 0.0], structure.results[index].fibres.warp]))
        drawings.append(
            NestedDrawing(
                panel.name,
                placed.place(outline.seam),
                placed.place(outline.cut),
                warp[1] - warp[0],
                [panel.name, f"{panel.mesh.area:.3f} {units}² (3D)"],
                named,
                tick=result.allowance * to_model if result.allowance > 0 else 0.01 * spacing,
            )
        )
    return drawings


def _outward(ring: np.ndarray, point: np.ndarray) -> np.ndarray:
    """Outward unit normal of the counter-clockwise ring at its segment nearest ``point``."""
    a, b = ring, np.roll(ring, -1, axis=0)
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", point - a, d) / np.einsum("ij,ij->i", d, d), 0, 1)
    k = int(np.argmin(np.linalg.norm(a + t[:, None] * d - point, axis=1)))
    tangent = d[k] / np.linalg.norm(d[k])
    return np.array([tangent[1], -tangent[0]])


def _lines_figure(outcome: JobOutcome):
    from ..io.plot import plot_cut_lines

    plan = outcome.cut.plan
    title = (
        f"{plan.counted}, {outcome.cut.options.seams} cutting lines, roll width "
        f"{outcome.cut.options.roll_width:g} {outcome.units}"
    )
    return plot_cut_lines(plan.cut.mesh, plan.cut.panel_ids, plan.cut.lines, title=title)


def _write_figure(path, figure, close: bool = True) -> None:
    import matplotlib.pyplot as plt

    from ..io.plot import DPI

    with atomic_path(path) as temporary:
        figure.savefig(temporary, dpi=DPI)
    if close:
        plt.close(figure)
