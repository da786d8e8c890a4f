"""Writing results: pattern meshes and JSON summaries, each file written atomically.

A file is first written under a temporary name in its target folder and then renamed, so a
failure never leaves a half-written file behind, and an existing file is only replaced when the
caller allows it.
"""

from __future__ import annotations

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


def write_surface(path: Path, mesh: SurfaceMesh, coordinates: np.ndarray | None = None) -> None:
    """Write the mesh (or, with ``coordinates`` ``(n, 2)``, the flat pattern at z = 0).

    The format follows the suffix (any format meshio writes: .obj, .vtu, .ply, .stl, …); nodes
    and cells are those of ``mesh``, in the same order.
    """
    import meshio

    points = mesh.points
    if coordinates is not None:
        points = np.column_stack([coordinates, np.zeros(len(coordinates))])
    out = meshio.Mesh(points, [(t, c) for t, c in mesh.cells.items()])
    _write_with(Path(path), lambda p: meshio.write(p, out, file_format=_meshio_format(path)))


def _meshio_format(path: Path) -> str | None:
    suffix = Path(path).suffix.lower()
    return {".obj": "obj", ".vtu": "vtu", ".ply": "ply", ".stl": "stl", ".vtk": "vtk"}.get(suffix)


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
    if result.converged:
        fields = result.fields
        weights = fields["pattern_area"]
        out["fields"] = {
            name: _statistics(values, weights)
            for name, values in fields.items()
            if name not in ("pattern_area", "surface_area", "energy")
        }
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
