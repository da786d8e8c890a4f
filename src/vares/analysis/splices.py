"""Splices: a ply cut into pieces along lines from its boundary to its boundary, each piece draped
(its pattern solved) on its own part of the mould.

A dart takes fabric out where a positively curved region holds too much of it; where the sheared
region is negatively curved (:mod:`vares.geometry.curvature`) a dart takes out what is missing
already, and its lips would have to overlap in the flat pattern. There the ply is **spliced**:
cut through, the pieces butted (or overlapped) on the mould, each with its own flat pattern. The
pieces drape separately, so none has to carry the shear the whole ply takes up over the curvature
between them.

:func:`solve_with_splices` solves the whole ply (the comparison), draws the splice lines onto the
mould (:func:`vares.geometry.drawn_lines.curves_on_surface`: the lines' points become nodes, their
ends go to the boundary), cuts it into pieces along them
(:func:`vares.geometry.cutting.cut_mesh`) and solves every piece with the same fabric and
settings. The largest shear of the spliced ply is the largest of its pieces'.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..geometry.cutting import CutMesh, LinesMeetError, cut_mesh
from ..geometry.drawn_lines import curves_on_surface, densified, point_spacing
from ..geometry.mesh import SurfaceMesh
from ..geometry.surface_lines import CuttingError, triangulated
from ..materials import Hyperelastic
from ..solver.api import solve
from ..solver.result import PatternResult
from ..structures.panels import Panel, split_panels
from .dart_lines import smoothed, to_segments

if TYPE_CHECKING:
    from .drape import PlyDrape
    from .drape_options import DrapeOptions

__all__ = [
    "SPLICE_SNAP",
    "SplicedPly",
    "drape_pieces",
    "solve_with_splices",
    "yarn_strain",
]

#: Where a splice line crosses an edge closer than this fraction of the edge's length to a node,
#: or passes a corner closer than this fraction of the cell's edges, it is moved onto the node
#: (:data:`vares.geometry.cutting.SNAP` for seams is 0.05): the cut then leaves no slivers,
#: whose linear triangles scatter the shear of a stiff-yarn fabric (on the shipped double dome
#: split along y = 0, one sliver of 0.25 mm at 0.05 showed 49.97° beside 29.2° around it).
SPLICE_SNAP = 0.4


def yarn_strain(result: PatternResult, nodal_mean: bool = False) -> np.ndarray | None:
    """Per cell of a pattern's mesh ``(m,)``: the larger of ``|warp stretch − 1|`` and ``|fill
    stretch − 1|`` on the mould (None for a law without yarns); with ``nodal_mean`` of the
    stretches averaged to the nodes and back (:func:`vares.analysis.dart_lines.smoothed`), which
    leaves out the cell-to-cell scatter of linear triangles with stiff yarns."""
    fields = result.fields
    if "warp_stretch" not in fields:
        return None
    warp, fill = np.asarray(fields["warp_stretch"]), np.asarray(fields["fill_stretch"])
    if nodal_mean:
        warp, fill = smoothed(result.mesh, warp), smoothed(result.mesh, fill)
    return np.maximum(np.abs(warp - 1.0), np.abs(fill - 1.0))


@dataclass(frozen=True)
class SplicedPly:
    """A ply before and after it was spliced.

    ``before``: the pattern of the whole ply; ``cut``: the mould cut along the splice lines
    (``cut.mesh``, ``cut.panel_ids``: the piece of every cell, ``cut.lines``: the lines' node
    chains); ``pieces``: the pieces (named ``piece-1`` …, in the order of ``cut.panel_ids``) and
    ``results`` their patterns; ``locking_angle`` in degrees; ``seconds``: the pieces' solves;
    ``nets``: the kinematic drape of every piece (:func:`drape_pieces`), or None;
    ``net_errors``: why a piece has no net (None where it has one); ``polylines``: the splice
    lines as drawn (:meth:`outline` follows them).
    """

    before: PatternResult
    cut: CutMesh
    pieces: list[Panel]
    results: list[PatternResult]
    locking_angle: float
    seconds: float
    nets: list[PlyDrape | None] | None = None
    net_errors: list[str | None] | None = None
    polylines: list[np.ndarray] | None = None

    @property
    def splice_lines(self) -> list[np.ndarray]:
        """The splice lines on the mould, ``(k, 3)`` each."""
        return [self.cut.mesh.points[chain] for chain in self.cut.lines]

    @property
    def converged(self) -> bool:
        """Whether every piece's pattern converged."""
        return all(r.converged for r in self.results)

    @property
    def max_shear_before(self) -> float:
        return float(np.nanmax(np.abs(self.before.fields["shear_angle"])))

    @property
    def max_shear_after(self) -> float:
        """The largest shear of any piece (degrees)."""
        return max(float(np.nanmax(np.abs(r.fields["shear_angle"]))) for r in self.results)

    @property
    def relieved(self) -> bool:
        """Whether every piece converged with its largest shear below the locking angle."""
        return bool(self.converged and self.max_shear_after < self.locking_angle)

    def outline(self, index: int) -> list[np.ndarray]:
        """The flat boundary rings ``(k, 2)`` of piece ``index`` (its mesh's boundary loops, in
        their order, in its pattern's frame), the points along a splice moved onto the splice
        line as drawn.

        The cut runs through nodes within :data:`SPLICE_SNAP` of a cell from the drawn line (no
        slivers), so the piece's edge along a splice zigzags round the line by up to 0.4 of an
        edge. Every boundary node on a splice is replaced by the flat image of its point on the
        drawn line: the closest point of the line, or at a splice's end on the mould's boundary
        the line's end, or where two splices cross the point where the drawn lines cross (the
        closest pair of their points). Each point is located in the piece's nearest cell and
        mapped with that cell's affine map from the mould to the pattern (beyond the cell, where
        the line passes outside the piece, the same map extended). The piece's mesh and pattern
        stay as solved; without :attr:`polylines` the rings are the mesh's loops."""
        from scipy.spatial import cKDTree

        from ..geometry.surface_points import FaceLocator, barycentric

        piece, result = self.pieces[index].mesh, self.results[index]
        flat = result.material_coordinates
        loops = piece.boundary_loops()
        rings = [flat[loop].copy() for loop in loops]
        if not self.polylines:
            return rings
        points = self.cut.mesh.points
        size = float(np.ptp(points, axis=0).max())
        on = cKDTree(np.vstack([points[chain] for chain in self.cut.lines]))
        ends = cKDTree(np.vstack([points[chain[[0, -1]]] for chain in self.cut.lines]))
        edge = 2.0 * point_spacing(piece)  # the mean edge
        curves = [densified(np.asarray(c, dtype=float), 0.05 * edge) for c in self.polylines]
        tips = np.vstack([c[[0, -1]] for c in curves])
        locate = FaceLocator(piece)
        triangles = piece.cells["triangle"]
        for ring, loop in zip(rings, loops, strict=True):
            at = piece.points[loop]
            for k in np.flatnonzero(on.query(at)[0] <= 1e-9 * size):
                end = bool(ends.query(at[k])[0] <= 1e-9 * size)
                target = _on_drawn(at[k], curves, tips, edge, end)
                if target is None:
                    continue
                face = int(locate.locate(target)[0][0])
                weights, _ = barycentric(target, piece.points[triangles[face]])
                ring[k] = weights @ flat[triangles[face]]
        return rings

    def joints(self, index: int) -> list[np.ndarray]:
        """Per boundary loop of piece ``index`` (in the order of :meth:`outline`'s rings) and
        per edge ``k`` of it (from the loop's point ``k`` to the next, the last back to the
        first): the index of the piece on the other side where the edge lies on a splice, else
        −1 (the mould's edge). The pieces keep the cut mesh's points, so an edge on a splice is
        an edge of the piece across it as well."""
        from scipy.spatial import cKDTree

        mesh = self.pieces[index].mesh
        loops = mesh.boundary_loops()
        others = [j for j in range(len(self.pieces)) if j != index]
        if not others:
            return [np.full(len(loop), -1) for loop in loops]
        middles, owners = [], []
        for j in others:
            other = self.pieces[j].mesh
            edges = other.boundary_edges()
            middles.append(other.points[edges].mean(axis=1))
            owners.append(np.full(len(edges), j))
        tree, owner = cKDTree(np.vstack(middles)), np.concatenate(owners)
        size = float(np.ptp(self.cut.mesh.points, axis=0).max())
        out = []
        for loop in loops:
            middle = 0.5 * (mesh.points[loop] + mesh.points[np.roll(loop, -1)])
            distance, nearest = tree.query(middle)
            out.append(np.where(distance <= 1e-9 * size, owner[nearest], -1))
        return out

    def cell_field(self, name: str) -> np.ndarray:
        """A per-cell field of the pieces' patterns on ``cut.mesh``'s cells ``(m, …)``."""
        first = np.asarray(self.results[0].fields[name])
        out = np.full((self.cut.mesh.num_cells, *first.shape[1:]), np.nan)
        for index, result in enumerate(self.results):
            out[self.cut.panel_ids == index] = np.asarray(result.fields[name])
        return out

    def summary(self) -> dict[str, Any]:
        """The numbers for a summary file: per piece its cells, area on the mould, largest shear,
        area at or beyond the locking angle, largest yarn strain of the cells and of the nodal
        means (:func:`yarn_strain`; where the law has yarns),
        Newton iterations and whether it converged, and its kinematic net's seed, largest shear
        and area share at or beyond the locking angle (with :attr:`nets`); the splice lines'
        lengths; the largest shear before and after."""
        pieces = []
        nets = self.nets or [None] * len(self.pieces)
        errors = self.net_errors or [None] * len(self.pieces)
        for piece, result, net, error in zip(self.pieces, self.results, nets, errors, strict=True):
            shear = np.abs(np.nan_to_num(result.fields["shear_angle"]))
            area = result.mesh.cell_areas()
            strain, mean = yarn_strain(result), yarn_strain(result, nodal_mean=True)
            pieces.append(
                {
                    "name": piece.name,
                    "cells": int(result.mesh.num_cells),
                    "area": float(area.sum()),
                    "max_shear": float(shear.max()),
                    "over_locking_fraction": float(
                        area[shear >= self.locking_angle].sum() / area.sum()
                    ),
                    "max_yarn_strain": None if strain is None else float(strain.max()),
                    "max_yarn_strain_nodal_mean": None if mean is None else float(mean.max()),
                    "iterations": int(result.iterations),
                    "converged": bool(result.converged),
                }
            )
            if net is not None:
                pieces[-1]["kinematic"] = {
                    "seed": [float(v) for v in net.seed],
                    "max_shear": float(net.producibility.max_shear),
                    "limit_fraction": float(net.producibility.fractions["limit"]),
                }
            elif error is not None:
                pieces[-1]["kinematic"] = {"error": error}
        return {
            "locking_angle": self.locking_angle,
            "max_shear_before": self.max_shear_before,
            "max_shear_after": self.max_shear_after,
            "relieved": self.relieved,
            "converged": self.converged,
            "splices": len(self.cut.lines),
            "splice_lengths": [
                float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) for p in self.splice_lines
            ],
            "pieces": pieces,
            "iterations_before": int(self.before.iterations),
            "seconds": self.seconds,
        }


def solve_with_splices(
    mesh: SurfaceMesh,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    locking_angle: float,
    polylines: Sequence[np.ndarray],
    snap: float = SPLICE_SNAP,
    before: PatternResult | None = None,
    **settings: Any,
) -> SplicedPly:
    """Splice the ply on ``mesh`` (the mould) along ``polylines`` (``(k, 3)`` each, on or near
    the mould, from its boundary to its boundary; e.g. a curves file's,
    :func:`vares.io.curves.read_curves`) and solve every piece (:func:`vares.solve` with
    ``material``, ``thickness`` and the keyword ``settings``, e.g. ``warp_direction``); the whole
    ply is solved first, for comparison (module docs), unless its pattern is given (``before``,
    of the same settings); ``snap``: :data:`SPLICE_SNAP`. Quads are split into triangles first.

    Raises :class:`~vares.geometry.surface_lines.CuttingError` when there are no lines or they
    do not cut the mould into pieces.
    """
    if not len(polylines):
        raise CuttingError("splices need at least one splice line")
    surface = triangulated(mesh)
    lines = [np.asarray(p, dtype=float) for p in polylines]
    cut = cut_along(surface, lines, snap)
    if cut.num_panels < 2:
        raise CuttingError(
            "the splice lines do not cut the mould into pieces: draw each from the boundary "
            "across the mould to the boundary"
        )
    if before is None:
        before = solve(surface, material, thickness, **settings)
    pieces = split_panels(
        cut.mesh, cut.panel_ids, {i: f"piece-{i + 1}" for i in range(cut.num_panels)}
    )
    clock = time.perf_counter()
    results = [solve(piece.mesh, material, thickness, **settings) for piece in pieces]
    seconds = time.perf_counter() - clock
    return SplicedPly(
        before, cut, pieces, results, float(locking_angle), seconds, polylines=list(lines)
    )


def _on_drawn(
    point: np.ndarray, curves: list[np.ndarray], tips: np.ndarray, edge: float, end: bool
) -> np.ndarray | None:
    """The point of the drawn ``curves`` (densified) that the cut's node at ``point`` stands
    for: its closest point; for a line's ``end`` the drawn line's end (within an ``edge`` of
    it) or, where two lines cross, the midpoint of their closest pair of points near it; None
    for an end that is neither."""
    if not end:
        return min((_closest_on(point, c) for c in curves), key=lambda q: q[1])[0]
    distance = np.linalg.norm(tips - point, axis=1)
    if distance.min() < edge:
        return tips[int(np.argmin(distance))]
    from scipy.spatial import cKDTree

    near = [c[np.linalg.norm(c - point, axis=1) < 3.0 * edge] for c in curves]
    near = [c for c in near if len(c)]
    best = None
    for i in range(len(near)):
        tree = cKDTree(near[i])
        for j in range(i + 1, len(near)):
            gap, index = tree.query(near[j])
            k = int(np.argmin(gap))
            if best is None or gap[k] < best[0]:
                best = (gap[k], 0.5 * (near[j][k] + near[i][index[k]]))
    return None if best is None else best[1]


def _closest_on(point: np.ndarray, curve: np.ndarray) -> tuple[np.ndarray, float]:
    """The closest point of the polyline ``curve`` ``(k, 3)`` to ``point`` and its distance."""
    distance, k, t = to_segments(point, curve[:-1], curve[1:])
    return curve[k] + t * (curve[k + 1] - curve[k]), distance


def cut_along(surface: SurfaceMesh, polylines: Sequence[np.ndarray], snap: float) -> CutMesh:
    """The triangle mesh ``surface`` cut along ``polylines`` (``(k, 3)`` each, from the boundary
    to the boundary): all at once where no two of them meet; else one after the other, each
    piece by piece (:func:`_piece_by_piece`), so that a line ends on the lines it crosses."""
    drawn, lines = curves_on_surface(surface, polylines, snap)
    try:
        return cut_mesh(drawn, lines, snap)
    except LinesMeetError:
        if len(polylines) < 2:
            raise
    return _piece_by_piece(surface, polylines, snap)


def _piece_by_piece(surface: SurfaceMesh, polylines: Sequence[np.ndarray], snap: float) -> CutMesh:
    """Lines that cross, cut one after the other: the points of each line (densified to half the
    mean edge length) go to the piece of the mould nearest to them, and each run of points over
    one piece cuts that piece, from its boundary to its boundary (the run with a point of the
    neighbouring pieces at either end: the line's end goes onto the splice it crosses there).
    The pieces are then welded into one cut mesh, its lines the splices piece by piece."""
    from scipy.spatial import cKDTree

    from ..geometry.drawn_lines import closest_points
    from ..geometry.surface_lines import min_angles
    from ..geometry.weld import weld

    spacing = point_spacing(surface)
    pieces, splices = [surface], []
    for number, polyline in enumerate(polylines, start=1):
        samples = densified(polyline, spacing)
        cursor = 0
        while cursor < len(samples):
            distance = np.array([closest_points(p, samples)[2] for p in pieces])
            owner = np.argmin(distance, axis=0)
            runs = _runs(owner, cursor)
            for piece, first, last in runs:
                portion = samples[max(first - 1, 0) : last + 2]
                try:
                    drawn, line = curves_on_surface(pieces[piece], [portion], snap)
                    cut = cut_mesh(drawn, line, snap)
                except CuttingError as exc:
                    if _along(samples[first : last + 1], splices, spacing):
                        raise CuttingError(
                            f"splice line {number} runs along a splice cut before it: draw "
                            "every splice once, each across the mould"
                        ) from None
                    raise CuttingError(f"splice line {number}: {exc}") from None
                cursor = last + 1
                if cut.num_panels >= 2:  # (a run along a splice cuts nothing off)
                    parts = split_panels(cut.mesh, cut.panel_ids)
                    pieces[piece : piece + 1] = [part.mesh for part in parts]
                    splices.append(cut.mesh.points[cut.lines[0]])
                    break  # the pieces changed: their points again
            else:
                break
    welded = weld(pieces)
    panel_ids = np.concatenate(
        [np.full(r["triangle"][1] - r["triangle"][0], k) for k, r in enumerate(welded.cell_ranges)]
    )
    tree = cKDTree(welded.mesh.points)
    chains = [tree.query(points)[1] for points in splices]
    seam_edges = np.unique(
        np.sort(np.vstack([np.column_stack([c[:-1], c[1:]]) for c in chains]), axis=1), axis=0
    )
    cells = welded.mesh.cells["triangle"]
    return CutMesh(
        welded.mesh,
        panel_ids,
        chains,
        seam_edges,
        float(min_angles(welded.mesh.points, cells).min()),
        float(min_angles(surface.points, surface.cells["triangle"]).min()),
    )


def _along(points: np.ndarray, splices: list[np.ndarray], spacing: float) -> bool:
    """Whether most of ``points`` (``spacing`` apart) lie within ``spacing`` of the ``splices``
    cut so far (drawn through nodes, a splice runs up to :data:`SPLICE_SNAP` of an edge from its
    curve): a line drawn along one. Asked only of a part of a line that could not be cut."""
    if not splices:
        return False
    from scipy.spatial import cKDTree

    near = cKDTree(np.vstack([densified(s, 0.25 * spacing) for s in splices]))
    distance, _ = near.query(points)
    return bool(np.median(distance) < spacing)


def _runs(owner: np.ndarray, start: int) -> list[tuple[int, int, int]]:
    """From ``start`` on, the runs of consecutive points of one owner with at least two points:
    ``(owner, first, last)``."""
    out, first = [], start
    for k in range(start + 1, len(owner) + 1):
        if k == len(owner) or owner[k] != owner[first]:
            if k - first >= 2:
                out.append((int(owner[first]), first, k - 1))
            first = k
    return out


def drape_pieces(
    spliced: SplicedPly, options: DrapeOptions, warp_direction: Sequence[float]
) -> SplicedPly:
    """``spliced`` with the kinematic drape of every piece (:func:`vares.analysis.drape.drape_ply`
    with ``options``, the warp ``warp_direction`` unless the options name one, each piece from
    its own node nearest its nodes' centroid): the industry's reference beside the pieces'
    patterns. A piece whose net cannot be made (a seed where the warp runs along the normal)
    gets None and the reason (:attr:`SplicedPly.net_errors`): the net is beside the pattern."""
    from ..geometry.drape_net import DrapeError
    from .drape import drape_ply

    own = options.replace(seed=None)
    warp = tuple(float(v) for v in warp_direction)
    nets: list[PlyDrape | None] = []
    errors: list[str | None] = []
    for piece in spliced.pieces:
        try:
            nets.append(drape_ply(piece.mesh, own, warp_direction=warp))
            errors.append(None)
        except DrapeError as exc:
            nets.append(None)
            errors.append(f"no net: {exc}")
    return dataclasses.replace(spliced, nets=nets, net_errors=errors)
