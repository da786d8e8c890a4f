"""Initial guesses: orthogonal projection onto a plane.

The plane also defines the pseudo-time path of DESIGN.md §1: ``x(τ) = P(x) + τ (x − P(x))``
with ``P`` the orthogonal projection onto it, so that at ``τ = 0`` the projected coordinates
are the exact stress-free pattern.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .elements import ELEMENTS
from .mesh import SurfaceMesh

__all__ = ["ProjectionPlane", "projection_plane"]

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


def _signed_projected_area(mesh: SurfaceMesh, axes: np.ndarray) -> float:
    coordinates = mesh.points @ axes.T
    total = 0.0
    for cell_type, cells in mesh.cells.items():
        element = ELEMENTS[cell_type]
        j = element.jacobians(coordinates, cells)
        det = j[..., 0, 0] * j[..., 1, 1] - j[..., 0, 1] * j[..., 1, 0]
        total += float(np.sum(det @ element.quadrature_weights))
    return total


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
    if _signed_projected_area(mesh, axes) < 0:
        axes[1] = -axes[1]  # view from the other side so the pattern keeps the cell orientation
    return ProjectionPlane(origin, axes)
