"""Cutting a triangle mesh along lines on it, so that panel boundaries follow the lines.

Every cell a line crosses is split along the line: the points where lines cross an edge become
nodes (shared by the cells on both sides of that edge), each crossed triangle becomes the convex
polygons the lines cut it into, and each polygon is triangulated by the triangulation that
maximises its smallest angle (dynamic programming over its diagonals). The new cells lie in the
planes of the cells they come from, so the cut surface is the same surface: same shape, same
area (to round-off). A crossing within ``snap`` × the edge length of a node is moved onto the
node, which avoids slivers; the smallest angle of the result is reported.

The cells are then grouped into panels: the connected regions left when the mesh is cut along
the lines (cells are neighbours across every edge that is no part of a line).
"""

from __future__ import annotations

import itertools
import math
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .mesh import SurfaceMesh
from .surface_lines import CuttingError, SurfaceLine, check_triangles, mesh_edges, min_angles

__all__ = [
    "CutMesh",
    "LinesMeetError",
    "cut_mesh",
    "panel_regions",
]

#: Crossings closer than this fraction of the edge length to a node are moved onto the node, and
#: so is a line that passes a cell's corner closer than this fraction of the cell's edges.
SNAP = 0.05


class LinesMeetError(CuttingError):
    """Two cutting lines cross or touch (after their crossings near nodes were moved onto them)."""


@dataclass(frozen=True)
class CutMesh:
    """A mesh cut along lines.

    ``mesh`` is the cut surface (triangles; the input's nodes first, then the new ones),
    ``panel_ids`` the panel of every cell ``(m,)`` (0 … panels − 1), ``lines`` the node chain of
    every line in the new mesh, ``seam_edges`` ``(k, 2)`` the edges that lie on lines,
    ``worst_angle`` the smallest angle (degrees) of any cell of the cut mesh and
    ``input_worst_angle`` that of the mesh before cutting.
    """

    mesh: SurfaceMesh
    panel_ids: np.ndarray
    lines: list[np.ndarray]
    seam_edges: np.ndarray
    worst_angle: float
    input_worst_angle: float

    @property
    def num_panels(self) -> int:
        return int(self.panel_ids.max()) + 1 if self.panel_ids.size else 0


@dataclass
class _Nodes:
    """The nodes of the cut mesh: the input's, and one per distinct edge crossing."""

    points: list[np.ndarray]
    on_edge: dict[tuple[int, int], list[tuple[float, int]]]
    where: dict[int, tuple[int, int, float]]  # new node → (a, b, t) on the input edge a < b
    key: dict[tuple[int, int, float], int]
    cell_size: dict[tuple[int, int], float]  # input edge → longest edge of the cells at it

    def add(self, a: int, b: int, t: float, snap: float) -> int:
        """The node at fraction ``t`` from ``a`` on the edge ``(a, b)``, or the end node when
        closer than ``snap`` × the size of the cells there."""
        if a == b:
            return a
        # within round-off of a node a crossing is the node, whatever the snap
        reach = max(snap, 1e-6) * self.cell_size[(min(a, b), max(a, b))]
        length = float(np.linalg.norm(self.points[b] - self.points[a]))
        if t * length <= reach:
            return a
        if (1.0 - t) * length <= reach:
            return b
        if a > b:
            a, b, t = b, a, 1.0 - t
        key = (a, b, round(t, 13))
        if key not in self.key:
            node = len(self.points)
            p = self.points
            self.points.append((1.0 - t) * p[a] + t * p[b])
            self.key[key] = node
            self.where[node] = (a, b, t)
            self.on_edge.setdefault((a, b), []).append((t, node))
        return self.key[key]


def cut_mesh(
    mesh: SurfaceMesh, lines: Sequence[SurfaceLine], snap: float = SNAP, *, panels: bool = True
) -> CutMesh:
    """Cut a triangle mesh along ``lines`` (module docs).

    A line of a single point inserts that point as a node. Lines may share their end nodes, but
    must not cross or touch elsewhere. With ``panels`` false the panel ids are left all zero
    (inserting nodes only).

    Raises
    ------
    LinesMeetError
        Two lines cross or touch.
    CuttingError
        A line leaves the cells it should run through.
    """
    triangles = check_triangles(mesh)
    num_input = mesh.num_points
    nodes = _Nodes([p for p in mesh.points], {}, {}, {}, _cell_sizes(mesh.points, triangles))
    boundary = {tuple(sorted(e)) for e in mesh.boundary_edges().tolist()}
    chains = [_off_boundary(_chain(line, nodes, snap), nodes, boundary) for line in lines]
    _check_disjoint(chains, num_input, nodes)
    faces_at_node, faces_at_edge = _incidence(triangles)
    chords: dict[int, list[tuple[int, int]]] = defaultdict(list)
    seams: set[tuple[int, int]] = set()
    for chain in chains:
        for u, w in itertools.pairwise(chain):
            _place_segment(u, w, nodes, faces_at_node, faces_at_edge, chords, seams, num_input)
    for key in nodes.on_edge:
        nodes.on_edge[key].sort()
    points = np.array(nodes.points)
    touched = set(chords)
    for a, b in nodes.on_edge:
        touched.update(faces_at_edge[(a, b)])
    kept = np.ones(len(triangles), dtype=bool)
    new_cells = []
    faces = np.array(sorted(touched), dtype=np.int64)
    kept[faces] = False
    origins, frames = _cell_frames(points, triangles[faces])
    for face, origin, axes in zip(faces.tolist(), origins, frames, strict=True):
        new_cells += _split_face(triangles[face], points, nodes, chords.get(face, []), origin, axes)
    cells = np.vstack([triangles[kept], np.array(new_cells, dtype=np.int64).reshape(-1, 3)])
    cut = SurfaceMesh(points, {"triangle": cells})
    seam_edges = np.array(sorted(seams), dtype=np.int64).reshape(-1, 2)
    ids = panel_regions(cells, seam_edges, len(points)) if panels else np.zeros(len(cells), int)
    return CutMesh(
        cut,
        ids,
        [np.array(c) for c in chains],
        seam_edges,
        float(min_angles(points, cells).min()),
        float(min_angles(mesh.points, triangles).min()),
    )


def _chain(line: SurfaceLine, nodes: _Nodes, snap: float) -> list[int]:
    """The nodes of a line in the cut mesh, crossings near a node moved onto it."""
    points = nodes.points
    where = [
        (int(a), int(b), float(t)) for (a, b), t in zip(line.ends, line.fractions, strict=True)
    ]
    for k in range(len(where) - 1):  # a line that cuts a cell's corner off closely: through it
        (a, b, _), (c, d, _) = where[k], where[k + 1]
        common = {a, b} & {c, d}
        if a == b or c == d or len(common) != 1:
            continue
        corner = common.pop()
        p, q = line.points[k], line.points[k + 1]
        size = min(nodes.cell_size[(min(a, b), max(a, b))], nodes.cell_size[(min(c, d), max(c, d))])
        if _distance_to_segment(points[corner], p, q) <= snap * size:
            where[k] = where[k + 1] = (corner, corner, 0.0)
    chain: list[int] = []
    for a, b, t in where:
        node = nodes.add(a, b, t, snap)
        if not chain or chain[-1] != node:
            chain.append(node)
    return chain


def _cell_sizes(points: np.ndarray, triangles: np.ndarray) -> dict[tuple[int, int], float]:
    """Every edge → the longest edge of the cells it belongs to."""
    edges, side = mesh_edges(triangles)
    length = np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1)
    size = np.zeros(len(edges))
    np.maximum.at(size, side.ravel(), np.repeat(length[side].max(axis=1), 3))
    return dict(zip(map(tuple, edges.tolist()), size.tolist(), strict=True))


def _off_boundary(chain: list[int], nodes: _Nodes, boundary: set) -> list[int]:
    """The chain without the pieces at its ends that run along the mesh's boundary (where a
    line's crossing next to its end point was moved onto a boundary node): no seam there."""

    def edge_of(node: int) -> tuple[int, int] | None:
        return nodes.where[node][:2] if node in nodes.where else None

    def along(u: int, w: int) -> bool:
        for edge in (edge_of(u), edge_of(w), (min(u, w), max(u, w))):
            if edge in boundary and all(n in edge or edge_of(n) == edge for n in (u, w)):
                return True
        return False

    start, end = 0, len(chain) - 1
    while start < end - 1 and along(chain[start], chain[start + 1]):
        start += 1
    while end > start + 1 and along(chain[end - 1], chain[end]):
        end -= 1
    return chain[start : end + 1]


def _distance_to_segment(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    direction = b - a
    length2 = float(direction @ direction)
    t = 0.0 if length2 == 0 else min(1.0, max(0.0, float((point - a) @ direction) / length2))
    return float(np.linalg.norm(a + t * direction - point))


def _check_disjoint(chains: list[list[int]], num_input: int, nodes: _Nodes) -> None:
    """Lines may share their end nodes, no other node."""
    users: dict[int, set[int]] = defaultdict(set)
    for index, chain in enumerate(chains):
        for node in chain:
            users[node].add(index)
    for node, who in users.items():
        if len(who) > 1 and any(node not in (chains[i][0], chains[i][-1]) for i in who):
            first, second = sorted(who)[:2]
            where = nodes.points[node]
            raise LinesMeetError(
                f"cutting lines {first + 1} and {second + 1} meet at "
                f"({where[0]:.6g}, {where[1]:.6g}, {where[2]:.6g}): lines must not cross "
                "or touch (place them further apart, or refine the mesh)"
            )


class _FacesAtNode:
    """The cells at every node of a triangle mesh, looked up when asked for (``[node]``: a set)."""

    def __init__(self, triangles: np.ndarray) -> None:
        corners = triangles.ravel()
        self.order = np.argsort(corners, kind="stable") // 3
        self.start = np.concatenate([[0], np.cumsum(np.bincount(corners))])

    def __getitem__(self, node: int) -> set[int]:
        if node + 1 >= len(self.start):
            return set()
        return set(self.order[self.start[node] : self.start[node + 1]].tolist())


class _FacesAtEdge:
    """The cells at every edge ``(a, b)`` (``a < b``) of a triangle mesh (``[edge]``: a list;
    ``edge in``: whether it is an edge)."""

    def __init__(self, at_node: _FacesAtNode) -> None:
        self.at_node = at_node

    def __getitem__(self, edge: tuple[int, int]) -> list[int]:
        return sorted(self.at_node[edge[0]] & self.at_node[edge[1]])

    def __contains__(self, edge: tuple[int, int]) -> bool:
        return bool(self[edge])


def _incidence(triangles: np.ndarray) -> tuple[_FacesAtNode, _FacesAtEdge]:
    at_node = _FacesAtNode(triangles)
    return at_node, _FacesAtEdge(at_node)


def _support(node: int, nodes: _Nodes, faces_at_node, faces_at_edge, num_input: int) -> set[int]:
    """The input cells a node lies in."""
    if node < num_input:
        return faces_at_node[node]
    a, b, _ = nodes.where[node]
    return set(faces_at_edge[(a, b)])


def _edge_of(node: int, nodes: _Nodes, num_input: int) -> tuple[int, int] | None:
    return None if node < num_input else nodes.where[node][:2]


def _place_segment(u, w, nodes, faces_at_node, faces_at_edge, chords, seams, num_input) -> None:
    """Record the segment ``u → w`` of a line: along an input edge, or a chord of one cell."""
    eu, ew = _edge_of(u, nodes, num_input), _edge_of(w, nodes, num_input)
    common_edge = None
    if eu is not None and ew is not None and eu == ew:
        common_edge = eu
    elif eu is not None and ew is None and w in eu:
        common_edge = eu
    elif ew is not None and eu is None and u in ew:
        common_edge = ew
    elif eu is None and ew is None and (min(u, w), max(u, w)) in faces_at_edge:
        common_edge = (min(u, w), max(u, w))
    if common_edge is not None:
        seams.update(_along_edge(common_edge, u, w, nodes))
        return
    shared = _support(u, nodes, faces_at_node, faces_at_edge, num_input) & _support(
        w, nodes, faces_at_node, faces_at_edge, num_input
    )
    if len(shared) != 1:
        where = nodes.points[u]
        raise CuttingError(
            f"a cutting line leaves the surface's cells near ({where[0]:.6g}, {where[1]:.6g}, "
            f"{where[2]:.6g})"
        )
    chords[shared.pop()].append((u, w))
    seams.add((min(u, w), max(u, w)))


def _along_edge(edge: tuple[int, int], u: int, w: int, nodes: _Nodes) -> list[tuple[int, int]]:
    """The pieces of the input edge ``edge`` between its nodes ``u`` and ``w`` (input nodes or
    crossings on it), as they will be after every crossing is inserted."""
    a, b = edge

    def position(node: int) -> float:
        return 0.0 if node == a else 1.0 if node == b else nodes.where[node][2]

    lo, hi = sorted((position(u), position(w)))
    along = [(0.0, a), *nodes.on_edge.get(edge, []), (1.0, b)]
    chain = [n for t, n in sorted(along) if lo <= t <= hi]
    return [(min(p, q), max(p, q)) for p, q in itertools.pairwise(chain)]


def _cell_frames(points: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every triangle's first corner ``(m, 3)`` and two orthonormal axes of its plane
    ``(m, 2, 3)``, the first along its first side."""
    origin = points[triangles[:, 0]]
    first = points[triangles[:, 1]] - origin
    normal = np.cross(first, points[triangles[:, 2]] - origin)
    axes = np.stack([first, np.cross(normal, first)], axis=1)
    return origin, axes / np.linalg.norm(axes, axis=2, keepdims=True)


def _split_face(
    corners: np.ndarray,
    points: np.ndarray,
    nodes: _Nodes,
    chords: list[tuple[int, int]],
    origin: np.ndarray,
    axes: np.ndarray,
) -> list[tuple[int, int, int]]:
    """The triangles a cell is split into by the crossings on its edges and its chords
    (``origin`` and ``axes``: the cell's frame, :func:`_cell_frames`)."""
    cycle: list[int] = []
    for k in range(3):
        a, b = int(corners[k]), int(corners[(k + 1) % 3])
        cycle.append(a)
        inner = nodes.on_edge.get((min(a, b), max(a, b)), [])
        ordered = [n for _, n in (inner if a < b else inner[::-1])]
        cycle += ordered
    polygons = [cycle]
    for u, w in chords:
        polygons = _split_polygon(polygons, u, w, points)
    out = []
    for polygon in polygons:
        flat = (points[polygon] - origin) @ axes.T
        out += [tuple(polygon[i] for i in t) for t in best_triangulation(flat)]
    return out


def _split_polygon(polygons: list[list[int]], u: int, w: int, points) -> list[list[int]]:
    for index, polygon in enumerate(polygons):
        if u in polygon and w in polygon:
            i, j = sorted((polygon.index(u), polygon.index(w)))
            if j - i == 1 or (i == 0 and j == len(polygon) - 1):
                return polygons  # already a side
            parts = [polygon[i : j + 1], polygon[j:] + polygon[: i + 1]]
            return polygons[:index] + parts + polygons[index + 1 :]
    where = points[u]
    raise LinesMeetError(
        f"cutting lines cross near ({where[0]:.6g}, {where[1]:.6g}, {where[2]:.6g}): lines must "
        "not cross"
    )


def best_triangulation(polygon: np.ndarray) -> list[tuple[int, int, int]]:
    """Triangles (indices into ``polygon``) of a convex polygon ``(n, 2)``, counter-clockwise,
    possibly with collinear nodes: the triangulation with the largest smallest angle and no
    degenerate triangle."""
    n = len(polygon)
    if n == 3:
        return [(0, 1, 2)]
    scale = float(np.ptp(polygon, axis=0).max()) ** 2

    def quality(i: int, j: int, k: int) -> float:
        return _smallest_angle(polygon[i], polygon[j], polygon[k], 1e-14 * scale)

    best: dict[tuple[int, int], tuple[float, int]] = {}
    for gap in range(2, n):
        for i in range(n - gap):
            j = i + gap
            choice = (-2.0, -1)
            for k in range(i + 1, j):
                value = min(
                    quality(i, k, j),
                    best[(i, k)][0] if k - i > 1 else np.inf,
                    best[(k, j)][0] if j - k > 1 else np.inf,
                )
                if value > choice[0]:
                    choice = (value, k)
            best[(i, j)] = choice
    if best[(0, n - 1)][0] <= 0:
        raise CuttingError("a cell cannot be split without a degenerate triangle")
    out: list[tuple[int, int, int]] = []
    stack = [(0, n - 1)]
    while stack:
        i, j = stack.pop()
        k = best[(i, j)][1]
        out.append((i, k, j))
        stack += [(a, b) for a, b in ((i, k), (k, j)) if b - a > 1]
    return out


def _smallest_angle(p, q, r, tiny: float) -> float:
    """Smallest angle (degrees) of the counter-clockwise triangle ``p q r``; −1 if degenerate or
    clockwise."""
    area = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    if area <= tiny:
        return -1.0
    smallest = math.pi
    for a, b, c in ((p, q, r), (q, r, p), (r, p, q)):
        u0, u1, v0, v1 = b[0] - a[0], b[1] - a[1], c[0] - a[0], c[1] - a[1]
        smallest = min(smallest, math.atan2(abs(u0 * v1 - u1 * v0), u0 * v0 + u1 * v1))
    return math.degrees(smallest)


def panel_regions(cells: np.ndarray, seam_edges: np.ndarray, num_points: int) -> np.ndarray:
    """Connected regions of triangles ``(m, 3)``, neighbours across every edge that is not one
    of the ``seam_edges`` ``(k, 2)``: a region label per cell ``(m,)``."""
    sides = np.stack([cells, np.roll(cells, -1, axis=1)], axis=-1).reshape(-1, 2)
    keys = np.sort(sides, axis=1) @ np.array([num_points, 1], dtype=np.int64)
    owner = np.repeat(np.arange(len(cells)), 3)
    seam_keys = seam_edges @ np.array([num_points, 1], dtype=np.int64)
    open_side = ~np.isin(keys, seam_keys)
    keys, owner = keys[open_side], owner[open_side]
    order = np.argsort(keys, kind="stable")
    keys, owner = keys[order], owner[order]
    pair = np.flatnonzero(keys[1:] == keys[:-1])
    graph = sp.coo_matrix(
        (np.ones(pair.size), (owner[pair], owner[pair + 1])), shape=(len(cells),) * 2
    )
    _, labels = connected_components(graph, directed=False)
    return labels
