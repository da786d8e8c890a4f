"""Reading a job's input: one surface, or the panels of a structure — repaired, in known units,
with what was changed or is doubtful said aloud; and reading back the patterns a job wrote (for
``vares erect DIR``)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..analysis.erection_model import Pattern
from ..geometry.examples import CUT_EXAMPLES, EXAMPLES, PANEL_NAMES, STRUCTURE_EXAMPLES
from ..geometry.mesh import MeshError, SurfaceMesh
from ..geometry.repair import RepairReport
from ..io.meshes import MeshFile, read_mesh, read_mesh_data, read_mesh_file, read_pattern
from ..io.rhino import read_3dm_file
from ..materials import Fibres
from ..structures.panels import Panel, split_panels
from ..units import implausible_size
from .job import Job, JobError

__all__ = ["DEFAULT_UNITS", "Input", "load_input", "safe_name", "saved_patterns", "saved_units"]

#: Units of coordinates when neither the file nor the job names any.
DEFAULT_UNITS = "m"


@dataclass
class Input:
    """The surfaces of a job (one for a single pattern), the cell data of a single mesh file
    (global cell order), the length units, what the repair changed (per file), warnings about
    the input, the pattern to start from (if the job names one) and, for a structure, the cell
    data of every panel."""

    panels: list[Panel]
    units: str
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)
    repairs: dict[str, dict[str, object]] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    initial_pattern: np.ndarray | None = None
    #: per panel of a structure, its cells' data (each panel's own cell order)
    panel_cell_data: list[dict[str, np.ndarray]] = field(default_factory=list)


def load_input(job: Job) -> Input:
    """Read the job's surface or panels; clear errors for inputs that do not fit the job."""
    source = job.input
    if source.example is not None:
        loaded = _example(job)
    elif job.structure is None or job.cut is not None:
        if source.meshes is not None:
            what = "cut one surface" if job.cut is not None else "pattern them with 'vares panels'"
            raise JobError(f"several mesh files are a structure: {what}")
        mesh_file = _read(job, source.mesh)
        panel = Panel(source.name or mesh_file.path.stem, mesh_file.surface())
        loaded = Input([panel], _units(job, [mesh_file.units]), mesh_file.cell_data)
        _note(loaded, [mesh_file])
    else:
        loaded = _structure(job)
    if source.initial_pattern is not None:
        if job.structure is not None:
            raise JobError("an initial pattern file is for a single surface, not a structure")
        path = job.path(source.initial_pattern)
        loaded.initial_pattern = read_pattern(path, loaded.panels[0].mesh)
    extent = max(float(np.ptp(p.mesh.points, axis=0).max()) for p in loaded.panels)
    doubt = implausible_size(extent, loaded.units)
    if doubt is not None:
        loaded.warnings.append(doubt)
    return loaded


def _read(job: Job, path: str) -> MeshFile:
    return read_mesh_file(job.path(path), repair=job.input.repair)


def _units(job: Job, declared: list[str | None]) -> str:
    """The job's units: the file's own, or those the job names (they must agree)."""
    named = {d for d in declared if d is not None}
    if len(named) > 1:
        raise JobError(f"the input files declare different units: {', '.join(sorted(named))}")
    given = job.input.units
    if named and given is not None and given not in named:
        raise JobError(
            f"the input declares its coordinates in {named.pop()}, the job says {given}: "
            "drop --units (the file's own are used) or fix the file"
        )
    return next(iter(named), given or DEFAULT_UNITS)


def _note_repair(loaded: Input, label: str, report: RepairReport) -> None:
    """Say what the repair of ``label`` (a file, or an object of one) changed, if anything."""
    if report.changed:
        loaded.repairs[label] = report.to_dict()
        loaded.warnings.append(f"repaired {label}: {'; '.join(report.actions())}")


def _note(loaded: Input, files: list[MeshFile]) -> None:
    for mesh_file in files:
        _note_repair(loaded, mesh_file.path.name, mesh_file.repair)
        precision = mesh_file.precision_warning()
        if precision is not None:
            loaded.warnings.append(precision)


def _example(job: Job) -> Input:
    name, cell_type = job.input.example, job.input.cell_type
    units = _units(job, [])
    if name in CUT_EXAMPLES and job.cut is None:
        raise JobError(f"example {name!r} is a surface to cut: 'vares cut --example {name}'")
    if job.structure is None or job.cut is not None:
        if name in STRUCTURE_EXAMPLES:
            raise JobError(f"example {name!r} is a structure: pattern it with 'vares panels'")
        mesh = {**EXAMPLES, **CUT_EXAMPLES}[name](cell_type=cell_type)
        return Input([Panel(job.input.name or name, mesh)], units)
    if name not in STRUCTURE_EXAMPLES:
        raise JobError(
            f"example {name!r} is a single surface; structure examples: "
            f"{', '.join(STRUCTURE_EXAMPLES)}"
        )
    mesh, ids = STRUCTURE_EXAMPLES[name](cell_type=cell_type)
    prefix = PANEL_NAMES.get(name, "panel")
    names = {int(i): f"{prefix}-{int(i) + 1}" for i in np.unique(ids)}
    return Input(split_panels(mesh, ids, names), units)


def _structure(job: Job) -> Input:
    paths = [job.path(p) for p in job.input.paths]
    if len(paths) == 1 and paths[0].suffix.lower() == ".3dm":
        rhino = read_3dm_file(paths[0], repair_meshes=job.input.repair)  # one parse
        panels = [Panel(m.name, m.mesh) for m in rhino.meshes]
        loaded = Input(panels, _units(job, [rhino.units]))
        for m in rhino.meshes:
            _note_repair(loaded, f"{paths[0].name}, object {m.name!r}", m.repair)
    elif len(paths) > 1:
        files = [_read(job, p) for p in paths]
        panels = [Panel(f.path.stem, f.surface()) for f in files]
        loaded = Input(panels, _units(job, [f.units for f in files]))
        loaded.panel_cell_data = [f.cell_data for f in files]
        _note(loaded, files)
    else:
        mesh_file = _read(job, paths[0])
        panels, cell_ids = _split(job, mesh_file)
        loaded = Input(panels, _units(job, [mesh_file.units]))
        loaded.panel_cell_data = [
            {k: np.asarray(v)[ids] for k, v in mesh_file.cell_data.items()} for ids in cell_ids
        ]
        _note(loaded, [mesh_file])
    if len(loaded.panels) < 2:
        raise JobError("a structure needs at least two panels")
    names = [p.name for p in loaded.panels]
    clashes = sorted({n for n in names if names.count(n) > 1})
    if clashes:
        raise JobError(
            f"two panels are named {clashes[0]!r}: their outputs would overwrite each other "
            "(rename the files or objects)"
        )
    return loaded


def _split(job: Job, mesh_file: MeshFile) -> tuple[list[Panel], list[np.ndarray]]:
    """Panels by the panel field of the cell data or, without one, the mesh's separate pieces;
    and the global ids of each panel's cells (in its own cell order)."""
    key = job.input.panel_field
    if key in mesh_file.cell_data:
        names = mesh_file.cell_names.get(key)  # a DXF's layer names
        ids = np.asarray(mesh_file.cell_data[key]).ravel()
        panels = split_panels(mesh_file.surface(), ids, names)
        # split_panels takes each panel's cells in the global order (type blocks in turn)
        return panels, [np.flatnonzero(ids == value) for value in np.unique(ids)]
    pieces = mesh_file.pieces()
    if len(pieces) < 2:
        raise MeshError(
            f"{mesh_file.path} is one piece and has no cell data {key!r} with panel ids "
            f"(it has: {', '.join(mesh_file.cell_data) or 'none'})"
        )
    panels = [Panel(f"{mesh_file.path.stem}-{k + 1}", mesh) for k, (mesh, _) in enumerate(pieces)]
    return panels, [cells for _, cells in pieces]


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
    cell_data = [{}] * len(folders)
    if job.prestress.field is not None and job.structure is None:
        cell_data = [read_mesh_data(job.path(job.input.mesh))[1]]
    elif job.prestress.field is not None and job.cut is not None:  # the cells strips came from
        cell_data = None
    elif job.prestress.field is not None:  # each panel's rows of the field, as when solved
        cell_data = load_input(job).panel_cell_data
        if len(cell_data) != len(folders):
            raise JobError("per-cell prestress needs the panels' cell data (a mesh file's)")
    patterns = []
    if cell_data is None:
        return _saved_strips(job, folders)
    for folder, data in zip(folders, cell_data, strict=True):
        name, mesh, coordinates, fibres = _saved_panel(folder)
        patterns.append(Pattern(mesh, coordinates, fibres, job.prestress.value(data), name))
    return patterns


def _saved_panel(folder: Path) -> tuple[str, SurfaceMesh, np.ndarray, Fibres]:
    """A panel's name, surface, pattern and fibres as a run wrote them into ``folder``."""
    summary = _read_json(folder / "summary.json")
    name = summary.get("name") or folder.name
    if not summary.get("converged"):
        raise JobError(f"{name}: the pattern did not converge ({summary.get('reason')})")
    mesh = read_mesh(folder / "surface.vtu")
    coordinates = read_pattern(folder / "pattern.vtu", mesh)
    fibres = Fibres(*(np.asarray(summary["fibres"][k], dtype=float) for k in ("warp", "fill")))
    return name, mesh, coordinates, fibres


def _saved_strips(job: Job, folders: list[Path]) -> list[Pattern]:
    """The saved patterns of a cut whose prestress is per cell of its surface: each strip's
    cells take the rows of the surface's cells they were cut from, as when solved."""
    from ..geometry.surface_lines import triangulated
    from ..structures.cutting import input_cells

    source = load_input(job)
    surface = source.panels[0].mesh
    rows = np.asarray(job.prestress.value(source.cell_data), dtype=float)
    patterns = []
    for folder in folders:
        name, mesh, coordinates, fibres = _saved_panel(folder)
        (ids,) = input_cells(surface, triangulated(surface), [Panel(name, mesh)])
        patterns.append(Pattern(mesh, coordinates, fibres, rows[ids], name))
    return patterns


def saved_units(job: Job) -> str:
    """The length units a run stated in its summary (those of the input, or the job's)."""
    name = "summary.json" if job.structure is None else "structure.json"
    units = _read_json(job.directory / name).get("units", {})
    return units.get("length") or job.input.units or DEFAULT_UNITS


def safe_name(name: str) -> str:
    """A panel name as a folder name (letters, digits, ``-_.``)."""
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "panel"
