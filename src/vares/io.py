"""Writing results: pattern meshes and JSON summaries, each file written atomically.

A file is first written under a temporary name in its target folder and then renamed, so a
failure never leaves a half-written file behind, and an existing file is only replaced when the
caller allows it.
"""

from __future__ import annotations

import itertools
import json
import os
import tempfile
from collections.abc import Callable, Iterable
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from .mesh import SurfaceMesh
from .solver import PatternResult

__all__ = [
    "OutputExistsError",
    "atomic_path",
    "check_writable",
    "field_statistics",
    "read_pattern",
    "summary",
    "write_json",
    "write_surface",
]


class OutputExistsError(FileExistsError):
    """An output file exists and overwriting was not allowed."""


def check_writable(paths: Iterable[Path], overwrite: bool) -> None:
    """Raise :class:`OutputExistsError` naming the paths that exist, unless ``overwrite``."""
    existing = [str(p) for p in paths if p.exists()]
    if existing and not overwrite:
        raise OutputExistsError(f"output exists: {', '.join(existing)} (use --force to overwrite)")


@contextmanager
def atomic_path(path: Path):
    """Yield a temporary path beside ``path`` (same suffix); rename it to ``path`` on success."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(
        dir=path.parent, prefix=f".{path.stem}-", suffix=path.suffix
    )
    os.close(handle)
    os.chmod(temporary, 0o666 & ~_umask())
    try:
        yield Path(temporary)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def _umask() -> int:
    current = os.umask(0)
    os.umask(current)
    return current


def _write_with(path: Path, writer: Callable[[Path], None]) -> None:
    with atomic_path(path) as temporary:
        writer(temporary)


def write_surface(
    path: Path,
    mesh: SurfaceMesh,
    coordinates: np.ndarray | None = None,
    fields: dict[str, np.ndarray] | None = None,
) -> None:
    """Write the mesh (or, with ``coordinates`` ``(n, 2)``, the flat pattern at z = 0).

    The format follows the suffix (any format meshio writes: .obj, .vtu, .ply, .stl, …); nodes
    and cells are those of ``mesh``, in the same order. ``fields`` (per cell, global cell order)
    are written as cell data where the format has it (VTU, VTK).
    """
    import meshio

    points = mesh.points
    if coordinates is not None:
        points = np.column_stack([coordinates, np.zeros(len(coordinates))])
    blocks = list(mesh.cells.items())
    cell_data = {}
    if fields:
        bounds = np.cumsum([0] + [len(c) for _, c in blocks])
        cell_data = {
            name: [np.asarray(values[a:b], dtype=float) for a, b in itertools.pairwise(bounds)]
            for name, values in fields.items()
        }
    out = meshio.Mesh(points, blocks, cell_data=cell_data)
    # the temporary file keeps the suffix, from which meshio takes the format
    _write_with(Path(path), lambda p: meshio.write(p, out))


def read_pattern(path: Path, mesh: SurfaceMesh) -> np.ndarray:
    """Pattern coordinates ``(n, 2)`` from a file written by :func:`write_surface` for ``mesh``.

    The file must have the same cells as ``mesh`` (same nodes and faces) and lie in z = 0.
    """
    import meshio

    from .mesh import MeshError

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    try:
        raw = meshio.read(path)
    except Exception as exc:
        raise MeshError(f"cannot read {path}: {type(exc).__name__}: {exc}") from exc
    cells = {b.type: b.data for b in raw.cells if b.type in mesh.cells}
    same = len(raw.points) == mesh.num_points and all(
        t in cells and np.array_equal(cells[t], c) for t, c in mesh.cells.items()
    )
    if not same:
        raise MeshError(f"{path} does not have the nodes and faces of the surface mesh")
    points = np.asarray(raw.points, dtype=float)
    if points.shape[1] == 3 and np.abs(points[:, 2]).max(initial=0.0) > 1e-9 * np.ptp(points):
        raise MeshError(f"{path} is not flat (z ≠ 0): not a pattern")
    return points[:, :2].copy()


def write_json(path: Path, data: dict) -> None:
    """Write ``data`` as indented JSON (numpy scalars and arrays converted)."""

    def default(value):
        if isinstance(value, np.ndarray):
            return value.tolist()
        if isinstance(value, np.generic):
            return value.item()
        raise TypeError(f"cannot write {type(value).__name__} to JSON")

    text = json.dumps(data, indent=2, default=default, allow_nan=True) + "\n"
    _write_with(Path(path), lambda p: p.write_text(text, encoding="utf-8"))


def _statistics(values: np.ndarray, weights: np.ndarray) -> dict[str, float]:
    finite = np.isfinite(values)
    if not finite.any():
        return {"min": float("nan"), "max": float("nan"), "mean": float("nan")}
    v, w = values[finite], weights[finite]
    return {"min": float(v.min()), "max": float(v.max()), "mean": float(v @ w / w.sum())}


def field_statistics(fields: dict[str, np.ndarray]) -> dict[str, dict[str, float]]:
    """Min, max and pattern-area-weighted mean of every per-cell field (areas excluded).

    For the 0/1 flags (``compressed_yarns``, ``wrinkling``) the mean is the area fraction.
    """
    weights = fields["pattern_area"]
    return {
        name: _statistics(values, weights)
        for name, values in fields.items()
        if name not in ("pattern_area", "surface_area", "energy")
    }


def summary(result: PatternResult, **extra: object) -> dict:
    """The key figures of a solve as a JSON-ready dictionary.

    Field statistics are min, max and pattern-area-weighted mean over the cells.
    """
    from . import __version__

    mesh = result.mesh
    last = result.history[-1] if result.history else None
    out: dict[str, object] = {
        "vares_version": __version__,
        **extra,
        "converged": result.converged,
        "reason": result.reason,
        "energy": result.energy,
        "iterations": result.iterations,
        "final_relative_residual": None if last is None else last.relative_residual,
        "strategy": result.strategy,
        "linear_solver": result.linear_solver,
        "elapsed_seconds": result.elapsed,
        "mesh": {
            "points": mesh.num_points,
            "cells": {t: len(c) for t, c in mesh.cells.items()},
        },
        "material": {"law": type(result.material).__name__, **result.material.parameters},
        "thickness": result.thickness,
        "surface_area": result.surface_area,
        "pattern_area": result.pattern_area,
        "steps": [
            {
                "strategy": s.strategy,
                "step": s.step,
                "tau": s.tau,
                "iterations": s.iterations,
                "converged": s.converged,
                "reason": s.reason,
            }
            for s in result.steps
        ],
    }
    out["fibres"] = {
        "orientation": result.orientation,
        "warp": result.fibres.warp,
        "fill": result.fibres.fill,
        "warp_direction": result.warp_direction,
        "warp_deviation_degrees": result.warp_deviation,
    }
    if result.converged:
        out["fields"] = field_statistics(result.fields)
    out["history"] = [
        {
            "strategy": r.strategy,
            "step": r.step,
            "tau": r.tau,
            "iteration": r.iteration,
            "residual": r.residual,
            "relative_residual": r.relative_residual,
            "energy": r.energy,
            "damping": r.damping,
        }
        for r in result.history
    ]
    return out
