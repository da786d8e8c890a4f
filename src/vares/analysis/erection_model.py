"""What an erection is built from: the panels' patterns welded into one structure, the
membrane blocks of the forward problem, the intended prestress, the supports and edge cables.

Supports: every boundary node of the welded structure is held at its design position; with edge
cables, only the corners (where the boundary turns by more than ``corner_angle``) are held and
every boundary stretch between two corners is a tension-only cable of axial stiffness ``EA`` cut
to its design length / (1 + cable force / EA).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..geometry.elements import ELEMENTS
from ..geometry.mesh import SurfaceMesh
from ..geometry.weld import Welded, corner_nodes, weld
from ..materials import Fibres
from ..mechanics.assembly import Assembler, Connectivity
from ..mechanics.erection import Cables, MembraneBlock, membrane_block
from ..mechanics.prestress import prestress_components
from ..solver.result import PatternResult
from .options import ErectionOptions

__all__ = ["Pattern", "Structure", "build_structure", "dof_map", "patterns_of"]


@dataclass(frozen=True)
class Pattern:
    """One panel's pattern to erect: its 3D ``mesh``, the pattern ``(n, 2)``, the fibres in the
    pattern frame, the intended prestress (force per length: a number, ``(warp, fill[, shear])``
    or one row per cell) and a name."""

    mesh: SurfaceMesh
    material_coordinates: np.ndarray
    fibres: Fibres | None = None
    prestress: Any = None
    name: str = "panel"

    @classmethod
    def of(cls, result: PatternResult, name: str = "panel") -> Pattern:
        """The pattern of a solve."""
        return cls(result.mesh, result.material_coordinates, result.fibres, result.prestress, name)


@dataclass(frozen=True)
class Structure:
    """The welded structure: ``welded`` (mesh and node maps), the membrane ``blocks`` with the
    welded ids of their cells (``block_cells``), the intended warp and fill prestress per welded
    cell ``(m, 2)``, the held nodes ``(n,)``, the cables, the panel names and, per panel, the
    welded id of each of its cells."""

    welded: Welded
    blocks: list[MembraneBlock]
    block_cells: list[np.ndarray]
    intended: np.ndarray
    held: np.ndarray
    cables: Cables | None
    names: list[str]
    panel_cells: list[np.ndarray]

    @property
    def mesh(self) -> SurfaceMesh:
        return self.welded.mesh


def build_structure(
    patterns: list[Pattern], thickness: float, options: ErectionOptions
) -> Structure:
    """Weld the panels' meshes and set up the blocks, prestress, supports and cables."""
    welded = weld([p.mesh for p in patterns])
    panel_cells = _panel_cell_ids(welded, patterns)
    block_cells, blocks, intended = _membrane(welded, patterns, panel_cells, thickness)
    held, cables = _supports(welded.mesh, options)
    return Structure(
        welded,
        blocks,
        block_cells,
        intended,
        held,
        cables,
        [p.name for p in patterns],
        panel_cells,
    )


def patterns_of(source: Any) -> list[Pattern]:
    """The patterns of a solve, of a structure (anything with ``results`` and ``panels``), or a
    list of solves or :class:`Pattern`."""
    if isinstance(source, PatternResult | Pattern):
        source = [source]
    elif hasattr(source, "results"):
        names = [p.name for p in getattr(source, "panels", [])]
        source = [
            Pattern.of(r, names[k] if k < len(names) else f"panel-{k + 1}")
            for k, r in enumerate(source.results)
        ]
    out = [
        Pattern.of(p, f"panel-{k + 1}") if isinstance(p, PatternResult) else p
        for k, p in enumerate(source)
    ]
    if not out:
        raise ValueError("nothing to erect: no patterns given")
    return out


def _type_offsets(mesh: SurfaceMesh) -> dict[str, int]:
    """Welded global id of the first cell of each cell type."""
    offsets, start = {}, 0
    for cell_type, cells in mesh.cells.items():
        offsets[cell_type], start = start, start + len(cells)
    return offsets


def _panel_cell_ids(welded: Welded, patterns: list[Pattern]) -> list[np.ndarray]:
    """Per panel, the welded id of each of its cells (in the panel's own cell order)."""
    offsets = _type_offsets(welded.mesh)
    return [
        np.concatenate(
            [offsets[t] + np.arange(*welded.cell_ranges[p][t]) for t in pattern.mesh.cells]
        )
        for p, pattern in enumerate(patterns)
    ]


def _membrane(welded: Welded, patterns: list[Pattern], ids: list[np.ndarray], thickness: float):
    """Per membrane block (panel × cell type): the welded cell ids, the block, and the intended
    warp and fill prestress per welded cell ``(m, 2)``."""
    mesh = welded.mesh
    intended = np.zeros((mesh.num_cells, 2))
    cell_ids, blocks = [], []
    offsets = _type_offsets(mesh)
    for p, pattern in enumerate(patterns):
        coordinates = np.asarray(pattern.material_coordinates, dtype=float)
        if coordinates.shape != (pattern.mesh.num_points, 2):
            raise ValueError(
                f"{pattern.name}: the pattern must have shape ({pattern.mesh.num_points}, 2); "
                f"got {coordinates.shape}"
            )
        components = prestress_components(pattern.prestress, pattern.mesh.num_cells)
        if components is not None:
            intended[ids[p]] = components[:, :2]
        for cell_type, cells in pattern.mesh.cells.items():
            start, end = welded.cell_ranges[p][cell_type]
            element = ELEMENTS[cell_type]
            try:
                block = membrane_block(
                    element,
                    mesh.cells[cell_type][start:end],
                    coordinates[cells],
                    mesh.points,
                    thickness,
                    pattern.fibres,
                )
            except ValueError as exc:
                raise ValueError(f"{pattern.name}: {exc}") from None
            blocks.append(block)
            cell_ids.append(offsets[cell_type] + np.arange(start, end))
    return cell_ids, blocks, intended


def _supports(mesh: SurfaceMesh, options: ErectionOptions) -> tuple[np.ndarray, Cables | None]:
    """Held nodes ``(n,)`` and the edge cables (module docs)."""
    held = np.zeros(mesh.num_points, dtype=bool)
    loops = mesh.boundary_loops()
    if options.cable_stiffness is None:
        held[np.concatenate(loops)] = True
        return held, None
    segments = []
    for loop in loops:
        held[corner_nodes(mesh, loop, options.corner_angle)] = True
        segments.append(np.column_stack([loop, np.roll(loop, -1)]))
    if held.sum() < 3:
        raise ValueError(
            f"edge cables need at least three corners held; the boundary turns by more than "
            f"{options.corner_angle:g}° at {int(held.sum())} node(s) (lower corner_angle)"
        )
    segments = np.vstack(segments)
    length = np.linalg.norm(np.diff(mesh.points[segments], axis=1)[:, 0], axis=1)
    rest = length / (1.0 + options.cable_force / options.cable_stiffness)
    return held, Cables(segments, rest, options.cable_stiffness)


#: The dof map of the last erection's structure, ``(key, Assembler)``: the erections of an
#: optimiser's trial patterns share their structure (cells and supports), and making its map
#: took a fifth of an erection from its converged state on the 10k hypar.
_LAST_DOF_MAP: tuple[bytes, Assembler] | None = None
#: Whether an erection of the last one's structure takes its dof map (benchmarks compare).
REUSE_DOF_MAP = True


def dof_map(connectivity: Connectivity, free: np.ndarray) -> Assembler:
    """The assembler of an erection (three dofs per node, ``free`` ones unknown): the last
    one's where the cells and the free dofs are the same (an assembler is never changed once
    made)."""
    global _LAST_DOF_MAP
    digest = hashlib.blake2b(np.ascontiguousarray(free).tobytes(), digest_size=16)
    digest.update(str(connectivity.num_points).encode())
    for name, cells in connectivity.cells.items():
        digest.update(f"{name}{cells.shape}".encode())
        digest.update(np.ascontiguousarray(cells).tobytes())
    key, last = digest.digest(), _LAST_DOF_MAP
    if REUSE_DOF_MAP and last is not None and last[0] == key:
        return last[1]
    assembler = Assembler(connectivity, free, dofs_per_node=3)
    _LAST_DOF_MAP = (key, assembler)
    return assembler
