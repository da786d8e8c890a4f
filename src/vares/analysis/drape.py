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
from .producibility import Producibility, producibility

__all__ = ["DrapeOptions", "PlyDrape", "drape_ply"]


@dataclass(frozen=True)
class PlyDrape:
    """A ply's kinematic drape, its producibility and the options they were made with; ``seed``
    ``(3,)`` and ``spacing`` as used (defaults filled in)."""

    drape: KinematicDrape
    producibility: Producibility
    options: DrapeOptions
    seed: np.ndarray
    spacing: float

    def summary(self) -> dict[str, Any]:
        """The numbers for a summary file."""
        _, source = self.options.locking
        net = self.drape.net
        return {
            "seed": self.seed,
            "warp": self.options.warp,
            "spacing": self.spacing,
            "fabric_kind": self.options.fabric_kind,
            "locking_angle_source": source,
            "net_nodes": int(net.valid.sum()),
            "nodes_interpolated_fraction": float(self.drape.node_in_net.mean()),
            "nodes_without_pattern": int(np.isnan(self.drape.material_coordinates[:, 0]).sum()),
            "producibility": self.producibility.summary(),
        }


@takes_options(DrapeOptions)
def drape_ply(mesh: SurfaceMesh, options: DrapeOptions | None = None, **settings: Any) -> PlyDrape:
    """Drape a ply kinematically on ``mesh`` (the mould) and classify its cells' shear against
    the locking angle (:func:`vares.geometry.drape.kinematic_drape`,
    :func:`vares.analysis.producibility.producibility`).

    ``options``: a :class:`DrapeOptions` to start from; keyword ``settings`` (below) change it.
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
    drape = kinematic_drape(mesh, seed, np.asarray(options.warp, dtype=float), spacing)
    locking, _ = options.locking
    check = producibility(drape.shear_angle, mesh.cell_areas(), locking, options.warn_fraction)
    return PlyDrape(drape, check, options, seed, spacing)
