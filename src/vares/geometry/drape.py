"""Kinematic drape of a woven ply on a mould, carried onto the mould's own mesh.

:func:`kinematic_drape` builds the pin-jointed net (:func:`vares.geometry.drape_net.kinematic_net`,
whose docs give the algorithm) and reads it on the mould's cells and nodes: per cell the shear
angle and the warp and fill directions of the net cell the cell's centroid lies in, per node the
flat pattern coordinates the net implies (the node's barycentric coordinates in the net triangle it
lies in, applied to that triangle's flat corners ``(u, v)``). Each net cell is split into two
triangles along its diagonal from ``(i, j)`` to ``(i + 1, j + 1)``.

The net runs on up to one spacing beyond the mould's edge (in the planes of the boundary faces),
so the mould's cells along its edge lie in complete net cells. Mesh nodes and cells outside the
net (beyond its last row of cells, or where a cell would have sheared to ±90°) are
**extrapolated** from the nearest net triangle (linearly for the flat coordinates, as constants
for the cell fields) when they lie within ``reach`` yarn spacings of a net node, and are NaN
farther out; :attr:`KinematicDrape.node_in_net` and
:attr:`KinematicDrape.cell_in_net` say which were interpolated.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .drape_net import DrapeError, KinematicNet, kinematic_net, yarn_shear
from .mesh import SurfaceMesh
from .surface_points import barycentric

__all__ = ["DrapeError", "KinematicDrape", "KinematicNet", "kinematic_drape"]

#: Corner offsets of the two triangles of a net cell ``(i, j)``:
#: (0,0)-(1,0)-(1,1) and (0,0)-(1,1)-(0,1).
_CELL_TRIANGLES = np.array([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]]])


@dataclass(frozen=True)
class KinematicDrape:
    """A kinematic drape: the net and what it means on the mould's mesh.

    ``net``: the :class:`KinematicNet` (node positions ``(nu, nv, 3)``, faces, flat coordinates,
    node and cell shears). Per mesh cell, in global cell order ``(m,)``: ``shear_angle`` (degrees,
    the decrease of the angle between the +warp and +fill yarns from 90°), ``warp`` and ``fill``
    ``(m, 3)`` (unit yarn directions in the cell's plane). Per mesh node ``(n,)``:
    ``material_coordinates`` ``(n, 2)`` (the flat pattern the net implies, the seed at the origin,
    the warp along +x). NaN where the net does not reach (module docs). ``node_in_net`` ``(n,)``
    and ``cell_in_net`` ``(m,)``: True where the node or the cell's centroid lies inside the net
    (interpolated), False where it was extrapolated or is NaN.
    """

    net: KinematicNet
    shear_angle: np.ndarray
    warp: np.ndarray
    fill: np.ndarray
    material_coordinates: np.ndarray
    node_in_net: np.ndarray
    cell_in_net: np.ndarray

    @property
    def spacing(self) -> float:
        """The net's yarn spacing (mesh length units)."""
        return self.net.spacing


def kinematic_drape(
    mesh: SurfaceMesh,
    seed: np.ndarray,
    warp_direction: np.ndarray,
    spacing: float,
    *,
    generators: tuple[np.ndarray, np.ndarray] | None = None,
    max_length: float | None = None,
    reach: float = 2.0,
) -> KinematicDrape:
    """Drape a woven ply kinematically onto ``mesh`` (the mould, triangles or quads).

    ``seed`` ``(3,)``: a point on the mould; ``warp_direction`` ``(3,)``: the warp there (projected
    onto the tangent plane; the fill is normal × warp); ``spacing``: the yarn spacing in the mesh's
    length unit (the net's cell size: smaller is finer and slower); ``generators``, ``max_length``:
    see :func:`~vares.geometry.drape_net.kinematic_net`; ``reach``: how many spacings beyond the
    net's nodes mesh nodes and cells are still extrapolated (module docs).
    """
    net = kinematic_net(
        mesh, seed, warp_direction, spacing, generators=generators, max_length=max_length
    )
    points = mesh.points
    centroids = np.vstack([points[c].mean(axis=1) for c in mesh.cells.values()])
    limit = reach * spacing
    cell, _, cell_in_net = _locate_in_net(net, centroids, limit)
    node_cell, node_weights, node_in_net = _locate_in_net(net, points, limit)

    warp_vectors, fill_vectors = net.cell_yarns()
    known = cell[:, 0] >= 0
    a, b = cell[known, 0], cell[known, 1]
    normals = mesh.area_vectors()[known]
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    shear = np.full(len(centroids), np.nan)
    warp = np.full((len(centroids), 3), np.nan)
    fill = np.full((len(centroids), 3), np.nan)
    warp[known] = _in_plane(warp_vectors[a, b], normals)
    fill[known] = _in_plane(fill_vectors[a, b], normals)
    shear[known] = yarn_shear(warp_vectors[a, b], fill_vectors[a, b])

    coordinates = np.full((len(points), 2), np.nan)
    known = node_cell[:, 0] >= 0
    corners = node_cell[known, None, :2] + _CELL_TRIANGLES[node_cell[known, 2]]  # (k, 3, 2)
    flat = (corners - np.array(net.seed)) * spacing
    coordinates[known] = np.einsum("kc,kcd->kd", node_weights[known], flat)
    return KinematicDrape(net, shear, warp, fill, coordinates, node_in_net, cell_in_net)


def _in_plane(vectors: np.ndarray, normals: np.ndarray) -> np.ndarray:
    vectors = vectors - np.einsum("ki,ki->k", vectors, normals)[:, None] * normals
    return vectors / np.linalg.norm(vectors, axis=1)[:, None]


def _locate_in_net(
    net: KinematicNet, queries: np.ndarray, limit: float, near: int = 4, chunk: int = 8192
):
    """For each query point ``(k, 3)``: the net triangle it lies in as ``(i, j, t)`` ``(k, 3)``
    (the cell ``(i, j)``, its triangle ``t``; −1 if none within ``limit``), the barycentric
    weights ``(k, 3)`` of its corners, and whether the point lies inside the net ``(k,)``.

    The candidates are the triangles round the ``near`` net nodes nearest to the point; the point
    goes to the candidate that holds it (nearest in the normal direction if several do), else to
    the candidate it lies least far outside of.
    """
    from scipy.spatial import cKDTree

    valid = net.reached  # the nodes just beyond the mould's edge too
    nodes = np.argwhere(valid)
    if len(nodes) < 3:
        raise DrapeError("the net has fewer than three nodes: the spacing is too large")
    tree = cKDTree(net.positions[valid])
    cell = np.full((len(queries), 3), -1, dtype=np.int64)
    weights = np.full((len(queries), 3), np.nan)
    inside = np.zeros(len(queries), dtype=bool)
    # most points lie in a cell of their nearest node; the others look round more nodes
    for count, rows in ((1, np.arange(len(queries))), (min(near, len(nodes)), None)):
        if rows is None:
            rows = np.flatnonzero(~inside)
        for start in range(0, len(rows), chunk):  # bounds the (k, 8 count, 3, 3) candidates
            part = rows[start : start + chunk]
            distance, nearest = tree.query(queries[part], k=count)
            cell[part], weights[part], inside[part] = _locate_chunk(
                net, nodes, queries[part], distance, nearest, limit
            )
    return cell, weights, inside


def _locate_chunk(net, nodes, queries, distance, nearest, limit):
    count = len(queries)
    cell = np.full((count, 3), -1, dtype=np.int64)
    weights = np.full((count, 3), np.nan)
    valid = net.reached  # the nodes just beyond the mould's edge too
    distance, nearest = distance.reshape(count, -1), nearest.reshape(count, -1)
    nu, nv = valid.shape
    offsets = np.array([[-1, -1], [-1, 0], [0, -1], [0, 0]])
    base = nodes[nearest][:, :, None, :] + offsets  # (k, near, 4, 2) candidate cells
    base = base.reshape(count, -1, 2)
    base = np.repeat(base, 2, axis=1)  # two triangles per cell
    tri = np.tile([0, 1], base.shape[1] // 2)[None, :].repeat(count, axis=0)
    corner_index = base[:, :, None, :] + _CELL_TRIANGLES[tri]  # (k, c, 3, 2)
    inside_grid = (
        (corner_index[..., 0] >= 0)
        & (corner_index[..., 0] < nu)
        & (corner_index[..., 1] >= 0)
        & (corner_index[..., 1] < nv)
    )
    ci = np.clip(corner_index[..., 0], 0, nu - 1)
    cj = np.clip(corner_index[..., 1], 0, nv - 1)
    usable = (inside_grid & valid[ci, cj]).all(axis=-1)
    corners = np.where(usable[..., None, None], net.positions[ci, cj], 0.0)
    corners[~usable] = np.eye(3)  # any non-degenerate triangle; masked below
    lam, height = barycentric(queries[:, None, :], corners)
    margin = np.where(usable, lam.min(axis=-1), -np.inf)
    holds = margin >= -1e-9
    # a triangle that holds the point scores in (1, 2] (the nearer its plane the higher), one
    # that does not scores its margin (< 0)
    score = np.where(holds, 1.0 + 1.0 / (1.0 + np.abs(height) / net.spacing), margin)
    best = np.argmax(score, axis=1)
    rows = np.arange(count)
    inside = holds[rows, best]
    within = inside | ((margin[rows, best] > -np.inf) & (distance[:, 0] <= limit))
    chosen = base[rows, best]
    cell[within, :2] = chosen[within]
    cell[within, 2] = tri[rows, best][within]
    weights[within] = lam[rows, best][within]
    return cell, weights, inside
