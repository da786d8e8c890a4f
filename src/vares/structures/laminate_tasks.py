"""Draping a laminate's distinct plies: one task per ply, run here, in local worker processes or on
the workers of a Dask distributed scheduler, and a darted ply's cells read back on the mould.

A task is a plain dictionary (the ply's mesh, material, warp, solve settings, kinematic net and
darts), so it pickles to any worker and its outcome does not depend on where it ran. A ply with
darts (``"auto"``, or dart lines of its own) is solved by
:func:`vares.analysis.darts.solve_with_darts`: the pattern of the ply's mesh, then the pattern of
the mesh cut open along the darts. Cutting the mesh makes the dart lines' points nodes, so the
cells a dart crosses are split, and every node of a dart but its tip gets a twin: the opened mesh
has more cells than the ply's. Each of its cells lies in one cell of the ply's mesh
(:attr:`~vares.geometry.slits.SlitMesh.cell_origin`); a cell no dart crosses is that very
triangle. A ply is cut with its darts only when they lower its largest shear
(:func:`~vares.structures.laminate_plies.darts_used`): darts that leave it as high or higher
(the rib's, docs/composites.md) are reported, and the ply is cut whole.
:func:`on_mould_cells` gives every cell of the ply's mesh the area-weighted mean of its pieces
(unit vectors normalised again), which is the piece's own value where the cell is whole.
"""

from __future__ import annotations

import hashlib
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..analysis.darts import solve_with_darts
from ..analysis.drape import drape_ply
from ..geometry.mesh import SurfaceMesh
from ..materials.forming import locking_angle
from ..options import OptionsError
from ..parallel import parallel_map
from ..solver.api import solve
from .laminate_options import LaminateOptions, PlyOptions
from .laminate_plies import Ply, darts_used

__all__ = [
    "dart_task",
    "darts_used",
    "drape_key",
    "drape_task",
    "drape_tasks",
    "on_mould_cells",
    "ply_locking_angle",
]


def drape_task(task: dict[str, Any]) -> dict[str, Any]:
    """Drape one distinct ply (in any process): the pattern of its mesh, with its darts when
    asked (``task["darts"]``: ``None``, or the keywords of the locking angle, the dart mode and
    given lines), and the kinematic net beside it (its failure is reported, not raised). Plies
    may be draped in several threads of one process at once (a Dask worker's threads): each
    thread solves with its own linear solver (:class:`vares.solver.linear.PardisoState`)."""
    return _drape(task)


def _drape(task: dict[str, Any]) -> dict[str, Any]:
    started = time.perf_counter()
    mesh = task["mesh"]
    settings = {**task["solve"], "warp_direction": tuple(task["warp"])}
    darted = None
    if task["darts"] is None:
        pattern = solve(mesh, task["material"], 1.0, **settings)
    else:
        darts = task["darts"]
        darted = solve_with_darts(
            mesh,
            task["material"],
            1.0,
            locking_angle=darts["locking_angle"],
            polylines=darts["polylines"],
            darts=darts["mode"],
            **settings,
        )
        pattern = darted.before
    kinematic, error = None, None
    if task["kinematic"] is not None:
        try:
            kinematic = drape_ply(mesh, **task["kinematic"])
        except Exception as exc:  # the net is beside the pattern: its failure is reported
            error = f"{type(exc).__name__}: {exc}"
    return {
        "pattern": pattern,
        "darted": darted,
        "kinematic": kinematic,
        "error": error,
        "seconds": time.perf_counter() - started,
    }


def drape_tasks(
    tasks: Sequence[dict[str, Any]], workers: int, scheduler: str | None = None
) -> tuple[list[dict[str, Any]], int]:
    """The outcomes of :func:`drape_task` for ``tasks``, in their order, and the number of
    workers that ran them: the Dask scheduler's at ``scheduler`` (``tcp://host:port``), else
    ``workers`` local processes (in this process when 1; :func:`vares.parallel.parallel_map`)."""
    return parallel_map(drape_task, tasks, workers=workers, scheduler=scheduler)


def on_mould_cells(
    values: np.ndarray, origin: np.ndarray, areas: np.ndarray, count: int, unit: bool = False
) -> np.ndarray:
    """Per cell of the ply's mesh ``(count, ...)``: the area-weighted mean of ``values``
    ``(k, ...)`` over the cells of the opened mesh that lie in it (``origin`` ``(k,)``: the cell
    each lies in; ``areas`` ``(k,)`` their 3D areas); normalised when ``unit`` (yarn directions).
    A cell no piece lies in is refused."""
    values = np.asarray(values, dtype=float)
    weighted = values * areas.reshape(-1, *([1] * (values.ndim - 1)))
    total = np.zeros((count, *values.shape[1:]))
    np.add.at(total, origin, weighted)
    weight = np.bincount(origin, areas, minlength=count)
    if (weight <= 0).any():
        raise ValueError(f"{int((weight <= 0).sum())} cells of the ply have no opened cell")
    if unit:
        return total / np.linalg.norm(total, axis=1)[:, None]
    return total / weight.reshape(-1, *([1] * (values.ndim - 1)))


def ply_locking_angle(options: LaminateOptions, ply: PlyOptions) -> float:
    """The locking angle of ``ply`` (degrees): its own, else the laminate's, else that of its
    fabric kind (or the laminate's fabric kind)."""
    if ply.locking_angle is not None:
        return float(ply.locking_angle)
    if options.locking_angle is not None:
        return float(options.locking_angle)
    return float(locking_angle(ply.fabric_kind or options.fabric_kind))


def dart_task(ply: Ply, options: LaminateOptions, mesh: SurfaceMesh) -> dict[str, Any] | None:
    """What the ply's darts need in its task, or ``None`` without darts."""
    mode = ply.options.darts or options.darts
    if ply.dart_lines is None and mode == "none":
        return None
    if ply.options.dart_lines is not None and ply.dart_lines is None:
        raise OptionsError("dart_lines", f"ply {ply.name}: pass the file's lines as dart_lines")
    if set(mesh.cells) != {"triangle"}:
        raise OptionsError("darts", f"ply {ply.name}: darts need a mould of triangles")
    lines = None if ply.dart_lines is None else [np.asarray(p, float) for p in ply.dart_lines]
    return {
        "locking_angle": ply_locking_angle(options, ply.options),
        "mode": "none" if lines is not None else mode,
        "polylines": lines,
    }


def drape_key(
    ply: Ply, options: LaminateOptions, seed: np.ndarray, cells: np.ndarray, darts: dict | None
) -> tuple:
    """What makes two plies one drape: orientation, material, seed, fabric kind, locking
    angle (both as the ply takes them, its own or the laminate's), cells and darts (the plies
    of a symmetric stack's halves share it)."""
    o = ply.options
    if darts is not None and darts["polylines"] is not None:
        digest = hashlib.sha1(
            b"".join(np.ascontiguousarray(p).tobytes() for p in darts["polylines"])
        )
        darts = {**darts, "polylines": digest.hexdigest()}
    return (
        None if darts is None else tuple(sorted(darts.items())),
        round(float(o.orientation) % 360.0, 9),
        repr(ply.material.parameters) + type(ply.material).__name__,
        tuple(np.round(seed, 12)),
        o.fabric_kind or options.fabric_kind,
        ply_locking_angle(options, o),
        cells.tobytes(),
    )
