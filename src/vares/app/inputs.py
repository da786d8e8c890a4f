"""Reading a job's input: one surface, or the panels of a structure; and reading back the
patterns a job wrote (for ``vares erect DIR``)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..analysis.erection_model import Pattern
from ..geometry.examples import EXAMPLES, PANEL_NAMES, STRUCTURE_EXAMPLES
from ..geometry.mesh import MeshError
from ..io.meshes import read_mesh, read_mesh_data, read_pattern
from ..io.rhino import read_3dm
from ..materials import Fibres
from ..structures.panels import Panel, split_panels
from .job import Job, JobError

__all__ = ["Input", "load_input", "safe_name", "saved_patterns"]


@dataclass
class Input:
    """The surfaces of a job (one for a single pattern) and, for a single mesh file, its cell
    data in global cell order."""

    panels: list[Panel]
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)


def load_input(job: Job) -> Input:
    """Read the job's surface or panels; clear errors for inputs that do not fit the job."""
    source = job.input
    if source.example is not None:
        return _example(job)
    if job.structure is None:
        if source.meshes is not None:
            raise JobError("several mesh files are a structure: pattern them with 'vares panels'")
        path = job.path(source.mesh)
        mesh, cell_data = read_mesh_data(path)
        return Input([Panel(source.name or path.stem, mesh)], cell_data)
    return Input(_structure_panels(job))


def _example(job: Job) -> Input:
    name, cell_type = job.input.example, job.input.cell_type
    if job.structure is None:
        if name in STRUCTURE_EXAMPLES:
            raise JobError(f"example {name!r} is a structure: pattern it with 'vares panels'")
        mesh = EXAMPLES[name](cell_type=cell_type)
        return Input([Panel(job.input.name or name, mesh)])
    if name not in STRUCTURE_EXAMPLES:
        raise JobError(
            f"example {name!r} is a single surface; structure examples: "
            f"{', '.join(STRUCTURE_EXAMPLES)}"
        )
    mesh, ids = STRUCTURE_EXAMPLES[name](cell_type=cell_type)
    prefix = PANEL_NAMES.get(name, "panel")
    names = {int(i): f"{prefix}-{int(i) + 1}" for i in np.unique(ids)}
    return Input(split_panels(mesh, ids, names))


def _structure_panels(job: Job) -> list[Panel]:
    files = [job.path(p) for p in job.input.paths]
    if len(files) > 1:
        panels = [Panel(f.stem, read_mesh(f)) for f in files]
    elif files[0].suffix.lower() == ".3dm":
        panels = [Panel(m.name, m.mesh) for m in read_3dm(files[0])]
    else:
        mesh, cell_data = read_mesh_data(files[0])
        key = job.input.panel_field
        if key not in cell_data:
            raise MeshError(
                f"{files[0]} has no cell data {key!r} with panel ids "
                f"(it has: {', '.join(cell_data) or 'none'})"
            )
        panels = split_panels(mesh, cell_data[key])
    if len(panels) < 2:
        raise JobError("a structure needs at least two panels")
    names = [p.name for p in panels]
    clashes = sorted({n for n in names if names.count(n) > 1})
    if clashes:
        raise JobError(
            f"two panels are named {clashes[0]!r}: their outputs would overwrite each other "
            "(rename the files or objects)"
        )
    return panels


def _read_json(path: Path) -> dict:
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path} (is this an output directory of vares?)")
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except ValueError as exc:
        raise JobError(f"{path}: not valid JSON: {exc}") from None


def saved_patterns(job: Job) -> list[Pattern]:
    """The patterns a job wrote into its output directory, one per panel: the surface and the
    pattern from ``surface.vtu`` and ``pattern.vtu``, the fibres from ``summary.json``, the
    prestress from the job (a per-cell prestress field is read from the input file)."""
    directory = job.directory
    if job.structure is None:
        folders = [directory]
    else:
        names = [p["name"] for p in _read_json(directory / "structure.json")["panels"]]
        folders = [directory / safe_name(name) for name in names]
    cell_data = {}
    if job.prestress.field is not None:
        _, cell_data = read_mesh_data(job.path(job.input.mesh))
    patterns = []
    for folder in folders:
        summary = _read_json(folder / "summary.json")
        name = summary.get("name") or folder.name
        if not summary.get("converged"):
            raise JobError(f"{name}: the pattern did not converge ({summary.get('reason')})")
        mesh = read_mesh(folder / "surface.vtu")
        coordinates = read_pattern(folder / "pattern.vtu", mesh)
        fibres = Fibres(*(np.asarray(summary["fibres"][k], dtype=float) for k in ("warp", "fill")))
        prestress = job.prestress.value(cell_data)
        patterns.append(Pattern(mesh, coordinates, fibres, prestress, name))
    return patterns


def safe_name(name: str) -> str:
    """A panel name as a folder name (letters, digits, ``-_.``)."""
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "panel"
