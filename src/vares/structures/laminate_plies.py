"""A laminate's plies and what draping one gives: :class:`Ply` (its options, material and dart
lines) and :class:`PlyDrapeResult` (one distinct drape, shared by the plies that differ only in
name and drop-off). Their own module so that the tasks (:mod:`.laminate_tasks`) and the pair
check (:mod:`.laminate_pairs`) take them without importing the laminate (:mod:`.laminate`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from ..analysis.darts import DartedPattern
from ..analysis.drape import PlyDrape
from ..geometry.mesh import SurfaceMesh
from ..materials import Hyperelastic
from ..options import OptionsError
from ..solver.result import PatternResult
from .laminate_options import PlyOptions

if TYPE_CHECKING:
    from ..analysis.splices import SplicedPly

__all__ = ["BlankPiece", "Ply", "PlyDrapeResult", "darts_used"]


@dataclass(frozen=True)
class Ply:
    """A ply: its :class:`PlyOptions`, its material (a hyperelastic law, thickness 1), the
    dart lines of its own (``(k, 3)`` polylines on or near the mould, mouth or tip first; e.g.
    the curves of its ``dart_lines`` file), if any, and its splice lines (``(k, 3)`` polylines
    from its boundary across it to the boundary; its ``splice_lines`` file's), if any."""

    options: PlyOptions
    material: Hyperelastic
    dart_lines: tuple[np.ndarray, ...] | None = None
    splice_lines: tuple[np.ndarray, ...] | None = None

    def __post_init__(self) -> None:
        if self.splice_lines is not None and (
            self.dart_lines is not None
            or self.options.darts == "auto"
            or self.options.splices == "auto"
        ):
            raise OptionsError(None, f"ply {self.name}: give darts or splice lines, not both")

    @property
    def name(self) -> str:
        return self.options.name


def darts_used(darted: DartedPattern | None) -> bool:
    """Whether a ply is cut with the darts of ``darted``
    (:attr:`~vares.analysis.darts.DartedPattern.kept`)."""
    return darted is not None and darted.kept


class BlankPiece(NamedTuple):
    """One piece of a ply as cut: ``piece`` its name (``None`` for a ply cut whole, else
    ``"piece-1"`` …), ``mesh`` its cells on the mould and ``pattern`` its flat pattern."""

    piece: str | None
    mesh: SurfaceMesh
    pattern: PatternResult


@dataclass
class PlyDrapeResult:
    """One distinct drape of a laminate (the plies ``plies`` share it).

    ``cells`` ``(k,)``: the mould cells it covers (global cell order); ``mesh`` the ply's mesh
    (those cells; the whole mould when the ply has no region) and ``nodes`` ``(n_ply,)`` its nodes'
    indices on the mould. ``seed``, ``warp_direction``, ``normal`` ``(3,)``: where it is laid and
    the warp there. ``pattern``: the mechanical drape (:func:`vares.solve`, warp along +x);
    ``kinematic``: the pin-jointed net beside it (``None`` when not asked for or failed, with
    ``kinematic_error``). ``darted``: the ply with its darts open (``None`` without darts asked
    for; its ``after`` is ``None`` when none was needed or placed; the ply is cut with them when
    :attr:`is_darted`) and ``locking_angle`` (degrees). ``spliced``: the ply cut into pieces
    along its splice lines and each piece's pattern (``None`` without splice lines), and with
    ``splices = "auto"`` ``placed``: what was tried through its seed and taken
    (:meth:`vares.analysis.splice_lines.PlacedSplices.summary`).
    Per mould cell ``(m,)`` / ``(m, 3)``, NaN outside the ply: ``warp``, ``fill`` (unit erected
    yarns), ``shear_angle`` (degrees, the decrease of the angle between the yarns) of the ply as
    laid (the darted or spliced patterns', each mould cell the area-weighted mean of its pieces
    in the opened or cut mesh: :func:`~vares.structures.laminate_tasks.on_mould_cells`), and the
    kinematic ``kinematic_warp``, ``kinematic_fill``, ``kinematic_shear_angle`` (a spliced
    ply's from its pieces' own nets, likewise). The pair check uses
    ``pattern``, the ply without darts or splices, on the mould's cells.
    """

    label: str
    plies: list[str]
    orientation: float
    cells: np.ndarray
    nodes: np.ndarray
    mesh: SurfaceMesh
    seed: np.ndarray
    warp_direction: np.ndarray
    normal: np.ndarray
    material: Hyperelastic
    pattern: PatternResult
    warp: np.ndarray
    fill: np.ndarray
    shear_angle: np.ndarray
    kinematic: PlyDrape | None
    kinematic_error: str | None
    kinematic_warp: np.ndarray
    kinematic_fill: np.ndarray
    kinematic_shear_angle: np.ndarray
    seconds: float
    locking_angle: float = float("nan")
    darted: DartedPattern | None = None
    spliced: SplicedPly | None = None
    placed: dict[str, Any] | None = None

    @property
    def is_spliced(self) -> bool:
        """Whether the ply is cut into pieces along splice lines."""
        return self.spliced is not None

    @property
    def pieces(self) -> list[BlankPiece]:
        """The ply as cut: its pieces along the splice lines, else its one blank
        (:attr:`blank_mesh`, :attr:`blank_pattern`)."""
        if self.spliced is not None:
            return [
                BlankPiece(piece.name, piece.mesh, result)
                for piece, result in zip(self.spliced.pieces, self.spliced.results, strict=True)
            ]
        return [BlankPiece(None, self.blank_mesh, self.blank_pattern)]

    def piece(self, name: str | None) -> BlankPiece:
        """The piece named ``name`` of :attr:`pieces` (``None``: the ply cut whole)."""
        return next(p for p in self.pieces if p.piece == name)

    @property
    def is_darted(self) -> bool:
        """Whether the ply is cut open along darts: asked for, placed, and lowering its largest
        shear (:func:`darts_used`)."""
        return darts_used(self.darted)

    @property
    def blank_mesh(self) -> SurfaceMesh:
        """The mesh of the blank as cut: the ply's mesh opened along its darts, if any (a
        spliced ply's pieces are :attr:`pieces`)."""
        return self.darted.slits.mesh if self.is_darted else self.mesh

    @property
    def blank_pattern(self) -> PatternResult:
        """The pattern of the blank as cut (of :attr:`blank_mesh`)."""
        return self.darted.after if self.is_darted else self.pattern

    @property
    def converged(self) -> bool:
        return bool(self.pattern.converged and all(p.pattern.converged for p in self.pieces))

    def summary(self) -> dict[str, Any]:
        """The numbers for a summary file."""
        area = self.mesh.cell_areas()
        shear = self.shear_angle[self.cells]
        data: dict[str, Any] = {
            "label": self.label,
            "plies": self.plies,
            "orientation": self.orientation,
            "seed": self.seed,
            "warp_direction": self.warp_direction,
            "cells": len(self.cells),
            "area": float(area.sum()),
            "converged": self.converged,
            "reason": self.pattern.reason,
            "iterations": self.pattern.iterations,
            "energy": self.pattern.energy,
            "warp_deviation": self.pattern.warp_deviation,
            "seconds": self.seconds,
            "max_shear": float(np.nanmax(np.abs(shear))),
            "mean_abs_shear": float(area @ np.abs(shear) / area.sum()),
        }
        if self.kinematic is not None:
            data["kinematic_drape"] = self.kinematic.summary()
            undarted = self.pattern.fields["shear_angle"]  # the net is not darted
            data["kinematic_drape"]["against_pattern"] = self.kinematic.comparison(undarted, area)
        elif self.kinematic_error is not None:
            data["kinematic_drape"] = {"error": self.kinematic_error}
        data["locking_angle"] = self.locking_angle
        data["darts"] = None if self.darted is None else self.darted.summary()
        data["splices"] = None if self.spliced is None else self.spliced.summary()
        if self.placed is not None:
            data["splices"] = {**(data["splices"] or {}), "placed": self.placed}
        return data
