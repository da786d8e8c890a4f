"""Running a laminate job and writing what it found (``vares laminate``).

Into the job's output folder (replaced as a whole when the run succeeds, see
:mod:`vares.app.staging`):

- ``laminate.json``: every ply, every distinct drape (convergence, shear, the kinematic net beside
  the pattern) and the pair matrices of the ply-stack check;
- ``laminate.md``: the same as tables (the ply stack, the drapes, the pair matrices);
- ``laminate.vtu``: the mould with, per ply, the cell vectors ``<ply>_warp`` and ``<ply>_fill``
  (unit, draped by the mechanical pattern; a darted ply's read back on the mould's cells), the cell
  field ``<ply>_shear_angle`` (degrees) and
  the kinematic net's ``<ply>_kinematic_warp``, ``<ply>_kinematic_fill`` and
  ``<ply>_kinematic_shear_angle``; NaN outside a ply's region;
- ``orientations.inp``: the Abaqus orientation table, one ``*ORIENTATION`` per ply
  (:mod:`vares.io.orientations`); ``orientations.csv``: the same directions with element ids and
  the shear angle (those of the mechanical drape, or of the kinematic net with
  ``fe_directions = "kinematic"``);
- ``patterns/<drape>.vtu``: each distinct blank, flat, with its per-cell fields (a darted ply's
  opened along its darts; a spliced ply's pieces one above the other, with the cell field
  ``piece``, 1 for the first);
- ``plies/<ply>.dxf``: each ply's cutter file, net and extended (trim) boundaries, rosette,
  label and dart lines (:mod:`vares.io.ply_dxf`; a spliced ply's pieces side by side);
  ``nest.dxf``: every ply (every piece of a spliced one) nested on the roll (with a
  ``roll_width``);
- ``plybook.html``: the ply book (:mod:`vares.app.ply_book`).

``laminate.json`` holds per ply its areas, mass and producibility (``blanks``) and the nest
(``nest``: roll width, length, yield; or why the plies were not nested).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..io.files import write_json, write_text
from ..io.meshes import write_surface, write_surfaces
from ..io.orientations import PlyOrientations, write_abaqus_orientations, write_orientation_csv
from ..io.ply_dxf import write_ply_dxf, write_ply_nest_dxf
from ..structures.laminate import PAIR_VALUES, LaminateResult, PlyDrapeResult, drape_laminate
from ..structures.laminate_blanks import PlyBlank, nest_plies, ply_blanks, side_by_side
from ..structures.laminate_pairs import PAIR_TITLES
from ..structures.nesting import RollNest
from .inputs import load_input, safe_name
from .job import JobError
from .laminate_job import LaminateJob
from .ply_book import ply_book, ply_producibility
from .staging import OutputFolder

__all__ = [
    "LaminateRun",
    "cutting_markdown",
    "file_label",
    "laminate_cutting",
    "laminate_files",
    "laminate_markdown",
    "orientation_tables",
    "run_laminate",
    "run_laminate_job",
    "write_laminate",
]


def laminate_files(
    job: LaminateJob, labels: list[str] | None = None, *, nested: bool = True
) -> list[Path]:
    """The files a run writes (``labels``: the distinct drapes' labels, if known); the nest's
    only with a ``roll_width`` and unless ``nested`` is False (the plies were not nested, see
    :attr:`LaminateRun.nest_error`). Two plies whose names make the same file name are
    refused."""
    directory = job.directory
    names = ["laminate.json", "laminate.md", "laminate.vtu", "orientations.inp", "orientations.csv"]
    nest = nested and job.laminate.roll_width is not None
    names += ["plybook.html"] + (["nest.dxf"] if nest else [])
    paths = [directory / n for n in names]
    dxf: dict[str, str] = {}
    for ply in job.plies:
        stem = safe_name(ply.name)
        if stem.lower() in dxf:
            raise JobError(
                f"plies {dxf[stem.lower()]!r} and {ply.name!r} would write the same cutter file "
                f"plies/{stem}.dxf: rename one"
            )
        dxf[stem.lower()] = ply.name
        paths.append(directory / "plies" / f"{stem}.dxf")
    for label in labels or []:
        paths.append(directory / "patterns" / f"{file_label(label)}.vtu")
    return paths


@dataclass
class LaminateRun:
    """A run of a laminate job: the draped laminate, each ply's blank (bottom first), the nest
    on the roll (``None`` without a ``roll_width`` or when a blank is wider than the roll:
    ``nest_error`` says so) and the mesh units."""

    result: LaminateResult
    blanks: list[PlyBlank]
    nest: RollNest | None
    nest_error: str | None
    units: str

    def summary(self) -> dict[str, Any]:
        """``laminate.json``: the laminate's summary with ``blanks`` and ``nest``."""
        blanks = []
        for blank in self.blanks:
            check = ply_producibility(self.result, blank.name, blank.piece)
            blanks.append(
                {
                    "ply": blank.name,
                    "piece": blank.piece,
                    "net_area": blank.net_area,
                    "trim_area": blank.trim_area,
                    "surface_area": blank.surface_area,
                    "trim_allowance": blank.allowance,
                    "splice_overlap": blank.splice_overlap if blank.piece is not None else None,
                    "laps_over": list(blank.laps_over),
                    "dart_overlap": blank.dart_overlap if blank.darts else None,
                    "areal_weight": blank.areal_weight,
                    "thickness": blank.thickness,
                    "net_mass": blank.mass(blank.net_area, self.units),
                    "trim_mass": blank.mass(blank.trim_area, self.units),
                    "producibility": check.summary(),
                }
            )
        nest: dict[str, Any] | None = None
        if self.nest is not None:
            nest = {
                "roll_width": self.nest.roll_width,
                "length": self.nest.length,
                "net_area": self.nest.net_area,
                "yield": self.nest.yield_,
                "seconds": self.nest.elapsed,
                "search_seconds": self.nest.search_time,
                "time_limit": self.nest.time_limit,
                "seed": self.nest.seed,
                "finished": self.nest.finished,
                "pieces": [
                    {
                        "ply": self.blanks[p.index].name,
                        "piece": self.blanks[p.index].piece,
                        "rotation": p.rotation,
                        "translation": list(p.translation),
                    }
                    for p in self.nest.pieces
                ],
            }
        elif self.nest_error is not None:
            nest = {"error": self.nest_error}
        return self.result.summary() | {"units": self.units, "blanks": blanks, "nest": nest}


def laminate_cutting(result: LaminateResult, units: str) -> LaminateRun:
    """The blanks of a draped laminate and, with a ``roll_width``, their nest on the roll."""
    blanks = ply_blanks(result)
    options = result.laminate.options
    nest, error = None, None
    if options.roll_width is not None:
        try:
            nest = nest_plies(blanks, options.roll_width, time_limit=options.nest_time)
        except ValueError as exc:  # a blank wider than the roll: the rest is still written
            error = str(exc)
    return LaminateRun(result, blanks, nest, error, units)


def file_label(label: str) -> str:
    """A drape's label as a file name: ``"-45°"`` → ``"drape_-45deg"``."""
    return safe_name("drape_" + label.replace("°", "deg").replace(" ", ""))


def orientation_tables(result: LaminateResult) -> list[PlyOrientations]:
    """Per ply (bottom first) its elements (labels from 1), draped warp, fill and shear: of the
    mechanical drape, or of the kinematic net with ``fe_directions = "kinematic"`` (then only
    the elements the net reaches)."""
    kinematic = result.laminate.options.fe_directions == "kinematic"
    tables = []
    for ply in result.laminate.plies:
        drape = result.drape(ply.name)
        if kinematic:
            warp, fill = drape.kinematic_warp, drape.kinematic_fill
            shear = drape.kinematic_shear_angle
        else:
            warp, fill, shear = drape.warp, drape.fill, drape.shear_angle
        cells = drape.cells[np.isfinite(warp[drape.cells]).all(axis=1)]
        default_fill = np.cross(drape.normal, drape.warp_direction)
        tables.append(
            PlyOrientations(
                ply.name,
                cells + 1,
                warp[cells],
                fill[cells],
                shear[cells],
                drape.warp_direction,
                default_fill / np.linalg.norm(default_fill),
            )
        )
    return tables


def _cell_vectors(result: LaminateResult) -> dict[str, np.ndarray]:
    fields: dict[str, np.ndarray] = {}
    for ply in result.laminate.plies:
        drape = result.drape(ply.name)
        name = ply.name
        fields[f"{name}_warp"] = drape.warp
        fields[f"{name}_fill"] = drape.fill
        fields[f"{name}_shear_angle"] = drape.shear_angle
        fields[f"{name}_kinematic_warp"] = drape.kinematic_warp
        fields[f"{name}_kinematic_fill"] = drape.kinematic_fill
        fields[f"{name}_kinematic_shear_angle"] = drape.kinematic_shear_angle
    return fields


def _percent(value: float) -> str:
    return "–" if not np.isfinite(value) else f"{100 * value:.1f}"


def _matrix_lines(result: LaminateResult, value: str) -> list[str]:
    title, unit = PAIR_TITLES[value]
    labels = result.labels
    matrix = result.pair_matrix(value)
    lines = [
        f"**{title}** ({unit}; row: the blank of, column: used for)",
        "",
        "| blank \\ ply | " + " | ".join(labels) + " |",
        "|---" * (len(labels) + 1) + "|",
    ]
    for label, row in zip(labels, matrix, strict=True):
        if unit == "%":
            cells = [_percent(v) for v in row]
        else:
            cells = ["–" if not np.isfinite(v) else f"{v:.3g}" for v in row]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return [*lines, ""]


def _darts_cell(drape: PlyDrapeResult) -> str:
    if drape.spliced is not None:
        spliced = drape.spliced
        return f"spliced: {len(spliced.pieces)} pieces ({spliced.max_shear_after:.2f}°)"
    if drape.darted is None:
        return "–"
    if drape.darted.after is not None and not drape.is_darted:
        return f"not cut: {len(drape.darted.dart_lines)} tried, no lower"
    if not drape.is_darted:
        return "none needed" if drape.darted.relieved else "none placed"
    return f"{len(drape.darted.dart_lines)} ({drape.darted.max_shear_after:.2f}°)"


def laminate_markdown(result: LaminateResult) -> str:
    """The run as Markdown tables: the stack, the drapes and the pair matrices."""
    options = result.laminate.options
    lines = [
        "# Laminate",
        "",
        f"{len(result.laminate.plies)} plies, {len(result.drapes)} distinct drapes, "
        f"{result.seconds:.2f} s on {result.workers} worker(s); reference direction "
        f"{tuple(options.reference)}; a yarn is compressed when shortened by more than "
        f"{100 * options.compression_strain:g} %.",
        "",
        "| ply | orientation | drape | region | drop-off |",
        "|---|---|---|---|---|",
    ]
    for ply in result.laminate.plies:
        o = ply.options
        region = (
            "–"
            if o.region is None
            else f"{o.region}" + ("" if o.region_value is None else f" = {o.region_value:g}")
        )
        drop = "–" if o.drop_off is None else str(o.drop_off)
        label = result.ply_drape[o.name]
        lines.append(f"| {o.name} | {o.orientation:g}° | {label} | {region} | {drop} |")
    lines += [
        "",
        "| drape | converged | iterations | energy | largest shear | kinematic largest shear "
        "| mean difference | darts or splices (largest shear with them) | seconds |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for drape in result.drapes:
        data = drape.summary()
        kinematic = data.get("kinematic_drape", {}).get("against_pattern", {})
        k_max = kinematic.get("max_kinematic_shear", np.nan)
        k_diff = kinematic.get("mean_abs_difference", np.nan)
        lines.append(
            f"| {drape.label} | {'yes' if drape.converged else 'no'} | {data['iterations']} | "
            f"{data['energy']:.6g} | {data['max_shear']:.2f}° | {k_max:.2f}° | {k_diff:.2f}° | "
            f"{_darts_cell(drape)} | {drape.seconds:.2f} |"
        )
    lines += ["", "## Ply-stack check", ""]
    for value in PAIR_VALUES:
        lines += _matrix_lines(result, value)
    return "\n".join(lines)


def cutting_markdown(run: LaminateRun) -> str:
    """The plies as cut and the nest, as Markdown."""
    units = run.units
    allowance = run.result.laminate.options.trim_allowance
    lines = [
        "",
        "## The plies as cut",
        "",
        f"| ply | orientation | net area [{units}²] | blank area (trim +{allowance:g}) "
        f"[{units}²] | mass of the net [g] |",
        "|---|---|---|---|---|",
    ]
    for blank in run.blanks:
        mass = blank.mass(blank.net_area, units)
        lines.append(
            f"| {blank.label} | {blank.orientation:+g}° | {blank.net_area:.6g} | "
            f"{blank.trim_area:.6g} | {'–' if mass is None else f'{mass:.4g}'} |"
        )
    nest = run.nest
    if nest is not None:
        lines += [
            "",
            f"Nested on a roll {nest.roll_width:g} {units} wide: {nest.length:.6g} {units} long, "
            f"yield {100 * nest.yield_:.1f} %.",
        ]
    elif run.nest_error is not None:
        lines += ["", f"Not nested: {run.nest_error}"]
    return "\n".join([*lines, ""])


def write_laminate(folder: OutputFolder, job: LaminateJob, run: LaminateRun) -> None:
    """Write every file of :func:`laminate_files` into the staged folder."""
    result = run.result
    paths = laminate_files(job, result.labels, nested=run.nest is not None)
    for path in paths:
        folder.staged(path).parent.mkdir(parents=True, exist_ok=True)
    staged = {p.name: folder.staged(p) for p in paths if p.parent == job.directory}
    write_json(staged["laminate.json"], run.summary())
    write_text(staged["laminate.md"], laminate_markdown(result) + cutting_markdown(run))
    write_surface(staged["laminate.vtu"], result.mesh, None, _cell_vectors(result))
    tables = orientation_tables(result)
    write_abaqus_orientations(staged["orientations.inp"], tables)
    write_orientation_csv(staged["orientations.csv"], tables)
    title = job.job.location.stem if job.job.location is not None else "laminate"
    write_text(
        staged["plybook.html"],
        ply_book(result, run.blanks, run.nest, units=run.units, title=title),
    )
    if run.nest is not None:
        write_ply_nest_dxf(staged["nest.dxf"], run.blanks, run.nest, units=run.units)
    dxf = [p for p in paths if p.parent.name == "plies"]
    for ply, path in zip(result.laminate.plies, dxf, strict=True):
        pieces = [b for b in run.blanks if b.name == ply.name]
        write_ply_dxf(folder.staged(path), pieces, units=run.units)
    vtu = [p for p in paths if p.parent.name == "patterns"]
    for drape, path in zip(result.drapes, vtu, strict=True):
        if drape.is_spliced:
            write_surfaces(folder.staged(path), _flat_pieces(drape, run.blanks))
        else:
            pattern = drape.blank_pattern
            write_surface(
                folder.staged(path), drape.blank_mesh, pattern.material_coordinates, pattern.fields
            )


def _flat_pieces(drape: PlyDrapeResult, blanks: list[PlyBlank]):
    """A spliced drape's pieces as parts of one file (:func:`write_surfaces`): each piece's
    mesh, its pattern placed as in the ply's cutter file, and its own cell fields."""
    first = drape.plies[0]
    pieces = [b for b in blanks if b.name == first]
    parts = []
    for blank, shift, (_, _, result) in zip(
        pieces, side_by_side(pieces), drape.pieces, strict=True
    ):
        own = {
            name: np.asarray(value)
            for name, value in result.fields.items()
            if np.shape(value)[:1] == (blank.mesh.num_cells,)
        }
        parts.append((blank.mesh, blank.coordinates + shift, own))
    return parts


def run_laminate_job(
    job: LaminateJob,
    *,
    force: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    darts: str | None = None,
    callback: Callable[[PlyDrapeResult], None] | None = None,
) -> LaminateRun:
    """Drape the job's laminate, cut and nest its plies and write its files (module docs).
    ``workers``, ``scheduler`` and ``darts`` replace the laminate table's."""
    loaded = load_input(job.job)
    mesh = loaded.panels[0].mesh
    inputs = [job.job.path(p) for p in job.job.input.paths]
    if job.job.location is not None:
        inputs.append(job.job.location)
    inputs += [
        job.job.path(file)
        for p in job.plies
        for file in (p.dart_lines, p.splice_lines)
        if file is not None
    ]
    folder = OutputFolder(
        job.directory, laminate_files(job), force=force, inputs=inputs, command="laminate"
    )
    folder.check()
    changes = {"workers": workers, "scheduler": scheduler, "darts": darts}
    options = job.laminate.replace(**{k: v for k, v in changes.items() if v is not None})
    result = drape_laminate(
        mesh,
        job.build_plies(),
        options,
        cell_data=loaded.cell_data,
        solve_settings=job.job.solve.to_dict(),
        callback=callback,
    )
    run = laminate_cutting(result, loaded.units)
    folder.start()
    try:
        write_laminate(folder, job, run)
        folder.commit()
    finally:
        folder.discard()
    return run


def run_laminate(
    job: LaminateJob,
    *,
    force: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    darts: str | None = None,
    callback: Callable[[PlyDrapeResult], None] | None = None,
) -> LaminateResult:
    """:func:`run_laminate_job`'s draped laminate."""
    run = run_laminate_job(
        job, force=force, workers=workers, scheduler=scheduler, darts=darts, callback=callback
    )
    return run.result
