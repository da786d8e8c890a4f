"""From one design surface to the roll: cutting lines, strips, patterns with matched seams, nest.

:func:`cut` divides a surface into strips that fit the roll (:mod:`.layout`), patterns them as a
structure with matched seams and the warp along each strip (:func:`.solve_structure`), draws each
pattern's cut line with the allowance of each edge's kind (seam, free edge, cable pocket, clamp
edge), checks the patterns' widths against the roll (and plans again with a narrower target if
one is too wide), and nests the pieces on the roll (:mod:`.nesting`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..geometry.cutting import CutMesh
from ..geometry.mesh import SurfaceMesh
from ..geometry.outline import allowance_outline
from ..geometry.refine import refine
from ..geometry.surface_lines import CuttingError, min_angles, triangulated
from ..materials import Hyperelastic
from ..options import split_settings, takes_options
from ..solver import IterationRecord, SolveOptions
from ..units import unit_factor
from .layout import CELLS_ACROSS, StripPlan, longest_edge_for, plan_strips, strips_along_lines
from .matching import StructureResult, solve_structure
from .nesting import RollNest, nest_pieces, usable_width
from .options import CutOptions, StructureOptions
from .pair_nest import pair_nest
from .pairing import choose_plan, pair_widths, split_lone_strip
from .panels import Panel, width_across_warp
from .seam_lines import SeamLine, seam_lines

__all__ = ["CutResult", "PieceOutline", "SeamLine", "cut", "input_cells", "with_patterns"]

#: Plans tried at most (each narrower than the last) until every pattern fits the roll.
MAX_ROUNDS = 3
#: A plan planned narrower again after one that was already (its patterns still too wide) asks
#: for this much less again: about how much the widths jump from one layout to the next (the
#: half wave at a 0.5 m roll, cut across: 0.538, then 0.501, then 0.503 m with 1e-3).
RETRY_MARGIN = 0.01


@dataclass(frozen=True)
class PieceOutline:
    """A pattern's outline: the seam ring ``(k, 2)`` (counter-clockwise, pattern coordinates),
    the kind of each of its edges (``"seam"`` or an edge type) and the cut ring ``(m, 2)``."""

    seam: np.ndarray
    edges: tuple[str, ...]
    cut: np.ndarray

    @property
    def area(self) -> float:
        x, y = self.seam[:, 0], self.seam[:, 1]
        return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


@dataclass
class CutResult:
    """What :func:`cut` produced: the strips (``plan``), their patterns (``structure``), the
    outlines and widths across the warp with allowances (mesh units), the seams and the nest
    (``None`` if the structure did not converge). ``rounds`` lists the widest pattern of every
    plan tried; ``surface_worst_angle`` is the smallest cell angle (degrees) of the surface
    before cutting (quads split into triangles), to compare with ``plan.cut.worst_angle``."""

    plan: StripPlan
    structure: StructureResult
    outlines: list[PieceOutline]
    widths: list[float]
    seams: list[SeamLine]
    nest: RollNest | None
    options: CutOptions
    surface_area: float
    units: str = "m"
    dxf_units: str = "mm"
    allowance: float = 0.0
    rounds: list[float] = field(default_factory=list)
    elapsed: float = 0.0
    surface_worst_angle: float = 0.0

    @property
    def converged(self) -> bool:
        return self.structure.converged

    @property
    def usable_width(self) -> float:
        """The widest piece the roll takes (:func:`~vares.structures.nesting.usable_width`)."""
        return usable_width(self.options.roll_width)

    @property
    def too_wide(self) -> list[int]:
        """The strips whose pattern, allowances included, the roll does not take."""
        return [k for k, width in enumerate(self.widths) if width > self.usable_width]

    @property
    def panel_area(self) -> float:
        """Total 3D area of the panels."""
        return float(sum(p.mesh.area for p in self.plan.panels))

    @property
    def notes(self) -> list[str]:
        """What the cut did to the surface and to the lines, for the user to know: the surface
        refined on its own faces, geodesics replaced by plane sections."""
        plan, notes = self.plan, []
        if plan.refinements:
            rounds = "round" if plan.refinements == 1 else "rounds"
            strip = (
                "a strip of a pair, about half as wide as the roll,"
                if plan.interlock
                else "a strip as wide as the roll"
            )
            notes.append(
                f"the surface was refined on its own faces ({plan.refinements} {rounds} of "
                f"midpoint subdivision, {plan.input_cells:,} → {plan.refined_cells:,} triangles) "
                f"so that {strip} is at least {CELLS_ACROSS} cells across; its shape and area "
                "are unchanged"
            )
        if plan.replaced_geodesics:
            notes.append(
                f"{plan.replaced_geodesics} of {len(plan.lines)} cutting lines are plane sections "
                "in place of geodesics that ran towards a neighbour or along the boundary"
            )
        if plan.interlock:
            notes.append(
                "the strips are planned to lie in pairs on the roll, head to tail, the warp along "
                "one seam of each" + _estimates(plan.compared)
            )
        if plan.pairs_refused:
            notes.append(
                "the strips lie one after the other: planned in pairs, head to tail, they could "
                f"not be ({plan.pairs_refused})"
            )
        if plan.cross_cut:
            strips = len(set(plan.strip_of))
            notes.append(
                f"{plan.cross_cut} of {strips} strips are cut across into {plan.pieces} pieces "
                "each (cross seams, matched like every seam; each piece's warp along its own "
                "length): whole, no number of strips fits the roll, as their flattened strips bow"
            )
        if plan.split is not None:
            a, b = (plan.panels[k].name for k in plan.split)
            notes.append(
                f"the strip without a partner is cut across at half its length: {a} and {b} "
                "lie side by side, the cross seam matched like every seam"
            )
        if self.nest is not None and self.nest.stopped:
            notes.append(self.nest.stopped)
        return notes


@takes_options(SolveOptions, StructureOptions, CutOptions)
def cut(
    mesh: SurfaceMesh,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    prestress: float | Sequence[float] | None = None,
    lines: Sequence[np.ndarray] | None = None,
    allowance: float = 0.0,
    units: str = "m",
    dxf_units: str = "mm",
    options: SolveOptions | None = None,
    structure: StructureOptions | None = None,
    cutting: CutOptions | None = None,
    callback: Callable[[IterationRecord], None] | None = None,
    nest: bool = True,
    **settings: Any,
) -> CutResult:
    """Cut a surface into strips of roll width, pattern them with matched seams and nest them.

    ``roll_width`` (an option, below) is in the mesh's ``units``; ``allowance`` (the seam
    allowance) and the edge allowances are in ``dxf_units``, as on the cutter's drawing.
    ``nest=False`` leaves the nest to a later :func:`with_patterns` (patterns that will change
    before they are cut). ``prestress`` is uniform or one row per cell of ``mesh`` (the
    membrane forces of a form-finding run): each strip's cells take the rows of the cells they
    were cut from.
    ``lines`` are the user's cutting lines (polylines ``(k, 3)`` near the surface), given
    with ``seams = "curves"`` (a job names a file of them instead: option ``curves``). The
    warp runs along each strip unless ``warp_direction`` is given.
    """
    mine = {k: settings.pop(k) for k in list(settings) if k in CutOptions.specs()}
    cutting = cutting.replace(**mine) if cutting is not None else CutOptions(**mine)
    options, structure = split_settings(
        settings, [options or SolveOptions(), structure or StructureOptions()]
    )
    if structure.roll_width not in (None, cutting.roll_width):
        raise ValueError(
            f"a cut has one roll width, the cut option roll_width ({cutting.roll_width:g}: every "
            f"strip's cut outline, allowances included, fits it); the structure's "
            f"({structure.roll_width:g}) differs: leave it unset"
        )
    structure = structure.replace(roll_width=cutting.roll_width)
    if (cutting.seams == "curves") != (lines is not None):
        raise CuttingError("seams = 'curves' and the cutting lines (lines=[…]) go together")
    started = time.perf_counter()
    scale = unit_factor(dxf_units, units)
    usable = usable_width(cutting.roll_width)
    allowances = _allowances(cutting, allowance, scale)
    surface = triangulated(mesh)
    per_cell = prestress is not None and np.ndim(prestress) == 2
    if per_cell and len(prestress) != mesh.num_cells:
        raise ValueError(
            f"a per-cell prestress needs one row per cell of the surface ({mesh.num_cells}); "
            f"got {len(prestress)}"
        )
    target, rounds, plan = usable, [], None
    for _ in range(MAX_ROUNDS):
        plan = _plan(surface, target, cutting, allowances, options, lines, plan)
        own = [
            {} if options.warp_direction is not None else {"warp_direction": tuple(w)}
            for w in plan.warps
        ]
        panel_prestress = None
        if per_cell:
            rows = np.asarray(prestress, dtype=float)
            panel_prestress = [rows[k] for k in input_cells(mesh, surface, plan.panels)]
        result = solve_structure(
            plan.panels,
            material,
            thickness,
            prestress=None if per_cell else prestress,
            panel_prestress=panel_prestress,
            panel_settings=own,
            options=options,
            structure=structure,
            callback=callback,
        )
        outlines = piece_outlines(plan.cut, result, cutting, allowances)
        widths = _widths(outlines, result)
        needs = widths
        if plan.interlock:
            warps = [r.fibres.warp for r in result.results]
            needs = pair_widths([o.cut for o in outlines], warps, plan.split)
        rounds.append(max(needs))
        if not result.converged or max(needs) <= usable or lines is not None:
            break
        # the flattened widths underestimated the patterns': ask the flattening for less, with
        # a margin of the widths' noise from one layout to the next once one such plan missed
        margin = RETRY_MARGIN if len(rounds) > 1 else 1e-3
        target = max(plan.widths) * usable / max(needs) * (1.0 - margin)
    nested = _nest(outlines, widths, result, cutting, scale, plan) if nest else None
    return CutResult(
        plan,
        result,
        outlines,
        widths,
        seam_lines(plan, result),
        nested,
        cutting,
        mesh.area,
        units,
        dxf_units,
        allowance,
        rounds,
        time.perf_counter() - started,
        float(min_angles(surface.points, surface.cells["triangle"]).min()),
    )


def input_cells(
    mesh: SurfaceMesh, surface: SurfaceMesh, panels: Sequence[Panel]
) -> list[np.ndarray]:
    """Per panel, the cell of the input ``mesh`` (global cell order) each of its cells lies in:
    the surface is refined and cut on its own faces, so every panel cell lies in one of the
    triangles of ``surface`` (``mesh`` with its quads split, :func:`triangulated`)."""
    from ..geometry.surface_points import FaceLocator

    offsets, start = {}, 0
    for cell_type, cells in mesh.cells.items():
        offsets[cell_type], start = start, start + len(cells)
    n_tri = len(mesh.cells.get("triangle", ()))
    n_quad = len(mesh.cells.get("quad", ()))
    # the triangulated surface: the triangles, then every quad's first half, then its second
    face = np.arange(n_tri + 2 * n_quad)
    quad = np.where(face < n_tri + n_quad, face - n_tri, face - n_tri - n_quad)
    origin = np.where(
        face < n_tri, offsets.get("triangle", 0) + face, offsets.get("quad", 0) + quad
    )
    locator = FaceLocator(surface)
    out = []
    for panel in panels:
        centres = np.concatenate(
            [panel.mesh.points[c].mean(axis=1) for c in panel.mesh.cells.values()]
        )
        faces, _, _ = locator.locate(centres)
        out.append(origin[faces])
    return out


def _estimates(compared: dict[str, tuple[int, float]]) -> str:
    if "alone" not in compared or "pairs" not in compared:
        return ""
    (alone, length), (pairs, paired) = compared["alone"], compared["pairs"]
    return (
        f" ({pairs} strips in place of {alone}, by the flattened strips {paired:.4g} of roll "
        f"in place of {length:.4g})"
    )


def _allowances(cutting: CutOptions, allowance: float, scale: float) -> dict[str, float]:
    """The allowance of every kind of edge, mesh units."""
    return {
        kind: scale * cutting.allowance(kind, allowance)
        for kind in ("seam", "free", "cable", "clamp")
    }


def _widths(outlines, structure: StructureResult) -> list[float]:
    """Every cut outline's width across its pattern's warp (mesh units)."""
    return [
        width_across_warp(o.cut, r.fibres.warp)
        for o, r in zip(outlines, structure.results, strict=True)
    ]


def _nest(outlines, widths, result: StructureResult, cutting: CutOptions, scale: float, plan):
    """The pieces nested on the roll, or None where they are not patterns or too wide: strips
    planned in pairs laid in pairs (:func:`~vares.structures.pair_nest.pair_nest`, where every
    pair fits and turning is allowed), the others searched for (:func:`nest_pieces`)."""
    if not result.converged or max(widths) > usable_width(cutting.roll_width):
        return None
    cuts, areas, gap = (
        [o.cut for o in outlines],
        [o.area for o in outlines],
        scale * cutting.piece_gap,
    )
    if plan.interlock and cutting.allow_turn:
        count = len(cuts)
        pairs = [(k, k + 1) for k in range(0, count - 1, 2)] + [(count - 1,)] * (count % 2)
        laid = pair_nest(cuts, cutting.roll_width, pairs, net_areas=areas, gap=gap)
        if laid is not None:
            return laid
    return nest_pieces(
        cuts,
        cutting.roll_width,
        net_areas=areas,
        allow_turn=cutting.allow_turn,
        gap=gap,
        time_limit=cutting.nest_time,
        seed=cutting.nest_seed,
    )


def with_patterns(cut_result: CutResult, structure: StructureResult) -> CutResult:
    """The cut with other patterns of its strips (e.g. optimised for the erected structure):
    outlines, widths, seams and the nest made again from ``structure``'s."""
    cutting = cut_result.options
    scale = unit_factor(cut_result.dxf_units, cut_result.units)
    allowances = _allowances(cutting, cut_result.allowance, scale)
    outlines = piece_outlines(cut_result.plan.cut, structure, cutting, allowances)
    widths = _widths(outlines, structure)
    nest = _nest(outlines, widths, structure, cutting, scale, cut_result.plan)
    return replace(
        cut_result,
        structure=structure,
        outlines=outlines,
        widths=widths,
        seams=seam_lines(cut_result.plan, structure),
        nest=nest,
    )


def _plan(
    surface,
    target,
    cutting: CutOptions,
    allowances,
    options,
    lines,
    earlier: StripPlan | None = None,
) -> StripPlan:
    """The strips: along the user's lines, or planned alone or in pairs (option ``interlock``,
    :func:`~vares.structures.pairing.choose_plan`; an ``earlier`` plan's choice is kept),
    a lone strip of pairs cut across (:func:`~vares.structures.pairing.split_lone_strip`)."""
    if cutting.seams == "curves":
        from ..geometry.drawn_lines import curves_on_surface

        fine, rounds = refine(surface, longest_edge_for(target))
        base, on_surface = curves_on_surface(fine, lines, cutting.snap)
        plan = strips_along_lines(base, on_surface, cutting.snap, options.warp_direction)
        plan.refinements, plan.input_cells = rounds, len(surface.cells["triangle"])
        plan.refined_cells = len(fine.cells["triangle"])
        return plan

    def planned(interlock: bool) -> StripPlan:
        return plan_strips(
            surface,
            target,
            seams=cutting.seams,
            layout=cutting.layout,
            direction=cutting.strip_direction,
            seam_allowance=allowances["seam"],
            edge_allowance=allowances[cutting.edge_type],
            warp_direction=options.warp_direction,
            snap=cutting.snap,
            interlock=interlock,
            cross_seams=cutting.cross_seams == "auto",
        )

    return split_lone_strip(choose_plan(planned, cutting.interlock, earlier))


def piece_outlines(
    cut_mesh: CutMesh, structure: StructureResult, cutting: CutOptions, allowances: dict
) -> list[PieceOutline]:
    """Every panel's seam ring, the kind of each edge and its cut ring (allowances in mesh
    units, by kind)."""
    points = cut_mesh.mesh.points
    n = len(points)
    seam_keys = set((cut_mesh.seam_edges @ np.array([n, 1])).tolist())
    loops = cut_mesh.mesh.boundary_loops()
    high = set()
    if len(loops) > 1:
        high = set(max(loops, key=lambda loop: points[loop, 2].mean()).tolist())
    cells = cut_mesh.mesh.cells["triangle"]
    outlines = []
    for index, result in enumerate(structure.results):
        used = np.unique(cells[cut_mesh.panel_ids == index])
        ring_nodes = result.mesh.boundary_loops()[0]  # the longest
        global_nodes = used[ring_nodes]
        kinds = []
        for a, b in zip(global_nodes, np.roll(global_nodes, -1), strict=True):
            if min(a, b) * n + max(a, b) in seam_keys:
                kinds.append("seam")
            elif a in high and b in high:
                kinds.append(cutting.high_edge_type or cutting.edge_type)
            else:
                kinds.append(cutting.edge_type)
        seam = result.material_coordinates[ring_nodes]
        ring = allowance_outline(seam, [allowances[k] for k in kinds])
        outlines.append(PieceOutline(seam, tuple(kinds), ring))
    return outlines
