"""A user's curves drawn onto the surface as cutting lines.

Each curve (a polyline near the surface, e.g. drawn in CAD on the design surface) is densified to
half the mean edge length and every point is moved to the closest point of the surface; its two
end points go to the closest point of the surface's boundary. Of the points that fall into one
cell only the first is kept. The kept points become nodes of the mesh (a point within ``snap`` ×
the cell size of an edge or node is put there), and the cutting line is the geodesic through them
in order (:func:`geodesic_lines` through every point): it passes through the curve's points and
is the shortest path between consecutive ones, so it follows the curve to within the mesh size.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np

from .cutting import cut_mesh
from .mesh import SurfaceMesh
from .surface_lines import CuttingError, EdgeLocator, SurfaceLine, check_triangles

__all__ = ["closest_points", "curves_on_surface", "densified", "point_spacing"]


def curves_on_surface(
    mesh: SurfaceMesh, curves: Sequence[np.ndarray], snap: float
) -> tuple[SurfaceMesh, list[SurfaceLine]]:
    """The curves ``(k, 3)`` as cutting lines on ``mesh`` (module docs): the mesh with the
    curves' points as nodes, and the lines on it."""
    import potpourri3d as pp3d

    check_triangles(mesh)  # triangles only
    spacing = point_spacing(mesh)
    size = float(np.ptp(mesh.points, axis=0).max())
    located = []
    for index, curve in enumerate(curves, start=1):
        points = densified(np.asarray(curve, dtype=float), spacing)
        faces, bary, distance = closest_points(mesh, points)
        if distance.max() > 0.05 * size:
            raise CuttingError(
                f"curve {index} lies up to {distance.max():.4g} from the surface: draw it on it"
            )
        keep = np.concatenate([[True], faces[1:] != faces[:-1]])
        keep[-1] = True
        located.append((faces[keep], bary[keep]))
    base, chains = _insert(mesh, located, snap)
    solver = pp3d.EdgeFlipGeodesicSolver(base.points, base.cells["triangle"])
    locate = EdgeLocator(base)
    lines = []
    for chain in chains:  # geodesic from point to point: the line passes through every one
        pieces = [
            np.asarray(solver.find_geodesic_path(int(a), int(b)))
            for a, b in itertools.pairwise(chain)
        ]
        path = np.vstack([pieces[0]] + [p[1:] for p in pieces[1:]])
        lines.append(locate.line(path))
    return base, lines


def point_spacing(mesh: SurfaceMesh) -> float:
    """The spacing a curve is densified to before it is drawn on ``mesh``: half its mean edge."""
    edges = mesh.edges()
    return 0.5 * float(np.linalg.norm(np.diff(mesh.points[edges], axis=1), axis=2).mean())


def densified(curve: np.ndarray, spacing: float) -> np.ndarray:
    """The polyline ``curve`` ``(k, 3)`` with points added: its own kept, none farther apart
    than ``spacing``."""
    out = [curve[:1]]
    for a, b in itertools.pairwise(curve):
        pieces = max(1, int(np.ceil(np.linalg.norm(b - a) / spacing)))
        t = np.arange(1, pieces + 1)[:, None] / pieces
        out.append(a + t * (b - a))
    return np.vstack(out)


def _insert(mesh: SurfaceMesh, located, snap: float):
    """Put the located points into the mesh as nodes; the ends onto the boundary."""
    triangles = mesh.cells["triangle"]
    boundary = {tuple(sorted(e)) for e in mesh.boundary_edges().tolist()}
    boundary_nodes = {node for edge in boundary for node in edge}
    points = mesh.points
    single = []  # one-point lines for cut_mesh: edge locations
    inner_faces, inner_bary, slots = [], [], []
    for curve, (faces, bary) in enumerate(located):
        for k, (face, weights) in enumerate(zip(faces, bary, strict=True)):
            corners = triangles[face]
            end = k in (0, len(faces) - 1)
            if end:
                a, b, t = _nearest_boundary_edge(points, corners, weights, boundary)
                if a is None and weights.max() > 1.0 - snap:  # at a corner on the boundary
                    node = int(corners[np.argmax(weights)])
                    if node in boundary_nodes:
                        a, b, t = node, node, 0.0
                if a is None:
                    raise _away_from_boundary(weights @ points[corners])
            else:
                a, b, t = _on_edge(corners, weights, snap)
            if a is None:
                if face in inner_faces:  # a cell holds one point: the curve passes it by
                    continue
                inner_faces.append(face)
                inner_bary.append(weights)
                slots.append((curve, k, "inner", len(inner_faces) - 1))
            else:
                single.append(SurfaceLine.at(points, np.array([[a, b]]), np.array([t])))
                slots.append((curve, k, "edge", len(single) - 1))
    base, inner_nodes = _split_faces(mesh, np.array(inner_faces, int), np.array(inner_bary))
    inserted = cut_mesh(base, single, snap, panels=False) if single else None
    chains: list[list[int]] = [[] for _ in located]
    for curve, _, kind, index in slots:
        node = inner_nodes[index] if kind == "inner" else int(inserted.lines[index][0])
        if not chains[curve] or chains[curve][-1] != node:
            chains[curve].append(node)
    for index, chain in enumerate(chains, start=1):
        if len(chain) < 2:
            raise CuttingError(f"curve {index} is shorter than a cell of the mesh")
    return (inserted.mesh if inserted else base), chains


def _on_edge(corners, weights, snap):
    """A point with a barycentric weight below ``snap`` lies on the opposite edge (or, with
    two, on the node): the edge location, or ``(None, None, None)`` inside the cell."""
    small = weights < snap
    if small.sum() >= 2:
        node = int(corners[np.argmax(weights)])
        return node, node, 0.0
    if small.sum() == 1:
        k = int(np.argmax(small))
        a, b = int(corners[(k + 1) % 3]), int(corners[(k + 2) % 3])
        wa, wb = weights[(k + 1) % 3], weights[(k + 2) % 3]
        return a, b, float(wb / (wa + wb))
    return None, None, None


def _away_from_boundary(position: np.ndarray) -> CuttingError:
    return CuttingError(
        f"a curve ends at ({position[0]:.6g}, {position[1]:.6g}, {position[2]:.6g}), away "
        "from the surface's boundary: cutting lines run from boundary to boundary"
    )


def _nearest_boundary_edge(points, corners, weights, boundary):
    """The point moved onto the closest boundary edge of its cell (the curve's end), or
    ``(None, None, None)`` when the cell has none."""
    position = weights @ points[corners]
    best = None
    for k in range(3):
        a, b = int(corners[k]), int(corners[(k + 1) % 3])
        if (min(a, b), max(a, b)) not in boundary:
            continue
        d = points[b] - points[a]
        t = float(np.clip((position - points[a]) @ d / (d @ d), 0.0, 1.0))
        distance = float(np.linalg.norm(points[a] + t * d - position))
        if best is None or distance < best[0]:
            best = (distance, a, b, t)
    if best is None:
        return None, None, None
    return best[1], best[2], best[3]


def _split_faces(mesh: SurfaceMesh, faces: np.ndarray, bary: np.ndarray):
    """Each of ``faces`` split into three triangles at its point; the new nodes."""
    triangles = mesh.cells["triangle"]
    if faces.size == 0:
        return mesh, []
    new = mesh.points.shape[0] + np.arange(len(faces))
    points = np.vstack([mesh.points, np.einsum("fk,fkd->fd", bary, mesh.points[triangles[faces]])])
    kept = np.ones(len(triangles), dtype=bool)
    kept[faces] = False
    a, b, c = triangles[faces].T
    fans = np.vstack(
        [np.column_stack([a, b, new]), np.column_stack([b, c, new]), np.column_stack([c, a, new])]
    )
    return SurfaceMesh(points, {"triangle": np.vstack([triangles[kept], fans])}), new.tolist()


def closest_points(
    mesh: SurfaceMesh, queries: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For points ``(k, 3)``: the triangle of the closest surface point, its barycentric
    coordinates ``(k, 3)`` and the distance (among the 32 triangles with the nearest
    centroids)."""
    from scipy.spatial import cKDTree

    triangles = check_triangles(mesh)
    corners = mesh.points[triangles]
    count = min(32, len(triangles))
    _, candidates = cKDTree(corners.mean(axis=1)).query(queries, k=count)
    candidates = candidates.reshape(len(queries), count)
    faces, barys, distances = [], [], []
    for point, near in zip(queries, candidates, strict=True):
        bary = _closest_on_triangles(point, corners[near])
        nearest = np.einsum("tk,tkd->td", bary, corners[near])
        distance = np.linalg.norm(nearest - point, axis=1)
        best = int(np.argmin(distance))
        faces.append(near[best])
        barys.append(bary[best])
        distances.append(distance[best])
    return np.array(faces), np.array(barys), np.array(distances)


def _closest_on_triangles(point: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Barycentric coordinates ``(t, 3)`` of the closest point to ``point`` on each triangle:
    the projection if inside, else the closest point of the nearest side."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    ab, ac = b - a, c - a
    normal = np.cross(ab, ac)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    projected = point - np.einsum("td,td->t", point - a, normal)[:, None] * normal
    gram = np.stack(
        [
            np.stack([(ab * ab).sum(1), (ab * ac).sum(1)], -1),
            np.stack([(ab * ac).sum(1), (ac * ac).sum(1)], -1),
        ],
        -2,
    )
    rhs = np.stack([((projected - a) * ab).sum(1), ((projected - a) * ac).sum(1)], -1)
    v, w = np.linalg.solve(gram, rhs[..., None])[..., 0].T
    bary = np.column_stack([1 - v - w, v, w])
    outside = (bary < 0).any(axis=1)
    for t in np.flatnonzero(outside):
        best = None
        for i, j in ((0, 1), (1, 2), (2, 0)):
            p, q = corners[t, i], corners[t, j]
            s = float(np.clip((point - p) @ (q - p) / ((q - p) @ (q - p)), 0.0, 1.0))
            distance = float(np.linalg.norm(p + s * (q - p) - point))
            if best is None or distance < best[0]:
                weights = np.zeros(3)
                weights[i], weights[j] = 1 - s, s
                best = (distance, weights)
        bary[t] = best[1]
    return bary
