"""Running a job: read, solve, and write every output file.

Output files (in the job's output directory):

``pattern.obj``                 the flat pattern (same nodes and faces as the input, z = 0)
``pattern.dxf``                 cutter drawing (seam, cut line, warp, marks, label)
``pattern.svg``, ``pattern.png`` the pattern drawn with its warp and fill directions
``pattern.vtu``, ``surface.vtu`` pattern and surface with every per-cell result (ParaView)
``summary.json``                the key figures, the compensation report and the history
``report.html``                 with ``report``: everything above for a person, in one file
``surface.obj``                 for examples: the example surface

All targets are checked before the solve (nothing is overwritten without ``force``) and every
file is written atomically. A solve that does not converge writes only ``summary.json``.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import examples as example_surfaces
from .batch import job_digest
from .compensation import CompensationReport, compensation_report
from .dxf import CutPiece, write_dxf
from .io import check_writable, summary, write_json, write_surface
from .job import Job, JobError
from .materials import Hyperelastic, fabric, make_material
from .mesh import SurfaceMesh, read_mesh_data
from .solver import IterationRecord, PatternResult, solve

__all__ = ["JobOutcome", "build_material", "run_job", "seam_marks", "solve_options"]


@dataclass
class JobOutcome:
    """What a job produced."""

    job: Job
    name: str
    mesh: SurfaceMesh
    material: Hyperelastic
    result: PatternResult
    compensation: CompensationReport | None
    files: list[Path] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)


def build_material(job: Job) -> Hyperelastic:
    """The job's material: a fabric preset or a law with its parameters."""
    settings = {k: v for k, v in job.material.items() if k != "thickness"}
    if "fabric" in settings:
        presets = job.path(settings["presets"]) if "presets" in settings else None
        return fabric(settings["fabric"], presets).material()
    law = settings.pop("law", "neo-hooke")
    if law in ("neo-hooke", "st-venant-kirchhoff"):
        settings = {"E": 1000.0, "nu": 0.3} | settings
    return make_material(law, settings)


def _load(job: Job) -> tuple[str, SurfaceMesh, dict[str, np.ndarray]]:
    if "example" in job.input:
        name = job.input["example"]
        if name not in example_surfaces.EXAMPLES:
            raise JobError(
                f"unknown example {name!r}; available: {', '.join(example_surfaces.EXAMPLES)}"
            )
        mesh = example_surfaces.EXAMPLES[name](cell_type=job.input.get("cell_type", "triangle"))
        return job.input.get("name", name), mesh, {}
    path = job.path(job.input["mesh"])
    mesh, cell_data = read_mesh_data(path)
    return job.input.get("name", path.stem), mesh, cell_data


def _prestress(job: Job, cell_data: dict[str, np.ndarray]):
    p = job.prestress
    if "warp" in p:
        return [p["warp"], p["fill"], p.get("shear", 0.0)]
    if "field" not in p:
        return None
    names = [p["field"]] if isinstance(p["field"], str) else list(p["field"])
    missing = [n for n in names if n not in cell_data]
    if missing or not 1 <= len(names) <= 3:
        known = ", ".join(cell_data) or "none"
        raise JobError(
            f"[prestress] field: no cell data {', '.join(missing) or names!r} in the "
            f"input (it has: {known})"
        )
    if len(names) == 1:
        return cell_data[names[0]]
    return np.column_stack([np.asarray(cell_data[n], dtype=float).ravel() for n in names])


def _outputs(job: Job, is_example: bool) -> dict[str, Path]:
    out = job.path(job.output.get("directory", "vares-out"))
    files = {
        name: out / name
        for name in (
            "summary.json",
            "pattern.obj",
            "pattern.dxf",
            "pattern.svg",
            "pattern.png",
            "pattern.vtu",
            "surface.vtu",
        )
    }
    for name in job.output.get("plots", []):
        for key in (f"pattern_{name}.svg", f"pattern_{name}.png", f"surface_{name}.png"):
            files[key] = out / key
    if is_example:
        files["surface.obj"] = out / "surface.obj"
    if job.output.get("report", False):
        files["report.html"] = out / "report.html"
    return files


def _warnings(result: PatternResult, report: CompensationReport | None) -> list[str]:
    notes = []
    if not result.converged:
        notes.append(f"the solve did not converge: {result.reason}")
        return notes
    fields = result.fields
    area = fields["surface_area"]
    total = area.sum()
    wrinkling = float(area[fields["wrinkling"] > 0].sum() / total)
    if wrinkling > 0:
        notes.append(
            f"compressive principal stress (wrinkling risk) on {100 * wrinkling:.1f} % of the area"
        )
    det_f = fields["det_F"]
    if det_f.min() < 0.95 or det_f.max() > 1.05:
        notes.append(f"large area distortion: det F from {det_f.min():.3f} to {det_f.max():.3f}")
    if report is not None:
        for yarn in ("warp", "fill"):
            y = getattr(report, yarn)
            if y.target_mean > 0 and y.slack_area_fraction > 0:
                notes.append(
                    f"{yarn} force below {report.slack_threshold:g} (slack risk) on "
                    f"{100 * y.slack_area_fraction:.1f} % of the area"
                )
    if result.warp_deviation is not None and abs(result.warp_deviation) > 0.1:
        notes.append(f"mean warp deviation {result.warp_deviation:.3g}° from the direction")
    return notes


def run_job(
    job: Job,
    *,
    force: bool = False,
    callback: Callable[[IterationRecord], None] | None = None,
    on_solve_start: Callable[[str, SurfaceMesh, Hyperelastic], None] | None = None,
) -> JobOutcome:
    """Run a job and write its files; returns what it did (also when the solve fails)."""
    material = build_material(job)
    name, mesh, cell_data = _load(job)
    files = _outputs(job, "example" in job.input)
    check_writable(files.values(), force)
    if on_solve_start is not None:
        on_solve_start(name, mesh, material)
    solver = job.solver
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = solve(
            mesh,
            material,
            job.material.get("thickness", 1.0),
            **solve_options(job, cell_data),
            linear_solver=solver.get("linear_solver"),
            callback=callback,
        )
    report = (
        compensation_report(result, job.prestress.get("slack_threshold", 0.0))
        if result.converged
        else None
    )
    outcome = JobOutcome(job, name, mesh, material, result, report)
    outcome.warnings = [str(w.message) for w in caught] + _warnings(result, report)

    data = summary(result, name=name, input=job.input, tolerance=solver.get("tolerance", 1e-10))
    data["warnings"] = outcome.warnings
    data["job_digest"] = job_digest(job)
    if report is not None:
        data["compensation"] = report.to_dict()
    if "surface.obj" in files:
        write_surface(files["surface.obj"], mesh)
        outcome.files.append(files["surface.obj"])
    if result.converged:
        _write_pattern_files(outcome, files)
    write_json(files["summary.json"], data)
    outcome.files.append(files["summary.json"])
    if "report.html" in files and result.converged:
        from .report import write_report

        write_report(files["report.html"], outcome)
        outcome.files.append(files["report.html"])
    return outcome


def _write_pattern_files(outcome: JobOutcome, files: dict[str, Path]) -> None:
    import matplotlib.pyplot as plt

    from .io import atomic_path
    from .plot import plot_pattern, plot_surface

    job, result, mesh = outcome.job, outcome.result, outcome.mesh
    x = result.material_coordinates
    write_surface(files["pattern.obj"], mesh, x)
    write_surface(files["pattern.vtu"], mesh, x, result.fields)
    write_surface(files["surface.vtu"], mesh, fields=result.fields)
    label = [
        f"surface {mesh.area:.4g} {job.input.get('units', 'm')}², pattern {result.pattern_area:.4g}"
    ]
    if outcome.compensation is not None and result.prestress is not None:
        c = outcome.compensation
        label.append(
            f"compensation warp {c.warp.compensation_mean:.2f} %, "
            f"fill {c.fill.compensation_mean:.2f} %"
        )
    output = job.output
    write_dxf(
        files["pattern.dxf"],
        [CutPiece(outcome.name, mesh, x, warp=result.fibres.warp, label=label)],
        units=output.get("dxf_units", "mm"),
        model_units=job.input.get("units", "m"),
        allowance=output.get("allowance", 0.0),
        mark_spacing=output.get("mark_spacing"),
    )

    def save(fig, keys: tuple[str, ...]) -> None:
        for key in keys:
            with atomic_path(files[key]) as temporary:
                fig.savefig(temporary, dpi=150)
            outcome.files.append(files[key])
        plt.close(fig)

    save(
        plot_pattern(mesh, x, fibres=result.fibres, title=f"{outcome.name}: pattern"),
        ("pattern.svg", "pattern.png"),
    )
    unit = "force/length" if result.thickness == 1.0 else "stress"
    scale = outcome.material.stiffness_scale * result.thickness
    for name in output.get("plots", []):
        values = result.fields[name]
        save(
            plot_pattern(
                mesh,
                x,
                values,
                field=name,
                fibres=result.fibres,
                stress_unit=unit,
                stress_scale=scale,
                title=f"{outcome.name}: {name}",
            ),
            (f"pattern_{name}.svg", f"pattern_{name}.png"),
        )
        save(
            plot_surface(
                mesh,
                values,
                field=name,
                stress_unit=unit,
                stress_scale=scale,
                title=f"{outcome.name}: {name}",
            ),
            (f"surface_{name}.png",),
        )
    outcome.files += [
        files[k] for k in ("pattern.obj", "pattern.dxf", "pattern.vtu", "surface.vtu")
    ]


def solve_options(job: Job, cell_data: dict[str, np.ndarray] | None = None) -> dict:
    """The :func:`vares.solve` keyword arguments of a job (all but mesh, material, thickness)."""
    fibres, solver = job.fibres, job.solver
    plane = solver.get("plane")
    if plane is None and "example" in job.input:
        plane = example_surfaces.EXAMPLE_PLANES.get(job.input["example"])
    return {
        "warp_angle": fibres.get("warp_angle", 0.0),
        "fill_angle": fibres.get("fill_angle"),
        "warp_direction": fibres.get("warp_direction"),
        "orientation": fibres.get("orientation", "held"),
        "prestress": _prestress(job, cell_data or {}),
        "strategy": solver.get("strategy", "auto"),
        "steps": solver.get("steps", 3),
        "initial_guess": solver.get("initial_guess"),
        "plane": None if plane in (None, "best-fit") else plane,
        "tolerance": solver.get("tolerance", 1e-10),
        "max_iterations": solver.get("max_iterations", 50),
    }


def seam_marks(structure, spacing: float) -> list[np.ndarray]:
    """Match mark points ``(k, 2)`` of every panel: at equal arc lengths, every ``spacing``
    (model units), along each seam, on both sides (so both patterns get the same marks)."""
    marks: list[list[np.ndarray]] = [[] for _ in structure.panels]
    for seam in structure.seams:
        sides = [
            (seam.first, structure.results[seam.first].material_coordinates[seam.nodes_first]),
            (seam.second, structure.results[seam.second].material_coordinates[seam.nodes_second]),
        ]
        length = np.linalg.norm(np.diff(sides[0][1], axis=0), axis=1).sum()
        positions = np.arange(spacing, length - 0.25 * spacing, spacing)
        for panel, chain in sides:
            segment = np.linalg.norm(np.diff(chain, axis=0), axis=1)
            cumulative = np.concatenate([[0.0], np.cumsum(segment)])
            index = np.clip(
                np.searchsorted(cumulative, positions, side="right") - 1, 0, len(segment) - 1
            )
            fraction = ((positions - cumulative[index]) / segment[index])[:, None]
            marks[panel].append(chain[index] + fraction * (chain[index + 1] - chain[index]))
    return [np.vstack(m) if m else np.zeros((0, 2)) for m in marks]
