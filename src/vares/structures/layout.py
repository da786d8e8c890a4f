"""Strips of roll width: where the cutting lines go, and the panels they cut the surface into.

For a family of cutting lines (:mod:`vares.geometry.line_families`) the strips are found by
iterating on what matters, the flattened width: place the lines, cut the mesh along them, flatten
every strip (least-squares conformal map, scaled to its area) and measure its extent across the
warp, allowances included; then move the lines so that all strips get the same width (each
gap's parameter span is scaled by (mean width / its width)^0.7, a few times, keeping the best),
and take the least number of strips whose equalised width fits the roll: one strip fewer is
tried too, and does not fit.

The flattened width is an estimate of the pattern's: :func:`vares.structures.cut.cut` checks the
patterns themselves and plans again with a narrower target if one is too wide.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..geometry.cutting import SNAP, CutMesh, cut_mesh
from ..geometry.flatten import lscm
from ..geometry.line_families import LineFamily, geodesic_between_ends, line_family
from ..geometry.mesh import SurfaceMesh
from ..geometry.surface_lines import CuttingError, SurfaceLine, triangulated
from .panels import Panel, split_panels, width_across_warp

__all__ = ["SEAM_KINDS", "StripPlan", "pattern_direction", "plan_strips", "strips_along_lines"]

SEAM_KINDS = ("geodesic", "planar")
#: Equalising iterations per number of strips, and the width ratio that is equal enough.
_EQUALISE, _EQUAL = 6, 1.005


@dataclass
class StripPlan:
    """Strips cut from a surface.

    ``cut`` is the cut mesh (panel ids in strip order), ``panels`` the strips (``strip-1`` …),
    ``lines`` the cutting lines as computed (geodesics or plane sections, on the mesh the cut
    started from) and ``warps`` the 3D direction along every strip. ``widths`` are the flattened
    strips' extents across their warps, allowances included (mesh units); ``evaluations`` counts
    the layouts tried.
    """

    cut: CutMesh
    panels: list[Panel]
    lines: list[SurfaceLine]
    warps: list[np.ndarray]
    widths: list[float]
    family: LineFamily | None = None
    evaluations: int = 0
    history: list[tuple[int, float]] = field(default_factory=list)  # (strips, widest)


def plan_strips(
    mesh: SurfaceMesh,
    width: float,
    *,
    seams: str = "geodesic",
    layout: str = "auto",
    direction: Sequence[float] | None = None,
    seam_allowance: float = 0.0,
    edge_allowance: float = 0.0,
    warp_direction: Sequence[float] | None = None,
    snap: float = SNAP,
    max_strips: int = 200,
) -> StripPlan:
    """The least number of equally wide strips whose flattened width, with a seam allowance on
    each seam side and ``edge_allowance`` on a side along the surface's boundary, is at most
    ``width`` (mesh units; module docs). ``warp_direction`` (3D) is measured across instead of
    the direction along each strip."""
    if seams not in SEAM_KINDS:
        raise ValueError(f"seams must be one of {', '.join(SEAM_KINDS)}; got {seams!r}")
    if not width > 0:
        raise ValueError(f"the roll width must be > 0; got {width!r}")
    surface = triangulated(mesh)
    family = line_family(surface, layout, direction)

    def evaluate(spans: np.ndarray) -> StripPlan:
        plan = _layout(surface, family, spans, seams, snap, warp_direction)
        plan.widths = _widths(plan, family, seam_allowance, edge_allowance)
        return plan

    total = family.span[1] - family.span[0]
    smallest = 2 if family.closed else 1
    first = evaluate(np.full(8, total / 8) if family.closed else np.array([total]))
    count = max(smallest, math.ceil(sum(first.widths) / width))
    tried: dict[int, StripPlan] = {}
    evaluations, history = 1, []
    while count not in tried:
        if count > max_strips:
            raise CuttingError(f"more than {max_strips} strips would be needed")
        spans, plan = np.full(count, total / count), None
        for _ in range(_EQUALISE):
            candidate = evaluate(spans)
            evaluations += 1
            widths = np.array(candidate.widths)
            if plan is None or widths.max() < max(plan.widths):
                plan = candidate
            if widths.max() <= _EQUAL * widths.min():
                break
            spans = spans * (widths.mean() / widths) ** 0.7  # damped: widths jump with the mesh
            spans *= total / spans.sum()
        tried[count] = plan
        history.append((count, max(plan.widths)))
        fits = max(plan.widths) <= width
        if fits and count - 1 >= smallest and count - 1 not in tried:
            count -= 1
        elif fits:
            break
        else:
            count += 1
    best = min((c for c, p in tried.items() if max(p.widths) <= width), default=None)
    if best is None:
        raise CuttingError(f"no layout of up to {max(tried)} strips fits the roll width {width:g}")
    plan = tried[best]
    plan.evaluations, plan.history = evaluations, history
    return plan


def _layout(surface, family, spans, seams, snap, warp_direction) -> StripPlan:
    """Cut along the family's lines at the boundaries of the parameter ``spans``."""
    bounds = family.span[0] + np.concatenate([[0.0], np.cumsum(spans)])
    if family.closed:
        bounds = bounds[:-1] + 0.25 * spans[0]
    else:
        bounds = bounds[1:-1]
    sections = []
    for s in bounds:
        found = family.sections(surface, float(s))
        if not found:
            raise CuttingError(f"a cutting line of parameter {s:.6g} misses the surface")
        sections.append(max(found, key=lambda line: line.length))
    base, lines = surface, sections
    if seams == "geodesic" and sections:
        base, lines = geodesic_between_ends(surface, sections, snap)
    return strips_along_lines(base, lines, snap, warp_direction, family)


def strips_along_lines(
    mesh: SurfaceMesh,
    lines: Sequence[SurfaceLine],
    snap: float = SNAP,
    warp_direction: Sequence[float] | None = None,
    family: LineFamily | None = None,
) -> StripPlan:
    """Cut a triangle mesh along ``lines`` into strips, ordered across (by ``family``'s
    parameter, or along the best-fit plane's first axis) and named ``strip-1`` …, with the
    direction along each strip (the mean of its seams, oriented alike) or ``warp_direction``."""
    cut = cut_mesh(mesh, lines, snap)
    points = cut.mesh.points
    cells = cut.mesh.cells["triangle"]
    centroids = points[cells].mean(axis=1)
    if family is not None:
        key = family.parameter(centroids)
    else:
        from ..geometry.flatten import projection_plane

        key = projection_plane(cut.mesh).project(centroids)[:, 0]
    order = np.argsort([np.median(key[cut.panel_ids == p]) for p in range(cut.num_panels)])
    renumber = np.empty_like(order)
    renumber[order] = np.arange(order.size)
    ids = renumber[cut.panel_ids]
    cut = CutMesh(cut.mesh, ids, cut.lines, cut.seam_edges, cut.worst_angle, cut.input_worst_angle)
    panels = split_panels(cut.mesh, ids, {i: f"strip-{i + 1}" for i in range(cut.num_panels)})
    if warp_direction is not None:
        warp = np.asarray(warp_direction, dtype=float)
        warps = [warp / np.linalg.norm(warp)] * len(panels)
    else:
        warps = _along_strips(cut, panels, family)
    return StripPlan(cut, panels, list(lines), warps, [], family)


def _along_strips(cut: CutMesh, panels: list[Panel], family) -> list[np.ndarray]:
    """Per panel: the sum of its seam segments (lines oriented alike), normalised."""
    points, cells = cut.mesh.points, cut.mesh.cells["triangle"]
    n = len(points)
    sides = np.stack([cells, np.roll(cells, -1, axis=1)], axis=-1).reshape(-1, 2)
    owner = np.repeat(cut.panel_ids, 3)
    keys = sides[:, 0] * n + sides[:, 1]
    lookup = dict(zip(keys.tolist(), owner.tolist(), strict=True))
    sums = np.zeros((len(panels), 3))
    for chain in cut.lines:
        for u, w in itertools.pairwise(chain):
            vector = points[w] - points[u]
            for key in (u * n + w, w * n + u):
                if key in lookup:
                    sums[lookup[key]] += vector
    out = []
    for index, panel in enumerate(panels):
        length = np.linalg.norm(sums[index])
        if length > 0:
            out.append(sums[index] / length)
        elif family is not None:
            out.append(family.warp(panel.mesh.points))
        else:
            from ..geometry.flatten import projection_plane

            out.append(projection_plane(panel.mesh).axes[0])
    return out


def pattern_direction(mesh: SurfaceMesh, coordinates: np.ndarray, direction) -> np.ndarray:
    """The unit 2D direction ``(2,)`` of a pattern ``(n, 2)`` that maps onto the 3D
    ``direction`` (projected on each cell; 3D-area-weighted mean over the triangles)."""
    cells = triangulated(mesh).cells["triangle"]
    p, x = mesh.points[cells], coordinates[cells]
    edges_3d = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]], axis=-1)  # (m, 3, 2)
    edges_2d = np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]], axis=-1)  # (m, 2, 2)
    mapping = edges_2d @ np.linalg.pinv(edges_3d)  # (m, 2, 3): tangent plane → pattern
    area = 0.5 * np.linalg.norm(np.cross(edges_3d[..., 0], edges_3d[..., 1]), axis=1)
    image = (mapping @ np.asarray(direction, dtype=float)) * area[:, None]
    total = image.sum(axis=0)
    return total / np.linalg.norm(total)


def _widths(plan: StripPlan, family, seam_allowance: float, edge_allowance: float) -> list[float]:
    """Flattened width of every strip with its two side allowances (module docs)."""
    out = []
    last = len(plan.panels) - 1
    for index, (panel, warp) in enumerate(zip(plan.panels, plan.warps, strict=True)):
        flat = lscm(panel.mesh)
        width = width_across_warp(flat, pattern_direction(panel.mesh, flat, warp))
        outer = family is not None and not family.closed and index in (0, last)
        sides = 2 if last == 0 else 1
        allowance = (
            sides * edge_allowance + (2 - sides) * seam_allowance if outer else 2 * seam_allowance
        )
        out.append(width + allowance)
    return out
