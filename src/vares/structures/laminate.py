"""A laminate: a stack of plies on one mould, each draped, every pair checked (DESIGN.md §8).

A ply is a fabric laid from a seed point with its warp at an ``orientation`` angle from the
laminate's reference direction: the reference projected onto the mould's tangent plane at the seed,
turned by the angle counter-clockwise about the surface normal there. That 3D direction is the
``warp_direction`` of the ply's mechanical drape (:func:`vares.solve`: the erected warp's
area-weighted mean angle from it is zero) and the warp of its kinematic net at the seed
(:func:`vares.analysis.drape.drape_ply`).

Plies that differ only in name and drop-off (the two halves of a symmetric stack) share one
drape. The **ply-stack check** (the seed's Fig. 11) erects the blank of drape A with the yarns of
drape B: a blank cut for A from a roll turned for B, i.e. B's yarns at ``θ_B − θ_A`` in A's
pattern frame (where A's warp runs along +x). It reports per pair the area whose warp or fill is
compressed (shortened by more than ``compression_strain``), the largest yarn compression and the
deviation of the erected yarns from B's own drape (:mod:`.laminate_pairs`). Where each ply lies
on the mould (its region's cells and mesh, its warp at the seed) is :mod:`.laminate_regions`.

A ply with darts (``darts = "auto"`` or dart lines of its own) is cut open where its shear reaches
its locking angle and solved again (:func:`vares.analysis.darts.solve_with_darts`): its blank,
cutter file and ply book are of the opened pattern, its fibre directions per mould cell are read
back from it, and the pair check stays with the ply's pattern without darts, on the mould's cells.
A ply with splice lines is cut into pieces along them, each draped on its own part of the mould
(:func:`vares.analysis.splices.solve_with_splices`): each piece is a blank of its own (cut,
nested and in the ply book), its fibre directions per mould cell are read back from the pieces,
and the pair check stays with the ply's pattern cut whole.
How the plies are run (here, in local processes, on a Dask scheduler) is :mod:`.laminate_tasks`.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..analysis.darts import DartedPattern
from ..analysis.drape import PlyDrape
from ..analysis.splices import SplicedPly
from ..geometry.mesh import SurfaceMesh
from ..options import OptionsError, split_settings, takes_options
from ..solver.result import PatternResult
from .laminate_options import LaminateOptions, PlyOptions
from .laminate_pairs import PAIR_VALUES, PairCheck, blank_used_for, draped_yarns, pair_check
from .laminate_plies import Ply, PlyDrapeResult, darts_used
from .laminate_regions import cell_blocks, ply_warp, region_cells, seed_on_mould, submesh
from .laminate_tasks import (
    cut_origin,
    dart_task,
    drape_key,
    drape_tasks,
    on_mould_cells,
    ply_locking_angle,
    splice_task,
)

__all__ = [
    "PAIR_VALUES",
    "PARALLEL_CELLS",
    "Laminate",
    "LaminateOptions",
    "LaminateResult",
    "PairCheck",
    "Ply",
    "PlyDrapeResult",
    "PlyOptions",
    "blank_used_for",
    "drape_laminate",
    "draped_yarns",
    "ply_locking_angle",
    "ply_warp",
]


#: Moulds of fewer cells are draped in the calling process unless ``workers`` says otherwise:
#: a worker's start (importing vares, loading its compiled kernels: 3–5 s) costs more than their
#: plies' solves (docs/composites.md, "In parallel").
PARALLEL_CELLS = 4000


@dataclass(frozen=True)
class Laminate:
    """A stack of plies, bottom (mould side) first, and the options they share."""

    plies: tuple[Ply, ...]
    options: LaminateOptions = field(default_factory=LaminateOptions)

    def __post_init__(self) -> None:
        if not self.plies:
            raise OptionsError(None, "a laminate needs at least one ply")
        names = [p.name for p in self.plies]
        repeated = sorted({n for n in names if names.count(n) > 1})
        if repeated:
            raise OptionsError("name", f"must be unique among the plies; repeated: {repeated}")
        orders = [p.options.drop_off for p in self.plies if p.options.drop_off is not None]
        if len(set(orders)) != len(orders):
            raise OptionsError("drop_off", f"must differ from ply to ply; got {orders}")


@dataclass
class LaminateResult:
    """A draped laminate: ``drapes`` (one per distinct ply, in the order of their first ply),
    ``ply_drape`` (ply name → the label of its drape), ``pairs`` (every ordered pair of drapes,
    ``(blank, ply)`` → :class:`PairCheck`), the laminate and the seconds taken."""

    mesh: SurfaceMesh
    laminate: Laminate
    drapes: list[PlyDrapeResult]
    ply_drape: dict[str, str]
    pairs: dict[tuple[str, str], PairCheck]
    seconds: float
    workers: int

    @property
    def converged(self) -> bool:
        return all(d.converged for d in self.drapes)

    @property
    def labels(self) -> list[str]:
        return [d.label for d in self.drapes]

    def drape(self, ply: str) -> PlyDrapeResult:
        """The drape of the ply named ``ply``."""
        label = self.ply_drape[ply]
        return next(d for d in self.drapes if d.label == label)

    def pair_matrix(self, value: str) -> np.ndarray:
        """``(k, k)`` matrix of one of :data:`PAIR_VALUES`: row = the blank's drape, column =
        the ply it is used for (both in the order of :attr:`labels`)."""
        if value not in PAIR_VALUES:
            raise ValueError(f"value must be one of {', '.join(PAIR_VALUES)}; got {value!r}")
        labels = self.labels
        return np.array([[getattr(self.pairs[a, b], value) for b in labels] for a in labels])

    def summary(self) -> dict[str, Any]:
        """The numbers for ``laminate.json`` (a pair not checked is ``None`` in the matrices)."""
        plies = []
        for ply in self.laminate.plies:
            o = ply.options
            plies.append(
                {
                    "name": o.name,
                    "orientation": o.orientation,
                    "drape": self.ply_drape[o.name],
                    "drop_off": o.drop_off,
                    "region": o.region,
                    "region_value": o.region_value,
                    "material": type(ply.material).__name__,
                }
            )
        return {
            "converged": self.converged,
            "seconds": self.seconds,
            "workers": self.workers,
            "reference": list(self.laminate.options.reference),
            "compression_strain": self.laminate.options.compression_strain,
            "plies": plies,
            "drapes": [d.summary() for d in self.drapes],
            "pair_labels": self.labels,
            "pairs": {v: _listed(self.pair_matrix(v)) for v in PAIR_VALUES},
        }


def _listed(matrix: np.ndarray) -> list[list[float | None]]:
    """A matrix as nested lists, NaN (a pair not checked) as ``None`` (JSON's null)."""
    return [[float(v) if np.isfinite(v) else None for v in row] for row in matrix]


def _label(orientation: float, taken: Sequence[str]) -> str:
    base = f"{orientation:g}°"
    label, count = base, 1
    while label in taken:
        count += 1
        label = f"{base} ({count})"
    return label


@takes_options(LaminateOptions)
def drape_laminate(
    mesh: SurfaceMesh,
    plies: Sequence[Ply],
    options: LaminateOptions | None = None,
    *,
    cell_data: Mapping[str, np.ndarray] | None = None,
    solve_settings: Mapping[str, Any] | None = None,
    callback: Callable[[PlyDrapeResult], None] | None = None,
    **settings: Any,
) -> LaminateResult:
    """Drape every ply of a laminate on the mould ``mesh`` and check every pair.

    ``plies``: the stack, bottom first (:class:`Ply`); ``options``: a :class:`LaminateOptions`
    to start from, changed by keyword ``settings`` (below). ``cell_data``: the mould's cell fields
    ``(m,)`` (a ply's ``region`` names one). ``solve_settings``: options of :func:`vares.solve`
    for every ply (not ``warp_direction``, which each ply sets). ``callback`` sees each drape as
    it ends. Distinct plies are draped in parallel by ``workers`` processes when more than one
    (default: one per core for a mould of at least :data:`PARALLEL_CELLS` cells, else one), or
    as tasks on the workers of the Dask scheduler at ``scheduler``.
    """
    (options,) = split_settings(settings, [options or LaminateOptions()])
    laminate = Laminate(tuple(plies), options)
    started = time.perf_counter()
    cell_data = cell_data or {}
    solve_options = dict(solve_settings or {})
    solve_options.pop("warp_direction", None)
    points = mesh.points
    seed_on_mould(mesh, options.seed, "the laminate")
    default_seed = (
        np.asarray(options.seed, dtype=float)
        if options.seed is not None
        else points[np.argmin(np.linalg.norm(points - points.mean(axis=0), axis=1))]
    )
    groups: dict[tuple, dict[str, Any]] = {}
    ply_drape: dict[str, tuple] = {}
    for ply in laminate.plies:
        o = ply.options
        cells = region_cells(o, cell_data, mesh.num_cells)
        if o.seed is not None:
            seed = np.asarray(o.seed, dtype=float)
        elif len(cells) < mesh.num_cells:
            blocks = cell_blocks(mesh, cells).values()
            region = points[np.unique(np.concatenate([b.ravel() for b in blocks]))]
            target = region.mean(axis=0) if options.seed is None else default_seed
            seed = region[np.argmin(np.linalg.norm(region - target, axis=1))]
        else:
            seed = default_seed
        sub, nodes = submesh(mesh, cells)
        seed_on_mould(sub, o.seed, f"ply {o.name!r}")
        darts = dart_task(ply, options, sub)
        splices = splice_task(ply, options, sub)
        key = drape_key(ply, options, seed, cells, darts, splices)
        ply_drape[o.name] = key
        if key in groups:
            groups[key]["plies"].append(o.name)
            continue
        warp, normal = ply_warp(sub, seed, np.asarray(options.reference), o.orientation)
        kinematic = None
        if options.kinematic:
            kinematic = {
                "seed": tuple(seed),
                "warp": tuple(warp),
                "spacing": options.spacing,
                "fabric_kind": o.fabric_kind or options.fabric_kind,
            }
        label = _label(o.orientation, [g["label"] for g in groups.values()])
        groups[key] = {
            "label": label,
            "plies": [o.name],
            "ply": ply,
            "seed": seed,
            "cells": cells,
            "nodes": nodes,
            "normal": normal,
            "task": {
                "name": o.name,
                "seed": tuple(seed),
                "mesh": sub,
                "material": ply.material,
                "warp": warp,
                "solve": solve_options,
                "kinematic": kinematic,
                "darts": darts,
                "splices": splices,
            },
            "locking_angle": ply_locking_angle(options, o),
        }
    tasks = [g["task"] for g in groups.values()]
    default = (os.cpu_count() or 1) if mesh.num_cells >= PARALLEL_CELLS else 1
    workers = min(options.workers or default, len(tasks))
    outcomes, workers = drape_tasks(tasks, workers, options.scheduler)
    drapes = []
    for group, outcome in zip(groups.values(), outcomes, strict=True):
        drape = _drape_result(mesh, group, outcome)
        drapes.append(drape)
        if callback is not None:
            callback(drape)
    labels = {key: g["label"] for key, g in groups.items()}
    pairs = {
        (a.label, b.label): pair_check(a, b, options.compression_strain)
        for a in drapes
        for b in drapes
    }
    return LaminateResult(
        mesh,
        laminate,
        drapes,
        {name: labels[key] for name, key in ply_drape.items()},
        pairs,
        time.perf_counter() - started,
        workers,
    )


def _drape_result(mesh: SurfaceMesh, group: dict[str, Any], outcome: dict[str, Any]):
    pattern: PatternResult = outcome["pattern"]
    sub = group["task"]["mesh"]
    cells = group["cells"]
    m = mesh.num_cells

    def spread(values: np.ndarray) -> np.ndarray:
        out = np.full((m, *values.shape[1:]), np.nan)
        out[cells] = values
        return out

    darted: DartedPattern | None = outcome["darted"]
    spliced: SplicedPly | None = outcome.get("spliced")
    shear = pattern.fields["shear_angle"]
    if spliced is not None:  # the ply as laid: its pieces, read back
        # each cut cell's mould cell, once for the pieces' patterns and their nets
        back = (cut_origin(sub, spliced.cut.mesh), spliced.cut.mesh.cell_areas(), sub.num_cells)
        warp, fill, shear = _read_back(*back, *_spliced_yarns(spliced))
    elif darts_used(darted):  # the ply as laid: opened, read back
        opened, laid = darted.slits.mesh, darted.after
        warp, fill = draped_yarns(
            opened, laid.material_coordinates, laid.fibres.warp, laid.fibres.fill
        )
        back = (darted.slits.cell_origin, opened.cell_areas(), sub.num_cells)
        warp, fill, shear = _read_back(*back, warp, fill, laid.fields["shear_angle"])
    else:
        warp, fill = draped_yarns(
            sub, pattern.material_coordinates, pattern.fibres.warp, pattern.fibres.fill
        )
    kinematic: PlyDrape | None = outcome["kinematic"]
    nan3 = np.full((len(cells), 3), np.nan)
    if kinematic is not None:
        net_warp, net_fill = kinematic.drape.warp, kinematic.drape.fill
        net_shear = kinematic.drape.shear_angle
        if spliced is not None and spliced.nets is not None:  # the pieces' nets, as laid
            net_warp, net_fill, net_shear = _read_back(*back, *_spliced_nets(spliced))
    else:
        net_warp, net_fill, net_shear = nan3, nan3, np.full(len(cells), np.nan)
    return PlyDrapeResult(
        label=group["label"],
        plies=group["plies"],
        orientation=float(group["ply"].options.orientation),
        cells=cells,
        nodes=group["nodes"],
        mesh=sub,
        seed=group["seed"],
        warp_direction=np.asarray(group["task"]["warp"]),
        normal=group["normal"],
        material=group["ply"].material,
        pattern=pattern,
        warp=spread(warp),
        fill=spread(fill),
        shear_angle=spread(shear),
        kinematic=kinematic,
        kinematic_error=outcome["error"],
        kinematic_warp=spread(net_warp),
        kinematic_fill=spread(net_fill),
        kinematic_shear_angle=spread(net_shear),
        seconds=outcome["seconds"],
        locking_angle=group["locking_angle"],
        darted=darted,
        spliced=spliced,
        placed=outcome.get("placed"),
    )


def _spliced_yarns(spliced: SplicedPly) -> tuple[np.ndarray, ...]:
    """A spliced ply's draped warp, fill ``(k, 3)`` and shear ``(k,)`` per cell of its cut
    mesh: each piece's."""
    cut = spliced.cut
    warp, fill = np.zeros((cut.mesh.num_cells, 3)), np.zeros((cut.mesh.num_cells, 3))
    for index, (piece, result) in enumerate(zip(spliced.pieces, spliced.results, strict=True)):
        cells = cut.panel_ids == index
        warp[cells], fill[cells] = draped_yarns(
            piece.mesh, result.material_coordinates, result.fibres.warp, result.fibres.fill
        )
    return warp, fill, spliced.cell_field("shear_angle")


def _spliced_nets(spliced: SplicedPly) -> tuple[np.ndarray, ...]:
    """The warp, fill and shear of a spliced ply's kinematic nets (one per piece) per cell of
    its cut mesh; NaN over a piece without a net."""
    cut = spliced.cut
    count = cut.mesh.num_cells
    warp, fill = np.full((count, 3), np.nan), np.full((count, 3), np.nan)
    shear = np.full(count, np.nan)
    for index, net in enumerate(spliced.nets or []):
        if net is not None:
            cells = cut.panel_ids == index
            warp[cells], fill[cells] = net.drape.warp, net.drape.fill
            shear[cells] = net.drape.shear_angle
    return warp, fill, shear


def _read_back(origin, areas, count, warp, fill, shear) -> tuple[np.ndarray, ...]:
    """Warp, fill and shear of an opened or cut mesh's cells (each in the ply's cell
    ``origin``, of 3D ``areas``) per cell of the ply's mesh (``count`` cells;
    :func:`on_mould_cells`)."""
    return (
        on_mould_cells(warp, origin, areas, count, unit=True),
        on_mould_cells(fill, origin, areas, count, unit=True),
        on_mould_cells(shear, origin, areas, count),
    )
