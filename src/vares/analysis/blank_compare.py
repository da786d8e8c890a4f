"""A forward drape against an inverse one: the blank's drape beside the VaReS pattern.

The VaReS pattern of a mould says, for every node of the mould's mesh, which material point of
the fabric lies there (its pattern coordinates ``X``); the forward drape says where every
material point of the blank went. Where both apply (the blank covers the mould) the two answer
the same question. :func:`against_pattern` brings the pattern into the blank's frame (the
rigid motion of the plane that fits the pattern's nodes best to the blank's material points at
the same places, least squares weighted by the nodes' areas), then compares per mould node the
3D position of the material point ``X`` in the forward drape with the node itself, and per mould
cell the forward drape's shear at the cell's material centroid with the pattern's shear.
"""

from __future__ import annotations

import numpy as np

from ..geometry.mesh import SurfaceMesh
from ..geometry.surface_points import FaceLocator
from .blank_drape import BlankDrapeResult

__all__ = ["against_pattern"]


def against_pattern(
    drape: BlankDrapeResult,
    mesh: SurfaceMesh,
    material_coordinates: np.ndarray,
    shear_angle: np.ndarray,
    *,
    within: np.ndarray | None = None,
) -> dict[str, object]:
    """Compare ``drape`` with the pattern ``material_coordinates`` ``(n, 2)`` of the mould
    ``mesh`` (triangles) and its per-cell ``shear_angle`` ``(m,)`` [°] (module docs).
    ``within`` ``(n,)`` bool: the mould nodes to compare (default: all the blank covers).

    Returns per node ``position_difference`` ``(n,)`` (length units, NaN where not compared),
    per cell ``drape_shear`` ``(m,)`` (the forward drape's shear at the cell's material
    centroid) and ``shear_difference`` (drape − pattern; degrees, NaN where not compared),
    their largest and RMS values, the fitted rotation ``turn`` (degrees) and the number of
    nodes and cells compared.
    """
    from matplotlib.tri import Triangulation

    X = np.asarray(material_coordinates, dtype=float)
    triangles = mesh.cells["triangle"]
    blank = drape.blank
    draped = SurfaceMesh(drape.positions, {"triangle": blank.triangles})
    faces, bary, found = FaceLocator(draped).locate(mesh.points)
    size = np.median(np.linalg.norm(np.diff(mesh.points[triangles[:, :2]], axis=1), axis=-1))
    covered = np.linalg.norm(found - mesh.points, axis=1) < 0.1 * size
    covered &= bary.min(axis=1) > -1e-9
    if within is not None:
        covered &= np.asarray(within, dtype=bool)
    if covered.sum() < 3:
        raise ValueError("the blank covers fewer than three nodes of the pattern's mesh")
    landed = np.einsum("kc,kci->ki", bary, blank.coordinates[blank.triangles[faces]])
    weights = _node_areas(mesh)[covered]
    rotation, shift = _rigid_fit(X[covered], landed[covered], weights)
    aligned = X @ rotation.T + shift
    finder = Triangulation(*blank.coordinates.T, blank.triangles).get_trifinder()
    position = np.full(len(X), np.nan)
    cell = finder(*aligned.T)
    inside = covered & (cell >= 0)
    located = _interpolate(blank, drape.positions, aligned[inside], cell[inside])
    position[inside] = np.linalg.norm(located - mesh.points[inside], axis=1)
    centroids = aligned[triangles].mean(axis=1)
    cell_of = finder(*centroids.T)
    compared = (cell_of >= 0) & covered[triangles].all(axis=1)
    on_mesh = np.full(len(triangles), np.nan)
    on_mesh[compared] = drape.shear_angle[cell_of[compared]]
    shear = on_mesh - np.asarray(shear_angle, dtype=float)
    areas = mesh.cell_areas()
    return {
        "position_difference": position,
        "shear_difference": shear,
        "drape_shear": on_mesh,
        "max_position_difference": float(np.nanmax(position)),
        "rms_position_difference": _rms(position, _node_areas(mesh)),
        "max_shear_difference": float(np.nanmax(np.abs(shear))),
        "rms_shear_difference": _rms(shear, areas),
        "mean_shear_difference": float(np.nansum(shear * areas) / areas[compared].sum()),
        "turn": float(np.degrees(np.arctan2(rotation[1, 0], rotation[0, 0]))),
        "nodes": int(inside.sum()),
        "cells": int(compared.sum()),
    }


def _node_areas(mesh: SurfaceMesh) -> np.ndarray:
    areas = np.zeros(mesh.num_points)
    triangles = mesh.cells["triangle"]
    np.add.at(areas, triangles.ravel(), np.repeat(mesh.cell_areas() / 3.0, 3))
    return areas


def _rigid_fit(source: np.ndarray, target: np.ndarray, weights: np.ndarray):
    """Rotation ``(2, 2)`` and shift ``(2,)`` taking ``source`` nearest to ``target``
    (weighted least squares, no reflection: Kabsch)."""
    w = weights / weights.sum()
    cs, ct = w @ source, w @ target
    H = (source - cs).T @ ((target - ct) * w[:, None])
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(Vt.T @ U.T))
    rotation = Vt.T @ np.diag([1.0, d]) @ U.T
    return rotation, ct - rotation @ cs


def _interpolate(blank, positions: np.ndarray, points: np.ndarray, cells: np.ndarray):
    """3D positions of flat ``points`` in the blank's ``cells``, linear in each cell."""
    corners = blank.coordinates[blank.triangles[cells]]  # (k, 3, 2)
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    m = np.stack([b - a, c - a], axis=-1)  # (k, 2, 2)
    st = np.linalg.solve(m, (points - a)[..., None])[..., 0]
    lam = np.column_stack([1 - st.sum(axis=1), st])
    return np.einsum("kc,kci->ki", lam, positions[blank.triangles[cells]])


def _rms(values: np.ndarray, weights: np.ndarray) -> float:
    ok = np.isfinite(values)
    return float(np.sqrt(np.sum(weights[ok] * values[ok] ** 2) / weights[ok].sum()))
