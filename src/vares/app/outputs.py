"""The files a job writes, planned before the solve and written after it.

One pattern (in the output directory; for a structure, in a folder per panel):

``pattern.obj``                 the flat pattern (same nodes and faces as the surface, z = 0)
``pattern.dxf``                 cutter drawing (seam, cut line, warp, marks, label)
``pattern.svg``, ``pattern.png`` the pattern drawn with its warp and fill directions
``pattern.vtu``, ``surface.vtu`` pattern and surface with every per-cell result (ParaView)
``summary.json``                the key figures, the compensation report and the history (and
                                with ``[scatter]`` the band of the pattern under the fabric's
                                scatter, key ``scatter``: :mod:`vares.app.run_band`)
``pattern_FIELD.svg/.png``, ``surface_FIELD.png``   the fields asked for with ``plots``
``surface.obj``                 the 3D surface, for examples and for a structure's panels
``report.html``                 with ``report``: everything above for a person, in one file

Every job writes ``job.toml`` into the output directory: the job as it ran (paths relative to
it), from which ``vares erect DIR`` (and ``vares run DIR/job.toml -o …``) take the input,
material, fibres and prestress; an erection writes ``erect/`` (:mod:`vares.app.erection_outputs`).

A structure adds ``structure.json`` (panels, seams before and after matching, the energy price,
the roll width check; with ``[scatter]`` the band of every panel and seam, key ``scatter``),
``structure.dxf`` (all patterns with matching marks) and, with ``report``,
its own ``report.html``. A cut job writes its pieces nested on the roll instead of
``structure.dxf``, and the files of :mod:`vares.app.cut_outputs`. Every target is checked
before the solve (nothing is overwritten without ``force``); every file is written atomically.
A solve that does not converge writes only the summaries.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .._version import __version__
from ..analysis.statistics import field_statistics
from ..io.dxf import CutPiece, write_dxf
from ..io.files import atomic_path, write_bytes, write_json, write_text
from ..io.meshes import write_surface
from ..io.sketch import DPI, pattern_sketch
from ..io.summary import summary
from ..structures.panels import width_across_warp
from ..structures.seams import seam_marks
from ..units import unit_factor
from .erection_outputs import erection_figures, erection_files
from .inputs import Input, safe_name
from .job import Job, JobError
from .outcome import JobOutcome, PanelOutcome
from .sections import MAX_MARKS

__all__ = [
    "JOB_FILE",
    "check_mark_spacing",
    "panel_directory",
    "planned_files",
    "safe_name",
    "write_job_file",
    "write_panel",
    "write_structure",
]

#: The job as it ran, in the output directory.
JOB_FILE = "job.toml"

#: The files of a cut job besides the strips' and the structure's (see app/cut_outputs.py).
CUT_FILES = ("cut.json", "nest.dxf", "nest.svg", "nest.png", "cut_lines.png", "panels.vtu")

#: The pictures of the pattern (``previews`` in the output options).
PREVIEW_FILES = ("pattern.svg", "pattern.png")
PATTERN_FILES = (
    "summary.json",
    "pattern.obj",
    "pattern.dxf",
    "pattern.svg",
    "pattern.png",
    "pattern.vtu",
    "surface.vtu",
)


def panel_directory(job: Job, name: str, root: Path | None = None) -> Path:
    """Where a panel's files go: the output folder ``root`` (default: the job's), or a folder
    of its own in it for a structure's panel."""
    root = job.directory if root is None else root
    return root if job.structure is None else root / safe_name(name)


def planned_files(job: Job, source: Input, save_job: Path | None = None) -> list[Path]:
    """Every file the job may write (checked for clashes before any work is done); a job file
    saved inside the output folder is one of them."""
    folders = [safe_name(p.name) for p in source.panels]
    clashes = sorted({f for f in folders if folders.count(f) > 1})
    if clashes:
        raise JobError(f"two panels would write into the same folder {clashes[0]!r}: rename them")
    files = []
    for panel in [] if job.cut is not None else source.panels:  # a cut's strips come later
        directory = panel_directory(job, panel.name)
        names = [n for n in PATTERN_FILES if job.output.previews or n not in PREVIEW_FILES]
        for field in job.output.plots:
            names += [f"pattern_{field}.svg", f"pattern_{field}.png", f"surface_{field}.png"]
        if job.input.example is not None or job.structure is not None:
            names.append("surface.obj")
        if job.output.report:
            names.append("report.html")
        files += [directory / n for n in names]
    if job.structure is not None:
        names = ["structure.json"] + (["report.html"] if job.output.report else [])
        names += list(CUT_FILES) if job.cut is not None else ["structure.dxf"]
        files += [job.directory / n for n in names]
    files.append(job.directory / JOB_FILE)
    if job.erection is not None:
        files += erection_files(job.directory / "erect")
    if save_job is not None and job.directory.resolve() in save_job.resolve().parents:
        files.append(save_job)
    return files


def check_mark_spacing(job: Job, source: Input) -> None:
    """Refuse a match mark spacing that would put more than :data:`MAX_MARKS` marks along the
    boundaries of the job's surfaces (a pattern's outline is as long as its surface's boundary,
    within the strain); a :class:`JobError` gives the shortest admissible spacing."""
    spacing = job.output.mark_spacing
    if spacing is None:
        return
    length = 0.0
    for panel in source.panels:
        points = panel.mesh.points
        for loop in panel.mesh.boundary_loops():
            ring = points[np.append(loop, loop[0])]
            length += float(np.linalg.norm(np.diff(ring, axis=0), axis=1).sum())
    units = job.output.dxf_units
    where = "surface's boundary" if len(source.panels) == 1 else "panels' boundaries"
    count = length * unit_factor(source.units, units) / spacing
    if count > MAX_MARKS:
        shortest = spacing * count / MAX_MARKS
        raise JobError(
            f"the match mark spacing (--mark-spacing) {spacing:g} {units} would put {count:.2g} "
            f"marks along the {length:.3g} {source.units} of the {where} (at most "
            f"{MAX_MARKS}): give a spacing of at least {shortest:.3g} {units}"
        )


def write_job_file(job: Job, directory: Path) -> Path:
    """``job.toml`` in ``directory`` (the staging folder of the output directory): the job as it
    ran, paths relative to the output directory."""
    text = job.to_toml(job.directory / JOB_FILE)
    path = directory / JOB_FILE
    write_text(path, text)
    return path


def write_panel(panel: PanelOutcome, outcome: JobOutcome, marks: np.ndarray | None = None) -> None:
    """The files of one pattern (all of them when it converged, else the summary and the
    surface); the paths go to ``panel.files``."""
    job, result = outcome.job, panel.result
    if job.input.example is not None or job.structure is not None:
        _write(panel, "surface.obj", lambda p: write_surface(p, panel.mesh, units=panel.units))
    if result.converged or result.uncuttable:
        dxf = result.converged or job.output.allow_overlap
        cut = None  # a strip of a cut job: its cut line with the allowance of every edge
        if outcome.cut is not None:
            cut = outcome.cut.outlines[outcome.panels.index(panel)].cut
        _write_pattern_files(panel, job, outcome.material.stiffness_scale, marks, dxf, cut)
    data = summary(
        result, name=panel.name, input=job.input.to_dict(), tolerance=result.options.tolerance
    )
    data["units"] = units_of(outcome)
    data["warnings"] = panel.warnings
    data["repairs"] = outcome.repairs
    if job.structure is None:
        data["job_digest"] = job.digest()
    if panel.compensation is not None:
        data["compensation"] = panel.compensation.to_dict()
    if panel.drape is not None:
        shear = result.fields["shear_angle"] if result.converged else None
        data["kinematic_drape"] = panel.drape.summary() | (
            {}
            if shear is None
            else {"against_pattern": panel.drape.comparison(shear, panel.mesh.cell_areas())}
        )
    if job.structure is None and outcome.erection is not None:
        data["erection"] = erection_figures(outcome.erection, outcome.units, outcome.optimum)
    if job.structure is None and outcome.scatter is not None:
        data["scatter"] = outcome.scatter.to_dict(outcome.units)
    _write(panel, "summary.json", lambda p: write_json(p, data))


def units_of(outcome: JobOutcome) -> dict[str, str]:
    """The units of a run's lengths, areas, stresses (force per length for thickness 1) and
    energies, as summaries state them."""
    length = outcome.units
    if outcome.job.material.fabric is not None:
        stress = "kN/m"  # the presets give E·t in kN/m
        energy = f"kN/m·{length}²"
    else:
        stress = "the material's units (force per length with thickness 1)"
        energy = f"stress × thickness × {length}²"
    return {"length": length, "area": f"{length}²", "stress": stress, "energy": energy}


def _write(panel: PanelOutcome, name: str, writer: Callable[[Path], None]) -> None:
    path = panel.directory / name
    writer(path)
    panel.files.append(path)


def _write_pattern_files(
    panel: PanelOutcome,
    job: Job,
    material_scale: float,
    marks: np.ndarray | None,
    dxf: bool,
    cut: np.ndarray | None,
) -> None:
    result, mesh = panel.result, panel.mesh
    x = result.material_coordinates
    fields = result.fields | ({} if panel.drape is None else panel.drape.fields())
    _write(panel, "pattern.obj", lambda p: write_surface(p, mesh, x, units=panel.units))
    _write(panel, "pattern.vtu", lambda p: write_surface(p, mesh, x, fields, units=panel.units))
    _write(
        panel,
        "surface.vtu",
        lambda p: write_surface(p, mesh, fields=fields, units=panel.units),
    )
    if dxf:
        _write_dxf(panel, job, marks, cut)
    _write_drawings(panel, job, material_scale)


def _write_dxf(
    panel: PanelOutcome, job: Job, marks: np.ndarray | None, cut: np.ndarray | None
) -> None:
    result, mesh, output = panel.result, panel.mesh, job.output
    x = result.material_coordinates
    piece = CutPiece(
        panel.name, mesh, x, result.fibres.warp, _label(panel, job), marks=marks, cut=cut
    )
    _write(
        panel,
        "pattern.dxf",
        lambda p: write_dxf(
            p,
            [piece],
            units=output.dxf_units,
            model_units=panel.units,
            allowance=output.allowance,
            mark_spacing=None if marks is not None else output.mark_spacing,
        ),
    )


def _label(panel: PanelOutcome, job: Job) -> list[str]:
    result = panel.result
    units = panel.units
    label = [f"surface {panel.mesh.area:.4g} {units}², pattern {result.pattern_area:.4g} {units}²"]
    if panel.compensation is not None and result.prestress is not None:
        c = panel.compensation
        label.append(
            f"compensation warp {c.warp.compensation_mean:.2f} %, "
            f"fill {c.fill.compensation_mean:.2f} %"
        )
    return label


def _write_drawings(panel: PanelOutcome, job: Job, material_scale: float) -> None:
    result, mesh = panel.result, panel.mesh
    x = result.material_coordinates
    if job.output.previews:  # drawn without matplotlib (io/sketch.py)
        crossings = None if result.overlap is None else result.overlap.crossings
        sketch = pattern_sketch(
            mesh, x, fibres=result.fibres, title=f"{panel.name}: pattern", marks=crossings
        )
        svg, png = PREVIEW_FILES
        _write(panel, svg, lambda path: write_text(path, sketch.svg()))
        _write(panel, png, lambda path: write_bytes(path, sketch.png(DPI)))
    if not job.output.plots:
        return  # matplotlib is not even imported
    from ..io.plot import plot_pattern_fields, plot_surface_fields

    fields = {name: result.fields[name] for name in job.output.plots}
    titles = {name: f"{panel.name}: {name} on the design shape" for name in fields}
    style = {
        "stress_unit": "force/length" if result.thickness == 1.0 else "stress",
        "stress_scale": material_scale * result.thickness,
        "titles": titles,
    }
    pictures = [  # each set of figures shares one rasterisation of the cells
        (plot_pattern_fields(mesh, x, fields, fibres=result.fibres, **style), ("svg", "png")),
        (plot_surface_fields(mesh, fields, **style), ("png",)),
    ]
    for (drawings, suffixes), prefix in zip(pictures, ("pattern", "surface"), strict=True):
        for name, fig in drawings:
            for suffix in suffixes:
                path = panel.directory / f"{prefix}_{name}.{suffix}"
                with atomic_path(path) as temporary:
                    fig.savefig(temporary, dpi=DPI)
                panel.files.append(path)


def structure_marks(outcome: JobOutcome) -> list[np.ndarray]:
    """Matching marks of every panel, at the job's spacing along every seam."""
    structure = outcome.structure
    coordinates = [r.material_coordinates for r in structure.results]
    return seam_marks(coordinates, structure.seams, outcome.mark_spacing())


def write_structure(outcome: JobOutcome, marks: list[np.ndarray] | None) -> None:
    """``structure.json`` and (when it converged) ``structure.dxf``; paths to ``outcome.files``."""
    job, structure = outcome.job, outcome.structure
    directory = outcome.directory
    # marks exist when every panel converged or ended in no cutting pattern; a cut job's
    # pieces are drawn on the roll instead
    drawn = structure.converged or (job.output.allow_overlap and marks is not None)
    if drawn and job.cut is None:
        pieces = [
            CutPiece(
                p.name,
                p.mesh,
                p.result.material_coordinates,
                warp=p.result.fibres.warp,
                label=[f"pattern {p.result.pattern_area:.4g}"],
                marks=m,
            )
            for p, m in zip(outcome.panels, marks, strict=True)
        ]
        write_dxf(
            directory / "structure.dxf",
            pieces,
            units=job.output.dxf_units,
            model_units=outcome.units,
            allowance=job.output.allowance,
        )
        outcome.files.append(directory / "structure.dxf")
    data = structure_summary(outcome)
    if outcome.cut is not None:
        from .cut_outputs import cutting_details

        data["cutting"] = cutting_details(outcome)
    if outcome.erection is not None:
        data["erection"] = erection_figures(outcome.erection, outcome.units, outcome.optimum)
    if outcome.scatter is not None:
        data["scatter"] = outcome.scatter.to_dict(outcome.units)
    write_json(directory / "structure.json", data)
    outcome.files.append(directory / "structure.json")


def structure_summary(outcome: JobOutcome) -> dict:
    """The key figures of a structure as a JSON-ready dictionary."""
    structure, job = outcome.structure, outcome.job
    return {
        "vares_version": __version__,
        "converged": structure.converged,
        "reason": structure.reason,
        "matched": structure.matched,
        "coupled_iterations": structure.iterations,
        "energy_independent": structure.energy_independent,
        "energy": structure.energy,
        "energy_price": structure.energy_price,
        "elapsed_seconds": structure.elapsed,
        "job_digest": job.digest(),
        "units": units_of(outcome),
        "options": structure.options.to_dict(),
        "material": {"law": type(outcome.material).__name__, **outcome.material.parameters},
        "panels": [
            {
                "name": p.name,
                "directory": os.path.relpath(p.directory, outcome.directory),
                "cells": p.mesh.num_cells,
                "surface_area": p.mesh.area,
                "pattern_area": p.result.pattern_area,
                "converged": p.result.converged,
                "reason": p.result.reason,
                "iterations": p.result.iterations,
                "width_across_warp": width_across_warp(
                    p.result.material_coordinates, p.result.fibres.warp
                ),
                "compensation": None if p.compensation is None else p.compensation.to_dict(),
                "fields": field_statistics(p.result.fields) if p.result.converged else None,
            }
            for p in outcome.panels
        ],
        "roll_width": structure.structure_options.roll_width,
        "too_wide": [{"panel": n, "width": w} for n, w in structure.too_wide],
        "seams": [s.to_dict() for s in structure.seam_reports],
        "matching_history": [
            {"iteration": h.iteration, "residual": h.residual, "violation": h.violation}
            for h in structure.history
        ],
    }
