"""Where a ply of a laminate lies on the mould: its cells (a region of the mould or all of it),
their mesh, and the ply's warp at its seed."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..geometry.drape_net import NORMAL_CONE, DrapeError, locate_seed
from ..geometry.mesh import SurfaceMesh
from ..options import OptionsError
from .laminate_options import PlyOptions

__all__ = ["cell_blocks", "ply_warp", "region_cells", "seed_on_mould", "submesh"]


def ply_warp(
    mesh: SurfaceMesh, seed: np.ndarray, reference: np.ndarray, orientation: float
) -> tuple[np.ndarray, np.ndarray]:
    """The warp ``(3,)`` (unit) of a ply at ``seed`` ``(3,)`` and the mould's unit normal there
    ``(3,)``: ``reference`` ``(3,)`` projected onto the tangent plane at the seed, turned by
    ``orientation`` degrees counter-clockwise about the normal. The normal is the area-weighted
    normal of the cells round the mould node nearest the seed."""
    seed = np.asarray(seed, dtype=float)
    node = int(np.argmin(np.linalg.norm(mesh.points - seed, axis=1)))
    vectors = mesh.area_vectors()
    around = np.concatenate([np.any(c == node, axis=1) for c in mesh.cells.values()])
    normal = vectors[around].sum(axis=0)
    normal /= np.linalg.norm(normal)
    reference = np.asarray(reference, dtype=float)
    tangent = reference - (reference @ normal) * normal
    if not np.linalg.norm(tangent) > np.sin(np.radians(NORMAL_CONE)) * np.linalg.norm(reference):
        raise OptionsError(
            "reference",
            f"is within {NORMAL_CONE:g}° of the mould's normal at the seed: it gives no "
            "direction there",
        )
    tangent /= np.linalg.norm(tangent)
    angle = np.radians(orientation)
    warp = np.cos(angle) * tangent + np.sin(angle) * np.cross(normal, tangent)
    return warp / np.linalg.norm(warp), normal


def seed_on_mould(mesh: SurfaceMesh, seed: Sequence[float] | None, name: str) -> None:
    """Raise :class:`DrapeError`, naming ``name`` (the ply or the laminate), when a given
    ``seed`` ``(3,)`` lies off the mould ``mesh`` (:func:`locate_seed`): a seed far from it would
    otherwise be moved silently to the nearest node. ``None`` (no seed given) passes."""
    if seed is None:
        return
    try:
        locate_seed(mesh, seed)
    except DrapeError as exc:
        raise DrapeError(f"{name}: {exc}") from None


def region_cells(
    ply: PlyOptions, cell_data: Mapping[str, np.ndarray], num_cells: int
) -> np.ndarray:
    """The global cells ``(k,)`` of the ply's region (every cell when it names none)."""
    if ply.region is None:
        return np.arange(num_cells)
    if ply.region not in cell_data:
        known = ", ".join(cell_data) or "none"
        raise OptionsError(
            "region", f"of ply {ply.name!r} names no cell field of the mould (it has: {known})"
        )
    values = np.asarray(cell_data[ply.region], dtype=float).reshape(num_cells, -1)[:, 0]
    chosen = values != 0 if ply.region_value is None else np.isclose(values, ply.region_value)
    cells = np.flatnonzero(chosen)
    if not cells.size:
        raise OptionsError("region", f"of ply {ply.name!r} holds no cell of the mould")
    return cells


def cell_blocks(mesh: SurfaceMesh, cells: np.ndarray) -> dict[str, np.ndarray]:
    """The node indices of the given global cells, by cell type."""
    blocks, start = {}, 0
    for cell_type, block in mesh.cells.items():
        mine = cells[(cells >= start) & (cells < start + len(block))] - start
        if mine.size:
            blocks[cell_type] = block[mine]
        start += len(block)
    return blocks


def submesh(mesh: SurfaceMesh, cells: np.ndarray) -> tuple[SurfaceMesh, np.ndarray]:
    """The mesh of the given global cells and its nodes' indices on ``mesh``."""
    if len(cells) == mesh.num_cells:
        return mesh, np.arange(mesh.num_points)
    blocks = cell_blocks(mesh, cells)
    nodes = np.unique(np.concatenate([b.ravel() for b in blocks.values()]))
    index = np.full(mesh.num_points, -1)
    index[nodes] = np.arange(len(nodes))
    sub = SurfaceMesh(mesh.points[nodes], {t: index[b] for t, b in blocks.items()})
    return sub, nodes
