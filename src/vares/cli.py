"""Command line: ``vares pattern``, ``example``, ``run``, ``evaluate``, ``fabrics``.

A thin layer over the Python API: options become a :class:`vares.job.Job`, which
:func:`vares.runner.run_job` runs. Progress goes to the terminal; every error becomes one line
``vares: error: …`` and an exit status (2: bad input or options, 1: the solve did not converge,
3: unexpected internal error), never a traceback.
"""

import inspect
import time
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from . import examples as example_surfaces
from .analysis import KEY_FIELDS
from .analysis import evaluate as evaluate_pattern
from .compensation import compensation_report
from .io import (
    OutputExistsError,
    atomic_path,
    check_writable,
    field_statistics,
    read_pattern,
    write_json,
    write_surface,
)
from .job import Job, JobError, load_job
from .materials import LAWS, MaterialError, load_presets, presets
from .mesh import MeshError, read_mesh
from .runner import JobOutcome, build_material, run_job
from .solver import STRATEGIES, IterationRecord

app = typer.Typer(
    help="Cutting patterns of doubly curved membranes by the Variation of Reference Strategy.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console(stderr=True, highlight=False, soft_wrap=True)

Law = StrEnum("Law", {name: name for name in LAWS})
Strategy = StrEnum("Strategy", {name: name for name in STRATEGIES})
Orientation = StrEnum("Orientation", {"held": "held", "free": "free"})
CellType = StrEnum("CellType", {"triangle": "triangle", "quad": "quad"})
Units = StrEnum("Units", {"mm": "mm", "cm": "cm", "m": "m"})


class InputError(Exception):
    """Bad input or options (exit status 2)."""


# ---------------------------------------------------------------------------- shared options
def _option(
    default: Any, kind: Any, *names: str, help: str, panel: str, **extra
) -> inspect.Parameter:
    name = names[0].split("/")[0].lstrip("-").replace("-", "_")
    option = typer.Option(*names, help=help, rich_help_panel=panel, **extra)
    return inspect.Parameter(
        name, inspect.Parameter.KEYWORD_ONLY, default=default, annotation=Annotated[kind, option]
    )


_M, _F, _P, _S, _O = "Material", "Fibres", "Prestress", "Solver", "Output"
SOLVE_OPTIONS = [
    _option(
        Law["neo-hooke"],
        Law,
        "--material",
        "-m",
        help="Hyperelastic law.",
        panel=_M,
        case_sensitive=False,
    ),
    _option(
        None,
        float | None,
        "--E",
        "-E",
        help="Young's modulus (neo-hooke, st-venant-kirchhoff; default 1000).",
        panel=_M,
    ),
    _option(
        None, float | None, "--nu", help="Poisson's ratio, -1 < nu <= 0.5 (default 0.3).", panel=_M
    ),
    _option(None, float | None, "--mu", help="Shear modulus (incompressible-neo-hooke).", panel=_M),
    _option(None, float | None, "--E1", help="Warp modulus (orthotropic).", panel=_M),
    _option(None, float | None, "--E2", help="Fill modulus (orthotropic).", panel=_M),
    _option(None, float | None, "--G12", help="In-plane shear modulus (orthotropic).", panel=_M),
    _option(
        None, float | None, "--nu12", help="Poisson's ratio warp→fill (orthotropic).", panel=_M
    ),
    _option(None, str | None, "--A", help="NCF warp coefficients 'A0,A1,…' (sum 0).", panel=_M),
    _option(None, str | None, "--B", help="NCF fill coefficients 'B0,B1,…' (sum 0).", panel=_M),
    _option(None, str | None, "--C", help="NCF shear coefficients 'C1,C2,…'.", panel=_M),
    _option(
        None,
        str | None,
        "--fabric",
        help="Fabric preset (see 'vares fabrics'); replaces --material.",
        panel=_M,
    ),
    _option(
        None, Path | None, "--presets", help="TOML file with your own fabric presets.", panel=_M
    ),
    _option(
        1.0,
        float,
        "--thickness",
        "-t",
        help="Thickness; 1 for laws given as force/length.",
        panel=_M,
    ),
    _option(0.0, float, "--warp-angle", help="Warp angle in the pattern frame, degrees.", panel=_F),
    _option(None, float | None, "--fill-angle", help="Fill angle (default warp + 90).", panel=_F),
    _option(
        None,
        str | None,
        "--warp-direction",
        help="3D direction 'x,y,z' the warp follows on the surface (overrides --warp-angle).",
        panel=_F,
    ),
    _option(
        Orientation.held,
        Orientation,
        "--orientation",
        help="Anisotropic: keep the initial "
        "guess's rotation (held) or let the energy choose it (free).",
        panel=_F,
        case_sensitive=False,
    ),
    _option(
        None,
        str | None,
        "--prestress",
        help="Prestress along the yarns, force/length: 'WARP,FILL' or one value for both.",
        panel=_P,
    ),
    _option(
        None,
        str | None,
        "--prestress-field",
        help="Per-cell prestress from the input's "
        "cell data: 'NAME' (columns warp, fill[, shear]) or 'WARP_NAME,FILL_NAME'.",
        panel=_P,
    ),
    _option(
        0.0,
        float,
        "--slack-threshold",
        help="Report cells whose achieved yarn force is below this (force/length).",
        panel=_P,
    ),
    _option(
        Strategy.auto,
        Strategy,
        "--strategy",
        "-s",
        help="Solution strategy.",
        panel=_S,
        case_sensitive=False,
    ),
    _option(3, int, "--steps", help="Pseudo-time steps (pseudo-time).", panel=_S),
    _option(
        None,
        str | None,
        "--plane",
        help="Initial-guess plane: best-fit, xy, yz, zx, or a "
        "normal 'nx,ny,nz' (default: best-fit; an example's own).",
        panel=_S,
    ),
    _option(1e-10, float, "--tolerance", help="Relative residual tolerance.", panel=_S),
    _option(50, int, "--max-iterations", help="Newton iterations per step.", panel=_S),
    _option(
        None,
        str | None,
        "--linear-solver",
        help="pardiso, cholmod or scipy-superlu (default: the fastest installed).",
        panel=_S,
    ),
    _option(Path("vares-out"), Path, "--output", "-o", help="Output directory.", panel=_O),
    _option(False, bool, "--report", help="Also write report.html.", panel=_O),
    _option(Units.m, Units, "--units", help="Units of the mesh coordinates.", panel=_O),
    _option(Units.mm, Units, "--dxf-units", help="Units of the DXF drawing.", panel=_O),
    _option(
        0.0, float, "--allowance", help="Seam allowance for the DXF cut line (DXF units).", panel=_O
    ),
    _option(
        None,
        float | None,
        "--mark-spacing",
        help="Match mark spacing along the seam line (DXF units).",
        panel=_O,
    ),
    _option(None, str | None, "--name", help="Panel name for drawings and report.", panel=_O),
    _option(
        None,
        str | None,
        "--plot",
        help="Fields to draw as pattern_FIELD.svg/.png and "
        "surface_FIELD.png, e.g. 'det_F,warp_stress,shear_angle'.",
        panel=_O,
    ),
    _option(
        None,
        Path | None,
        "--save-job",
        help="Write the job as TOML (rerun with 'vares run').",
        panel=_O,
    ),
    _option(False, bool, "--force", "-f", help="Overwrite existing output files.", panel=_O),
    _option(False, bool, "--quiet", "-q", help="Show no progress.", panel=_O),
]


def _with_options(parameters: list[inspect.Parameter]):
    """Give a ``**options`` command the shared option parameters (one definition for all)."""

    def decorate(func):
        signature = inspect.signature(func)
        own = [p for p in signature.parameters.values() if p.kind != p.VAR_KEYWORD]
        func.__signature__ = signature.replace(parameters=own + parameters)
        return func

    return decorate


def _numbers(option: str, text: str | None) -> list[float] | None:
    if text is None:
        return None
    try:
        return [float(v) for v in text.split(",")]
    except ValueError as exc:
        raise InputError(f"{option}: cannot read numbers from {text!r}") from exc


def _vector(option: str, text: str) -> list[float]:
    values = _numbers(option, text)
    if len(values) != 3:
        raise InputError(f"{option}: expected three numbers 'x,y,z'; got {text!r}")
    return values


def _material_section(o: dict[str, Any]) -> dict[str, Any]:
    """The ``[material]`` section the material options describe."""
    material: dict[str, Any] = {"thickness": o["thickness"]}
    parameters = {k: o[k] for k in ("E", "nu", "mu", "E1", "E2", "G12", "nu12") if o[k] is not None}
    for key in ("A", "B", "C"):
        if o[key] is not None:
            parameters[key] = _numbers(f"--{key}", o[key])
    if o["fabric"] is not None:
        if parameters or str(o["material"]) != "neo-hooke":
            raise InputError("--fabric sets the material; drop --material and its parameters")
        material["fabric"] = o["fabric"]
        if o["presets"] is not None:
            material["presets"] = str(o["presets"].resolve())
    else:
        if o["presets"] is not None:
            raise InputError("--presets needs --fabric")
        material["law"] = str(o["material"])
        material.update(parameters)
    return material


def job_from_options(source: dict[str, Any], o: dict[str, Any]) -> Job:
    """The job the command line describes."""
    material = _material_section(o)
    fibres: dict[str, Any] = {"warp_angle": o["warp_angle"], "orientation": str(o["orientation"])}
    if o["fill_angle"] is not None:
        fibres["fill_angle"] = o["fill_angle"]
    if o["warp_direction"] is not None:
        fibres["warp_direction"] = _vector("--warp-direction", o["warp_direction"])
    prestress: dict[str, Any] = {"slack_threshold": o["slack_threshold"]}
    if o["prestress"] is not None and o["prestress_field"] is not None:
        raise InputError("give --prestress or --prestress-field, not both")
    if o["prestress"] is not None:
        values = _numbers("--prestress", o["prestress"])
        if len(values) not in (1, 2, 3):
            raise InputError(
                f"--prestress: expected 'WARP,FILL' or one value; got {o['prestress']!r}"
            )
        prestress["warp"], prestress["fill"] = values[0], values[1 if len(values) > 1 else 0]
        if len(values) == 3:
            prestress["shear"] = values[2]
    if o["prestress_field"] is not None:
        names = o["prestress_field"].split(",")
        prestress["field"] = names[0] if len(names) == 1 else names
    solver: dict[str, Any] = {
        "strategy": str(o["strategy"]),
        "steps": o["steps"],
        "tolerance": o["tolerance"],
        "max_iterations": o["max_iterations"],
    }
    if o["plane"] is not None:
        solver["plane"] = _vector("--plane", o["plane"]) if "," in o["plane"] else o["plane"]
    if o["linear_solver"] is not None:
        solver["linear_solver"] = o["linear_solver"]
    output: dict[str, Any] = {
        "directory": str(o["output"].resolve()),
        "report": o["report"],
        "dxf_units": str(o["dxf_units"]),
        "allowance": o["allowance"],
    }
    if o["mark_spacing"] is not None:
        output["mark_spacing"] = o["mark_spacing"]
    if o.get("plot"):
        output["plots"] = [f.strip() for f in o["plot"].split(",") if f.strip()]
    input_ = {**source, "units": str(o["units"])}
    if o["name"] is not None:
        input_["name"] = o["name"]
    job = Job(input_, material, fibres, prestress, solver, output, base=Path.cwd())
    job.check("command line")
    return job


# ---------------------------------------------------------------------------- presentation
def _progress(quiet: bool):
    if quiet:
        return None

    def show(record: IterationRecord) -> None:
        extra = f"  α={record.step_length:.3g} {record.tangent}" if record.iteration else ""
        console.print(
            f"  {record.strategy:<18} step {record.step:>2}  τ={record.tau:6.4f}  "
            f"it {record.iteration:>2}  residual {record.relative_residual:9.3e}  "
            f"energy {record.energy: .6e}{extra}"
        )

    return show


def _field_table(fields: dict[str, np.ndarray]) -> Table:
    table = Table("field", "min", "mean", "max", title="per-cell results (mean: area-weighted)")
    statistics = field_statistics(fields)
    for name in KEY_FIELDS:
        s = statistics[name]
        table.add_row(name, f"{s['min']:.6g}", f"{s['mean']:.6g}", f"{s['max']:.6g}")
    return table


def _compensation_table(report) -> Table:
    table = Table(
        "",
        "warp",
        "fill",
        title="compensation and prestress (force per length; means area-weighted)",
    )
    for row in report.rows():
        table.add_row(*row)
    return table


def _show(outcome: JobOutcome) -> None:
    result = outcome.result
    status = "[green]converged[/]" if result.converged else f"[red]failed[/]: {result.reason}"
    console.print(
        f"{status} in {result.iterations} iterations ({' → '.join(result.strategy)}), "
        f"{result.elapsed:.2f} s; energy {result.energy:.6e}; "
        f"area 3D {result.surface_area:.6g}, pattern {result.pattern_area:.6g}"
    )
    if result.converged:
        console.print(_field_table(result.fields))
        if result.prestress is not None and outcome.compensation is not None:
            console.print(_compensation_table(outcome.compensation))
        if result.warp_deviation is not None:
            console.print(
                f"mean deviation of the warp from the direction: {result.warp_deviation:.2e}°"
            )
    for warning in outcome.warnings:
        console.print(f"[yellow]warning:[/] {warning}")
    for path in outcome.files:
        console.print(f"  wrote {path}")


def _fail(message: str, code: int) -> int:
    console.print(f"vares: error: {message}", markup=False)
    return code


def _guarded(func):
    """Run a command body, turning known errors into one-line messages and exit codes."""
    try:
        func()
    except typer.Exit:
        raise
    except (
        MeshError,
        MaterialError,
        InputError,
        JobError,
        OutputExistsError,
        FileNotFoundError,
        ValueError,
    ) as exc:
        raise typer.Exit(_fail(str(exc), 2)) from None
    except OSError as exc:
        raise typer.Exit(_fail(f"{exc.strerror or exc}: {exc.filename or ''}".strip(), 2)) from None
    except KeyboardInterrupt:
        raise typer.Exit(_fail("interrupted", 130)) from None
    except Exception as exc:  # one line, never a traceback
        raise typer.Exit(_fail(f"internal error: {type(exc).__name__}: {exc}", 3)) from None


def _execute(job: Job, *, force: bool, quiet: bool, save_job: Path | None = None) -> None:
    if save_job is not None:
        check_writable([save_job], force)

    def starting(name, mesh, material) -> None:
        if not quiet:
            console.print(
                f"{name}: {mesh}; {material!r}, thickness {job.material.get('thickness', 1.0):g}"
            )

    outcome = run_job(job, force=force, callback=_progress(quiet), on_solve_start=starting)
    if save_job is not None:
        with atomic_path(save_job) as temporary:
            temporary.write_text(job.to_toml(), encoding="utf-8")
        outcome.files.append(save_job)
    if not quiet:
        _show(outcome)
    if not outcome.result.converged:
        raise typer.Exit(_fail(f"the solve did not converge: {outcome.result.reason}", 1))


# ---------------------------------------------------------------------------- commands
@app.command()
@_with_options(SOLVE_OPTIONS)
def pattern(
    input: Annotated[Path, typer.Argument(help="Surface mesh (OBJ, STL, PLY, VTU, Gmsh, 3dm, …).")],
    **options: Any,
) -> None:
    """Compute the cutting pattern of a surface mesh.

    Writes pattern.obj, pattern.dxf, pattern.svg/.png, pattern.vtu, surface.vtu and summary.json
    (and report.html with --report) into the output directory.
    """

    def body() -> None:
        job = job_from_options({"mesh": str(input.resolve())}, options)
        _execute(job, force=options["force"], quiet=options["quiet"], save_job=options["save_job"])

    _guarded(body)


@app.command()
@_with_options(SOLVE_OPTIONS)
def example(
    example_name: Annotated[
        str,
        typer.Argument(metavar="NAME", help="Example: " + ", ".join(example_surfaces.EXAMPLES)),
    ],
    cell_type: Annotated[
        CellType, typer.Option("--cell-type", help="Mesh cells.", case_sensitive=False)
    ] = CellType.triangle,
    **options: Any,
) -> None:
    """Write a shipped example surface (surface.obj) and compute its pattern."""

    def body() -> None:
        job = job_from_options({"example": example_name, "cell_type": str(cell_type)}, options)
        _execute(job, force=options["force"], quiet=options["quiet"], save_job=options["save_job"])

    _guarded(body)


@app.command()
def run(
    job_file: Annotated[Path, typer.Argument(metavar="JOB", help="Job file (TOML).")],
    force: Annotated[bool, typer.Option("--force", "-f", help="Overwrite output files.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Show no progress.")] = False,
) -> None:
    """Run a job file: input, material, fibres, prestress, solver and outputs in one TOML."""

    def body() -> None:
        _execute(load_job(job_file), force=force, quiet=quiet)

    _guarded(body)


EVALUATE_OPTIONS = [
    p
    for p in SOLVE_OPTIONS
    if p.name
    in (
        "material",
        "E",
        "nu",
        "mu",
        "E1",
        "E2",
        "G12",
        "nu12",
        "A",
        "B",
        "C",
        "fabric",
        "presets",
        "thickness",
        "warp_angle",
        "fill_angle",
        "force",
        "quiet",
    )
] + [
    _option(Path("evaluation-out"), Path, "--output", "-o", help="Output directory.", panel=_O),
    _option(
        0.0,
        float,
        "--compression-threshold",
        help="Yarn stresses below minus this count as compressed.",
        panel=_O,
    ),
]


@app.command()
@_with_options(EVALUATE_OPTIONS)
def evaluate(
    surface: Annotated[Path, typer.Argument(help="The 3D surface mesh.")],
    pattern_file: Annotated[
        Path, typer.Argument(metavar="PATTERN", help="Its pattern (e.g. pattern.obj).")
    ],
    **options: Any,
) -> None:
    """Evaluate a given pattern with a material and yarn directions (ply-stack check).

    Reports where the yarns go into compression (where a ply cut from this pattern wrinkles)
    and writes evaluation.json and evaluation.vtu into the output directory.
    """

    def body() -> None:
        material = build_material(Job(material=_material_section(options)))
        mesh = read_mesh(surface)
        coordinates = read_pattern(pattern_file, mesh)
        output = options["output"]
        paths = [output / "evaluation.json", output / "evaluation.vtu"]
        check_writable(paths, options["force"])
        result = evaluate_pattern(
            mesh,
            coordinates,
            material,
            options["thickness"],
            warp_angle=options["warp_angle"],
            fill_angle=options["fill_angle"],
            compression_threshold=options["compression_threshold"],
        )
        if result.inverted_cells.size:
            raise InputError(f"the pattern inverts {result.inverted_cells.size} cell(s)")
        data = {
            "surface": str(surface),
            "pattern": str(pattern_file),
            "material": {"law": type(material).__name__, **material.parameters},
            "warp": result.fibres.warp,
            "fill": result.fibres.fill,
            "energy": result.energy,
            "compression_threshold": options["compression_threshold"],
            "compressed_cells": result.compressed_cells,
            "compressed_area_fraction": result.compressed_area_fraction,
            "fields": field_statistics(result.fields),
        }
        write_surface(paths[1], mesh, coordinates, result.fields)
        write_json(paths[0], data)
        if not options["quiet"]:
            console.print(_field_table(result.fields))
            console.print(
                f"yarns in compression in {result.compressed_cells.size} of {mesh.num_cells} "
                f"cells ({100 * result.compressed_area_fraction:.1f} % of the area)"
            )
            for path in paths:
                console.print(f"  wrote {path}")

    _guarded(body)


@app.command()
def fabrics(
    presets_file: Annotated[
        Path | None, typer.Option("--presets", help="TOML file with your own presets.")
    ] = None,
) -> None:
    """List the fabric presets (typical values: use your own biaxial test values to cut)."""

    def body() -> None:
        catalogue = presets() | (load_presets(presets_file) if presets_file else {})
        table = Table(
            "preset",
            "E1 (warp)",
            "E2 (fill)",
            "G12",
            "nu12",
            "description",
            title="fabric presets: stiffness E·t as force per length (thickness 1)",
        )
        for name, p in catalogue.items():
            table.add_row(
                name, f"{p.E1:g}", f"{p.E2:g}", f"{p.G12:g}", f"{p.nu12:g}", p.description
            )
        out = Console(highlight=False, soft_wrap=True)
        out.print(table)
        for name, p in catalogue.items():
            out.print(f"{name}: {p.source}")

    _guarded(body)


PANEL_OPTIONS = [
    p for p in SOLVE_OPTIONS if p.name not in ("report", "save_job", "name", "plot")
] + [
    _option(
        None,
        str | None,
        "--panel-field",
        help="Cell data with a panel id per cell (one input mesh; default 'panel').",
        panel="Panels",
    ),
    _option(
        None,
        str | None,
        "--example",
        help="Pattern a shipped structure instead: hypar-strips.",
        panel="Panels",
    ),
    _option(
        True,
        bool,
        "--match/--no-match",
        help="Solve the panels together so that every seam has the same length on both sides.",
        panel="Panels",
    ),
    _option(
        None,
        float | None,
        "--roll-width",
        help="Usable fabric roll width (mesh units): report panels wider across the warp.",
        panel="Panels",
    ),
]


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "panel"


@app.command()
@_with_options(PANEL_OPTIONS)
def panels(
    inputs: Annotated[
        list[Path] | None,
        typer.Argument(
            help="One mesh with a panel id per cell, a 3dm file with one object per "
            "panel, or one mesh file per panel."
        ),
    ] = None,
    **options: Any,
) -> None:
    """Pattern a structure of several panels with matching seams.

    Writes one pattern per panel (NAME.obj), structure.dxf (all panels side by side, with match
    marks at the same places on both sides of every seam) and structure.json (panels, seam
    lengths before and after matching, the energy price of matching, roll width check).
    """
    from .examples import hypar_strips
    from .panels import Panel, roll_width_check, solve_structure, split_panels
    from .rhino import read_3dm
    from .runner import seam_marks, solve_options

    def body() -> None:
        files = list(inputs or [])
        if bool(files) == bool(options["example"]):
            raise InputError("give input files or --example, not both and not neither")
        source = {"mesh": str(files[0].resolve())} if files else {"example": "hypar"}
        job = job_from_options(source, {**options, "report": False, "save_job": None, "name": None})
        material = build_material(job)
        cell_data: dict[str, np.ndarray] = {}
        if options["example"] is not None:
            if options["example"] != "hypar-strips":
                raise InputError(
                    f"unknown structure example {options['example']!r}; available: hypar-strips"
                )
            mesh, ids = hypar_strips()
            structure_panels = split_panels(mesh, ids, {i: f"strip-{i + 1}" for i in range(6)})
        elif len(files) == 1 and files[0].suffix.lower() == ".3dm":
            structure_panels = [Panel(m.name, m.mesh) for m in read_3dm(files[0])]
        elif len(files) == 1:
            from .mesh import read_mesh_data

            mesh, cell_data = read_mesh_data(files[0])
            key = options["panel_field"] or "panel"
            if key not in cell_data:
                raise InputError(
                    f"{files[0]} has no cell data {key!r} with panel ids "
                    f"(it has: {', '.join(cell_data) or 'none'})"
                )
            structure_panels = split_panels(mesh, cell_data[key])
        else:
            structure_panels = [Panel(f.stem, read_mesh(f)) for f in files]
        if len(structure_panels) < 2:
            raise InputError("a structure needs at least two panels")
        out = options["output"]
        targets = [out / f"{_safe(p.name)}.obj" for p in structure_panels]
        targets += [out / "structure.dxf", out / "structure.json"]
        check_writable(targets, options["force"])
        kwargs = solve_options(job, None)
        if "field" in job.prestress:
            raise InputError("per-cell prestress is not available for structures yet")
        structure = solve_structure(
            structure_panels,
            material,
            job.material.get("thickness", 1.0),
            match_seams=options["match"],
            linear_solver=job.solver.get("linear_solver"),
            **kwargs,
        )
        names = [p.name for p in structure_panels]
        too_wide = (
            []
            if options["roll_width"] is None
            else roll_width_check(structure.results, names, options["roll_width"])
        )
        written = []
        if structure.converged:
            for panel, result, target in zip(
                structure_panels, structure.results, targets, strict=False
            ):
                write_surface(target, panel.mesh, result.material_coordinates)
                written.append(target)
            from .dxf import UNITS, CutPiece, write_dxf

            factor = UNITS[str(options["units"])][0] / UNITS[str(options["dxf_units"])][0]
            spacing = (options["mark_spacing"] or 500.0) / factor
            marks = seam_marks(structure, spacing)
            pieces = [
                CutPiece(
                    p.name,
                    p.mesh,
                    r.material_coordinates,
                    warp=r.fibres.warp,
                    label=[f"pattern {r.pattern_area:.4g}"],
                    marks=m,
                )
                for p, r, m in zip(structure_panels, structure.results, marks, strict=True)
            ]
            write_dxf(
                out / "structure.dxf",
                pieces,
                units=str(options["dxf_units"]),
                model_units=str(options["units"]),
                allowance=options["allowance"],
            )
            written.append(out / "structure.dxf")
        data = {
            "matched": structure.matched,
            "converged": structure.converged,
            "reason": structure.reason,
            "coupled_iterations": structure.iterations,
            "energy_independent": structure.energy_independent,
            "energy": structure.energy,
            "energy_price": structure.energy_price,
            "elapsed_seconds": structure.elapsed,
            "material": {"law": type(material).__name__, **material.parameters},
            "panels": [
                {
                    "name": p.name,
                    "cells": p.mesh.num_cells,
                    "surface_area": p.mesh.area,
                    "pattern_area": r.pattern_area,
                    "converged": r.converged,
                    "iterations": r.iterations,
                    "width_across_warp": float(
                        np.ptp(
                            r.material_coordinates @ np.array([-r.fibres.warp[1], r.fibres.warp[0]])
                        )
                    ),
                    "compensation": (
                        compensation_report(r, options["slack_threshold"]).to_dict()
                        if r.converged
                        else None
                    ),
                }
                for p, r in zip(structure_panels, structure.results, strict=True)
            ],
            "roll_width": options["roll_width"],
            "too_wide": [{"panel": n, "width": w} for n, w in too_wide],
            "seams": [
                {
                    **{
                        k: getattr(s, k)
                        for k in (
                            "first",
                            "second",
                            "segments",
                            "length_first_before",
                            "length_second_before",
                            "length_first_after",
                            "length_second_after",
                            "max_segment_mismatch_after",
                        )
                    },
                    "mismatch_before": s.mismatch_before,
                    "mismatch_after": s.mismatch_after,
                }
                for s in structure.seam_reports
            ],
        }
        write_json(out / "structure.json", data)
        written.append(out / "structure.json")
        if not options["quiet"]:
            table = Table(
                "seam",
                "segments",
                "length A",
                "length B",
                "mismatch before",
                "mismatch after",
                title="seams (pattern lengths)",
            )
            for s in structure.seam_reports:
                table.add_row(
                    f"{s.first} | {s.second}",
                    str(s.segments),
                    f"{s.length_first_after:.6f}",
                    f"{s.length_second_after:.6f}",
                    f"{s.mismatch_before:.2e}",
                    f"{s.mismatch_after:.2e}",
                )
            console.print(table)
            console.print(
                f"{len(structure_panels)} panels, {len(structure.seams)} seams; "
                f"energy {structure.energy:.6e}, price of matching "
                f"{structure.energy_price:.3e}; {structure.elapsed:.2f} s"
            )
            for name, width in too_wide:
                console.print(
                    f"[yellow]warning:[/] {name} is {width:.4g} wide across the "
                    f"warp, more than the roll width {options['roll_width']:g}"
                )
            for path in written:
                console.print(f"  wrote {path}")
        if not structure.converged:
            raise typer.Exit(_fail(f"the structure did not converge: {structure.reason}", 1))

    _guarded(body)


@app.command()
def batch(
    jobs: Annotated[list[Path], typer.Argument(metavar="JOB...", help="Job files (TOML).")],
    workers: Annotated[
        int | None,
        typer.Option("--workers", "-w", help="Local worker processes (default: one per core)."),
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler",
            help="Run on an existing Dask distributed "
            "cluster: scheduler address, e.g. tcp://10.0.0.5:8786.",
        ),
    ] = None,
    force: Annotated[bool, typer.Option("--force", "-f", help="Rerun complete jobs too.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Only the final table.")] = False,
) -> None:
    """Run many jobs in parallel; complete jobs are skipped, failing ones reported."""
    from .batch import run_batch

    def body() -> None:
        missing = [str(j) for j in jobs if not j.is_file()]
        if missing:
            raise FileNotFoundError(f"no such file: {', '.join(missing)}")
        count = {"n": 0}

        def progress(status) -> None:
            count["n"] += 1
            if not quiet:
                colour = {"done": "green", "skipped": "cyan"}.get(status.status, "red")
                console.print(
                    f"[{count['n']}/{len(jobs)}] [{colour}]{status.status}[/] "
                    f"{status.job} ({status.seconds:.2f} s) {status.message}"
                )

        started = time.perf_counter()
        statuses = run_batch(
            jobs, workers=workers, scheduler=scheduler, force=force, callback=progress
        )
        elapsed = time.perf_counter() - started
        tally = {
            s: sum(x.status == s for x in statuses)
            for s in ("done", "skipped", "not converged", "failed")
        }
        console.print(", ".join(f"{n} {s}" for s, n in tally.items() if n) + f" in {elapsed:.2f} s")
        bad = [s for s in statuses if s.status in ("failed", "not converged")]
        if bad:
            raise typer.Exit(
                _fail(
                    f"{len(bad)} of {len(statuses)} jobs did not finish: "
                    f"{bad[0].job}: {bad[0].message}",
                    1,
                )
            )

    _guarded(body)
