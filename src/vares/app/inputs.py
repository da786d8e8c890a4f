"""Reading a job's input: one surface, or the panels of a structure."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..geometry.examples import CUT_EXAMPLES, EXAMPLES, STRUCTURE_EXAMPLES
from ..geometry.mesh import MeshError
from ..io.meshes import read_mesh, read_mesh_data
from ..io.rhino import read_3dm
from ..structures.panels import Panel, split_panels
from .job import Job, JobError

__all__ = ["Input", "load_input"]


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
    if job.structure is None or job.cut is not None:
        if source.meshes is not None:
            what = "cut one surface" if job.cut is not None else "pattern them with 'vares panels'"
            raise JobError(f"several mesh files are a structure: {what}")
        path = job.path(source.mesh)
        mesh, cell_data = read_mesh_data(path)
        return Input([Panel(source.name or path.stem, mesh)], cell_data)
    return Input(_structure_panels(job))


def _example(job: Job) -> Input:
    name, cell_type = job.input.example, job.input.cell_type
    if name in CUT_EXAMPLES and job.cut is None:
        raise JobError(f"example {name!r} is a surface to cut: 'vares cut --example {name}'")
    if job.structure is None or job.cut is not None:
        if name in STRUCTURE_EXAMPLES:
            raise JobError(f"example {name!r} is a structure: pattern it with 'vares panels'")
        mesh = {**EXAMPLES, **CUT_EXAMPLES}[name](cell_type=cell_type)
        return Input([Panel(job.input.name or name, mesh)])
    if name not in STRUCTURE_EXAMPLES:
        raise JobError(
            f"example {name!r} is a single surface; structure examples: "
            f"{', '.join(STRUCTURE_EXAMPLES)}"
        )
    mesh, ids = STRUCTURE_EXAMPLES[name](cell_type=cell_type)
    return Input(split_panels(mesh, ids, {int(i): f"strip-{int(i) + 1}" for i in np.unique(ids)}))


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
