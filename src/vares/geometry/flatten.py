"""Initial guesses: orthogonal projection onto a plane, a conformal flattening (LSCM), or
Tutte's embedding, which never folds a disk.

The plane also defines the pseudo-time path of DESIGN.md §1: ``x(τ) = P(x) + τ (x − P(x))``
with ``P`` the orthogonal projection onto it, so that at ``τ = 0`` the projected coordinates
are the exact stress-free pattern. Where the projection folds or flattens cells badly (a surface
steeper than about 78° to the plane, or turning by more than 180°), the least-squares conformal
map is the better start.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .elements import ELEMENTS
from .mesh import SurfaceMesh

__all__ = [
    "PlaneSpec",
    "ProjectionPlane",
    "factorized",
    "inverted_cells",
    "lscm",
    "projection_distortion",
    "projection_plane",
    "signed_area",
    "squashed_share",
    "triangle_gradients",
    "triangulated",
    "tutte",
    "untangle",
]

_NAMED_PLANES = {
    "xy": (0, 1),
    "x-y": (0, 1),
    "yz": (1, 2),
    "y-z": (1, 2),
    "zx": (2, 0),
    "z-x": (2, 0),
    "xz": (0, 2),
    "x-z": (0, 2),
}

PlaneSpec = str | Sequence[float] | np.ndarray | None


@dataclass(frozen=True)
class ProjectionPlane:
    """A plane through ``origin`` with orthonormal in-plane axes ``axes[0]``, ``axes[1]`` and
    ``normal = axes[0] × axes[1]``. Pattern coordinates are ``(x − origin) · axes``.
    """

    origin: np.ndarray
    axes: np.ndarray  # (2, 3)

    @property
    def normal(self) -> np.ndarray:
        return np.cross(self.axes[0], self.axes[1])

    def project(self, points: np.ndarray) -> np.ndarray:
        """In-plane coordinates ``(n, 2)`` of 3D points ``(n, 3)``."""
        return (points - self.origin) @ self.axes.T

    def height(self, points: np.ndarray) -> np.ndarray:
        """Signed distance of each point from the plane."""
        return (points - self.origin) @ self.normal

    def lift(self, points: np.ndarray, tau: float) -> np.ndarray:
        """The pseudo-time surface ``P(x) + τ (x − P(x))``."""
        return points - (1.0 - tau) * np.outer(self.height(points), self.normal)


def signed_area(mesh: SurfaceMesh, coordinates: np.ndarray) -> float:
    """Total signed area of the mesh laid out at 2D ``coordinates`` (negative if mirrored)."""
    return float(sum(ELEMENTS[t].areas(coordinates, c).sum() for t, c in mesh.cells.items()))


def projection_plane(mesh: SurfaceMesh, plane: PlaneSpec = None) -> ProjectionPlane:
    """The plane of the initial guess.

    ``plane`` is ``None`` or ``"best-fit"`` (least-squares plane of the nodes), a coordinate
    plane name (``"xy"``, ``"yz"``, ``"zx"``, also written ``"x-y"`` …) or a normal vector
    ``(3,)``. The in-plane axes are chosen so that the projected cells keep the mesh's
    orientation (positive area); with a coordinate plane they are the coordinate axes when
    possible, e.g. ``"xy"`` gives pattern coordinates ``(x, y)`` for a mesh facing +z.
    """
    points = mesh.points
    origin = points.mean(axis=0)
    if plane is None or (isinstance(plane, str) and plane.lower() in ("best-fit", "bestfit")):
        _, _, vt = np.linalg.svd(points - origin, full_matrices=False)
        normal = vt[2]
        first = None
    elif isinstance(plane, str):
        key = plane.lower().replace(" ", "")
        if key not in _NAMED_PLANES:
            raise ValueError(
                f"unknown plane {plane!r}; use 'best-fit', 'xy', 'yz', 'zx' or a normal vector"
            )
        i, j = _NAMED_PLANES[key]
        eye = np.eye(3)
        first, normal = eye[i], np.cross(eye[i], eye[j])
    else:
        normal = np.asarray(plane, dtype=float)
        if normal.shape != (3,) or not np.all(np.isfinite(normal)) or not normal.any():
            raise ValueError(f"a plane normal must be a non-zero finite 3-vector; got {plane!r}")
        first = None
    normal = normal / np.linalg.norm(normal)
    if first is None:
        # First axis: the global axis that lies most in the plane, projected onto it.
        eye = np.eye(3)
        candidate = eye[np.argmin(np.abs(eye @ normal))]
        first = candidate - (candidate @ normal) * normal
    first = first / np.linalg.norm(first)
    axes = np.array([first, np.cross(normal, first)])
    if signed_area(mesh, mesh.points @ axes.T) < 0:
        axes[1] = -axes[1]  # view from the other side so the pattern keeps the cell orientation
    return ProjectionPlane(origin, axes)


def triangulated(mesh: SurfaceMesh) -> np.ndarray:
    """All cells as triangles (quads split along their 0–2 diagonal), ``(k, 3)``."""
    parts = []
    for cell_type, cells in mesh.cells.items():
        if cell_type == "triangle":
            parts.append(cells)
        else:
            parts.append(cells[:, [0, 1, 2]])
            parts.append(cells[:, [0, 2, 3]])
    return np.vstack(parts)


def lscm(mesh: SurfaceMesh, factorize: Callable | None = None) -> np.ndarray:
    """Least-squares conformal map (Lévy et al. 2002) of the surface, scaled to its 3D area.

    Minimises ``Σ_t A_t |∇v − R₉₀ ∇u|²`` (the Cauchy–Riemann residual of each triangle in its own
    plane) with two far-apart nodes pinned, by one sparse direct solve of the normal equations.
    The map keeps the cells' orientation; it is conformal, not isometric, so it is rescaled to
    the 3D area. Returns pattern coordinates ``(n, 2)``. ``factorize``: a function from the
    (symmetric positive definite) normal matrix to its solver ``rhs ↦ x`` (default
    :func:`factorized`; the solve passes its own sparse solver, PARDISO factorising the lion's
    in a fraction of SuperLU's time, docs/benchmarks.md).
    """
    import scipy.sparse as sp

    points = mesh.points
    tris = triangulated(mesh)
    gx, gy, areas = triangle_gradients(points, tris)
    weight = np.sqrt(areas)[:, None]
    n, k = mesh.num_points, len(tris)
    rows = np.repeat(np.arange(k), 3).reshape(k, 3)
    # unknowns: u at 2i, v at 2i+1; residuals r1 = u_x − v_y, r2 = u_y + v_x
    data = np.concatenate(
        [
            (weight * gx).ravel(),
            (-weight * gy).ravel(),
            (weight * gy).ravel(),
            (weight * gx).ravel(),
        ]
    )
    row_index = np.concatenate(
        [2 * rows.ravel(), 2 * rows.ravel(), 2 * rows.ravel() + 1, 2 * rows.ravel() + 1]
    )
    col_index = np.concatenate(
        [2 * tris.ravel(), 2 * tris.ravel() + 1, 2 * tris.ravel(), 2 * tris.ravel() + 1]
    )
    matrix = sp.csr_matrix((data, (row_index, col_index)), shape=(2 * k, 2 * n))

    centred = points - points.mean(axis=0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    first, second = int(np.argmin(centred @ axis)), int(np.argmax(centred @ axis))
    pinned = np.array([2 * first, 2 * first + 1, 2 * second, 2 * second + 1])
    pinned_values = np.array([0.0, 0.0, np.linalg.norm(points[second] - points[first]), 0.0])
    free = np.setdiff1d(np.arange(2 * n), pinned)
    a_free, a_pinned = matrix[:, free], matrix[:, pinned]
    normal_matrix = (a_free.T @ a_free).tocsc()
    rhs = -(a_free.T @ (a_pinned @ pinned_values))
    solution = np.empty(2 * n)
    solution[pinned] = pinned_values
    solution[free] = (factorize or factorized)(normal_matrix)(rhs)
    coordinates = solution.reshape(-1, 2)
    coordinates -= coordinates.mean(axis=0)
    flat_area = signed_area(mesh, coordinates)
    if flat_area <= 0:
        raise ValueError("the conformal map is degenerate for this surface")
    return coordinates * np.sqrt(mesh.area / flat_area)


def triangle_gradients(
    points: np.ndarray, triangles: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The gradients of the three linear shape functions of each triangle ``(k, 3)`` in its own
    plane, along its first edge (``gx``) and across it (``gy``), each ``(k, 3)`` (1/length), and
    the triangles' areas ``(k,)``. A field ``u`` of the nodes has the gradient
    ``(gx · u[t], gy · u[t])`` in triangle ``t``."""
    p0, p1, p2 = points[triangles[:, 0]], points[triangles[:, 1]], points[triangles[:, 2]]
    e1, e2 = p1 - p0, p2 - p0
    normal = np.cross(e1, e2)
    double_area = np.linalg.norm(normal, axis=1)
    ex = e1 / np.linalg.norm(e1, axis=1)[:, None]
    ey = np.cross(normal / double_area[:, None], ex)
    # local coordinates of the corners: (0, 0), (x1, 0), (x2, y2)
    x1 = np.einsum("ij,ij->i", e1, ex)
    x2 = np.einsum("ij,ij->i", e2, ex)
    y2 = np.einsum("ij,ij->i", e2, ey)
    gx = np.column_stack([-y2, y2, np.zeros_like(y2)]) / (x1 * y2)[:, None]
    gy = np.column_stack([x2 - x1, -x2, x1]) / (x1 * y2)[:, None]
    return gx, gy, 0.5 * double_area


def factorized(matrix):
    """A solver ``rhs ↦ x`` for a sparse ``matrix`` that is symmetric positive definite or
    diagonally dominant (the Laplacians and normal equations of the flattenings), factorised
    once: SuperLU with a symmetric ordering (minimum degree on ``AᵀA + A``) and pivots on the
    diagonal, which such a matrix needs no others than; several times faster than its default
    column ordering on a surface's Laplacian. ``rhs`` ``(m,)`` or ``(m, k)``."""
    from scipy.sparse.linalg import splu

    factors = splu(
        matrix.tocsc(),
        permc_spec="MMD_AT_PLUS_A",
        diag_pivot_thresh=0.0,
        options={"SymmetricMode": True},
    )
    return factors.solve


def inverted_cells(mesh: SurfaceMesh, coordinates: np.ndarray) -> np.ndarray:
    """Global ids of the cells a pattern ``(n, 2)`` inverts or collapses (``det J ≤ 0`` at a
    check point: a triangle's one value, a quad's corners)."""
    out, offset = [], 0
    for cell_type, cells in mesh.cells.items():
        j = ELEMENTS[cell_type].jacobians(coordinates, cells, at="check")
        det = j[..., 0, 0] * j[..., 1, 1] - j[..., 0, 1] * j[..., 1, 0]
        out.append(offset + np.flatnonzero(~(det > 0).all(axis=1)))
        offset += len(cells)
    return np.concatenate(out)


def projection_distortion(mesh: SurfaceMesh, plane: ProjectionPlane) -> float:
    """Smallest ratio of projected to 3D area element over all cells (≤ 0 where it folds).

    Evaluated where ``det J`` is checked (a triangle's single value, a quad's corners): 1 for a
    surface parallel to the plane, ``cos θ`` where the surface is inclined by ``θ``.
    """
    return float(_projected_area_ratios(mesh, plane)[0].min())


def squashed_share(mesh: SurfaceMesh, plane: ProjectionPlane, ratio: float) -> float:
    """The share of the surface's area whose projection onto ``plane`` keeps less than
    ``ratio`` of its area (or folds): where the surface is steeper than ``arccos(ratio)``. A
    few noisy slivers of a scan weigh nothing here, unlike in :func:`projection_distortion`."""
    ratios, areas = _projected_area_ratios(mesh, plane)
    return float(areas[ratios < ratio].sum() / areas.sum())


def _projected_area_ratios(mesh: SurfaceMesh, plane: ProjectionPlane):
    """Projected / 3D area element at every check point, and the 3D area it stands for."""
    coordinates = plane.project(mesh.points)
    ratios, areas = [], []
    for cell_type, cells in mesh.cells.items():
        element = ELEMENTS[cell_type]
        j = element.jacobians(coordinates, cells, at="check")
        det = j[..., 0, 0] * j[..., 1, 1] - j[..., 0, 1] * j[..., 1, 0]
        corner = element.corner_areas(mesh.points, cells)
        ratios.append((det / corner).ravel())
        areas.append(np.broadcast_to(corner, det.shape).ravel())
    return np.concatenate(ratios), np.concatenate(areas)


def tutte(
    mesh: SurfaceMesh,
    conformal: np.ndarray | None = None,
    factorize: Callable | None = None,
) -> np.ndarray:
    """Tutte's embedding with mean-value weights (Floater 2003): one-to-one on any disk-like
    triangle mesh, whatever its shape. Returns pattern coordinates ``(n, 2)``.

    The outer boundary is laid on an ellipse shaped like the conformal map's boundary (its
    principal axes and aspect), at positions proportional to the 3D arc length; every inner
    node is the mean-value-weighted average of its neighbours (one sparse solve). Holes are
    closed for the solve by a node at their centre joined to the hole's boundary. The result
    keeps the cells' orientation and is scaled to the 3D area. Quads are split along a diagonal
    for the weights; a strongly non-convex quad may still fold (it is checked by the caller).
    ``conformal``: the conformal map (:func:`lscm`) if the caller has it already.
    ``factorize``: a function from the (unsymmetric) system matrix to its solver ``rhs ↦ x``
    (default :func:`factorized`, SuperLU; the solve passes PARDISO's LU where it has PARDISO,
    :func:`vares.solver.linear.unsymmetric_factorizer`).
    """
    import scipy.sparse as sp

    loops = sorted(mesh.boundary_loops(), key=lambda loop: _loop_length(mesh.points, loop))
    outer, holes = loops[-1], loops[:-1]
    points, triangles = _closed_holes(mesh.points, triangulated(mesh), holes)
    n = len(points)
    rows, cols, weights = _mean_value_weights(points, triangles)
    laplacian = sp.csr_matrix((weights, (rows, cols)), shape=(n, n))
    laplacian = sp.diags(np.asarray(laplacian.sum(axis=1)).ravel()) - laplacian
    boundary_xy = _ellipse(mesh, outer, conformal)
    inner = np.setdiff1d(np.arange(n), outer)
    rhs = -laplacian[inner][:, outer] @ boundary_xy
    coordinates = np.empty((n, 2))
    coordinates[outer] = boundary_xy
    system = laplacian[inner][:, inner].tocsc()
    coordinates[inner] = (factorize or factorized)(system)(np.asarray(rhs))
    coordinates = coordinates[: mesh.num_points]
    area = signed_area(mesh, coordinates)
    if area < 0:
        coordinates[:, 1] = -coordinates[:, 1]
        area = -area
    coordinates -= coordinates.mean(axis=0)
    return coordinates * np.sqrt(mesh.area / area)


def untangle(
    mesh: SurfaceMesh, coordinates: np.ndarray, rings: tuple[int, ...] = (1, 2, 3, 5, 8)
) -> np.ndarray | None:
    """A pattern whose few folded cells are mended where they are: the nodes within ``k`` rings
    of cells around them are placed again as the mean-value-weighted average of their
    neighbours (Tutte's embedding of that patch, its rim and the mesh boundary held), for each
    ``k`` of ``rings`` in turn until no cell folds. The rest of the pattern is untouched: a
    rough scan's projection with a few flipped slivers stays as close to the optimum as it was,
    where Tutte's embedding of the whole would start far from it. ``None`` when the folds
    persist (one held on the boundary, or too many); the input when nothing folds.
    """
    import scipy.sparse as sp

    inverted = inverted_cells(mesh, coordinates)
    if not inverted.size:
        return coordinates
    n = mesh.num_points
    rows, cols, weights = _mean_value_weights(mesh.points, triangulated(mesh))
    laplacian = sp.csr_matrix((weights, (rows, cols)), shape=(n, n))
    laplacian = (sp.diags(np.asarray(laplacian.sum(axis=1)).ravel()) - laplacian).tocsr()
    blocks = list(mesh.cells.values())
    cell_nodes = [block.ravel() for block in blocks]
    owner = np.concatenate(
        [offset + np.repeat(np.arange(len(b)), b.shape[1]) for offset, b in _offsets(blocks)]
    )
    incidence = sp.csr_matrix(
        (np.ones(owner.size), (owner, np.concatenate(cell_nodes))), shape=(mesh.num_cells, n)
    )
    held = np.zeros(n, dtype=bool)
    for loop in mesh.boundary_loops():
        held[loop] = True
    patch = np.zeros(n, dtype=bool)
    patch[np.unique(incidence[inverted].indices)] = True
    grown = 0
    for ring in rings:
        while grown < ring:  # one more ring of cells: every node of a cell touching the patch
            cells = np.flatnonzero(incidence @ patch.astype(float))
            inner, patch = patch, np.zeros(n, dtype=bool)
            patch[np.unique(incidence[cells].indices)] = True
            grown += 1
        free = np.flatnonzero(inner & ~held)
        if not free.size:
            continue
        fixed = np.flatnonzero(~np.isin(np.arange(n), free))
        trial = coordinates.copy()
        system = laplacian[free][:, free].tocsc()
        rhs = -laplacian[free][:, fixed] @ coordinates[fixed]
        trial[free] = factorized(system)(np.asarray(rhs))
        if not inverted_cells(mesh, trial).size:
            return trial
    return None


def _offsets(blocks: list[np.ndarray]):
    offset = 0
    for block in blocks:
        yield offset, block
        offset += len(block)


def _loop_length(points: np.ndarray, loop: np.ndarray) -> float:
    ring = points[np.append(loop, loop[0])]
    return float(np.linalg.norm(np.diff(ring, axis=0), axis=1).sum())


def _closed_holes(points, triangles, holes):
    """Points and triangles with a node added at the centre of each hole, joined to it."""
    extra_points, extra_triangles = [], []
    for k, hole in enumerate(holes):
        centre = len(points) + k
        extra_points.append(points[hole].mean(axis=0))
        # the hole's loop runs against the surrounding cells: close it the other way round
        extra_triangles.append(
            np.column_stack([np.roll(hole, -1), hole, np.full(len(hole), centre)])
        )
    if not holes:
        return points, triangles
    return np.vstack([points, extra_points]), np.vstack([triangles, *extra_triangles])


def _mean_value_weights(points, triangles):
    """``w_ij = (tan(α_i/2) + tan(β_i/2)) / |x_i − x_j|`` summed over the triangles at edge
    ``ij`` (α, β the angles at ``i`` beside the edge): positive on any mesh."""
    rows, cols, values = [], [], []
    for k in range(3):
        i, j, m = triangles[:, k], triangles[:, (k + 1) % 3], triangles[:, (k + 2) % 3]
        a, b = points[j] - points[i], points[m] - points[i]
        la, lb = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
        cosine = np.clip(np.einsum("ij,ij->i", a, b) / (la * lb), -1.0, 1.0)
        half_tan = np.tan(0.5 * np.arccos(cosine))
        rows += [i, i]
        cols += [j, m]
        values += [half_tan / la, half_tan / lb]
    return np.concatenate(rows), np.concatenate(cols), np.concatenate(values)


def _ellipse(mesh: SurfaceMesh, outer: np.ndarray, conformal: np.ndarray | None) -> np.ndarray:
    """Positions of the outer loop's nodes on an ellipse with the conformal boundary's axes."""
    ring = mesh.points[np.append(outer, outer[0])]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(ring, axis=0), axis=1))])
    angle = 2 * np.pi * arc[:-1] / arc[-1]
    try:
        shape = (lscm(mesh) if conformal is None else conformal)[outer]
    except (ValueError, RuntimeError):
        shape = mesh.points[outer][:, :2]
    centred = shape - shape.mean(axis=0)
    _, spread, axes = np.linalg.svd(centred, full_matrices=False)
    ratio = spread[1] / spread[0] if spread[0] > 0 else 1.0
    ratio = max(ratio, 0.05)  # a very thin ellipse would squeeze the inner nodes together
    return np.column_stack([np.cos(angle), ratio * np.sin(angle)]) @ axes
