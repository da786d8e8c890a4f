"""Gauss curvature of a triangle mesh, and the sign of the curvature a ply must take up.

At an interior node the **angle defect** ``2π − Σ θ`` (the corner angles of its triangles) is the
integral of the Gauss curvature ``K`` over the node's share of the surface (Gauss–Bonnet); divided
by a third of the area of its triangles it is ``K`` there. A boundary node has no defect of its own
(the boundary's turning is geodesic curvature, not ``K``): a cell takes the mean ``K`` of its
interior corners, and a cell with none takes that of the cells around its corners.

Why the sign matters to a ply. A fabric whose yarns keep their length covers a positively curved
region (a dome, ``K > 0``) only by shearing in more fabric than the region's area holds at its
rim: a **dart** (a notch in the flat pattern, closed on the mould) takes that fabric out. A
negatively curved region (a saddle, the concave foot of a dome, ``K < 0``) needs more fabric
at its rim than a sheet brings there: a notch takes out what is missing already; the fabric has to
come from somewhere else (a **splice**, which cuts the ply into pieces that drape separately, or a
gore let in). :func:`curvature_sign_shares` tells which of the two a region is.
"""

from __future__ import annotations

import numpy as np

from .mesh import SurfaceMesh
from .surface_lines import triangulated

__all__ = ["FLAT", "angle_defects", "cell_gauss_curvature", "curvature_sign_shares"]

#: A cell whose Gauss curvature times its area is within this many radians of zero is flat.
FLAT = 1e-6


def angle_defects(mesh: SurfaceMesh) -> tuple[np.ndarray, np.ndarray]:
    """Per node of the triangulated ``mesh`` ``(n,)``: the angle defect ``2π − Σ θ`` (radians;
    0 at boundary nodes) and a third of the area of the node's triangles (mesh units²)."""
    mesh = triangulated(mesh)
    triangles = mesh.cells["triangle"]
    corners = mesh.points[triangles]
    angles = np.empty(triangles.shape)
    for k in range(3):
        a = corners[:, (k + 1) % 3] - corners[:, k]
        b = corners[:, (k + 2) % 3] - corners[:, k]
        cosine = np.einsum("ij,ij->i", a, b)
        sine = np.linalg.norm(np.cross(a, b), axis=1)
        angles[:, k] = np.arctan2(sine, cosine)
    n = mesh.num_points
    total = np.bincount(triangles.ravel(), angles.ravel(), minlength=n)
    area = np.repeat(mesh.cell_areas() / 3.0, 3)
    share = np.bincount(triangles.ravel(), area, minlength=n)
    defect = np.where(_interior(mesh), 2.0 * np.pi - total, 0.0)
    return defect, share


def _interior(mesh: SurfaceMesh) -> np.ndarray:
    """Whether each node ``(n,)`` is off the boundary."""
    interior = np.ones(mesh.num_points, dtype=bool)
    interior[np.unique(mesh.boundary_edges())] = False
    return interior


def cell_gauss_curvature(mesh: SurfaceMesh) -> np.ndarray:
    """The Gauss curvature ``K`` of every triangle of the triangulated ``mesh`` ``(m,)`` (1 /
    mesh units²; module docs): the mean of its interior corners' angle defect per area, or, for a
    cell with no interior corner, the mean of the interior-corner values of the cells around its
    corners (each counted once per corner it shares; NaN where there are none)."""
    mesh = triangulated(mesh)
    triangles = mesh.cells["triangle"]
    defect, share = angle_defects(mesh)
    interior = _interior(mesh)
    nodal = np.where(interior, defect / np.where(share > 0, share, 1.0), 0.0)
    counted = interior[triangles]
    count = counted.sum(axis=1)
    value = np.where(count > 0, nodal[triangles].sum(axis=1) / np.maximum(count, 1), np.nan)
    lonely = count == 0
    if lonely.any():  # the mean over the interior corners of the cells around each corner
        ring_sum, ring_count = _ring_means(triangles, nodal, counted, mesh.num_points)
        own = ring_sum[triangles[lonely]].sum(axis=1)
        many = ring_count[triangles[lonely]].sum(axis=1)
        value[lonely] = np.where(many > 0, own / np.maximum(many, 1), np.nan)
    return value


def _ring_means(
    triangles: np.ndarray, nodal: np.ndarray, counted: np.ndarray, n: int
) -> tuple[np.ndarray, np.ndarray]:
    """Per node: the sum of the interior-corner values of its cells, and how many there are."""
    per_cell = (nodal[triangles] * counted).sum(axis=1)
    per_count = counted.sum(axis=1).astype(float)
    ring_sum = np.bincount(triangles.ravel(), np.repeat(per_cell, 3), minlength=n)
    ring_count = np.bincount(triangles.ravel(), np.repeat(per_count, 3), minlength=n)
    return ring_sum, ring_count


def curvature_sign_shares(mesh: SurfaceMesh, cells: np.ndarray) -> dict[str, float]:
    """The shares of the area of the triangles ``cells`` (indices or a mask into the triangulated
    ``mesh``'s cells) that are positively curved, negatively curved and flat (``K`` × the cell's
    area within :data:`FLAT` of zero): ``{"positive", "negative", "flat"}``, summing to 1 (all 0
    for no cells)."""
    mesh = triangulated(mesh)
    area = mesh.cell_areas()
    curvature = np.nan_to_num(cell_gauss_curvature(mesh), nan=0.0)
    chosen = np.zeros(len(area), dtype=bool)
    chosen[np.asarray(cells)] = True
    weight = area[chosen]
    total = float(weight.sum())
    if not total > 0:
        return {"positive": 0.0, "negative": 0.0, "flat": 0.0}
    signed = curvature[chosen] * weight
    positive = float(weight[signed > FLAT].sum()) / total
    negative = float(weight[signed < -FLAT].sum()) / total
    return {"positive": positive, "negative": negative, "flat": 1.0 - positive - negative}
