"""Command line: ``vares pattern``, ``vares example``, ``vares evaluate``.

A thin layer over the Python API: it parses options, shows progress, writes files and turns
every error into a one-line message and a non-zero exit status (2: bad input or options,
1: the solve did not converge, 3: unexpected internal error).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from . import examples as example_surfaces
from .analysis import evaluate as evaluate_pattern
from .compensation import compensation_report
from .io import (
    OutputExistsError,
    check_writable,
    field_statistics,
    read_pattern,
    summary,
    write_json,
    write_surface,
)
from .materials import LAWS, Hyperelastic, MaterialError, load_presets, make_material, presets
from .materials import fabric as fabric_preset
from .mesh import MeshError, SurfaceMesh, read_mesh_data
from .solver import IterationRecord, PatternResult, solve

app = typer.Typer(
    help="Cutting patterns of doubly curved membranes by the Variation of Reference Strategy.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console(stderr=True, highlight=False, soft_wrap=True)

Law = StrEnum("Law", {name: name for name in LAWS})


class Strategy(StrEnum):
    auto = "auto"
    newton = "newton"
    pseudo_time = "pseudo-time"
    damping = "damping"


class Orientation(StrEnum):
    held = "held"
    free = "free"


class CellType(StrEnum):
    triangle = "triangle"
    quad = "quad"


class InputError(Exception):
    """Bad input or options (exit status 2)."""


# ---------------------------------------------------------------------------- options
def _opt(*names: str, help: str, **kwargs) -> typer.models.OptionInfo:
    return typer.Option(*names, help=help, **kwargs)


MaterialOption = Annotated[
    Law,
    _opt(
        "--material",
        "-m",
        help="Hyperelastic law.",
        case_sensitive=False,
        rich_help_panel="Material",
    ),
]
_PANEL = {"rich_help_panel": "Material"}
YoungOption = Annotated[
    float | None,
    _opt(
        "--E",
        "-E",
        help="Young's modulus (neo-hooke, st-venant-kirchhoff; default 1000). "
        "Without prestress only the stresses scale with it, not the pattern.",
        **_PANEL,
    ),
]
PoissonOption = Annotated[
    float | None, _opt("--nu", help="Poisson's ratio, -1 < nu <= 0.5 (default 0.3).", **_PANEL)
]
ShearOption = Annotated[
    float | None, _opt("--mu", help="Shear modulus (incompressible-neo-hooke).", **_PANEL)
]
E1Option = Annotated[float | None, _opt("--E1", help="Warp modulus (orthotropic).", **_PANEL)]
E2Option = Annotated[float | None, _opt("--E2", help="Fill modulus (orthotropic).", **_PANEL)]
G12Option = Annotated[
    float | None, _opt("--G12", help="In-plane shear modulus (orthotropic).", **_PANEL)
]
Nu12Option = Annotated[
    float | None, _opt("--nu12", help="Poisson's ratio warp→fill (orthotropic).", **_PANEL)
]
AOption = Annotated[
    str | None, _opt("--A", help="NCF warp coefficients 'A0,A1,…' (sum 0).", **_PANEL)
]
BOption = Annotated[
    str | None, _opt("--B", help="NCF fill coefficients 'B0,B1,…' (sum 0).", **_PANEL)
]
COption = Annotated[str | None, _opt("--C", help="NCF shear coefficients 'C1,C2,…'.", **_PANEL)]
ThicknessOption = Annotated[
    float, _opt("--thickness", "-t", help="Thickness; 1 for laws given as force/length.", **_PANEL)
]
FabricOption = Annotated[
    str | None,
    _opt("--fabric", help="Fabric preset (see 'vares fabrics'); replaces --material.", **_PANEL),
]
PresetsOption = Annotated[
    Path | None, _opt("--presets", help="TOML file with your own fabric presets.", **_PANEL)
]
_PRESTRESS = {"rich_help_panel": "Prestress"}
PrestressOption = Annotated[
    str | None,
    _opt(
        "--prestress",
        help="Prestress along the yarns, force/length: 'WARP,FILL' or one value for both.",
        **_PRESTRESS,
    ),
]
PrestressFieldOption = Annotated[
    str | None,
    _opt(
        "--prestress-field",
        help="Per-cell prestress from the input's cell data: 'NAME' "
        "(columns warp, fill[, shear]) or 'WARP_NAME,FILL_NAME'.",
        **_PRESTRESS,
    ),
]
SlackOption = Annotated[
    float,
    _opt(
        "--slack-threshold",
        help="Report cells whose achieved yarn force is below this (force/length).",
        **_PRESTRESS,
    ),
]
_FIBRES = {"rich_help_panel": "Fibres"}
WarpAngleOption = Annotated[
    float, _opt("--warp-angle", help="Warp angle in the pattern frame, degrees.", **_FIBRES)
]
FillAngleOption = Annotated[
    float | None,
    _opt("--fill-angle", help="Fill angle in the pattern frame (default warp + 90).", **_FIBRES),
]
WarpDirectionOption = Annotated[
    str | None,
    _opt(
        "--warp-direction",
        help="3D direction 'x,y,z' the warp follows on the surface (overrides --warp-angle).",
        **_FIBRES,
    ),
]
OrientationOption = Annotated[
    Orientation,
    _opt(
        "--orientation",
        help="Anisotropic laws: keep the initial guess's rotation (held) "
        "or let the energy choose it (free).",
        case_sensitive=False,
        **_FIBRES,
    ),
]
_SOLVER = {"rich_help_panel": "Solver"}
StrategyOption = Annotated[
    Strategy,
    _opt("--strategy", "-s", help="Solution strategy.", case_sensitive=False, **_SOLVER),
]
StepsOption = Annotated[int, _opt("--steps", help="Pseudo-time steps (pseudo-time).", **_SOLVER)]
ToleranceOption = Annotated[
    float, _opt("--tolerance", help="Relative residual tolerance.", **_SOLVER)
]
MaxIterationsOption = Annotated[
    int, _opt("--max-iterations", help="Newton iterations per step.", **_SOLVER)
]
ForceOption = Annotated[bool, _opt("--force", "-f", help="Overwrite existing output files.")]
QuietOption = Annotated[bool, _opt("--quiet", "-q", help="Show no progress.")]
OutOption = Annotated[Path, _opt("--output", "-o", help="Output directory.")]


@dataclass
class MaterialOptions:
    law: Law
    E: float | None
    nu: float | None
    mu: float | None
    E1: float | None
    E2: float | None
    G12: float | None
    nu12: float | None
    A: str | None
    B: str | None
    C: str | None

    fabric: str | None = None
    presets: Path | None = None

    def build(self) -> Hyperelastic:
        if self.fabric is not None:
            given = [
                n
                for n in ("E", "nu", "mu", "E1", "E2", "G12", "nu12", "A", "B", "C")
                if getattr(self, n) is not None
            ]
            if given or str(self.law) != "neo-hooke":
                raise InputError("--fabric sets the material; drop --material and its parameters")
            return fabric_preset(self.fabric, self.presets).material()
        if self.presets is not None:
            raise InputError("--presets needs --fabric")
        law = str(self.law)
        given = {
            "E": self.E,
            "nu": self.nu,
            "mu": self.mu,
            "E1": self.E1,
            "E2": self.E2,
            "G12": self.G12,
            "nu12": self.nu12,
            "A": _numbers("--A", self.A),
            "B": _numbers("--B", self.B),
            "C": _numbers("--C", self.C),
        }
        given = {name: value for name, value in given.items() if value is not None}
        if law in ("neo-hooke", "st-venant-kirchhoff"):
            given = {"E": 1000.0, "nu": 0.3} | given
        return make_material(law, given)


def _numbers(option: str, text: str | None) -> list[float] | None:
    if text is None:
        return None
    try:
        return [float(v) for v in text.split(",")]
    except ValueError as exc:
        raise InputError(f"{option}: cannot read numbers from {text!r}") from exc


def _vector(option: str, text: str) -> np.ndarray:
    values = _numbers(option, text)
    if len(values) != 3:
        raise InputError(f"{option}: expected three numbers 'x,y,z'; got {text!r}")
    return np.array(values)


def _prestress(
    text: str | None, field: str | None, cell_data: dict[str, np.ndarray] | None
) -> np.ndarray | None:
    if text is not None and field is not None:
        raise InputError("give --prestress or --prestress-field, not both")
    if text is not None:
        values = _numbers("--prestress", text)
        if len(values) not in (1, 2, 3):
            raise InputError(f"--prestress: expected 'WARP,FILL' or one value; got {text!r}")
        return np.array(values[0] if len(values) == 1 else values)
    if field is None:
        return None
    if cell_data is None:
        raise InputError("--prestress-field needs an input file with cell data")
    names = field.split(",")
    missing = [n for n in names if n not in cell_data]
    if missing or len(names) > 3:
        known = ", ".join(cell_data) or "none"
        raise InputError(
            f"--prestress-field: no cell data {', '.join(missing) or field!r} "
            f"in the input (it has: {known})"
        )
    if len(names) == 1:
        return cell_data[names[0]]
    return np.column_stack([np.asarray(cell_data[n], dtype=float).ravel() for n in names])


def _plane(text: str):
    return _vector("--plane", text) if "," in text else text


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


_TABLE_FIELDS = (
    "det_F",
    "warp_stretch",
    "fill_stretch",
    "shear_angle",
    "warp_stress",
    "fill_stress",
    "stress_min",
    "stress_max",
)


def _field_table(fields: dict[str, np.ndarray]) -> Table:
    table = Table("field", "min", "mean", "max", title="per-cell results (mean: area-weighted)")
    statistics = field_statistics(fields)
    for name in _TABLE_FIELDS:
        if name in statistics:
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
    w, f = report.warp, report.fill
    rows = [
        ("compensation, mean", lambda y: f"{y.compensation_mean:.3f} %"),
        (
            "compensation, min … max",
            lambda y: f"{y.compensation_min:.3f} … {y.compensation_max:.3f} %",
        ),
        ("target prestress", lambda y: f"{y.target_mean:.4g}"),
        ("achieved, mean", lambda y: f"{y.achieved_mean:.4g}"),
        ("achieved, min … max", lambda y: f"{y.achieved_min:.4g} … {y.achieved_max:.4g}"),
        ("RMS deviation from target", lambda y: f"{y.rms_deviation:.3g}"),
        (
            f"slack: below {report.slack_threshold:g}",
            lambda y: f"{100 * y.slack_area_fraction:.1f} % ({y.slack_cells} cells)",
        ),
    ]
    for label, cell in rows:
        table.add_row(label, cell(w), cell(f))
    return table


def _report(result: PatternResult, outputs: list[Path], report=None) -> None:
    status = "[green]converged[/]" if result.converged else f"[red]failed[/]: {result.reason}"
    console.print(
        f"{status} in {result.iterations} iterations ({' → '.join(result.strategy)}), "
        f"{result.elapsed:.2f} s; energy {result.energy:.6e}; "
        f"area 3D {result.surface_area:.6g}, pattern {result.pattern_area:.6g}"
    )
    if result.converged:
        console.print(_field_table(result.fields))
        if report is not None:
            console.print(_compensation_table(report))
        if result.warp_deviation is not None:
            console.print(
                f"mean deviation of the warp from the direction: {result.warp_deviation:.2e}°"
            )
    for path in outputs:
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


def _solve_and_write(
    mesh: SurfaceMesh,
    outdir: Path,
    material: Hyperelastic,
    *,
    input_name: str,
    write_input: bool,
    thickness: float,
    warp_angle: float,
    fill_angle: float | None,
    warp_direction: str | None,
    orientation: Orientation,
    prestress: np.ndarray | None,
    slack_threshold: float,
    strategy: Strategy,
    steps: int,
    plane: str,
    tolerance: float,
    max_iterations: int,
    force: bool,
    quiet: bool,
) -> None:
    direction = None if warp_direction is None else _vector("--warp-direction", warp_direction)
    paths = {
        "pattern": outdir / "pattern.obj",
        "pattern_vtu": outdir / "pattern.vtu",
        "surface_vtu": outdir / "surface.vtu",
        "summary": outdir / "summary.json",
    }
    if write_input:
        paths["surface"] = outdir / "surface.obj"
    check_writable(paths.values(), force)
    if not quiet:
        console.print(f"{input_name}: {mesh}; {material!r}, thickness {thickness:g}")
    result = solve(
        mesh,
        material,
        thickness,
        warp_angle=warp_angle,
        fill_angle=fill_angle,
        warp_direction=direction,
        orientation=str(orientation),
        prestress=prestress,
        strategy=str(strategy),
        steps=steps,
        plane=_plane(plane),
        tolerance=tolerance,
        max_iterations=max_iterations,
        callback=_progress(quiet),
    )
    written = []
    if write_input:
        write_surface(paths["surface"], mesh)
        written.append(paths["surface"])
    data = summary(result, input=input_name, tolerance=tolerance)
    report = None
    if result.converged:
        report = compensation_report(result, slack_threshold)
        data["compensation"] = report.to_dict()
        write_surface(paths["pattern"], mesh, result.material_coordinates)
        write_surface(paths["pattern_vtu"], mesh, result.material_coordinates, result.fields)
        write_surface(paths["surface_vtu"], mesh, fields=result.fields)
        written += [paths["pattern"], paths["pattern_vtu"], paths["surface_vtu"]]
    write_json(paths["summary"], data)
    written.append(paths["summary"])
    if not quiet:
        _report(result, written, report)
    if not result.converged:
        raise typer.Exit(_fail(f"the solve did not converge: {result.reason}", 1))


# ---------------------------------------------------------------------------- commands
@app.command()
def pattern(
    input: Annotated[Path, typer.Argument(help="Surface mesh (OBJ, STL, PLY, VTU, Gmsh, …).")],
    output: OutOption = Path("pattern-out"),
    material: MaterialOption = Law["neo-hooke"],
    E: YoungOption = None,
    nu: PoissonOption = None,
    mu: ShearOption = None,
    E1: E1Option = None,
    E2: E2Option = None,
    G12: G12Option = None,
    nu12: Nu12Option = None,
    A: AOption = None,
    B: BOption = None,
    C: COption = None,
    fabric: FabricOption = None,
    presets_file: PresetsOption = None,
    thickness: ThicknessOption = 1.0,
    warp_angle: WarpAngleOption = 0.0,
    fill_angle: FillAngleOption = None,
    warp_direction: WarpDirectionOption = None,
    orientation: OrientationOption = Orientation.held,
    prestress: PrestressOption = None,
    prestress_field: PrestressFieldOption = None,
    slack_threshold: SlackOption = 0.0,
    strategy: StrategyOption = Strategy.auto,
    steps: StepsOption = 3,
    plane: Annotated[
        str,
        _opt(
            "--plane",
            help="Initial-guess plane: best-fit, xy, yz, zx, or a normal 'nx,ny,nz'.",
            **_SOLVER,
        ),
    ] = "best-fit",
    tolerance: ToleranceOption = 1e-10,
    max_iterations: MaxIterationsOption = 50,
    force: ForceOption = False,
    quiet: QuietOption = False,
) -> None:
    """Compute the cutting pattern of a surface mesh.

    Writes OUTPUT/pattern.obj (the flat pattern, same nodes and faces as the input, z = 0),
    OUTPUT/pattern.vtu and OUTPUT/surface.vtu (pattern and surface with every per-cell result,
    for ParaView) and OUTPUT/summary.json (convergence, energy, areas, field ranges, history).
    """
    options = MaterialOptions(material, E, nu, mu, E1, E2, G12, nu12, A, B, C, fabric, presets_file)

    def body() -> None:
        built = options.build()
        mesh, cell_data = read_mesh_data(input)
        _solve_and_write(
            mesh,
            output,
            built,
            input_name=str(input),
            write_input=False,
            thickness=thickness,
            warp_angle=warp_angle,
            fill_angle=fill_angle,
            warp_direction=warp_direction,
            orientation=orientation,
            prestress=_prestress(prestress, prestress_field, cell_data),
            slack_threshold=slack_threshold,
            strategy=strategy,
            steps=steps,
            plane=plane,
            tolerance=tolerance,
            max_iterations=max_iterations,
            force=force,
            quiet=quiet,
        )

    _guarded(body)


@app.command()
def example(
    name: Annotated[str, typer.Argument(help="Example: " + ", ".join(example_surfaces.EXAMPLES))],
    output: OutOption = Path("example-out"),
    cell_type: Annotated[
        CellType, typer.Option("--cell-type", help="Mesh cells.", case_sensitive=False)
    ] = CellType.triangle,
    material: MaterialOption = Law["neo-hooke"],
    E: YoungOption = None,
    nu: PoissonOption = None,
    mu: ShearOption = None,
    E1: E1Option = None,
    E2: E2Option = None,
    G12: G12Option = None,
    nu12: Nu12Option = None,
    A: AOption = None,
    B: BOption = None,
    C: COption = None,
    fabric: FabricOption = None,
    presets_file: PresetsOption = None,
    thickness: ThicknessOption = 1.0,
    warp_angle: WarpAngleOption = 0.0,
    fill_angle: FillAngleOption = None,
    warp_direction: WarpDirectionOption = None,
    orientation: OrientationOption = Orientation.held,
    prestress: PrestressOption = None,
    prestress_field: PrestressFieldOption = None,
    slack_threshold: SlackOption = 0.0,
    strategy: StrategyOption = Strategy.auto,
    steps: StepsOption = 3,
    plane: Annotated[
        str, _opt("--plane", help="Initial-guess plane (default: the example's own).", **_SOLVER)
    ] = "",
    tolerance: ToleranceOption = 1e-10,
    max_iterations: MaxIterationsOption = 50,
    force: ForceOption = False,
    quiet: QuietOption = False,
) -> None:
    """Write a shipped example surface (OUTPUT/surface.obj) and compute its pattern."""
    options = MaterialOptions(material, E, nu, mu, E1, E2, G12, nu12, A, B, C, fabric, presets_file)

    def body() -> None:
        if name not in example_surfaces.EXAMPLES:
            raise InputError(
                f"unknown example {name!r}; available: {', '.join(example_surfaces.EXAMPLES)}"
            )
        built = options.build()
        mesh = example_surfaces.EXAMPLES[name](cell_type=str(cell_type))
        _solve_and_write(
            mesh,
            output,
            built,
            input_name=name,
            write_input=True,
            thickness=thickness,
            warp_angle=warp_angle,
            fill_angle=fill_angle,
            warp_direction=warp_direction,
            orientation=orientation,
            prestress=_prestress(prestress, prestress_field, None),
            slack_threshold=slack_threshold,
            strategy=strategy,
            steps=steps,
            plane=plane or example_surfaces.EXAMPLE_PLANES.get(name, "best-fit"),
            tolerance=tolerance,
            max_iterations=max_iterations,
            force=force,
            quiet=quiet,
        )

    _guarded(body)


@app.command()
def evaluate(
    surface: Annotated[Path, typer.Argument(help="The 3D surface mesh.")],
    pattern_file: Annotated[
        Path, typer.Argument(metavar="PATTERN", help="Its pattern (e.g. pattern.obj).")
    ],
    output: OutOption = Path("evaluation-out"),
    material: MaterialOption = Law["neo-hooke"],
    E: YoungOption = None,
    nu: PoissonOption = None,
    mu: ShearOption = None,
    E1: E1Option = None,
    E2: E2Option = None,
    G12: G12Option = None,
    nu12: Nu12Option = None,
    A: AOption = None,
    B: BOption = None,
    C: COption = None,
    fabric: FabricOption = None,
    presets_file: PresetsOption = None,
    thickness: ThicknessOption = 1.0,
    warp_angle: WarpAngleOption = 0.0,
    fill_angle: FillAngleOption = None,
    force: ForceOption = False,
    quiet: QuietOption = False,
) -> None:
    """Evaluate a given pattern with a material and yarn directions (ply-stack check).

    Reports where the yarns go into compression (where a ply cut from this pattern wrinkles)
    and writes OUTPUT/evaluation.json and OUTPUT/evaluation.vtu.
    """
    options = MaterialOptions(material, E, nu, mu, E1, E2, G12, nu12, A, B, C, fabric, presets_file)

    def body() -> None:
        built = options.build()
        mesh = read_mesh_data(surface)[0]
        coordinates = read_pattern(pattern_file, mesh)
        paths = [output / "evaluation.json", output / "evaluation.vtu"]
        check_writable(paths, force)
        result = evaluate_pattern(
            mesh, coordinates, built, thickness, warp_angle=warp_angle, fill_angle=fill_angle
        )
        if result.inverted_cells.size:
            raise InputError(f"the pattern inverts {result.inverted_cells.size} cell(s)")
        data = {
            "surface": str(surface),
            "pattern": str(pattern_file),
            "material": {"law": type(built).__name__, **built.parameters},
            "warp_angle": warp_angle,
            "fill_angle": fill_angle if fill_angle is not None else warp_angle + 90.0,
            "energy": result.energy,
            "compressed_cells": result.compressed_cells,
            "compressed_area_fraction": result.compressed_area_fraction,
            "fields": field_statistics(result.fields),
        }
        write_surface(paths[1], mesh, coordinates, result.fields)
        write_json(paths[0], data)
        if not quiet:
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
    presets_file: PresetsOption = None,
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
        Console(highlight=False).print(table)
        for name, p in catalogue.items():
            Console(highlight=False, soft_wrap=True).print(f"{name}: {p.source}")

    _guarded(body)
