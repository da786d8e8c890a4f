"""Slits in a triangle mesh: lines walked across the surface, and the mesh cut open along them.

A **slit** is a cut from the boundary into the surface (a dart of a composite ply, DESIGN.md §8).
:func:`walk_line` traces a :class:`~vares.geometry.surface_lines.SurfaceLine` from a point across
the cells, each step straight inside a cell along a direction the caller gives per cell (a field
of directions, or the way to the next point of a polyline), and records where it crosses the
edges: consecutive points lie in one cell, as a surface line's must.

:func:`open_slits` cuts the mesh along such lines (:func:`vares.geometry.cutting.cut_mesh`, which
makes the lines' points nodes and their pieces edges) and then gives every node of a line but its
tip a twin: the cells on one side of the line keep the node, those on the other side take the
twin. Both lips of the slit are then free boundary, joined only at the tip; the surface keeps its
shape and area.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .cutting import SNAP, cut_mesh
from .mesh import SurfaceMesh
from .surface_lines import CuttingError, SurfaceLine, check_triangles
from .surface_points import FaceLocator, barycentric, face_neighbours

__all__ = ["SlitMesh", "open_slits", "walk_line"]

#: A direction for the walk in a face, given the face, the point ``(3,)`` and the last direction
#: ``(3,)`` (None at the start): a 3D vector (projected onto the face), or None to stop.
Direction = Callable[[int, np.ndarray, np.ndarray | None], np.ndarray | None]


def walk_line(
    mesh: SurfaceMesh,
    face: int,
    weights: np.ndarray,
    direction: Direction,
    max_length: float,
    max_steps: int = 100_000,
) -> SurfaceLine:
    """The line walked from the point with barycentric ``weights`` ``(3,)`` in ``face``.

    In every face the walk goes straight along ``direction(face, point, last)`` projected onto
    the face to the side it leaves by, and on into the face across it; it ends where
    ``direction`` returns None, before the mesh's boundary, or after ``max_length`` (mesh
    units), or before it would enter a face it has crossed already (a direction field that
    turns the walk back on itself: a slit must not cross itself). The line holds the start
    (when it lies on an edge or is a node) and every edge crossing but one onto the boundary;
    where the walk ends inside a face, its last crossing is the line's end. A walk that stands
    on a node and whose step leaves its face at once goes on in the face of the node's fan the
    step points into (the node is a point of the line).
    """
    triangles = check_triangles(mesh)
    points = mesh.points
    neighbours = face_neighbours(triangles)
    w = np.asarray(weights, dtype=float)
    ends: list[tuple[int, int]] = []
    fractions: list[float] = []
    zero = np.flatnonzero(w <= 1e-12)
    if len(zero) == 1:
        k = int(zero[0])
        a, b = triangles[face][(k + 1) % 3], triangles[face][(k + 2) % 3]
        ends.append((int(a), int(b)))
        fractions.append(float(w[(k + 2) % 3] / (w[(k + 1) % 3] + w[(k + 2) % 3])))
    elif len(zero) == 2:  # the start is a node
        node = int(triangles[face][int(np.argmax(w))])
        ends.append((node, node))
        fractions.append(0.0)
    last: np.ndarray | None = None
    length = 0.0
    visited = {int(face)}
    fans: list[list[int]] | None = None  # the faces around every node, when first needed
    for _ in range(max_steps):
        corners = points[triangles[face]]
        here = w @ corners
        step = direction(face, here, last)
        if step is None:
            break
        rate = barycentric(here + step, corners)[0] - w
        with np.errstate(divide="ignore", invalid="ignore"):
            reach = np.where(rate < -1e-14, -w / rate, np.inf)
        k = int(np.argmin(reach))
        if not np.isfinite(reach[k]):
            break
        exit_weights = np.clip(w + reach[k] * rate, 0.0, None)
        exit_weights[k] = 0.0
        exit_weights /= exit_weights.sum()
        exit_point = exit_weights @ corners
        length += float(np.linalg.norm(exit_point - here))
        last = exit_point - here if np.linalg.norm(exit_point - here) > 0 else last
        a, b = int(triangles[face][(k + 1) % 3]), int(triangles[face][(k + 2) % 3])
        t = float(
            exit_weights[(k + 2) % 3] / (exit_weights[(k + 1) % 3] + exit_weights[(k + 2) % 3])
        )
        following = int(neighbours[face, k])
        at_node = _at_node(w, triangles[face])
        if at_node is not None and reach[k] <= VERTEX_REACH:
            # the walk stands on a node and its step leaves the face at once: go on in the face
            # of the node's fan that the step points into (a line through a node would stop or
            # turn back across the faces next to it)
            if fans is None:
                fans = _fans(triangles)
            onward = _fan_face(at_node, here, step, fans, triangles, points, visited)
            if onward is None:
                break
            if not ends or _node_of(ends[-1], fractions[-1]) != at_node:
                ends.append((at_node, at_node))  # (unless the last crossing is the node)
                fractions.append(0.0)
            visited.add(onward)
            face = onward
            w = (triangles[onward] == at_node).astype(float)
            continue
        if following < 0 or following in visited:
            break  # before the boundary, or before a face crossed already (turning back)
        ends.append((a, b))
        fractions.append(t)
        if length >= max_length:
            break
        visited.add(following)
        corners_next = triangles[following]
        w = np.zeros(3)
        w[int(np.flatnonzero(corners_next == a)[0])] = 1.0 - t
        w[int(np.flatnonzero(corners_next == b)[0])] = t
        face = following
    return SurfaceLine.at(points, np.array(ends, dtype=np.int64), np.array(fractions))


#: A walk whose step from a node leaves its face within this fraction of the step is on the
#: node (:func:`walk_line`).
VERTEX_REACH = 1e-9


def _at_node(w: np.ndarray, cell: np.ndarray) -> int | None:
    """The node of ``cell`` the point of barycentric ``w`` stands on (within 1e-9), or None."""
    k = int(np.argmax(w))
    return int(cell[k]) if w[k] >= 1.0 - 1e-9 else None


def _node_of(end: tuple[int, int], fraction: float) -> int | None:
    """The node an edge position ``end`` (a, b) at ``fraction`` from a is on, or None."""
    if end[0] == end[1] or fraction <= 1e-9:
        return int(end[0])
    return int(end[1]) if fraction >= 1.0 - 1e-9 else None


def _fans(triangles: np.ndarray) -> list[list[int]]:
    """The faces around every node."""
    fans: list[list[int]] = [[] for _ in range(int(triangles.max()) + 1)]
    for face, cell in enumerate(triangles.tolist()):
        for node in cell:
            fans[node].append(face)
    return fans


def _fan_face(node, here, step, fans, triangles, points, visited) -> int | None:
    """The face around ``node`` not walked yet that the ``step`` from ``here`` (on the node)
    points into (its projection onto the face between the face's two edges at the node), or
    None."""
    for face in fans[node]:
        if face in visited:
            continue
        corners = points[triangles[face]]
        normal = np.cross(corners[1] - corners[0], corners[2] - corners[0])
        normal /= np.linalg.norm(normal)
        along = step - (step @ normal) * normal
        if not np.linalg.norm(along) > 0:
            continue
        size = float(np.ptp(corners, axis=0).max())
        probe = here + 1e-6 * size * along / np.linalg.norm(along)
        if np.all(barycentric(probe, corners)[0] >= -1e-12):
            return int(face)
    return None


@dataclass(frozen=True)
class SlitMesh:
    """A mesh cut open along slits.

    ``mesh``: the opened surface (triangles); ``parent`` ``(n,)``: for every node, the node of
    the cut mesh it is (itself, or the node a twin was made of); ``lips``: per slit, the node
    chains ``(k,)`` of its two lips from the mouth (on the boundary) to the shared tip, the
    left lip (as the slit runs in from the mouth, seen along the cells' normal) first;
    ``cell_origin`` ``(m,)``: the cell of the input mesh every cell lies in; ``lines``: the
    slits as walked (3D polylines ``(k, 3)``).
    """

    mesh: SurfaceMesh
    parent: np.ndarray
    lips: list[tuple[np.ndarray, np.ndarray]]
    cell_origin: np.ndarray
    lines: list[np.ndarray]

    def lip_gaps(self, coordinates: np.ndarray) -> list[np.ndarray]:
        """Per slit, the distance ``(k,)`` between the twin nodes of its two lips in a pattern
        ``coordinates`` ``(n, 2)`` (or any positions ``(n, d)``), mouth first, tip (0) last."""
        return [np.linalg.norm(coordinates[a] - coordinates[b], axis=1) for a, b in self.lips]


def open_slits(mesh: SurfaceMesh, lines: Sequence[SurfaceLine], snap: float = SNAP) -> SlitMesh:
    """Cut ``mesh`` along ``lines`` and open each cut (module docs). Every line must start on
    the boundary and end inside the surface; lines must not cross or touch.

    Raises
    ------
    CuttingError
        A line that does not start on the boundary, ends on it, or is shorter than a cell.
    """
    triangles = check_triangles(mesh)
    cut = cut_mesh(mesh, lines, snap, panels=False)
    cells = cut.mesh.cells["triangle"].copy()
    points = cut.mesh.points
    boundary = set(np.unique(cut.mesh.boundary_edges()).tolist())
    slit_edges = set()
    chains = []
    for index, chain in enumerate(cut.lines, start=1):
        if len(chain) < 2:
            raise CuttingError(f"slit {index} is shorter than a cell of the mesh")
        if int(chain[0]) not in boundary and int(chain[-1]) in boundary:
            chain = chain[::-1]
        chains.append(chain)
        if int(chain[0]) not in boundary:
            raise CuttingError(f"slit {index} does not start on the surface's boundary")
        if int(chain[-1]) in boundary:
            raise CuttingError(
                f"slit {index} runs from boundary to boundary: it would cut a piece off"
            )
        slit_edges.update((min(a, b), max(a, b)) for a, b in itertools.pairwise(chain.tolist()))
    parent = list(range(len(points)))
    new_points = list(points)
    lips = []
    for chain in chains:
        twins = []
        for node, following in itertools.pairwise(chain.tolist()):
            twin = _twin(cells, node, following, slit_edges, len(new_points))
            if twin is None:
                raise CuttingError(
                    f"the slit through {points[node]} does not divide the cells there"
                )
            new_points.append(points[node])
            parent.append(node)
            twins.append(twin)
        lips.append((np.array(chain), np.array([*twins, int(chain[-1])])))
    opened = SurfaceMesh(np.array(new_points), {"triangle": cells})
    centroids = points[cut.mesh.cells["triangle"]].mean(axis=1)
    origin, _, _ = FaceLocator(SurfaceMesh(mesh.points, {"triangle": triangles})).locate(centroids)
    return SlitMesh(opened, np.array(parent), lips, origin, [c.points for c in lines])


def _twin(cells: np.ndarray, node: int, following: int, slit_edges: set, twin: int) -> int | None:
    """Give the cells at ``node`` on the right of the slit (as it runs on to ``following``) the
    new node ``twin`` (in place): the node's cells on the left, where the slit's piece runs
    ``node → following`` in the cell's own order, keep the node, so every lip is one side's.
    None when the slit does not divide the cells around the node in two."""
    around = np.flatnonzero((cells == node).any(axis=1))
    label = {int(c): i for i, c in enumerate(around)}
    root = list(range(len(around)))

    def find(i: int) -> int:
        while root[i] != i:
            root[i] = root[root[i]]
            i = root[i]
        return i

    by_edge: dict[tuple[int, int], list[int]] = {}
    for cell in around.tolist():
        for other in cells[cell].tolist():
            if other != node:
                by_edge.setdefault((min(node, other), max(node, other)), []).append(cell)
    for edge, users in by_edge.items():
        if len(users) == 2 and edge not in slit_edges:
            root[find(label[users[0]])] = find(label[users[1]])
    groups = {find(i) for i in range(len(around))}
    if len(groups) != 2:
        return None
    left = [
        c
        for c in around.tolist()
        if following in cells[c]
        and cells[c][(int(np.flatnonzero(cells[c] == node)[0]) + 1) % 3] == following
    ]
    if len(left) != 1:
        return None
    side = find(label[left[0]])
    for i, cell in enumerate(around.tolist()):
        if find(i) != side:
            cells[cell][cells[cell] == node] = twin
    return twin
