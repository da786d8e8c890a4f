"""Darts: cuts from a ply's boundary into the region whose shear exceeds the locking angle, and
the pattern solved again with the darts open (DESIGN.md §8).

**Where.** The cells at or beyond the locking angle form regions (neighbours across edges),
joined through the cells whose :func:`smoothed` shear is within :data:`JOIN_FRACTION` of it: the
cell-to-cell scatter of linear triangles with stiff yarns does not split a region. A region that
reaches the boundary gets one dart from the boundary side nearest the region's shear-weighted
centre there (weights: the shear beyond the locking angle); a region inside the surface, from
the boundary side nearest its most sheared cell.

**Where the bisector leads nowhere** (a region inside the ply, whose cells between it and the
boundary are sheared less than the tip angle: the corners of a box-shaped part), or its darts
leave the shear at or beyond the locking angle, every region gets a dart along a **fall line**
(:func:`fall_line_darts`), in rounds of their own: from the boundary up the slope of the
mould to the positively curved patch beside the region (the excess fabric a dart takes out lies
there; the region itself is often negatively curved, at the foot of a corner), and through it.
The slope is that of the mould's draw direction, the mean of its cells' normals (the direction
a punch closes in); the line goes straight on where the mould is flat (a flange) and where it
would turn by more than :data:`FALL_TURN` from one cell to the next. Its tip is where the
smoothed shear is below the tip angle beyond the positively curved patch.

**Which way.** Sheared yarns at an angle ``θ < 90°`` lengthen the bisector of their acute angle
(``2 cos(θ/2)``) and shorten the other diagonal (``2 sin(θ/2)``): the fabric is squeezed across
the bisector. A cut along the bisector opens against that squeeze, and relieves the most shear.
The dart follows the bisector of the erected yarns (``F Φ₁``, ``F Φ₂`` of the pattern) from cell
to cell (:func:`vares.geometry.slits.walk_line`) until the smoothed shear falls below the
dart's **tip angle**, or to ``max_length``. On a sphere, with the warp along a symmetry plane, the
bisector on the 45° meridians is the meridian itself.

**How far.** :func:`solve_with_darts` solves the pattern, places the darts with the tip angle
``dart_tip × locking angle``, opens them (:func:`vares.geometry.slits.open_slits`: both lips
free boundary, joined at the tip) and solves again, started from the first pattern; while the
largest shear is still at or beyond the locking angle it lengthens the darts (the tip angle
lowered by ``dart_step × locking angle``) for at most ``dart_rounds`` rounds
(:class:`~vares.analysis.dart_options.DartOptions`). Where the bisector's darts leave it there,
the fall lines' darts are solved in rounds as well; the round kept is the first below the
locking angle, else the converged one with the least largest shear, of either rule. Dart lines
a user gives (polylines near the mould, :func:`darts_from_polylines`) are opened as they are,
once.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..geometry.curvature import FLAT, cell_gauss_curvature, curvature_sign_shares
from ..geometry.drawn_lines import closest_points
from ..geometry.face_walk import node_normals
from ..geometry.mesh import SurfaceMesh
from ..geometry.slits import SlitMesh, open_slits, walk_line
from ..geometry.surface_lines import CuttingError, SurfaceLine, triangulated
from ..geometry.surface_points import FaceLocator, face_neighbours
from ..materials import Hyperelastic
from ..options import split_settings, takes_options
from ..solver.api import solve
from ..solver.result import PatternResult
from .dart_options import DartOptions

#: Cells at or beyond the locking angle belong to one region when cells whose smoothed shear is
#: at least this fraction of it join them.
JOIN_FRACTION = 0.9
#: A given dart line is followed past the nearest of its next this many points (module docs).
PROGRESS_WINDOW = 64
#: Darts that leave the shear at or beyond the locking angle where more than this share of the
#: area beyond it is negatively curved are answered with the advice to splice the ply.
NEGATIVE_SHARE = 0.5
#: A fall line goes straight on across a cell whose slope (the sine of its angle to the plane
#: normal to the draw direction) is below this, and where its slope would turn it by more than
#: FALL_TURN degrees from its last step (a valley between two cells of a coarse mesh turns the
#: fall direction back and forth across their common edge).
FLAT_SLOPE = 0.05
FALL_TURN = 45.0
#: The positively curved patch beside a region is looked for within the region's extent from its
#: most sheared cell, and at least this many mean edge lengths from it.
PATCH_EDGES = 6.0
#: A fall line that ends further than this many mean edge lengths from the boundary (it turned
#: back on itself, or ran into a pit) makes no dart.
MOUTH_EDGES = 3.0
#: A mould has a draw direction (for fall lines) where its cells' area vectors add up to more
#: than this fraction of its area (a closed surface's add up to nothing).
DRAWN = 0.2
#: The rules of automatic darts, in the order they are tried (module docs).
RULES = ("bisector", "fall line")

__all__ = [
    "NEGATIVE_SHARE",
    "RULES",
    "DartOptions",
    "DartRound",
    "DartedPattern",
    "darts_from_polylines",
    "erected_yarns",
    "fall_line_darts",
    "over_locking_curvature",
    "place_darts",
    "smoothed",
    "solve_with_darts",
    "to_segments",
]


def over_locking_curvature(result: PatternResult, locking_angle: float) -> dict[str, float]:
    """The shares of the area at or beyond ``locking_angle`` of a pattern that lie on positively
    curved, negatively curved and flat parts of its mould
    (:func:`vares.geometry.curvature.curvature_sign_shares`): darts relieve the first kind, not
    the second (:mod:`vares.analysis.splices`)."""
    shear = np.abs(np.nan_to_num(np.asarray(result.fields["shear_angle"], dtype=float)))
    return curvature_sign_shares(result.mesh, shear >= locking_angle)


def erected_yarns(
    mesh: SurfaceMesh, coordinates: np.ndarray, warp: np.ndarray, fill: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The erected warp and fill ``(m, 3)`` (unit) of every triangle of ``mesh`` for the pattern
    ``coordinates`` ``(n, 2)`` whose yarns run along ``warp`` and ``fill`` ``(2,)``: ``F Φ`` with
    the triangle's constant deformation gradient ``F = [x₁ − x₀, x₂ − x₀] [X₁ − X₀, X₂ − X₀]⁻¹``."""
    triangles = mesh.cells["triangle"]
    x, X = mesh.points[triangles], np.asarray(coordinates, dtype=float)[triangles]
    spatial = np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]], axis=-1)  # (m, 3, 2)
    material = np.stack([X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]], axis=-1)  # (m, 2, 2)
    F = spatial @ np.linalg.inv(material)
    out = []
    for phi in (np.asarray(warp, dtype=float), np.asarray(fill, dtype=float)):
        v = F @ phi
        out.append(v / np.linalg.norm(v, axis=1)[:, None])
    return out[0], out[1]


def place_darts(
    mesh: SurfaceMesh,
    shear_angle: np.ndarray,
    warp: np.ndarray,
    fill: np.ndarray,
    locking_angle: float,
    tip_angle: float,
    max_length: float | None = None,
) -> list[SurfaceLine]:
    """Dart lines on the triangle mesh ``mesh`` for the per-cell ``shear_angle`` ``(m,)``
    (degrees, NaN where unknown) and erected yarns ``warp``, ``fill`` ``(m, 3)`` (module docs):
    one per region at or beyond ``locking_angle``, from the boundary along the bisector of the
    yarns' acute angle until the :func:`smoothed` shear is below ``tip_angle`` (or
    ``max_length``, default half the mesh's bounding-box diagonal). Regions are taken by their
    largest shear, largest first; cells within :data:`JOIN_FRACTION` of the locking angle
    (smoothed) join them, and a dart that would come within two mean edge lengths of an earlier
    one is left out (that one relieves its region)."""
    triangles = mesh.cells["triangle"]
    points = mesh.points
    found = _Regions(mesh, shear_angle, locking_angle, max_length)
    if not found.order:
        return []
    magnitude, smooth = found.magnitude, found.smooth
    acute = np.einsum("ij,ij->i", warp, fill) >= 0
    bisector = warp + np.where(acute[:, None], fill, -fill)
    bisector /= np.linalg.norm(bisector, axis=1)[:, None]
    sides = found.sides  # (face, corner opposite the boundary side)
    mids = 0.5 * (found.side_ends[0] + found.side_ends[1])
    lines: list[SurfaceLine] = []
    for region in found.order:
        cells = np.flatnonzero(found.regions == region)
        at_boundary = np.isin(sides[:, 0], cells)
        if at_boundary.any():
            weights = np.maximum(magnitude[sides[at_boundary, 0]] - locking_angle, 0.0) + 1e-9
            centre = weights @ mids[at_boundary] / weights.sum()
        else:
            centre = points[triangles[cells[np.argmax(magnitude[cells])]]].mean(axis=0)
        side = int(np.argmin(np.linalg.norm(mids - centre, axis=1)))
        face, corner = (int(v) for v in sides[side])
        start = np.full(3, 0.5)
        start[corner] = 0.0
        inward = points[triangles[face, corner]] - mids[side]

        def direction(cell: int, _: np.ndarray, last: np.ndarray | None, inward=inward):
            if smooth[cell] < tip_angle:
                return None
            d = bisector[cell]
            return d if d @ (inward if last is None else last) >= 0 else -d

        found.keep(walk_line(mesh, face, start, direction, found.max_length), lines)
    return lines


class _Regions:
    """The regions of a ply's cells at or beyond the locking angle (:func:`place_darts`), largest
    shear first (``order``), with what both rules of placing darts share: the shear's magnitude
    and its :func:`smoothed` field, the cells' neighbours, the boundary sides (``sides``: face,
    corner opposite; ``side_ends``: their end points), the mean edge length and the longest
    dart."""

    def __init__(
        self,
        mesh: SurfaceMesh,
        shear_angle: np.ndarray,
        locking_angle: float,
        max_length: float | None,
    ) -> None:
        triangles, points = mesh.cells["triangle"], mesh.points
        self.magnitude = np.abs(np.nan_to_num(np.asarray(shear_angle, dtype=float), nan=0.0))
        over = self.magnitude >= locking_angle
        self.order: list[int] = []
        if not over.any():
            return
        self.smooth = smoothed(mesh, self.magnitude)
        self.neighbours = face_neighbours(triangles)
        self.edge = float(np.linalg.norm(np.diff(points[mesh.edges()], axis=1), axis=2).mean())
        size = float(np.linalg.norm(np.ptp(points, axis=0)))
        self.max_length = 0.5 * size if max_length is None else max_length
        joined = over | (self.smooth >= JOIN_FRACTION * locking_angle)
        self.regions = _regions(joined, self.neighbours)
        self.sides = np.argwhere(self.neighbours < 0)
        self.side_ends = tuple(
            points[triangles[self.sides[:, 0], (self.sides[:, 1] + k) % 3]] for k in (1, 2)
        )
        magnitude, regions = self.magnitude, self.regions
        largest = {r: magnitude[regions == r].max() for r in set(regions[over].tolist())}
        self.order = sorted(largest, key=lambda r: -largest[r])

    def keep(self, line: SurfaceLine, lines: list[SurfaceLine]) -> None:
        """Add ``line`` to ``lines`` unless it is shorter than two crossings or comes within two
        mean edge lengths of one of them (that one relieves its region)."""
        near = [_distance(line.points, other.points) < 2.0 * self.edge for other in lines]
        if len(line.points) >= 3 and not any(near):
            lines.append(line)


def fall_line_darts(
    mesh: SurfaceMesh,
    shear_angle: np.ndarray,
    locking_angle: float,
    tip_angle: float,
    max_length: float | None = None,
) -> list[SurfaceLine]:
    """Dart lines along fall lines of the mould (module docs) on the triangle mesh ``mesh`` for
    the per-cell ``shear_angle`` ``(m,)`` (degrees): one per region at or beyond
    ``locking_angle`` (the regions of :func:`place_darts`) that has a positively curved patch
    within its extent (at least :data:`PATCH_EDGES` mean edges) from its most sheared cell. The
    line runs from the boundary up the fall line through the patch's cell nearest its centre
    (its cells weighted by their curvature times area) and on until the :func:`smoothed` shear
    is below ``tip_angle`` beyond the patch (a fall line not reaching the boundary makes no
    dart). None where the mould has no draw direction (its cells' area vectors add up to less
    than :data:`DRAWN` of its area: a nearly closed surface)."""
    triangles = mesh.cells["triangle"]
    points = mesh.points
    found = _Regions(mesh, shear_angle, locking_angle, max_length)
    if not found.order:
        return []
    vectors = mesh.area_vectors()  # the cells' areas along their normals
    area = np.linalg.norm(vectors, axis=1)
    up = vectors.sum(axis=0)
    if not np.linalg.norm(up) > DRAWN * area.sum():
        return []
    up /= np.linalg.norm(up)
    normals = node_normals(mesh)[triangles].mean(axis=1)  # smooth, not the facets'
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    slope = up - (normals @ up)[:, None] * normals  # uphill, of length the slope's sine
    steep = np.linalg.norm(slope, axis=1) > FLAT_SLOPE
    curvature = np.nan_to_num(cell_gauss_curvature(mesh), nan=0.0)
    positive = (curvature * area > FLAT) & steep
    centres = points[triangles].mean(axis=1)
    smooth, turn = found.smooth, np.cos(np.radians(FALL_TURN))

    def fall(sense: float, patch: np.ndarray | None = None):
        """The walk's direction: down (``sense`` −1) or up (+1, its tip past ``patch``)."""

        def direction(cell: int, _: np.ndarray, last: np.ndarray | None):
            beyond = patch is not None and not patch[cell] and smooth[cell] < tip_angle
            if beyond and last is not None:
                return None
            step = sense * slope[cell]
            if last is None:
                return step if steep[cell] else None
            straight = step @ last < turn * np.linalg.norm(step) * np.linalg.norm(last)
            return last if not steep[cell] or straight else step

        return direction

    third = np.full(3, 1.0 / 3.0)
    polylines = []
    for region in found.order:
        cells = np.flatnonzero(found.regions == region)
        peak = centres[cells[np.argmax(found.magnitude[cells])]]
        extent = max(
            float(np.linalg.norm(centres[cells] - peak, axis=1).max()), PATCH_EDGES * found.edge
        )
        near = np.flatnonzero(np.linalg.norm(centres - peak, axis=1) <= extent)
        weight = np.where(positive[near], curvature[near] * area[near], 0.0)
        if not weight.sum() > 0:
            continue
        centre = weight @ centres[near] / weight.sum()
        patch = near[weight > 0]
        seed = int(patch[np.argmin(np.linalg.norm(centres[patch] - centre, axis=1))])
        down = walk_line(mesh, seed, third, fall(-1.0), 2.0 * found.max_length)
        if not len(down.points):
            continue
        distance, side, t = to_segments(down.points[-1], *found.side_ends)
        if distance > MOUTH_EDGES * found.edge:
            continue  # the fall line does not reach the boundary
        a, b = found.side_ends[0][side], found.side_ends[1][side]
        # on through every positively curved cell: the patch of a box's corner reaches past
        # the region's extent to the punch face (held to the region's extent, the square cups'
        # darts stopped short: 39–65°, three not kept, against 30–39°); over a dome, on over
        # its top
        tip = walk_line(mesh, seed, third, fall(1.0, positive), found.max_length)
        # through the middles of the walks' steps, inside their cells (a point on an edge is in
        # either cell by round-off, and the dart's walk through it could stop or turn there)
        path = np.vstack([down.points[::-1], centres[seed], tip.points])
        middles = 0.5 * (path[1:] + path[:-1])
        polylines.append(
            np.vstack(
                [
                    a + t * (b - a),
                    middles[: len(down.points)],
                    centres[seed],
                    middles[len(down.points) :],
                ]
            )
        )
    lines: list[SurfaceLine] = []
    for polyline in polylines:
        try:
            (line,) = darts_from_polylines(mesh, [polyline])
        except CuttingError:  # (a line a dart cannot follow is no dart)
            continue
        found.keep(line, lines)
    return lines


def smoothed(mesh: SurfaceMesh, values: np.ndarray) -> np.ndarray:
    """A per-cell field ``(m,)`` averaged to the nodes (area-weighted) and back to the cells
    (mean of their nodes): the shear of linear triangles with stiff yarns scatters from cell to
    cell, and a dart's regions and tip follow the trend, not one cell."""
    triangles = mesh.cells["triangle"]
    areas = mesh.cell_areas()
    total = np.bincount(triangles.ravel(), np.repeat(areas * values, 3), mesh.num_points)
    weight = np.bincount(triangles.ravel(), np.repeat(areas, 3), mesh.num_points)
    return (total / np.maximum(weight, 1e-300))[triangles].mean(axis=1)


def _distance(a: np.ndarray, b: np.ndarray) -> float:
    """The least distance between the points of two polylines ``(k, 3)``."""
    return float(np.min(np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)))


def _regions(over: np.ndarray, neighbours: np.ndarray) -> np.ndarray:
    """Connected regions of the cells ``over`` (neighbours across edges); −1 elsewhere."""
    faces = np.repeat(np.arange(len(neighbours)), 3)
    other = neighbours.ravel()
    keep = (other >= 0) & over[faces] & over[np.maximum(other, 0)]
    graph = coo_matrix(
        (np.ones(keep.sum()), (faces[keep], other[keep])), shape=(len(over), len(over))
    )
    _, labels = connected_components(graph, directed=False)
    return np.where(over, labels, -1)


def darts_from_polylines(mesh: SurfaceMesh, polylines: Sequence[np.ndarray]) -> list[SurfaceLine]:
    """Dart lines through the user's ``polylines`` ``(k, 3)`` (points on or near the mould): each
    point is moved to the closest point of the surface, and the line walks from point to point
    straight in every cell it crosses. The end nearer the boundary is the mouth (moved onto the
    boundary); the line ends inside the surface, in the cell of the other end."""
    triangles = mesh.cells["triangle"]
    points = mesh.points
    neighbours = face_neighbours(triangles)
    sides = np.argwhere(neighbours < 0)
    a = points[triangles[sides[:, 0], (sides[:, 1] + 1) % 3]]
    b = points[triangles[sides[:, 0], (sides[:, 1] + 2) % 3]]
    size = float(np.linalg.norm(np.ptp(points, axis=0)))
    lines = []
    for index, polyline in enumerate(polylines, start=1):
        polyline = np.asarray(polyline, dtype=float).reshape(-1, 3)
        if len(polyline) < 2:
            raise CuttingError(f"dart line {index} needs two points or more")
        faces, bary, distance = closest_points(mesh, polyline)
        if distance.max() > 0.05 * size:
            raise CuttingError(
                f"dart line {index} lies up to {distance.max():.4g} from the mould: draw it on it"
            )
        on_surface = np.einsum("kc,kcd->kd", bary, points[triangles[faces]])
        gaps = [to_segments(p, a, b)[0] for p in (on_surface[0], on_surface[-1])]
        if gaps[1] < gaps[0]:
            on_surface, faces = on_surface[::-1], faces[::-1]
        _, side, t = to_segments(on_surface[0], a, b)
        face, corner = (int(v) for v in sides[side])
        start = np.zeros(3)
        start[(corner + 1) % 3], start[(corner + 2) % 3] = 1.0 - t, t
        targets = list(zip(faces[1:].tolist(), on_surface[1:], strict=True))

        def direction(cell: int, here: np.ndarray, _: np.ndarray | None, targets=targets):
            if targets:  # progress: past the nearest of the next points (a walk through a node
                # skips the cells around it, and a point left in one would turn the walk back)
                ahead = np.array([p for _, p in targets[:PROGRESS_WINDOW]])
                del targets[: int(np.argmin(np.linalg.norm(ahead - here, axis=1)))]
            while targets and (targets[0][0] == cell or np.allclose(targets[0][1], here)):
                targets.pop(0)
            return None if not targets else targets[0][1] - here

        length = float(np.linalg.norm(np.diff(on_surface, axis=0), axis=1).sum())
        line = walk_line(mesh, face, start, direction, 1.5 * length + size * 1e-9)
        if len(line.points) < 2:
            raise CuttingError(f"dart line {index} is shorter than a cell of the mould")
        lines.append(line)
    return lines


def to_segments(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[float, int, float]:
    """The distance from ``point`` to the nearest of the segments ``a``–``b`` ``(s, 3)``, its
    index and the fraction along it (a segment of zero length: its point)."""
    d = b - a
    length = np.einsum("ij,ij->i", d, d)
    t = np.clip(np.einsum("ij,ij->i", point - a, d) / np.where(length > 0, length, 1.0), 0.0, 1.0)
    distance = np.linalg.norm(a + t[:, None] * d - point, axis=1)
    k = int(np.argmin(distance))
    return float(distance[k]), k, float(t[k])


@dataclass(frozen=True)
class DartRound:
    """One solve with darts: the tip angle (degrees; None for given lines), the darts' lengths
    (mesh units), the largest shear after (degrees), Newton iterations, seconds, converged, and
    the rule that placed the darts (:data:`RULES`: ``"bisector"``, ``"fall line"``, or
    ``"given"``)."""

    tip_angle: float | None
    lengths: list[float]
    max_shear: float
    iterations: int
    seconds: float
    converged: bool
    rule: str = "bisector"


@dataclass(frozen=True)
class DartedPattern:
    """A pattern before and after its darts were opened.

    ``before``: the pattern of the mesh without darts; ``after``: of ``slits.mesh`` with the
    darts of the round ``chosen`` open (None when no dart was needed or placed): the first
    round below the locking angle, else the converged one with the least largest shear;
    ``slits``: the opened mesh, its lips and the dart lines ``(k, 3)`` on the mould; ``rounds``:
    every solve with darts; ``locking_angle`` in degrees.
    """

    before: PatternResult
    after: PatternResult | None
    slits: SlitMesh | None
    locking_angle: float
    rounds: list[DartRound] = field(default_factory=list)
    chosen: int = -1

    @property
    def dart_lines(self) -> list[np.ndarray]:
        """The dart lines on the mould, mouth first, ``(k, 3)`` each."""
        return [] if self.slits is None else self.slits.lines

    @property
    def max_shear_before(self) -> float:
        return float(np.nanmax(np.abs(self.before.fields["shear_angle"])))

    @property
    def max_shear_after(self) -> float | None:
        return None if self.after is None else self.rounds[self.chosen].max_shear

    @property
    def final(self) -> PatternResult:
        """The pattern with the darts open, or without darts when none was opened."""
        return self.before if self.after is None else self.after

    @property
    def kept(self) -> bool:
        """Whether the ply is cut with the darts: some were opened, the solve with them
        converged, and they lower its largest shear (darts that leave it as high or higher are
        reported, not cut)."""
        if self.after is None or not self.after.converged:
            return False
        return bool(self.max_shear_after < self.max_shear_before)

    @property
    def relieved(self) -> bool:
        """Whether the largest shear ends below the locking angle (with or without darts)."""
        shear = self.max_shear_before if self.after is None else self.max_shear_after
        return bool(self.final.converged and shear < self.locking_angle)

    def dart_pattern_lines(self) -> list[np.ndarray]:
        """Both lips of every dart in the final pattern ``(k, 2)`` each: mouth → tip → mouth."""
        if self.after is None or self.slits is None:
            return []
        X = self.after.material_coordinates
        return [np.vstack([X[a], X[b][::-1][1:]]) for a, b in self.slits.lips]

    def summary(self) -> dict[str, Any]:
        """The numbers for a summary file."""
        gaps = [] if self.after is None else self.slits.lip_gaps(self.after.material_coordinates)
        return {
            "locking_angle": self.locking_angle,
            "max_shear_before": self.max_shear_before,
            "max_shear_after": self.max_shear_after,
            "relieved": self.relieved,
            "kept": self.kept,
            "darts": len(self.dart_lines),
            "dart_lengths": [
                float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) for p in self.dart_lines
            ],
            "mouth_openings": [float(g[0]) for g in gaps],
            "iterations_before": self.before.iterations,
            "seconds_before": self.before.elapsed,
            "rounds": [vars(r) for r in self.rounds],
            "chosen_round": None if self.after is None else self.chosen % len(self.rounds),
            "chosen_rule": None if self.after is None else self.rounds[self.chosen].rule,
            "over_locking_curvature": self.over_locking_curvature(),
        }

    def over_locking_curvature(self) -> dict[str, float] | None:
        """The shares of the area at or beyond the locking angle in the pattern without darts
        that lie on positively curved, negatively curved and flat parts of the mould (None when
        there is none): darts relieve the first kind, not the second
        (:mod:`vares.analysis.splices`)."""
        if not self.max_shear_before >= self.locking_angle:
            return None
        return over_locking_curvature(self.before, self.locking_angle)

    @property
    def needs_splices(self) -> bool:
        """Whether the darts left the shear at or beyond the locking angle where most of the
        area beyond it is negatively curved (more than :data:`NEGATIVE_SHARE`)."""
        shares = self.over_locking_curvature()
        return bool(
            not self.relieved and shares is not None and shares["negative"] > NEGATIVE_SHARE
        )


@takes_options(DartOptions)
def solve_with_darts(
    mesh: SurfaceMesh,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    locking_angle: float,
    polylines: Sequence[np.ndarray] | None = None,
    options: DartOptions | None = None,
    **settings: Any,
) -> DartedPattern:
    """Solve the pattern of ``mesh`` (:func:`vares.solve` with ``material`` and ``thickness``),
    place darts where its shear reaches ``locking_angle`` (degrees) with ``darts="auto"``, or
    open the dart lines ``polylines`` (``(k, 3)`` each, on or near the mould; e.g. a curves
    file's, :func:`vares.io.curves.read_curves`), and solve again with the darts open, started
    from the first pattern (module docs). Quads are split into triangles first.

    ``options``: a :class:`DartOptions` to start from; keyword ``settings`` that are dart
    options (below) change it, the others go to :func:`vares.solve` (e.g. ``warp_direction``).
    """
    dart_keys = DartOptions.specs()
    (options,) = split_settings(
        {k: v for k, v in settings.items() if k in dart_keys}, [options or DartOptions()]
    )
    solve_settings = {k: v for k, v in settings.items() if k not in dart_keys}
    if options.dart_lines is not None and polylines is None:
        raise ValueError("dart_lines names a file: pass its lines as polylines (read_curves)")
    if options.splice_lines is not None:
        raise ValueError("splice_lines are for solve_with_splices (vares.analysis.splices)")
    mesh = triangulated(mesh)
    given = None if polylines is None else darts_from_polylines(mesh, polylines)  # refused early
    before = solve(mesh, material, thickness, **solve_settings)
    result = DartedPattern(before, None, None, locking_angle)
    if not before.converged or (polylines is None and options.darts == "none"):
        return result
    fibres = before.fibres
    warp, fill = erected_yarns(mesh, before.material_coordinates, fibres.warp, fibres.fill)
    shear = before.fields["shear_angle"]
    plans: list[tuple[float | None, str, list[SurfaceLine] | None]]
    if given is not None:
        plans = [(None, "given", given)]
    else:
        if not np.nanmax(np.abs(shear)) >= locking_angle:
            return result
        fractions = [options.dart_tip - r * options.dart_step for r in range(options.dart_rounds)]
        tips = [max(f, 0.0) * locking_angle for f in fractions]
        plans = [(tip, rule, None) for rule in RULES for tip in tips]
    locator = FaceLocator(mesh)
    done: list[DartRound] = []
    best: tuple[float, PatternResult, SlitMesh, int] | None = None
    finished: set[str] = set()  # rules whose darts grow no longer
    for tip, rule, lines in plans:
        if rule in finished:
            continue
        if lines is None and rule == "bisector":
            lines = place_darts(
                mesh, shear, warp, fill, locking_angle, tip, options.dart_max_length
            )
        elif lines is None:
            lines = fall_line_darts(mesh, shear, locking_angle, tip, options.dart_max_length)
        lengths = [line.length for line in lines]
        previous = next((r.lengths for r in reversed(done) if r.rule == rule), [])
        if not lines or (len(previous) == len(lengths) and np.allclose(lengths, previous)):
            finished.add(rule)  # none, or no longer than the last round's: nothing new to solve
            continue
        slits = open_slits(mesh, lines)
        start = _carried(locator, mesh, before.material_coordinates, slits.mesh.points)
        clock = time.perf_counter()
        after = solve(slits.mesh, material, thickness, **{**solve_settings, "initial_guess": start})
        seconds = time.perf_counter() - clock
        largest = float(np.nanmax(np.abs(after.fields["shear_angle"])))
        done.append(
            DartRound(tip, lengths, largest, after.iterations, seconds, after.converged, rule)
        )
        rank = largest if after.converged else np.inf
        if best is None or rank < best[0]:
            best = (rank, after, slits, len(done) - 1)
        if after.converged and largest < locking_angle:
            break
    if best is None:
        return DartedPattern(before, None, None, locking_angle, done)
    return DartedPattern(before, best[1], best[2], locking_angle, done, best[3])


def _carried(
    locator: FaceLocator, mesh: SurfaceMesh, coordinates: np.ndarray, points: np.ndarray
) -> np.ndarray:
    """The pattern ``coordinates`` of ``mesh`` read at ``points`` ``(k, 3)`` on it (linear in
    the cell each lies in): the start of the solve with the darts open (their lips together)."""
    faces, weights, _ = locator.locate(points)
    return np.einsum("kc,kcd->kd", weights, coordinates[mesh.cells["triangle"][faces]])
