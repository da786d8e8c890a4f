"""Panels: the named pieces a structure is made of, and how a mesh is split into them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.mesh import MeshError, SurfaceMesh

__all__ = ["Panel", "split_panels", "width_across_warp"]


@dataclass(frozen=True)
class Panel:
    """A named panel of a structure."""

    name: str
    mesh: SurfaceMesh


def split_panels(
    mesh: SurfaceMesh, panel_ids: np.ndarray, names: dict[int, str] | None = None
) -> list[Panel]:
    """Split a mesh into panels by a per-cell id (global cell order); each panel is validated
    as a surface of its own and keeps its nodes' coordinates (shared nodes are duplicated)."""
    panel_ids = np.asarray(panel_ids).ravel()
    if panel_ids.shape != (mesh.num_cells,):
        raise MeshError(
            f"panel ids must have one value per cell ({mesh.num_cells}); got {panel_ids.size}"
        )
    if not np.all(np.equal(np.mod(panel_ids, 1), 0)):
        raise MeshError("panel ids must be integers")
    panels = []
    bounds = np.cumsum([0] + [len(c) for c in mesh.cells.values()])
    for value in np.unique(panel_ids):
        cells = {}
        for (cell_type, block), a, b in zip(
            mesh.cells.items(), bounds[:-1], bounds[1:], strict=True
        ):
            chosen = block[panel_ids[a:b] == value]
            if len(chosen):
                cells[cell_type] = chosen
        used = np.unique(np.concatenate([c.ravel() for c in cells.values()]))
        renumber = np.full(mesh.num_points, -1)
        renumber[used] = np.arange(used.size)
        name = (names or {}).get(int(value), f"panel-{int(value)}")
        try:
            panel_mesh = SurfaceMesh(mesh.points[used], {t: renumber[c] for t, c in cells.items()})
        except MeshError as exc:
            raise MeshError(f"panel {name}: {exc}") from exc
        panels.append(Panel(name, panel_mesh))
    return panels


def width_across_warp(coordinates: np.ndarray, warp: np.ndarray | None) -> float:
    """Extent of a pattern ``(n, 2)`` across its warp (the fabric width it needs)."""
    warp = np.array([1.0, 0.0]) if warp is None else np.asarray(warp, dtype=float)
    return float(np.ptp(coordinates @ np.array([-warp[1], warp[0]])))
