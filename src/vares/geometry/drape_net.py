"""Kinematic drape: the pin-jointed net ("fishnet") of a woven ply laid on a mould.

The yarns are inextensible and free to shear at their crossings. From a **seed point** on the
mould and a **warp direction** there, two generator yarns run from the seed along ±warp and ±fill
(fill ⟂ warp in the seed's tangent plane, of the node normals interpolated there): discrete
geodesics (each node ``spacing`` from the one before, the chords turning only along the
interpolated normal) or polylines the user gives. Every other node ``(i, j)`` is the point of the
mould at the distance ``spacing`` from both ``(i ∓ 1, j)`` and ``(i, j ∓ 1)`` (Mack & Taylor 1956,
Van der Weeën 1991), on the side away from ``(i ∓ 1, j ∓ 1)``: the circle where the two spheres
meet, intersected with the plane of a face, the search walking across faces until the point lies
inside the face it was computed with (exact on the triangle mesh). The net runs on up to one
spacing beyond the mould's edge, in the planes of its boundary faces. Nodes are found by
anti-diagonals ``|i| + |j| = k``, all nodes of one diagonal (in all four quadrants) at once.

The shear angle is the decrease of the angle between the yarns from 90°, signed: the angle between
the +warp and +fill yarns of the grid. On a surface of Gauss curvature ``K`` it is ``γ ≈ K u v``
near the seed (``u = i·spacing``, ``v = j·spacing``, signed yarn lengths from the seed); on a
sphere exactly ``γ = f(K u v)`` with ``z f'' + f' = cos f``, ``f(0) = 0`` (Chebyshev nets, see
docs/composites.md). The net implies a flat pattern: the node ``(i, j)`` goes to ``(u, v)``.
:func:`vares.geometry.drape.kinematic_drape` carries the net onto the mould's own cells and
nodes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .face_walk import (
    FaceWalk,
    circle_intersections,
    node_normals,
    smooth_normals,
    sphere_intersections,
)
from .mesh import SurfaceMesh
from .surface_lines import triangulated
from .surface_points import FaceLocator, barycentric

__all__ = [
    "NORMAL_CONE",
    "DrapeError",
    "KinematicNet",
    "chord_nodes",
    "kinematic_net",
    "locate_seed",
    "yarn_shear",
]

NORMAL_CONE = 5.0
"""Degrees: a warp (or reference) direction this close to the mould's normal at the seed is
refused. Its projection onto the tangent plane would be set by the facets' tilt there (about
0.1° at the pole of an irregular hemisphere), not by the direction given."""


class DrapeError(ValueError):
    """A drape that cannot be made (the seed is off the mould, a generator is too short, …)."""


@dataclass(frozen=True)
class KinematicNet:
    """The nodes of a kinematic drape on a ``(nu, nv)`` grid (warp index first).

    ``positions`` ``(nu, nv, 3)``: the nodes, NaN where the net does not reach (beyond the
    mould's edge, or beyond a cell that would shear to ±90°); ``faces`` ``(nu, nv)``: the
    triangle of the (triangulated) mould each node lies in, −1 where there is none; ``seed``: the
    grid index of the seed node; ``spacing``: the yarn spacing (length units of the mesh). The
    net runs on **beyond the mould's edge** by up to one spacing, in the planes of the boundary
    faces it leaves: those nodes have positions but the face −1 (:attr:`reached`, not
    :attr:`valid`), and they complete the net's cells over the edge, so that the net stops where
    it leaves the mould, not a cell short of it.
    """

    positions: np.ndarray
    faces: np.ndarray
    seed: tuple[int, int]
    spacing: float

    @property
    def valid(self) -> np.ndarray:
        """``(nu, nv)`` bool: where the net has a node on the mould."""
        return self.faces >= 0

    @property
    def reached(self) -> np.ndarray:
        """``(nu, nv)`` bool: where the net has a node, on the mould or just beyond its edge."""
        return np.isfinite(self.positions[..., 0])

    @property
    def yarn_lengths(self) -> tuple[np.ndarray, np.ndarray]:
        """Signed yarn lengths from the seed: ``u = (i − seed_i)·spacing`` ``(nu, 1)`` along the
        warp and ``v = (j − seed_j)·spacing`` ``(1, nv)`` along the fill."""
        nu, nv = self.faces.shape
        u = (np.arange(nu) - self.seed[0])[:, None] * self.spacing
        v = (np.arange(nv) - self.seed[1])[None, :] * self.spacing
        return u, v

    @property
    def flat(self) -> np.ndarray:
        """The flat pattern of the nodes ``(nu, nv, 2)``: ``(u, v)``, NaN where there is no node."""
        u, v = self.yarn_lengths
        flat = np.stack(np.broadcast_arrays(u, v), axis=-1).astype(float)
        flat[~self.reached] = np.nan
        return flat

    @property
    def node_shear(self) -> np.ndarray:
        """Shear angle at each node ``(nu, nv)`` in degrees, from the yarns through the node's
        two neighbours on each side (centred: second-order accurate); NaN at the net's edge."""
        p = self.positions
        nan = np.full_like(p[:1], np.nan)
        warp = np.concatenate([nan, p[2:] - p[:-2], nan], axis=0)
        nan = np.full_like(p[:, :1], np.nan)
        fill = np.concatenate([nan, p[:, 2:] - p[:, :-2], nan], axis=1)
        return yarn_shear(warp, fill)

    @property
    def cell_shear(self) -> np.ndarray:
        """Shear angle of each net cell ``(nu − 1, nv − 1)`` in degrees: between the mean warp
        (its two warp sides) and the mean fill (its two fill sides); NaN for incomplete cells."""
        warp, fill = self.cell_yarns()
        return yarn_shear(warp, fill)

    def cell_yarns(self) -> tuple[np.ndarray, np.ndarray]:
        """The mean warp and fill vectors of every net cell, ``(nu − 1, nv − 1, 3)`` each (sums
        of the cell's two sides of each family: twice the mean)."""
        p = self.positions
        warp = (p[1:, :-1] - p[:-1, :-1]) + (p[1:, 1:] - p[:-1, 1:])
        fill = (p[:-1, 1:] - p[:-1, :-1]) + (p[1:, 1:] - p[1:, :-1])
        return warp, fill


def yarn_shear(warp: np.ndarray, fill: np.ndarray) -> np.ndarray:
    """Shear angles ``(...)`` in degrees, ``90° − ∠(warp, fill)``, of yarn vectors ``(..., 3)``."""
    with np.errstate(invalid="ignore", divide="ignore"):
        cosine = np.einsum("...i,...i->...", warp, fill) / (
            np.linalg.norm(warp, axis=-1) * np.linalg.norm(fill, axis=-1)
        )
    return 90.0 - np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


def chord_nodes(polyline: np.ndarray, spacing: float) -> np.ndarray:
    """Points ``(k, 3)`` along a polyline ``(p, 3)``, each at the straight distance ``spacing``
    from the one before, the first from the polyline's start (which is not included); as many as
    fit before the polyline ends."""
    polyline = np.asarray(polyline, dtype=float)
    nodes, current, segment = [], polyline[0], 0
    while segment < len(polyline) - 1:
        ahead = np.linalg.norm(polyline[segment + 1 :] - current, axis=1)
        beyond = np.flatnonzero(ahead >= spacing)
        if not beyond.size:
            break
        end = segment + 1 + int(beyond[0])
        a, b = polyline[end - 1], polyline[end]
        # |a + t (b − a) − current| = spacing, the root in [0, 1] (a is nearer than spacing)
        d, w = b - a, a - current
        qa, qb, qc = d @ d, 2 * d @ w, w @ w - spacing**2
        t = (-qb + np.sqrt(max(qb * qb - 4 * qa * qc, 0.0))) / (2 * qa)
        current = a + t * d
        nodes.append(current)
        segment = end - 1
    return np.array(nodes).reshape(-1, 3)


def kinematic_net(
    mesh: SurfaceMesh,
    seed: np.ndarray,
    warp_direction: np.ndarray,
    spacing: float,
    *,
    generators: tuple[np.ndarray, np.ndarray] | None = None,
    max_length: float | None = None,
) -> KinematicNet:
    """The kinematic drape's net from ``seed`` ``(3,)`` with the warp along ``warp_direction``
    ``(3,)`` (projected onto the mould's tangent plane at the seed) and yarns ``spacing`` apart.

    ``generators``: the warp and fill generator yarns as polylines ``(p, 3)`` on the mould through
    the seed (each is split at its point nearest the seed; the half whose start points along
    ``warp_direction``, respectively the fill, is the + half), instead of the geodesics.
    ``max_length``: the longest generator yarn each way (default: twice the mould's bounding-box
    diagonal). Quads are triangulated first.
    """
    if not spacing > 0:
        raise DrapeError(f"the yarn spacing must be positive; got {spacing}")
    tri_mesh = triangulated(mesh)
    triangles = tri_mesh.cells["triangle"]
    locator = FaceLocator(tri_mesh)
    size = float(np.linalg.norm(np.ptp(tri_mesh.points, axis=0)))
    face, bary, seed_point = locate_seed(tri_mesh, seed, locator)
    at_nodes = node_normals(tri_mesh)
    normal = smooth_normals(at_nodes, triangles, np.array([face]), bary[None])[0]
    warp = np.asarray(warp_direction, dtype=float).reshape(3)
    length = float(np.linalg.norm(warp))
    warp = warp - (warp @ normal) * normal
    if not np.linalg.norm(warp) > np.sin(np.radians(NORMAL_CONE)) * length:
        raise DrapeError(
            f"the warp direction is within {NORMAL_CONE:g}° of the mould's normal at the seed "
            f"({np.round(normal, 4).tolist()}): it gives no direction along the mould"
        )
    warp /= np.linalg.norm(warp)
    fill = np.cross(normal, warp)
    walk = FaceWalk.of(tri_mesh, spacing)
    if generators is None:
        length = 2.0 * size if max_length is None else float(max_length)
        yarns, beyond = _geodesic_generators(
            walk, at_nodes, face, seed_point, normal, (warp, fill), spacing, length
        )
    else:
        halves = _given_generators(generators, seed_point, warp, fill)
        yarns = [chord_nodes(y, spacing) for y in halves]
        beyond = [np.zeros(len(y), dtype=bool) for y in yarns]
    warp_minus, warp_plus, fill_minus, fill_plus = yarns

    nu = len(warp_minus) + 1 + len(warp_plus)
    nv = len(fill_minus) + 1 + len(fill_plus)
    si, sj = len(warp_minus), len(fill_minus)
    positions = np.full((nu, nv, 3), np.nan)
    positions[si, sj] = seed_point
    positions[si + 1 :, sj] = warp_plus
    positions[:si, sj] = warp_minus[::-1]
    positions[si, sj + 1 :] = fill_plus
    positions[si, :sj] = fill_minus[::-1]
    off = np.zeros((nu, nv), dtype=bool)  # beyond the mould's edge
    off[si + 1 :, sj], off[:si, sj] = beyond[1], beyond[0][::-1]
    off[si, sj + 1 :], off[si, :sj] = beyond[3], beyond[2][::-1]
    planes = np.full((nu, nv), -1, dtype=np.int64)  # the face each node's walk ended in
    on_axes = np.isfinite(positions[..., 0])
    planes[on_axes] = locator.locate(positions[on_axes])[0]
    planes[si, sj] = face
    _march(positions, planes, off, (si, sj), spacing, walk)
    faces = np.where(off, -1, planes)
    return KinematicNet(positions, faces, (si, sj), float(spacing))


def locate_seed(
    mesh: SurfaceMesh, seed: np.ndarray, locator: FaceLocator | None = None
) -> tuple[int, np.ndarray, np.ndarray]:
    """The triangle, barycentric coordinates ``(3,)`` and nearest point ``(3,)`` of ``seed``
    ``(3,)`` on the triangulated mould ``mesh`` (``locator``: its :class:`FaceLocator`, built if
    not given). Raises :class:`DrapeError` when the seed lies farther from the mould than the
    size of the triangle nearest it."""
    mesh = triangulated(mesh)
    locator = FaceLocator(mesh) if locator is None else locator
    seed = np.asarray(seed, dtype=float).reshape(3)
    if not np.isfinite(seed).all():
        raise DrapeError(f"the seed must be three finite numbers; got {seed.tolist()}")
    face, bary, point = (a[0] for a in locator.locate(seed[None]))
    reach = np.ptp(mesh.points[mesh.cells["triangle"][face]], axis=0).max()
    if np.linalg.norm(point - seed) > reach:
        where, nearest = (", ".join(f"{v:.6g}" for v in p) for p in (seed, point))
        raise DrapeError(f"the seed ({where}) is not on the mould (nearest point ({nearest}))")
    return int(face), bary, point


def _geodesic_generators(
    walk, node_normals, face, seed, seed_normal, directions, spacing, length
) -> list[np.ndarray]:
    """The generator yarns' nodes along −warp, +warp, −fill, +fill from ``seed``, each
    ``(k, 3)`` without the seed, and which of them lie beyond the mould's edge ``(k,)``: every
    node at the chord distance ``spacing`` from the one before, in the plane of the previous
    chord and the interpolated normal there (the chords turn only along the surface's normal: a
    discrete geodesic). The four are walked together until they leave the mould (the first node
    beyond its edge, within ``spacing`` of it, is the last) or reach ``length``."""
    warp, fill = directions
    heading = np.array([-warp, warp, -fill, fill])
    point = np.repeat(seed[None], 4, axis=0)
    where = np.full(4, face, dtype=np.int64)
    normal = np.repeat(seed_normal[None], 4, axis=0)
    yarns: list[list[np.ndarray]] = [[], [], [], []]
    beyond: list[list[bool]] = [[], [], [], []]
    active = np.arange(4)
    for _ in range(int(length / spacing)):
        if not active.size:
            break
        along = (
            heading[active]
            - np.einsum("ki,ki->k", heading[active], normal[active])[:, None] * normal[active]
        )
        along /= np.linalg.norm(along, axis=1)[:, None]
        across = normal[active]
        radius = np.full(len(active), float(spacing))
        found, faces, off = circle_intersections(
            point[active], radius, along, across, where[active], walk, beyond=spacing
        )
        ok = faces >= 0
        rows = active[ok]
        edge = set(active[ok & off].tolist())
        heading[rows] = found[ok] - point[rows]
        point[rows], where[rows] = found[ok], faces[ok]
        bary, _ = barycentric(found[ok], walk.corners[faces[ok]])
        normal[rows] = smooth_normals(node_normals, walk.triangles, faces[ok], bary)
        for r in rows:
            yarns[r].append(point[r].copy())
            beyond[r].append(r in edge)
        active = rows[~np.isin(rows, list(edge))]
    return [np.array(y).reshape(-1, 3) for y in yarns], [np.array(b, dtype=bool) for b in beyond]


def _given_generators(generators, seed, warp, fill) -> list[np.ndarray]:
    halves = []
    for polyline, direction in zip(generators, (warp, fill), strict=True):
        polyline = np.asarray(polyline, dtype=float).reshape(-1, 3)
        if len(polyline) < 2:
            raise DrapeError("a generator yarn needs at least two points")
        k = int(np.argmin(np.linalg.norm(polyline - seed, axis=1)))
        ahead = np.vstack([seed, polyline[k + 1 :]]) if k + 1 < len(polyline) else seed[None]
        behind = np.vstack([seed, polyline[:k][::-1]]) if k > 0 else seed[None]
        if len(ahead) == 1 or (ahead[1] - seed) @ direction < 0:
            ahead, behind = behind, ahead
        halves += [behind, ahead]
    return halves


def _march(positions, faces, off, seed, spacing, walk: FaceWalk) -> None:
    """Fill the nodes off the generator yarns in place, by anti-diagonals from the seed:
    ``positions``, ``faces`` (the face each node's walk ended in) and ``off`` (the node lies
    beyond the mould's edge, in that face's plane)."""
    nu, nv = faces.shape
    a, b = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    i, j = a - seed[0], b - seed[1]
    level = np.abs(i) + np.abs(j)
    inner = (i != 0) & (j != 0)
    di, dj = np.sign(i), np.sign(j)
    for k in range(2, int(level.max(initial=0)) + 1):
        ta, tb = np.nonzero(inner & (level == k))
        ia, jb = ta - di[ta, tb], tb - dj[ta, tb]
        start = faces[ia, tb]
        ready = (start >= 0) & (faces[ta, jb] >= 0) & (faces[ia, jb] >= 0)
        ta, tb, ia, jb, start = ta[ready], tb[ready], ia[ready], jb[ready], start[ready]
        if not ta.size:
            continue
        point, face, beyond = sphere_intersections(
            positions[ia, jb],
            positions[ia, tb],
            positions[ta, jb],
            start,
            spacing,
            walk,
        )
        positions[ta, tb] = point
        faces[ta, tb] = face
        off[ta, tb] = beyond
