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

A ply with splice lines is solved by :func:`vares.analysis.splices.solve_with_splices`, one
with ``splices = "auto"`` by :func:`vares.analysis.splice_lines.place_splices` (through its
seed; none where it stays below its locking angle): the pattern of the ply's mesh (the pair
check's), then the mesh cut into pieces along the lines and every piece's pattern; with the
kinematic net, every piece gets its own too (from its node nearest its centroid), beside the
whole ply's. The cut splits the cells the lines cross, too;
each cut cell lies in one cell of the ply's mesh (:func:`cut_origin`).
:func:`on_mould_cells` gives every cell of the ply's mesh the area-weighted mean of its pieces
(unit vectors normalised again), which is the piece's own value where the cell is whole.
"""

from __future__ import annotations

import dataclasses
import hashlib
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..analysis.darts import solve_with_darts
from ..analysis.drape import drape_ply
from ..analysis.splice_lines import place_splices
from ..analysis.splices import solve_with_splices
from ..geometry.mesh import SurfaceMesh
from ..geometry.surface_lines import CuttingError
from ..materials.forming import locking_angle
from ..options import OptionsError
from ..parallel import parallel_map
from ..solver.api import solve
from .laminate_options import LaminateOptions, PlyOptions
from .laminate_plies import Ply, darts_used

__all__ = [
    "cut_origin",
    "dart_task",
    "darts_used",
    "drape_key",
    "drape_task",
    "drape_tasks",
    "on_mould_cells",
    "ply_locking_angle",
    "splice_task",
]


def drape_task(task: dict[str, Any]) -> dict[str, Any]:
    """Drape one distinct ply (in any process): the pattern of its mesh, with its darts when
    asked (``task["darts"]``: ``None``, or the keywords of the locking angle, the dart mode and
    given lines) or its pieces along splice lines (``task["splices"]``: ``None``, or the locking
    angle and the lines), and the kinematic net beside it (its failure is reported, not raised;
    a spliced ply's pieces each get one too). Plies may be draped in several threads of one
    process at once (a Dask worker's threads): each thread solves with its own linear solver
    (:class:`vares.solver.pardiso.PardisoState`)."""
    return _drape(task)


def _drape(task: dict[str, Any]) -> dict[str, Any]:
    started = time.perf_counter()
    mesh = task["mesh"]
    settings = {**task["solve"], "warp_direction": tuple(task["warp"])}
    darted = spliced = placed = None
    try:
        splices = task.get("splices")
        if splices is not None:
            cut = {"locking_angle": splices["locking_angle"], **settings}
            if splices["polylines"] is None:  # through the seed
                found = place_splices(mesh, task["material"], 1.0, seed=task["seed"], **cut)
                pattern, spliced, placed = found.before, found.spliced, found.summary()
            else:
                lines = splices["polylines"]
                spliced = solve_with_splices(mesh, task["material"], 1.0, polylines=lines, **cut)
                pattern = spliced.before
        elif task["darts"] is None:
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
    except CuttingError as exc:  # a ply's darts or splices: which ply's
        raise CuttingError(f"ply {task.get('name', '?')}: {exc}") from None
    kinematic, error = None, None
    if task["kinematic"] is not None:
        kinematic, error = _net(mesh, task["kinematic"])
        if spliced is not None:  # every piece's own net, from its node nearest its centroid
            own = {**task["kinematic"], "seed": None}
            nets, errors = zip(*(_net(piece.mesh, own) for piece in spliced.pieces), strict=True)
            spliced = dataclasses.replace(spliced, nets=list(nets), net_errors=list(errors))
    return {
        "pattern": pattern,
        "darted": darted,
        "spliced": spliced,
        "placed": placed,
        "kinematic": kinematic,
        "error": error,
        "seconds": time.perf_counter() - started,
    }


def _net(mesh: SurfaceMesh, settings: dict[str, Any]) -> tuple[Any, str | None]:
    """The kinematic net on ``mesh`` and None, or None and why it failed (the net is beside the
    pattern: its failure is reported)."""
    try:
        return drape_ply(mesh, **settings), None
    except Exception as exc:
        return None, f"{type(exc).__name__}: {exc}"


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


def cut_origin(mesh: SurfaceMesh, cut: SurfaceMesh) -> np.ndarray:
    """The cell of the triangle mesh ``mesh`` ``(k,)`` that each cell of ``cut`` lies in:
    ``cut`` is ``mesh`` with lines cut into it (every cell of it a part of one of ``mesh``'s,
    so its centroid lies inside that cell)."""
    from ..geometry.surface_points import FaceLocator

    centroids = np.concatenate([cut.points[c].mean(axis=1) for c in cut.cells.values()])
    return FaceLocator(mesh).locate(centroids)[0]


def cutting_modes(ply: Ply, options: LaminateOptions) -> tuple[str, str]:
    """How the ply is cut: its darts' mode (``"lines"``, ``"auto"`` or ``"none"``) and its
    splices' (the same). A ply's own darts, dart lines, splice lines or splices override the
    laminate's darts and splices; the laminate's apply to the plies that name neither."""
    o = ply.options
    if ply.splice_lines is not None or o.splice_lines is not None:
        return "none", "lines"
    if ply.dart_lines is not None or o.dart_lines is not None:
        return "lines", "none"
    if o.darts == "auto" or o.splices == "auto":
        return o.darts or "none", o.splices or "none"
    darts = o.darts or options.darts
    splices = o.splices or ("none" if darts == "auto" else options.splices)
    return darts, splices


def splice_task(ply: Ply, options: LaminateOptions, mesh: SurfaceMesh) -> dict[str, Any] | None:
    """What the ply's splices need in its task (their locking angle, and the lines: ``None`` to
    place them through the seed), or ``None`` without splices."""
    _, mode = cutting_modes(ply, options)
    if mode == "none":
        return None
    if mode == "lines" and ply.splice_lines is None:
        raise OptionsError("splice_lines", f"ply {ply.name}: pass the file's lines as splice_lines")
    if set(mesh.cells) != {"triangle"}:
        raise OptionsError("splice_lines", f"ply {ply.name}: splices need a mould of triangles")
    lines = None if mode == "auto" else [np.asarray(p, float) for p in ply.splice_lines]
    return {"locking_angle": ply_locking_angle(options, ply.options), "polylines": lines}


def dart_task(ply: Ply, options: LaminateOptions, mesh: SurfaceMesh) -> dict[str, Any] | None:
    """What the ply's darts need in its task, or ``None`` without darts (a spliced ply has
    none: its pieces relieve it)."""
    mode, _ = cutting_modes(ply, options)
    if mode == "none":
        return None
    if mode == "lines" and ply.dart_lines is None:
        raise OptionsError("dart_lines", f"ply {ply.name}: pass the file's lines as dart_lines")
    if set(mesh.cells) != {"triangle"}:
        raise OptionsError("darts", f"ply {ply.name}: darts need a mould of triangles")
    lines = None if ply.dart_lines is None else [np.asarray(p, float) for p in ply.dart_lines]
    return {
        "locking_angle": ply_locking_angle(options, ply.options),
        "mode": "none" if lines is not None else mode,
        "polylines": lines,
    }


def _digested(lines: dict | None) -> tuple | None:
    """A darts' or splices' task entry as a key: its polylines by their digest."""
    if lines is None:
        return None
    if lines["polylines"] is not None:
        digest = hashlib.sha1()
        for p in lines["polylines"]:  # each line's shape too: [A, B] is not [A + B]
            digest.update(repr(np.shape(p)).encode() + np.ascontiguousarray(p).tobytes())
        lines = {**lines, "polylines": digest.hexdigest()}
    return tuple(sorted(lines.items()))


def drape_key(
    ply: Ply,
    options: LaminateOptions,
    seed: np.ndarray,
    cells: np.ndarray,
    darts: dict | None,
    splices: dict | None = None,
) -> tuple:
    """What makes two plies one drape: orientation, material, seed, fabric kind, locking
    angle (both as the ply takes them, its own or the laminate's), cells, darts and splices
    (the plies of a symmetric stack's halves share it)."""
    o = ply.options
    return (
        _digested(darts),
        _digested(splices),
        round(float(o.orientation) % 360.0, 9),
        repr(ply.material.parameters) + type(ply.material).__name__,
        tuple(np.round(seed, 12)),
        o.fabric_kind or options.fabric_kind,
        ply_locking_angle(options, o),
        cells.tobytes(),
    )
