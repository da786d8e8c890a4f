"""The blanks of a laminate's plies as cut: net and extended (trim) boundaries, the rosette at the
ply's seed, areas and masses, and every ply nested on the roll (DESIGN.md §8).

A ply's **net boundary** is its pattern's boundary (the part's edge, flat); its **extended
boundary** is the net grown by ``trim_allowance`` (mesh units, mitred corners; the DXF's cut line,
:func:`vares.geometry.outline.cut_outline`) along the mould's edge: the blank as cut, with the
excess trimmed after draping. A **joint** is not trimmed: along a splice each piece is cut to
the line (butt), or laps over the pieces before it by ``splice_overlap``; a dart's lips are cut
to the dart (butt), or its left lip laps over the right one by ``dart_overlap`` (and a notch the
edges' allowances would close at its mouth is cut open again). The **rosette** sits at the
pattern point of the mould node nearest the ply's seed, with the warp (0°) and the fill (90°)
of the ply's pattern. Every pattern comes with its warp along +x, which is the roll's
direction: the plies are nested as they are (or turned by 180°, which keeps the warp along the
roll) by :func:`vares.structures.nesting.nest_pieces`.
A darted ply's blank is its pattern opened along the darts: the darts' lips are part of its net
boundary, and its ``darts`` are both lips of each, mouth → tip → mouth, in the pattern frame.
A spliced ply is cut as several blanks, one per piece (in the order of the pieces, named
``"<ply> piece-1"`` … by :attr:`PlyBlank.label`): each is nested on its own; its net boundary
along a splice follows the splice line as drawn, mapped into its pattern
(:meth:`vares.analysis.splices.SplicedPly.outline`: the mesh's edge there zigzags round the line
by up to 0.4 of an edge, through the nodes the cut snapped to); its rosette sits at
the pattern point of its node nearest the seed when the seed lies inside it, else (also when
the seed lies on a splice) of its node nearest its centroid. :func:`side_by_side` lays a ply's
pieces out in one frame (its cutter file, its pattern file).
A ply's mass is that of its flat blank: the areal weight (g/m², of the undeformed fabric) times
the pattern's area.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..analysis.darts import DartedPattern
from ..geometry.mesh import SurfaceMesh
from ..geometry.outline import MITRE_LIMIT, edge_outline, region_rings, ring_area
from ..geometry.outline import cut_outline as extended_boundary
from ..geometry.surface_lines import CuttingError
from ..units import METRES
from .blank_options import BlankOptions
from .laminate import LaminateResult
from .laminate_plies import BlankPiece
from .nesting import RollNest, nest_pieces, usable_width

if TYPE_CHECKING:
    from ..analysis.splices import SplicedPly

__all__ = [
    "MITRE_LIMIT",
    "BlankOutline",
    "PlyBlank",
    "blank_outlines",
    "extended_boundary",
    "nest_plies",
    "ply_blanks",
    "ring_area",
    "side_by_side",
]


@dataclass(frozen=True)
class PlyBlank:
    """One ply's blank in its pattern frame (mesh units, warp along +x).

    ``net``: the pattern's boundary rings ``(k, 2)``, the outline first, then holes (a spliced
    piece's along its splices on the drawn lines: module docs); ``trim``:
    the extended boundary's rings, likewise; ``origin`` ``(2,)``: the rosette's point (the
    pattern point of the mould node nearest the seed); ``warp``, ``fill`` ``(2,)``: the unit yarn
    directions of the pattern; ``net_area``, ``trim_area``: flat areas; ``surface_area``: the 3D
    area of the ply on the mould; ``areal_weight`` (g/m²) and ``thickness`` (mm) when known;
    ``darts``: the open dart lines ``(k, 2)`` (both lips, mouth → tip → mouth), none undarted;
    ``piece``: the piece's name for a spliced ply (``None`` for a ply cut whole) and ``pieces``
    how many the ply is cut into; ``splice_overlap``: the ply's overlap at its splices (0: butt)
    and ``laps_over``: the names of the pieces this one laps over by it; ``dart_overlap``: a
    darted ply's overlap of its darts' left lips (0: butt; module docs).
    """

    name: str
    drape: str
    orientation: float
    mesh: SurfaceMesh
    coordinates: np.ndarray
    net: list[np.ndarray]
    trim: list[np.ndarray]
    origin: np.ndarray
    warp: np.ndarray
    fill: np.ndarray
    net_area: float
    trim_area: float
    surface_area: float
    allowance: float
    areal_weight: float | None
    thickness: float | None
    darts: list[np.ndarray] = field(default_factory=list)
    piece: str | None = None
    pieces: int = 1
    splice_overlap: float = 0.0
    laps_over: tuple[str, ...] = ()
    dart_overlap: float = 0.0

    @property
    def label(self) -> str:
        """The blank's name on the roll and in the files: the ply's, with its piece's."""
        return self.name if self.piece is None else f"{self.name} {self.piece}"

    def mass(self, area: float, units: str) -> float | None:
        """Grams of fabric in ``area`` (mesh units², e.g. :attr:`net_area`) of mesh ``units``;
        ``None`` without an areal weight."""
        if self.areal_weight is None:
            return None
        return self.areal_weight * area * METRES[units] ** 2

    @property
    def width(self) -> float:
        """The extended blank's width across the warp (along y)."""
        return float(np.ptp(self.trim[0][:, 1]))


def ply_blanks(result: LaminateResult) -> list[PlyBlank]:
    """Every ply's blank, bottom first (a spliced ply's pieces in their order; module docs),
    with the laminate's ``trim_allowance``."""
    options = result.laminate.options
    allowance = float(options.trim_allowance)
    blanks = []
    outlines: dict[tuple, list[BlankOutline]] = {}  # per drape and overlaps
    for ply in result.laminate.plies:
        drape = result.drape(ply.name)
        pieces = drape.pieces
        holder = _seed_piece(pieces, drape.seed) if len(pieces) > 1 else 0
        o = ply.options
        overlap = options.splice_overlap if o.splice_overlap is None else o.splice_overlap
        dart_overlap = options.dart_overlap if o.dart_overlap is None else o.dart_overlap
        key = (drape.label, overlap, dart_overlap)
        if key not in outlines:  # the plies of one drape share its outlines
            edges = BlankOptions(
                trim_allowance=allowance, splice_overlap=overlap, dart_overlap=dart_overlap
            )
            darted = drape.darted if drape.is_darted else None
            outlines[key] = blank_outlines(pieces, edges, drape.spliced, darted, ply.name)
        for index, (piece, mesh, pattern) in enumerate(pieces):
            coordinates = pattern.material_coordinates
            net, trim, laps = outlines[key][index]
            target = drape.seed if index == holder else mesh.points.mean(axis=0)
            node = int(np.argmin(np.linalg.norm(mesh.points - target, axis=1)))
            fibres = pattern.fibres
            blanks.append(
                PlyBlank(
                    name=ply.name,
                    drape=drape.label,
                    orientation=float(o.orientation),
                    mesh=mesh,
                    coordinates=coordinates,
                    net=net,
                    trim=trim,
                    origin=coordinates[node].copy(),
                    warp=np.asarray(fibres.warp, dtype=float),
                    fill=np.asarray(fibres.fill, dtype=float),
                    net_area=ring_area(net[0]) + sum(ring_area(r) for r in net[1:]),
                    trim_area=ring_area(trim[0]) + sum(ring_area(r) for r in trim[1:]),
                    surface_area=float(mesh.cell_areas().sum()),
                    allowance=allowance,
                    areal_weight=o.areal_weight or options.areal_weight,
                    thickness=o.thickness or options.ply_thickness,
                    darts=drape.darted.dart_pattern_lines() if drape.is_darted else [],
                    piece=piece,
                    pieces=len(pieces),
                    splice_overlap=overlap if drape.is_spliced else 0.0,
                    laps_over=tuple(pieces[j][0] for j in laps),
                    dart_overlap=dart_overlap if drape.is_darted else 0.0,
                )
            )
    return blanks


class BlankOutline(NamedTuple):
    """One piece's outlines in its pattern frame: ``net`` and ``trim`` rings (the largest first
    and counter-clockwise, holes clockwise; module docs) and ``laps``, the indices of the
    pieces it laps over at its splices."""

    net: list[np.ndarray]
    trim: list[np.ndarray]
    laps: list[int]


def blank_outlines(
    pieces: Sequence[BlankPiece],
    options: BlankOptions,
    spliced: SplicedPly | None = None,
    darted: DartedPattern | None = None,
    ply: str = "",
) -> list[BlankOutline]:
    """The net and trim outlines of a ply's ``pieces`` as cut (module docs): along the mould's
    edge the net grown by ``options.trim_allowance``; along the splices of ``spliced`` (the
    ply cut into these pieces) the line as drawn, butt or lapping over the pieces before by
    ``options.splice_overlap``; along the lips of the darts of ``darted`` (the ply cut whole,
    opened along them) butt or the left lip lapping by ``options.dart_overlap``. ``ply`` names
    the ply in the refusal of an overlap too wide for its pieces (:class:`CuttingError`)."""
    allowance, overlap = options.trim_allowance, options.splice_overlap
    if spliced is not None:
        _check_overlap(ply, "splice_overlap", overlap, pieces)
    elif darted is not None:
        _check_overlap(ply, "dart_overlap", options.dart_overlap, pieces)
    outlines = []
    for index, (_, mesh, pattern) in enumerate(pieces):
        coordinates = pattern.material_coordinates
        laps: list[int] = []
        if spliced is not None:  # along a splice: the line as drawn
            loops = spliced.outline(index)
            across = spliced.joints(index)
            widths = [np.where(j < 0, allowance, np.where(j < index, overlap, 0.0)) for j in across]
            laps = sorted({int(j) for a in across for j in a[(a >= 0) & (a < index)]})
        else:  # (a dart's lips butt or lap: the notches cut open below)
            loops = [coordinates[loop] for loop in mesh.boundary_loops()]
            widths = [np.full(len(loop), allowance) for loop in loops]
        net, trim = _outlines(loops, widths, allowance)
        if darted is not None and darted.slits.lips:
            notches = [(coordinates[a], coordinates[b]) for a, b in darted.slits.lips]
            trim = _open_notches(net, trim, notches, allowance, options.dart_overlap)
        outlines.append(BlankOutline(net, trim, laps if overlap > 0 else []))
    return outlines


def _check_overlap(ply: str, key: str, overlap: float, pieces) -> None:
    """Refuse an overlap at a ply's joints of half its narrowest piece's width or more (its
    flat extent across the warp or along it, whichever is less): a lap is a strip beside the
    joint, not a second piece."""
    if not overlap > 0:
        return
    extents = [np.ptp(p.pattern.material_coordinates, axis=0).min() for p in pieces]
    k = int(np.argmin(extents))
    if overlap >= 0.5 * extents[k]:
        which = f"its {pieces[k].piece}" if pieces[k].piece is not None else "its blank"
        raise CuttingError(
            f"ply {ply}: {key} = {overlap:g} is half as wide as {which} ({extents[k]:.4g} "
            "wide, mesh units) or more: an overlap is a strip beside the joint"
        )


def _outlines(loops, widths, allowance: float):
    """A blank's net rings (the largest first and counter-clockwise, holes clockwise) and its
    trim rings, from its boundary ``loops`` ``(k, 2)`` and the allowance of every edge of each
    (edge ``i`` from point ``i`` to the next): the trim ``allowance`` on the mould's edge, a
    splice's or a dart's own on a joint (module docs)."""
    order = sorted(range(len(loops)), key=lambda k: -abs(ring_area(loops[k])))
    net, edges = [], []
    for rank, k in enumerate(order):
        ring, width = loops[k], np.asarray(widths[k], dtype=float)
        if (ring_area(ring) > 0) != (rank == 0):  # edge i of the reversed ring: n − 2 − i
            ring, width = ring[::-1], np.roll(width[::-1], -1)
        net.append(ring)
        edges.append(width)
    return net, edge_outline(net, edges, allowance)


def _open_notches(net, trim, notches, allowance: float, overlap: float) -> list[np.ndarray]:
    """The trim rings ``trim`` (the net grown by ``allowance`` all round) with every dart's
    lips butt, or the left one lapping over the right one by ``overlap``: cut out the wedge
    between the lips and their lines on beyond the mouth (the allowance grown into the notch,
    and over its mouth where the notch is narrower there than the allowance), put back the net
    and the left lip's overlap (``notches``: per dart the left and the right lip's points
    ``(k, 2)``, mouth to tip)."""
    from shapely.geometry import LineString, Polygon
    from shapely.ops import unary_union

    reach = MITRE_LIMIT * allowance + overlap + 1.0e-9
    region = Polygon(trim[0], trim[1:])
    kept = [Polygon(net[0], net[1:])]
    for left, right in notches:
        beyond = [lip[0] + reach * (lip[0] - lip[1]) / np.linalg.norm(lip[0] - lip[1])
                  for lip in (left, right)]  # fmt: skip
        wedge = Polygon(np.vstack([beyond[0], left, right[::-1], beyond[1]])).buffer(0)
        region = region.difference(wedge)
        if overlap > 0:  # the band along the left lip, on the notch's side
            band = LineString(left).buffer(
                overlap, cap_style="flat", join_style="mitre", mitre_limit=MITRE_LIMIT
            )
            kept.append(band.intersection(wedge))
    return region_rings(unary_union([region, *kept]))


def _seed_piece(pieces, seed: np.ndarray) -> int | None:
    """The index of the piece whose surface lies nearest the seed (the one it lies on); None
    when the seed's nearest node of it is on its boundary (the seed on a splice: at the edge
    of every piece beside it)."""
    from ..geometry.surface_points import FaceLocator

    distance = [
        float(np.linalg.norm(FaceLocator(p.mesh).locate(seed)[2][0] - seed)) for p in pieces
    ]
    index = int(np.argmin(distance))
    mesh = pieces[index].mesh
    node = int(np.argmin(np.linalg.norm(mesh.points - seed, axis=1)))
    return None if node in set(mesh.boundary_edges().ravel().tolist()) else index


def side_by_side(blanks: Sequence[PlyBlank], gap: float = 0.4) -> list[np.ndarray]:
    """Shifts ``(2,)`` that lay ``blanks`` (a ply's pieces) out one above the other across the
    warp (along +y), ``gap`` times the largest blank's size apart (room for a label below
    each), the first where it is."""
    if not blanks:
        return []
    size = max(float(np.ptp(b.trim[0], axis=0).max()) for b in blanks)
    shifts, top = [np.zeros(2)], float(blanks[0].trim[0][:, 1].max())
    for blank in blanks[1:]:
        low = float(blank.trim[0][:, 1].min())
        shifts.append(np.array([0.0, top + gap * size - low]))
        top = float(blank.trim[0][:, 1].max()) + shifts[-1][1]
    return shifts


def nest_plies(
    blanks: Sequence[PlyBlank], roll_width: float, *, time_limit: float = 10.0
) -> RollNest:
    """Every blank's extended outline on a roll of ``roll_width`` (mesh units), the warp along
    the roll; the yield is the net area over the roll used. A blank wider than the roll takes
    is refused with its name and width."""
    widest = usable_width(roll_width)
    for blank in blanks:
        if blank.width > widest:
            raise ValueError(
                f"ply {blank.label} is {blank.width:.6g} wide across its warp (with the trim "
                f"allowance); a roll_width of {roll_width:g} takes at most {widest:.6g}"
            )
    return nest_pieces(
        [b.trim[0] for b in blanks],
        roll_width,
        net_areas=[b.net_area for b in blanks],
        time_limit=time_limit,
    )
