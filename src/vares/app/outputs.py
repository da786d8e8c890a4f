"""The files a job writes, planned before the solve and written after it.

One pattern (in the output directory; for a structure, in a folder per panel):

``pattern.obj``                 the flat pattern (same nodes and faces as the surface, z = 0)
``pattern.dxf``                 cutter drawing (seam, cut line, warp, marks, label)
``pattern.svg``, ``pattern.png`` the pattern drawn with its warp and fill directions
``pattern.vtu``, ``surface.vtu`` pattern and surface with every per-cell result (ParaView)
``summary.json``                the key figures, the compensation report and the history
``pattern_FIELD.svg/.png``, ``surface_FIELD.png``   the fields asked for with ``plots``
``surface.obj``                 the 3D surface, for examples and for a structure's panels
``report.html``                 with ``report``: everything above for a person, in one file

A structure adds ``structure.json`` (panels, seams before and after matching, the energy price,
the roll width check), ``structure.dxf`` (all patterns with matching marks) and, with ``report``,
its own ``report.html``. Every job writes ``job.toml`` into the output directory: the job as it
ran (paths relative to it), from which ``vares erect DIR`` (and ``vares run DIR/job.toml -o …``)
take the input, material, fibres and prestress. An erection (``[erection]``, ``--erect``, ``vares
erect``) writes into ``erect/``:

``erect.json``                  the key figures (converged, deviation, stresses against the
                                intended prestress, wrinkled and slack area) and the history
``erected.vtu``                 the erected surface with the displacement and normal deviation
                                per node, the membrane forces and states (and those on the design
                                shape, ``design_*``) per cell
``erected.obj``                 the erected surface
``deviation.png``, ``warp_stress.png``, ``fill_stress.png``, ``state.png``  drawn on it

Every target is checked before the solve (nothing is overwritten without ``force``); every file is
written atomically. A solve that does not converge writes only the summaries (and is not erected).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from .._version import __version__
from ..analysis.erection import ErectionResult
from ..analysis.statistics import field_statistics
from ..io.dxf import UNITS, CutPiece, write_dxf
from ..io.files import atomic_path, write_json
from ..io.meshes import write_surface
from ..io.summary import summary
from ..structures.panels import width_across_warp
from ..structures.seams import seam_marks
from .inputs import Input, safe_name
from .job import Job, JobError
from .outcome import JobOutcome, PanelOutcome
from .sections import STRUCTURE_MARK_SPACING

__all__ = [
    "ERECTION_FILES",
    "JOB_FILE",
    "erection_directory",
    "erection_files",
    "panel_directory",
    "planned_files",
    "safe_name",
    "write_erection",
    "write_job_file",
    "write_panel",
    "write_structure",
]

PATTERN_FILES = (
    "summary.json",
    "pattern.obj",
    "pattern.dxf",
    "pattern.svg",
    "pattern.png",
    "pattern.vtu",
    "surface.vtu",
)
#: The job as it ran, in the output directory.
JOB_FILE = "job.toml"
#: The files of an erection, in the output directory's ``erect/``.
ERECTION_FILES = (
    "erect.json",
    "erected.vtu",
    "erected.obj",
    "deviation.png",
    "warp_stress.png",
    "fill_stress.png",
    "state.png",
)


def panel_directory(job: Job, name: str) -> Path:
    """Where a panel's files go: the output directory, or its own folder in a structure's."""
    return job.directory if job.structure is None else job.directory / safe_name(name)


def planned_files(job: Job, source: Input) -> list[Path]:
    """Every file the job may write (checked for clashes before any work is done)."""
    folders = [safe_name(p.name) for p in source.panels]
    clashes = sorted({f for f in folders if folders.count(f) > 1})
    if clashes:
        raise JobError(f"two panels would write into the same folder {clashes[0]!r}: rename them")
    files = []
    for panel in source.panels:
        directory = panel_directory(job, panel.name)
        names = list(PATTERN_FILES)
        for field in job.output.plots:
            names += [f"pattern_{field}.svg", f"pattern_{field}.png", f"surface_{field}.png"]
        if job.input.example is not None or job.structure is not None:
            names.append("surface.obj")
        if job.output.report:
            names.append("report.html")
        files += [directory / n for n in names]
    if job.structure is not None:
        names = ["structure.json", "structure.dxf"] + (["report.html"] if job.output.report else [])
        files += [job.directory / n for n in names]
    files.append(job.directory / JOB_FILE)
    if job.erection is not None:
        files += erection_files(erection_directory(job))
    return files


def erection_directory(job: Job) -> Path:
    """Where an erection's files go: ``erect/`` in the output directory."""
    return job.directory / "erect"


def erection_files(directory: Path, report: bool = False) -> list[Path]:
    """The files an erection writes into ``directory``."""
    return [directory / n for n in ERECTION_FILES + (("report.html",) if report else ())]


def write_job_file(job: Job) -> Path:
    """``job.toml`` in the output directory: the job as it ran, paths relative to it."""
    path = job.directory / JOB_FILE
    with atomic_path(path) as temporary:
        temporary.write_text(job.to_toml(path), encoding="utf-8")
    return path


def write_erection(result: ErectionResult, directory: Path, units: str) -> list[Path]:
    """The files of an erection (:data:`ERECTION_FILES`) in ``directory``; returns their paths."""
    import matplotlib.pyplot as plt

    from ..io.plot import plot_surface

    files = []
    fields = dict(result.fields) | {f"design_{k}": v for k, v in result.design_fields.items()}
    points = {
        "displacement": result.displacement,
        "normal_deviation": result.normal_deviation,
        "held": result.held.astype(float),
    }
    writers = {
        "erect.json": lambda p: write_json(p, result.to_dict(units=units)),
        "erected.vtu": lambda p: write_surface(
            p, result.mesh, result.erected_points, fields, points
        ),
        "erected.obj": lambda p: write_surface(p, result.mesh, result.erected_points),
    }
    for name, writer in writers.items():
        writer(directory / name)
        files.append(directory / name)
    erected = result.erected_mesh
    per_cell = np.concatenate(
        [result.normal_deviation[c].mean(axis=1) for c in result.mesh.cells.values()]
    )
    scale = result.material.stiffness_scale * result.thickness
    drawings = {
        "deviation.png": (per_cell, "normal_deviation", f"normal deviation ({units})"),
        "warp_stress.png": (result.fields["warp_stress"], "warp_stress", "warp force, erected"),
        "fill_stress.png": (result.fields["fill_stress"], "fill_stress", "fill force, erected"),
        "state.png": (result.fields["state"], "state", "taut / wrinkled / slack, erected"),
    }
    for name, (values, field, title) in drawings.items():
        fig = plot_surface(
            erected,
            values,
            field=field,
            title=title,
            stress_unit="force/length",
            stress_scale=scale,
        )
        with atomic_path(directory / name) as temporary:
            fig.savefig(temporary, dpi=150)
        plt.close(fig)
        files.append(directory / name)
    return files


def write_panel(
    panel: PanelOutcome, job: Job, material_scale: float, marks: np.ndarray | None = None
) -> None:
    """The files of one pattern (all of them when it converged, else the summary and the
    surface); the paths go to ``panel.files``."""
    result = panel.result
    if job.input.example is not None or job.structure is not None:
        _write(panel, "surface.obj", lambda p: write_surface(p, panel.mesh))
    if result.converged:
        _write_pattern_files(panel, job, material_scale, marks)
    data = summary(
        result, name=panel.name, input=job.input.to_dict(), tolerance=result.options.tolerance
    )
    data["warnings"] = panel.warnings
    if job.structure is None:
        data["job_digest"] = job.digest()
    if panel.compensation is not None:
        data["compensation"] = panel.compensation.to_dict()
    _write(panel, "summary.json", lambda p: write_json(p, data))


def _write(panel: PanelOutcome, name: str, writer: Callable[[Path], None]) -> None:
    path = panel.directory / name
    writer(path)
    panel.files.append(path)


def _write_pattern_files(
    panel: PanelOutcome, job: Job, material_scale: float, marks: np.ndarray | None
) -> None:
    result, mesh = panel.result, panel.mesh
    x = result.material_coordinates
    _write(panel, "pattern.obj", lambda p: write_surface(p, mesh, x))
    _write(panel, "pattern.vtu", lambda p: write_surface(p, mesh, x, result.fields))
    _write(panel, "surface.vtu", lambda p: write_surface(p, mesh, fields=result.fields))
    output = job.output
    spacing = output.mark_spacing
    if marks is not None and spacing is None:
        spacing = STRUCTURE_MARK_SPACING
    piece = CutPiece(
        panel.name, mesh, x, warp=result.fibres.warp, label=_label(panel, job), marks=marks
    )
    _write(
        panel,
        "pattern.dxf",
        lambda p: write_dxf(
            p,
            [piece],
            units=output.dxf_units,
            model_units=job.input.units,
            allowance=output.allowance,
            mark_spacing=None if marks is not None else spacing,
        ),
    )
    _write_drawings(panel, job, material_scale)


def _label(panel: PanelOutcome, job: Job) -> list[str]:
    result = panel.result
    label = [f"surface {panel.mesh.area:.4g} {job.input.units}², pattern {result.pattern_area:.4g}"]
    if panel.compensation is not None and result.prestress is not None:
        c = panel.compensation
        label.append(
            f"compensation warp {c.warp.compensation_mean:.2f} %, "
            f"fill {c.fill.compensation_mean:.2f} %"
        )
    return label


def _write_drawings(panel: PanelOutcome, job: Job, material_scale: float) -> None:
    import matplotlib.pyplot as plt

    from ..io.plot import plot_pattern, plot_surface

    result, mesh = panel.result, panel.mesh
    x = result.material_coordinates

    def save(fig, names: tuple[str, ...]) -> None:
        for name in names:
            path = panel.directory / name
            with atomic_path(path) as temporary:
                fig.savefig(temporary, dpi=150)
            panel.files.append(path)
        plt.close(fig)

    save(
        plot_pattern(mesh, x, fibres=result.fibres, title=f"{panel.name}: pattern"),
        ("pattern.svg", "pattern.png"),
    )
    unit = "force/length" if result.thickness == 1.0 else "stress"
    scale = material_scale * result.thickness
    for name in job.output.plots:
        values = result.fields[name]
        title = f"{panel.name}: {name}"
        save(
            plot_pattern(
                mesh,
                x,
                values,
                field=name,
                fibres=result.fibres,
                stress_unit=unit,
                stress_scale=scale,
                title=title,
            ),
            (f"pattern_{name}.svg", f"pattern_{name}.png"),
        )
        save(
            plot_surface(
                mesh, values, field=name, stress_unit=unit, stress_scale=scale, title=title
            ),
            (f"surface_{name}.png",),
        )


def structure_marks(outcome: JobOutcome) -> list[np.ndarray]:
    """Matching marks of every panel, at the job's spacing (DXF units) along every seam."""
    job, structure = outcome.job, outcome.structure
    factor = UNITS[job.input.units][0] / UNITS[job.output.dxf_units][0]
    spacing = (job.output.mark_spacing or STRUCTURE_MARK_SPACING) / factor
    return seam_marks([r.material_coordinates for r in structure.results], structure.seams, spacing)


def write_structure(outcome: JobOutcome, marks: list[np.ndarray] | None) -> None:
    """``structure.json`` and (when it converged) ``structure.dxf``; paths to ``outcome.files``."""
    job, structure = outcome.job, outcome.structure
    directory = job.directory
    if structure.converged:
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
            model_units=job.input.units,
            allowance=job.output.allowance,
        )
        outcome.files.append(directory / "structure.dxf")
    write_json(directory / "structure.json", structure_summary(outcome))
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
        "options": structure.options.to_dict(),
        "material": {"law": type(outcome.material).__name__, **outcome.material.parameters},
        "panels": [
            {
                "name": p.name,
                "directory": str(p.directory),
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
