"""Strips of roll width: where the cutting lines go, and the panels they cut the surface into.

For a family of cutting lines (:mod:`vares.geometry.line_families`) the strips are found by
iterating on what matters, the flattened width: place the lines, cut the mesh along them, flatten
every strip (least-squares conformal map, scaled to its area) and measure its extent across the
warp, allowances included; then move the lines so that all strips get the same width, and take
the least number of strips whose equalised width fits the roll: one strip fewer is tried too,
and does not fit (how the number is searched for: :mod:`.equalise`).

A line is every piece of the plane section of its parameter (a plane near a sagging edge cuts the
surface twice: the corner beyond it is a strip of its own), or the geodesic between the ends of
that piece. The pieces a gap between two lines leaves are its strips, and the gap is as wide as
the widest of them. A geodesic that touches the boundary between its ends (a geodesic hugs a
sagging edge), or comes closer to a line of the neighbouring parameter than ``APART`` × their
parameters' difference (compared at the same coordinate along the strips), is replaced by its
plane section, and so on until all lines keep apart: plane sections of different parameters
never meet.

A design mesh is often coarser than the strips: the surface is refined on its own faces first
(:mod:`vares.geometry.refine`) until no edge is longer than the roll width / ``CELLS_ACROSS``
(half that for strips in pairs, each about half the roll wide: :func:`longest_edge_for`);
if lines still meet where their crossings were moved onto the same node, it is refined further.

The flattened width is an estimate of the pattern's: :func:`vares.structures.cut.cut` checks the
patterns themselves and plans again with a narrower target if one is too wide.

Tapered strips can be planned to lie in pairs on the roll, head to tail (``interlock``): the
warp of each runs along one of its seams, and the width that counts is the one two strips need
side by side (:mod:`.widths`; when to, :mod:`.pairing`).
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence

import numpy as np

from ..geometry.cutting import SNAP, CutMesh, LinesMeetError, cut_mesh
from ..geometry.line_families import LineFamily, geodesic_between_ends, line_family
from ..geometry.mesh import SurfaceMesh
from ..geometry.refine import refine
from ..geometry.surface_lines import CuttingError, SurfaceLine, triangulated
from .cross_seams import MAX_PIECES, split_across
from .equalise import NoFitError, NotNarrowerError, least_count
from .panels import split_panels
from .strip_plan import StripPlan, along_strips
from .widths import pattern_direction, strip_widths

__all__ = [
    "APART",
    "CELLS_ACROSS",
    "MAX_REFINED_CELLS",
    "SEAM_KINDS",
    "StripPlan",
    "longest_edge_for",
    "pattern_direction",
    "plan_strips",
    "strips_along_lines",
]

SEAM_KINDS = ("geodesic", "planar")
#: Cells across a strip of roll width at least (by their longest edges; module docs).
CELLS_ACROSS = 2
#: The most triangles the surface may be refined to for the strips: a narrower roll is refused
#: before the refinement (the conic tent at a 1 mm roll filled 24 GB and was killed).
MAX_REFINED_CELLS = 2_000_000
#: Neighbouring lines stay at least this fraction of their parameters' difference apart.
APART = 0.2
#: Pieces of a plane section shorter than this fraction of the roll width are no cutting lines.
_SHORTEST = 0.1
#: Strips cut across into one piece more whose gaps are at least this fraction of their mean
#: width before are not cut into more (:func:`_in_pieces`).
_NARROWER_PIECES = 0.95
#: Further refinements at most, when planned lines meet, before plane sections replace geodesics.
_RETRIES = 2


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
    interlock: bool = False,
    cross_seams: bool = True,
) -> StripPlan:
    """The least number of equally wide strips whose flattened width, with a seam allowance on
    each seam side and ``edge_allowance`` on a side along the surface's boundary, is at most
    ``width`` (mesh units; module docs). ``warp_direction`` (3D) is measured across instead of
    the direction along each strip. The surface is refined on its own faces where its cells are
    too large for strips of ``width``. With ``interlock`` the strips are planned to lie in
    pairs, head to tail: the warp runs along one seam of each (the same side of every strip,
    unless ``warp_direction`` is given) and two of them must fit ``width`` side by side.
    With ``cross_seams``, where strips alone fit no roll of ``width`` whole, however many, the
    strips too wide are cut across into pieces (:mod:`.cross_seams`): as few pieces a strip as
    let some number of strips fit."""
    if seams not in SEAM_KINDS:
        raise CuttingError(f"seams must be one of {', '.join(SEAM_KINDS)}; got {seams!r}")
    if not width > 0:
        raise CuttingError(f"the roll width must be > 0; got {width!r}")
    surface = triangulated(mesh)
    family = line_family(surface, layout, direction)  # of the input: refining keeps the shape
    input_cells = len(surface.cells["triangle"])
    total = family.span[1] - family.span[0]
    if not family.closed:  # the whole surface, no line: the number of strips before refining
        whole = strips_along_lines(surface, [], snap, warp_direction, family)
        estimate = sum(strip_widths(whole, family, seam_allowance, edge_allowance)) / width
        if estimate > max_strips:
            raise CuttingError(f"more than {max_strips} strips would be needed")
    # in pairs two strips share the width, each about half of it
    strips = f"strips in pairs {width:g} wide" if interlock else f"strips of {width:g}"
    longest = longest_edge_for(width, interlock)
    cells = refined_cells(surface, longest)
    if cells > MAX_REFINED_CELLS:
        raise CuttingError(
            f"{strips} would need the surface refined to about {cells:,.0f} cells "
            f"(edges of at most {longest:g}; at most {MAX_REFINED_CELLS:,}): try a wider roll"
        )
    refined = _Refined(surface, width, longest, strips)

    def evaluate(spans: np.ndarray, pieces: int = 1) -> tuple[StripPlan, np.ndarray]:
        plan = refined.layout(family, spans, seams, snap, warp_direction)
        if interlock and warp_direction is None:
            plan.warps = along_strips(plan.cut, plan.panels, family, one_seam=True)
            plan.straight_warp = True
        plan.interlock = interlock
        plan.widths = strip_widths(plan, family, seam_allowance, edge_allowance)
        if pieces > 1:
            plan = split_across(plan, width, pieces, snap, own_warps=warp_direction is None)
            plan.widths = strip_widths(plan, family, seam_allowance, edge_allowance)
        plan.input_cells = input_cells
        return plan, _gap_widths(plan, family, spans)

    smallest = 2 if family.closed else 1
    first, _ = evaluate(np.full(8, total / 8) if family.closed else np.array([total]))
    count = max(smallest, math.ceil(sum(first.widths) / width))
    try:
        plan = least_count(evaluate, total, count, smallest, width, max_strips, interlock)
    except NotNarrowerError as whole:
        if interlock or not cross_seams:
            raise
        plan = _in_pieces(evaluate, whole, total, count, smallest, width, max_strips)
    plan.evaluations += 1
    return plan


def _in_pieces(evaluate, whole: NotNarrowerError, total, count, smallest, width, max_strips):
    """The plan of :func:`plan_strips` with the strips too wide cut across into the fewest
    pieces (2 … ``MAX_PIECES``) for which some number of strips fits ``width``; ``whole`` is
    the refusal of whole strips. Refused where one piece more does not make the gaps narrower
    on average (the strips are wide, not bowed; a gap too wide at the least span a gap may have
    is bowed whatever the mean), or more strips than ``max_strips`` would be needed."""
    mean = whole.mean
    for pieces in range(2, MAX_PIECES + 1):
        try:
            return least_count(
                functools.partial(evaluate, pieces=pieces),
                total, count, smallest, width, max_strips, False,
            )  # fmt: skip
        except NotNarrowerError as refused:
            if not refused.bowed and refused.mean >= _NARROWER_PIECES * mean:
                break
            mean = refused.mean
    raise NoFitError(f"{whole}; cut across into {pieces} pieces they do not fit either") from None


def longest_edge_for(width: float, interlock: bool = False) -> float:
    """The longest edge the surface may have for strips planned on a roll ``width`` wide: a
    strip as wide as the roll is :data:`CELLS_ACROSS` cells across; a strip of a pair
    (``interlock``) is about half as wide, and as many cells across."""
    return width / CELLS_ACROSS / (2.0 if interlock else 1.0)


def refined_cells(surface: SurfaceMesh, longest: float) -> float:
    """About how many triangles the triangle mesh ``surface`` has once refined on its own faces
    until no edge is longer than ``longest`` (each halving of a cell's longest edge a 1-to-4
    split): what the width asks for, even where that takes more than the
    :data:`~vares.geometry.refine.MAX_ROUNDS` rounds a refinement does (a roll that narrow is
    refused, not planned on a surface too coarse for it)."""
    corners = surface.points[surface.cells["triangle"]]
    edges = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=-1).max(axis=1)
    halvings = np.ceil(np.log2(np.maximum(edges / longest, 1.0)))
    return float(np.sum(4.0**halvings))


class _Refined:
    """The surface the lines are placed on: refined on its own faces until its edges are at most
    ``longest`` (:func:`longest_edge_for` the roll ``width``), and further (each time halving
    that length; ``_RETRIES`` times at most for the whole plan) when planned lines meet; then
    plane sections in place of geodesics where they still do."""

    def __init__(self, surface: SurfaceMesh, width: float, longest: float, strips: str) -> None:
        self.width, self.longest, self.strips = width, longest, strips
        self.surface, self.rounds = refine(surface, self.longest)
        self.retries = _RETRIES

    def layout(self, family, spans, seams, snap, warp_direction) -> StripPlan:
        while True:
            try:
                plan = _layout(self.surface, family, spans, seams, snap, warp_direction, self.width)
                return self._counted(plan)
            except LinesMeetError:
                if not self.retries:
                    break
            self.retries -= 1
            self.longest /= 2
            self.surface, rounds = refine(self.surface, self.longest)
            self.rounds += rounds
        try:  # plane sections of different parameters never cross: only a snap joins them
            plan = _layout(self.surface, family, spans, "planar", snap, warp_direction, self.width)
        except LinesMeetError as exc:
            raise CuttingError(
                f"the cutting lines for {self.strips} meet even on the surface refined "
                f"{self.rounds} times ({exc}): try a wider roll, another layout or strip direction"
            ) from None
        plan.replaced_geodesics = len(plan.lines) if seams == "geodesic" else 0
        return self._counted(plan)

    def _counted(self, plan: StripPlan) -> StripPlan:
        plan.refinements, plan.refined_cells = self.rounds, len(self.surface.cells["triangle"])
        return plan


def _bounds(family: LineFamily, spans: np.ndarray) -> np.ndarray:
    """The parameters of the lines between gaps of parameter ``spans`` (ascending)."""
    bounds = family.span[0] + np.concatenate([[0.0], np.cumsum(spans)])
    if family.closed:
        return bounds[:-1] + 0.25 * spans[0]
    return bounds[1:-1]


def _gap_widths(plan: StripPlan, family: LineFamily, spans: np.ndarray) -> np.ndarray:
    """The width of every gap ``(len(spans),)``: that of the widest strip in it (0 if none)."""
    bounds = _bounds(family, spans)
    cells = plan.cut.mesh.cells["triangle"]
    key = family.parameter(plan.cut.mesh.points[cells].mean(axis=1))
    out = np.zeros(len(spans))
    for index, width in enumerate(plan.widths):
        median = np.median(key[plan.cut.panel_ids == index])
        gap = int(np.searchsorted(bounds, median, side="right"))
        if family.closed:
            gap = (gap - 1) % len(spans)
        out[gap] = max(out[gap], width)
    return out


def _layout(surface, family, spans, seams, snap, warp_direction, width) -> StripPlan:
    """Cut along the family's lines at the boundaries of the parameter ``spans``: every piece of
    each plane section at least ``_SHORTEST`` × ``width`` long, or its geodesic (module docs)."""
    bounds = _bounds(family, spans)
    sections, where = [], []
    for index, s in enumerate(bounds):
        for line in family.sections(surface, float(s)):
            if line.length >= _SHORTEST * width:
                sections.append(line)
                where.append(index)
    base, lines, replaced = surface, sections, 0
    if seams == "geodesic" and sections:
        base, lines = geodesic_between_ends(surface, sections, snap)
        replaced = _keep_apart(family, base, bounds, sections, lines, where)
    plan = strips_along_lines(base, lines, snap, warp_direction, family)
    plan.replaced_geodesics = replaced
    return plan


def _same_section(
    family: LineFamily, mesh: SurfaceMesh, s: float, section: SurfaceLine
) -> SurfaceLine:
    """The piece of the plane section of parameter ``s`` on ``mesh`` (the surface the section
    was found on, with nodes inserted) that passes through the middle of ``section``."""
    middle = section.points[len(section.points) // 2]

    def distance(line: SurfaceLine) -> float:
        return float(np.linalg.norm(line.points - middle, axis=1).min())

    return min(family.sections(mesh, s), key=distance)


def _keep_apart(family, base, bounds, sections, lines, where) -> int:
    """Replace by its plane section (in ``lines``, in place) every geodesic that touches the
    boundary between its ends, or that comes closer to a line of a neighbouring parameter than
    ``APART`` × their parameters' difference; the number replaced."""
    period = family.span[1] - family.span[0]
    own = [float(bounds[k]) for k in where]
    boundary = _boundary(base)
    geodesic = [not _touches(line, boundary) for line in lines]
    last = len(bounds) - 1
    pairs = []
    for i, j in itertools.permutations(range(len(lines)), 2):
        if where[j] == where[i] + 1:
            pairs.append((i, j, own[j]))
        elif family.closed and last > 0 and where[i] == last and where[j] == 0:
            pairs.append((i, j, own[j] + period))
    replace = [k for k in range(len(lines)) if not geodesic[k]]
    while True:
        for k in replace:
            lines[k], geodesic[k] = _same_section(family, base, own[k], sections[k]), False
        replace = []
        for i, j, above in pairs:
            if (geodesic[i] or geodesic[j]) and _too_close(
                family, lines[i], own[i], lines[j], above
            ):
                replace += [k for k in (i, j) if geodesic[k] and k not in replace]
        if not replace:
            return geodesic.count(False)


def _chart(family: LineFamily, line: SurfaceLine, s: float) -> tuple[np.ndarray, np.ndarray]:
    """A line's points as (along, parameter), the parameter continued from ``s`` (points on the
    axis of a radial family, where every line passes, left out), sorted along."""
    points = line.points
    if family.kind == "radial":
        radius = np.hypot(points[:, 0] - family.centre[0], points[:, 1] - family.centre[1])
        points = points[radius > 1e-9 * radius.max(initial=0.0)]
    along, offset = family.along(points), family.parameter(points) - s
    if family.kind == "radial":
        offset = np.mod(offset + np.pi, 2 * np.pi) - np.pi
    order = np.argsort(along)
    return along[order], s + offset[order]


def _too_close(family, first: SurfaceLine, s: float, second: SurfaceLine, t: float) -> bool:
    """Whether two lines of parameters ``s < t`` come closer than ``APART`` × (t − s) in the
    parameter, where both run (compared at the same coordinates along the strips)."""
    along_1, p_1 = _chart(family, first, s)
    along_2, p_2 = _chart(family, second, t)
    if not (len(along_1) and len(along_2)):
        return False
    low, high = max(along_1[0], along_2[0]), min(along_1[-1], along_2[-1])
    if not high > low:
        return False
    where = np.linspace(low, high, 65)
    gap = np.interp(where, along_2, p_2) - np.interp(where, along_1, p_1)
    return bool(gap.min() < APART * (t - s))


def _boundary(mesh: SurfaceMesh) -> tuple[set[int], set[tuple[int, int]]]:
    edges = mesh.boundary_edges()
    return set(edges.ravel().tolist()), {tuple(sorted(e)) for e in edges.tolist()}


def _touches(line: SurfaceLine, boundary: tuple[set[int], set[tuple[int, int]]]) -> bool:
    """Whether a line meets the mesh's boundary between its ends."""
    nodes, edges = boundary
    for a, b in line.ends[1:-1].tolist():
        if (a == b and a in nodes) or (a != b and (min(a, b), max(a, b)) in edges):
            return True
    return False


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
        warps = along_strips(cut, panels, family)
    return StripPlan(cut, panels, list(lines), warps, [], family)
