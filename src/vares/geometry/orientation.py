"""Fibre orientation on the erected surface: where the warp runs once the pattern is erected.

The warp of a pattern is the constant direction ``Φ₁`` of the pattern plane; erected, it runs along
``F Φ₁`` on the surface. A designer prescribes a 3D direction ``d`` instead: the deviation of a
quadrature point is the signed angle, about the surface normal, from ``d`` projected onto the
tangent plane to ``F Φ₁``. Its 3D-area-weighted mean is what vares drives to zero.
"""

from __future__ import annotations

import numpy as np

from .elements import ELEMENTS, inverse
from .mesh import SurfaceMesh

__all__ = ["erected_warp", "warp_deviation"]

#: Points where the prescribed direction is within this angle (rad) of the normal are skipped.
_MIN_TANGENTIAL = 1e-3


def warp_deviation(
    mesh: SurfaceMesh, coordinates: np.ndarray, warp: np.ndarray, direction: np.ndarray
) -> tuple[float, np.ndarray]:
    """Mean and per-cell deviation (radians) of the erected warp from a 3D ``direction``.

    Parameters
    ----------
    mesh, coordinates
        The surface and a pattern ``(n, 2)`` of it.
    warp
        Unit warp direction in the pattern plane, ``(2,)``.
    direction
        The 3D direction the warp should follow, ``(3,)``.

    Returns
    -------
    mean, per_cell
        The 3D-area-weighted mean deviation and the per-cell mean (NaN where ``direction`` is
        normal to the surface over the whole cell). Positive means the warp runs counter-clockwise
        of ``direction`` seen against the surface normal.

    Raises
    ------
    ValueError
        ``direction`` is zero, or normal to the surface everywhere.
    """
    direction = np.asarray(direction, dtype=float)
    if direction.shape != (3,) or not np.all(np.isfinite(direction)) or not direction.any():
        raise ValueError(f"the warp direction must be a non-zero 3-vector; got {direction!r}")
    direction = direction / np.linalg.norm(direction)
    total_angle, total_weight, per_cell = 0.0, 0.0, []
    for cell_type, cells in mesh.cells.items():
        element = ELEMENTS[cell_type]
        j = element.jacobians(mesh.points, cells)  # (m, q, 3, 2)
        J = element.jacobians(coordinates, cells)  # (m, q, 2, 2)
        erected = np.einsum("mqik,mqkl,l->mqi", j, inverse(J), warp)
        normal = np.cross(j[..., 0], j[..., 1])
        area = np.linalg.norm(normal, axis=-1)
        normal /= area[..., None]
        tangential = direction - (normal @ direction)[..., None] * normal
        usable = np.linalg.norm(tangential, axis=-1) > _MIN_TANGENTIAL
        angle = np.arctan2(
            np.einsum("mqi,mqi->mq", np.cross(tangential, erected), normal),
            np.einsum("mqi,mqi->mq", tangential, erected),
        )
        weight = np.where(usable, area * element.quadrature_weights, 0.0)
        total_angle += float(np.sum(weight * angle))
        total_weight += float(np.sum(weight))
        with np.errstate(invalid="ignore", divide="ignore"):
            per_cell.append(np.sum(weight * angle, axis=1) / np.sum(weight, axis=1))
    if total_weight == 0.0:
        raise ValueError("the warp direction is normal to the surface everywhere")
    return total_angle / total_weight, np.concatenate(per_cell)


def erected_warp(mesh: SurfaceMesh, coordinates: np.ndarray, warp: np.ndarray) -> np.ndarray:
    """The 3D-area-weighted mean direction ``(3,)`` (unit) of a pattern's erected warp
    ``F Φ₁ / |F Φ₁|`` over the surface (``warp`` ``(2,)`` in the pattern plane)."""
    total = np.zeros(3)
    for cell_type, cells in mesh.cells.items():
        element = ELEMENTS[cell_type]
        j = element.jacobians(mesh.points, cells)  # (m, q, 3, 2)
        J = element.jacobians(coordinates, cells)  # (m, q, 2, 2)
        erected = np.einsum("mqik,mqkl,l->mqi", j, inverse(J), np.asarray(warp, dtype=float))
        erected /= np.linalg.norm(erected, axis=-1, keepdims=True)
        area = np.linalg.norm(np.cross(j[..., 0], j[..., 1]), axis=-1)
        total += np.einsum("mq,q,mqi->i", area, element.quadrature_weights, erected)
    return total / np.linalg.norm(total)
