"""Command line: ``vares pattern``, ``vares example``.

A thin layer over the Python API: it parses options, shows progress, writes files and turns
every error into a one-line message and a non-zero exit status (2: bad input or options,
1: the solve did not converge, 3: unexpected internal error).
"""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console

from . import examples as example_surfaces
from .io import OutputExistsError, check_writable, summary, write_json, write_surface
from .materials import (
    Hyperelastic,
    IncompressibleNeoHooke,
    MaterialError,
    NeoHooke,
    StVenantKirchhoff,
)
from .mesh import MeshError, SurfaceMesh, read_mesh
from .solver import IterationRecord, PatternResult, solve

app = typer.Typer(
    help="Cutting patterns of doubly curved membranes by the Variation of Reference Strategy.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console(stderr=True, highlight=False, soft_wrap=True)


class Law(StrEnum):
    neo_hooke = "neo-hooke"
    st_venant_kirchhoff = "st-venant-kirchhoff"
    incompressible_neo_hooke = "incompressible-neo-hooke"


class Strategy(StrEnum):
    auto = "auto"
    newton = "newton"
    pseudo_time = "pseudo-time"
    damping = "damping"


class CellType(StrEnum):
    triangle = "triangle"
    quad = "quad"


class InputError(Exception):
    """Bad input or options (exit status 2)."""


# Options shared by the commands that solve.
MaterialOption = Annotated[
    Law, typer.Option("--material", "-m", help="Hyperelastic law.", case_sensitive=False)
]
YoungOption = Annotated[
    float,
    typer.Option(
        "--E",
        "-E",
        help="Young's modulus (neo-hooke, st-venant-kirchhoff). Without prestress only the "
        "stresses scale with it, not the pattern.",
    ),
]
PoissonOption = Annotated[float, typer.Option("--nu", help="Poisson's ratio, -1 < nu <= 0.5.")]
ShearOption = Annotated[
    float, typer.Option("--mu", help="Shear modulus (incompressible-neo-hooke).")
]
ThicknessOption = Annotated[
    float, typer.Option("--thickness", "-t", help="Thickness; 1 for laws given as force/length.")
]
StrategyOption = Annotated[
    Strategy, typer.Option("--strategy", "-s", help="Solution strategy.", case_sensitive=False)
]
StepsOption = Annotated[int, typer.Option("--steps", help="Pseudo-time steps (pseudo-time).")]
PlaneOption = Annotated[
    str,
    typer.Option(
        "--plane",
        help="Initial-guess plane: best-fit, xy, yz, zx, or a normal 'nx,ny,nz'.",
    ),
]
ToleranceOption = Annotated[float, typer.Option("--tolerance", help="Relative residual tolerance.")]
MaxIterationsOption = Annotated[
    int, typer.Option("--max-iterations", help="Newton iterations per step.")
]
ForceOption = Annotated[
    bool, typer.Option("--force", "-f", help="Overwrite existing output files.")
]
QuietOption = Annotated[bool, typer.Option("--quiet", "-q", help="Show no progress.")]
OutOption = Annotated[Path, typer.Option("--output", "-o", help="Output directory.")]


def _material(law: Law, E: float, nu: float, mu: float) -> Hyperelastic:
    if law is Law.neo_hooke:
        return NeoHooke(E=E, nu=nu)
    if law is Law.st_venant_kirchhoff:
        return StVenantKirchhoff(E=E, nu=nu)
    return IncompressibleNeoHooke(mu=mu)


def _plane(text: str):
    if "," not in text:
        return text
    try:
        normal = [float(v) for v in text.split(",")]
    except ValueError as exc:
        raise InputError(f"--plane: cannot read a normal from {text!r}") from exc
    return np.array(normal)


def _progress(quiet: bool):
    if quiet:
        return None

    def show(record: IterationRecord) -> None:
        console.print(
            f"  {record.strategy:<18} step {record.step:>2}  τ={record.tau:6.4f}  "
            f"it {record.iteration:>2}  residual {record.relative_residual:9.3e}  "
            f"energy {record.energy: .6e}"
        )

    return show


def _report(result: PatternResult, outputs: list[Path]) -> None:
    status = "[green]converged[/]" if result.converged else f"[red]failed[/]: {result.reason}"
    console.print(
        f"{status} in {result.iterations} iterations ({' → '.join(result.strategy)}), "
        f"{result.elapsed:.2f} s; energy {result.energy:.6e}; "
        f"area 3D {result.surface_area:.6g}, pattern {result.pattern_area:.6g}"
    )
    for path in outputs:
        console.print(f"  wrote {path}")


def _solve_and_write(
    mesh: SurfaceMesh,
    outdir: Path,
    extra_outputs: dict[Path, object],
    *,
    input_name: str,
    law: Law,
    E: float,
    nu: float,
    mu: float,
    thickness: float,
    strategy: Strategy,
    steps: int,
    plane: str,
    tolerance: float,
    max_iterations: int,
    force: bool,
    quiet: bool,
) -> None:
    material = _material(law, E, nu, mu)
    pattern_path, summary_path = outdir / "pattern.obj", outdir / "summary.json"
    check_writable([pattern_path, summary_path, *extra_outputs], force)
    if not quiet:
        console.print(f"{input_name}: {mesh}; {material!r}, thickness {thickness:g}")
    result = solve(
        mesh,
        material,
        thickness,
        strategy=strategy.value,
        steps=steps,
        plane=_plane(plane),
        tolerance=tolerance,
        max_iterations=max_iterations,
        callback=_progress(quiet),
    )
    written = []
    for path, surface in extra_outputs.items():
        write_surface(path, surface)
        written.append(path)
    data = summary(result, input=input_name, tolerance=tolerance)
    if result.converged:
        write_surface(pattern_path, mesh, result.material_coordinates)
        written.append(pattern_path)
    write_json(summary_path, data)
    written.append(summary_path)
    if not quiet:
        _report(result, written)
    if not result.converged:
        raise typer.Exit(_fail(f"the solve did not converge: {result.reason}", 1))


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


@app.command()
def pattern(
    input: Annotated[Path, typer.Argument(help="Surface mesh (OBJ, STL, PLY, VTU, Gmsh, …).")],
    output: OutOption = Path("pattern-out"),
    material: MaterialOption = Law.neo_hooke,
    E: YoungOption = 1000.0,
    nu: PoissonOption = 0.3,
    mu: ShearOption = 1.0,
    thickness: ThicknessOption = 1.0,
    strategy: StrategyOption = Strategy.auto,
    steps: StepsOption = 3,
    plane: PlaneOption = "best-fit",
    tolerance: ToleranceOption = 1e-10,
    max_iterations: MaxIterationsOption = 30,
    force: ForceOption = False,
    quiet: QuietOption = False,
) -> None:
    """Compute the cutting pattern of a surface mesh.

    Writes OUTPUT/pattern.obj (the flat pattern, same nodes and faces as the input, z = 0) and
    OUTPUT/summary.json (convergence, energy, areas, field ranges, iteration history).
    """

    def body() -> None:
        mesh = read_mesh(input)
        _solve_and_write(
            mesh,
            output,
            {},
            input_name=str(input),
            law=material,
            E=E,
            nu=nu,
            mu=mu,
            thickness=thickness,
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
    material: MaterialOption = Law.neo_hooke,
    E: YoungOption = 1000.0,
    nu: PoissonOption = 0.3,
    mu: ShearOption = 1.0,
    thickness: ThicknessOption = 1.0,
    strategy: StrategyOption = Strategy.auto,
    steps: StepsOption = 3,
    plane: Annotated[str, typer.Option("--plane", help="Initial-guess plane.")] = "xy",
    tolerance: ToleranceOption = 1e-10,
    max_iterations: MaxIterationsOption = 30,
    force: ForceOption = False,
    quiet: QuietOption = False,
) -> None:
    """Write a shipped example surface (OUTPUT/surface.obj) and compute its pattern."""

    def body() -> None:
        if name not in example_surfaces.EXAMPLES:
            raise InputError(
                f"unknown example {name!r}; available: {', '.join(example_surfaces.EXAMPLES)}"
            )
        mesh = example_surfaces.EXAMPLES[name](cell_type=cell_type.value)
        _solve_and_write(
            mesh,
            output,
            {output / "surface.obj": mesh},
            input_name=name,
            law=material,
            E=E,
            nu=nu,
            mu=mu,
            thickness=thickness,
            strategy=strategy,
            steps=steps,
            plane=plane,
            tolerance=tolerance,
            max_iterations=max_iterations,
            force=force,
            quiet=quiet,
        )

    _guarded(body)
