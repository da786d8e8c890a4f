"""A ply draped kinematically and checked for producibility (:class:`DrapeOptions`: where it is
laid and how its shear is judged)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..geometry.drape import KinematicDrape, kinematic_drape
from ..geometry.mesh import SurfaceMesh
from ..options import split_settings, takes_options
from .drape_options import DrapeOptions
from .producibility import CLASSES, Producibility, producibility

__all__ = ["DrapeOptions", "PlyDrape", "drape_ply"]


@dataclass(frozen=True)
class PlyDrape:
    """A ply's kinematic drape, its producibility and the options they were made with; ``seed``
    ``(3,)``, ``warp`` ``(3,)`` and ``spacing`` as used (defaults filled in)."""

    drape: KinematicDrape
    producibility: Producibility
    options: DrapeOptions
    seed: np.ndarray
    warp: np.ndarray
    spacing: float

    def summary(self) -> dict[str, Any]:
        """The numbers for a summary file."""
        _, source = self.options.locking
        net = self.drape.net
        return {
            "seed": self.seed,
            "warp": self.warp,
            "spacing": self.spacing,
            "fabric_kind": self.options.fabric_kind,
            "locking_angle_source": source,
            "net_nodes": int(net.valid.sum()),
            "nodes_interpolated_fraction": float(self.drape.node_in_net.mean()),
            "nodes_without_pattern": int(np.isnan(self.drape.material_coordinates[:, 0]).sum()),
            "producibility": self.producibility.summary(),
        }

    def comparison(self, shear_angle: np.ndarray, areas: np.ndarray) -> dict[str, float]:
        """The kinematic shear against another per-cell shear angle ``(m,)`` (degrees, e.g.
        the mechanical pattern's ``fields["shear_angle"]``) on the cells ``areas`` ``(m,)``
        where both have a value: the area-weighted mean and the largest difference (other −
        kinematic), the largest magnitude of each, and their correlation."""
        kinematic = self.drape.shear_angle
        both = np.isfinite(kinematic) & np.isfinite(shear_angle)
        if both.sum() < 2:
            return {"cells": int(both.sum())}
        difference = shear_angle[both] - kinematic[both]
        weights = areas[both] / areas[both].sum()
        return {
            "cells": int(both.sum()),
            "mean_abs_difference": float(weights @ np.abs(difference)),
            "max_abs_difference": float(np.abs(difference).max()),
            "max_shear": float(np.abs(shear_angle[both]).max()),
            "max_kinematic_shear": float(np.abs(kinematic[both]).max()),
            "correlation": float(np.corrcoef(shear_angle[both], kinematic[both])[0, 1]),
        }

    def fields(self) -> dict[str, np.ndarray]:
        """Per-cell fields ``(m,)`` for a mesh file: ``kinematic_shear_angle`` (degrees) and
        ``producibility`` (the index of the class in :data:`~vares.analysis.producibility.CLASSES`:
        0 ok, 1 warn, 2 limit, 3 none)."""
        codes = np.zeros(len(self.producibility.classes))
        for code, name in enumerate(CLASSES):
            codes[self.producibility.classes == name] = code
        return {"kinematic_shear_angle": self.drape.shear_angle, "producibility": codes}


@takes_options(DrapeOptions)
def drape_ply(
    mesh: SurfaceMesh,
    options: DrapeOptions | None = None,
    *,
    warp_direction: tuple[float, float, float] = (1.0, 0.0, 0.0),
    **settings: Any,
) -> PlyDrape:
    """Drape a ply kinematically on ``mesh`` (the mould) and classify its cells' shear against
    the locking angle (:func:`vares.geometry.drape.kinematic_drape`,
    :func:`vares.analysis.producibility.producibility`).

    ``options``: a :class:`DrapeOptions` to start from; keyword ``settings`` (below) change it.
    ``warp_direction`` ``(3,)``: the warp when the options give none (a job passes its
    pattern's warp direction).
    """
    (options,) = split_settings(settings, [options or DrapeOptions()])
    points = mesh.points
    if options.seed is None:
        seed = points[np.argmin(np.linalg.norm(points - points.mean(axis=0), axis=1))]
    else:
        seed = np.asarray(options.seed, dtype=float)
    spacing = options.spacing
    if spacing is None:
        edges = mesh.edges()
        spacing = 0.5 * float(
            np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1).mean()
        )
    warp = np.asarray(options.warp if options.warp is not None else warp_direction, dtype=float)
    drape = kinematic_drape(mesh, seed, warp, spacing)
    locking, _ = options.locking
    check = producibility(drape.shear_angle, mesh.cell_areas(), locking, options.warn_fraction)
    return PlyDrape(drape, check, options, seed, warp, spacing)
