"""Where darts go on a ply's mould (:mod:`vares.analysis.darts` solves the ply with them open):
along the yarns' bisector from the boundary into each region at or beyond the locking angle
(:func:`place_darts`), along the mould's fall lines through the positively curved patch beside a
region (:func:`fall_line_darts`), or through a user's polylines (:func:`darts_from_polylines`);
the rules are those of :mod:`vares.analysis.darts`' module docs."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..geometry.curvature import FLAT, cell_gauss_curvature
from ..geometry.drawn_lines import closest_points
from ..geometry.face_walk import node_normals
from ..geometry.mesh import SurfaceMesh
from ..geometry.slits import walk_line
from ..geometry.surface_lines import CuttingError, SurfaceLine
from ..geometry.surface_points import face_neighbours

__all__ = [
    "DRAWN",
    "darts_from_polylines",
    "erected_yarns",
    "fall_line_darts",
    "place_darts",
    "smoothed",
    "to_segments",
]

#: Cells at or beyond the locking angle belong to one region when cells whose smoothed shear is
#: at least this fraction of it join them.
JOIN_FRACTION = 0.9
#: A given dart line is followed past the nearest of its next this many points (module docs).
PROGRESS_WINDOW = 64
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
