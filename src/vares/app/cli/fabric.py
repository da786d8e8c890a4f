"""``vares fabric fit``: a fabric file from biaxial test records; ``vares fabric band``: the
band of a panel's pattern under the scatter of the fabric's compensation values
(docs/fabrics.md)."""

import inspect
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from .common import check_parallel, console, guarded, scheduler_option, workers_option
from .flags import InputError, flag_name, option_parameter, with_flags

if TYPE_CHECKING:  # the engine is imported when a command runs
    from ...materials.fitting import FabricFit

__all__ = ["band", "fabric_app", "fit"]

fabric_app = typer.Typer(
    help="Fabrics from biaxial tests: fit constants and compensation values to test records.",
    no_args_is_help=True,
)


def _pair(text: str | None, flag: str) -> tuple[float, float] | None:
    if text is None:
        return None
    parts = text.split(",")
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        values = ()
    if len(values) != 2 or not all(v > 0 for v in values):
        raise InputError(f"{flag} takes two positive numbers 'warp,fill' (kN/m); got {text!r}")
    return values[0], values[1]


@fabric_app.command("fit")
def fit(
    files: Annotated[
        list[Path],
        typer.Argument(
            metavar="FILE...",
            help="Biaxial test records (CSV/TSV), one per specimen or test: MSAJ/M-02 load "
            "ratio records give the constants, EN 17117-2 records the compensation values.",
        ),
    ],
    output: Annotated[
        Path, typer.Option("--output", "-o", help="The fabric file to write (.toml).")
    ],
    prestress: Annotated[
        str | None,
        typer.Option(
            help="The project's prestress 'warp,fill' (kN/m): compensation values are read there."
        ),
    ] = None,
    name: Annotated[
        str | None, typer.Option(help="The fabric's name (default: the output file's stem).")
    ] = None,
    cycle: Annotated[
        int,
        typer.Option(help="The cycle of each load ratio the constants are fitted to (-1: last)."),
    ] = -1,
    reciprocal: Annotated[
        bool,
        typer.Option(
            "--reciprocal/--no-reciprocal",
            help="Fit with the reciprocity constraint nu_wf/E_w = nu_fw/E_f.",
        ),
    ] = True,
    G12: Annotated[
        float | None,
        typer.Option("--G12", help="Shear stiffness (kN/m); biaxial tests do not measure it."),
    ] = None,
    shear_from: Annotated[
        str,
        typer.Option(help="Preset whose G12 is taken when --G12 is not given."),
    ] = "pes-pvc-type-2",
    compensate_by: Annotated[
        str | None,
        typer.Option(
            help="The file's default compensation of a pattern: 'measured' (the compensation "
            "values; default when there are any) or 'law' (the fitted law)."
        ),
    ] = None,
    plots: Annotated[
        Path | None,
        typer.Option(
            help="Also draw each record's loops or compensation reading and the residuals per "
            "load ratio into this folder (PNG)."
        ),
    ] = None,
    report: Annotated[
        Path | None,
        typer.Option(
            help="Also write the fit's HTML report here: measured against fitted per load "
            "ratio, the residuals, the compensation per cycle and the tables."
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", "-f", help="Overwrite the output file.")
    ] = False,
) -> None:
    """Fit a fabric to biaxial test records and write a fabric file for --fabric.

    The constants E_w, E_f, nu_wf (E1, E2, nu12) are fitted by least squares of the strain
    residual over the load ratios of the chosen cycle (MSAJ/M-02), per specimen; the file holds
    their mean and scatter, the compensation values at --prestress (EN 17117-2) and where
    every number came from.
    """

    def body() -> None:
        from ...io.biaxial import read_biaxial
        from ...io.files import check_writable, write_text
        from ...materials import fabric
        from ...materials.fabric_file import fit_toml
        from ...materials.fitting import fit_fabric

        if output.suffix != ".toml":
            raise InputError(f"--output must end in .toml; got {output}")
        if compensate_by not in (None, "measured", "law"):
            raise InputError(f"--compensate-by takes measured or law; got {compensate_by!r}")
        pair = _pair(prestress, "--prestress")
        if compensate_by == "measured" and pair is None:
            raise InputError(
                "--compensate-by measured needs --prestress: the compensation values are read "
                "at the prestress the compensation records (EN 17117-2) hold"
            )
        if report is not None and report.suffix.lower() not in (".html", ".htm"):
            raise InputError(f"--report must end in .html; got {report}")
        check_writable([output] if report is None else [output, report], force)
        if G12 is not None:
            if not G12 > 0:
                raise InputError(f"--G12 must be positive; got {G12:g}")
            shear, shear_source = G12, "given (--G12)"
        else:
            shear, shear_source = fabric(shear_from).G12, f"from preset {shear_from}"
        records = [read_biaxial(path) for path in files]
        fitted = fit_fabric(
            records,
            name=name or output.stem,
            G12=shear,
            G12_source=shear_source,
            prestress=pair,
            cycle=cycle,
            reciprocal=reciprocal,
        )
        text = fit_toml(fitted, compensate_by)
        if plots is not None:
            from ...io.fabric_plots import fabric_figures, figure_paths

            check_writable([p for *_, p in figure_paths(fitted, records, plots)], force)
        pages = {}  # made before any file is written
        if report is not None:
            from ..fabric_report import fit_report

            pages[report] = fit_report(fitted, records)
        write_text(output, text)
        _show(fitted)
        console.print(f"wrote {output}")
        if plots is not None:
            figures = fabric_figures(fitted, records, plots)
            console.print(f"drew {len(figures)} figures in {plots}")
        for path, page in pages.items():
            write_text(path, page)
            console.print(f"wrote {path}")

    guarded(body)


def _show(fitted: "FabricFit") -> None:
    """The fit's tables: constants per specimen, residual per load ratio, compensation."""
    from rich.table import Table

    from ..fabric_report import compensation_rows, constant_rows

    table = Table(
        "specimen",
        "E1 (warp)",
        "E2 (fill)",
        "nu12",
        "nu21",
        "rms residual",
        "nonlinear rms",
        title="fitted constants (kN/m; ± standard error of the fit)",
    )
    *rows, mean = constant_rows(fitted)
    for f, row in zip(fitted.fits, rows, strict=True):
        nonlinear = f"{f.nonlinear.get('rms', float('nan')):.2e}"
        table.add_row(*row, nonlinear + (" *" if f.linear_is_poor else ""))
    table.add_row(*mean, "")
    console.print(table)
    if any(f.linear_is_poor for f in fitted.fits):
        console.print(
            "* the nonlinear response ε = Cσ + (k_w σ_w², k_f σ_f²) fits markedly better: the "
            "linear constants are secant values over the tested range"
        )
    residuals = Table(
        "specimen", "ratio", "rms warp", "rms fill", title="strain residual per load ratio"
    )
    for f in fitted.fits:
        for r in f.residuals:
            residuals.add_row(f.name, r.label, f"{r.rms_warp:.2e}", f"{r.rms_fill:.2e}")
    console.print(residuals)
    console.print(f"G12 = {fitted.G12:g} kN/m {fitted.G12_source} (not measured by biaxial tests)")
    if fitted.compensation is not None and fitted.prestress is not None:
        values = Table(
            "specimen",
            "warp",
            "fill",
            title=f"compensation values at {fitted.prestress[0]:g}/{fitted.prestress[1]:g} kN/m",
        )
        for row in compensation_rows(fitted):
            values.add_row(*row)
        console.print(values)
    single = [
        what
        for what, summary in (
            ("constants", fitted.constants),
            ("compensation values", fitted.compensation),
        )
        if summary is not None and summary.specimens == 1
    ]
    if single:
        console.print(
            f"the {' and the '.join(single)} come from one specimen: their scatter is unknown "
            "(written as 0); a band (vares fabric band) needs two or more"
        )


def _scatter_flags() -> list[inspect.Parameter]:
    """The flags of :class:`ScatterOptions`, from its declarations."""
    from ...analysis.scatter import ScatterOptions

    defaults = ScatterOptions.defaults()
    return [
        option_parameter(
            name,
            defaults[name],
            {"int": int, "float": float, "str": str}[spec.kind],
            flag_name(name, spec),
            help=f"{spec.help} ({spec.bounds()})",
            panel="Scatter",
        )
        for name, spec in ScatterOptions.specs().items()
    ]


@fabric_app.command("band")
@with_flags(_scatter_flags())
def band(
    fabric_file: Annotated[
        Path,
        typer.Option(
            "--fabric",
            help="A fabric file with measured compensation values and their scatter (with "
            "--sampled constants: with the scatter of its constants).",
        ),
    ],
    inputs: Annotated[
        list[Path] | None,
        typer.Argument(
            metavar="MESH...",
            help="The panel's surface mesh file, or one file per panel of a structure.",
        ),
    ] = None,
    example: Annotated[
        str | None, typer.Option(help="A shipped example surface or structure instead.")
    ] = None,
    prestress: Annotated[
        str | None,
        typer.Option(help="Prestress 'warp,fill' (kN/m; default: the one measured at)."),
    ] = None,
    warp_direction: Annotated[
        str | None, typer.Option(help="Warp direction 'x,y,z' on the surface.")
    ] = None,
    match: Annotated[
        bool,
        typer.Option("--match/--no-match", help="Match the seams of a structure's panels."),
    ] = True,
    erect: Annotated[
        bool,
        typer.Option(
            "--erect/--no-erect",
            help="Erect the nominal patterns with each sample's fabric (the prestress range).",
        ),
    ] = True,
    workers: Annotated[int | None, workers_option("the samples", "1: in this process")] = None,
    scheduler: Annotated[str | None, scheduler_option("the samples")] = None,
    output: Annotated[
        Path | None,
        typer.Option(
            "--output",
            "-o",
            help="Write summary.json and report.html of the band into this folder.",
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", "-f", help="Overwrite the output files.")
    ] = False,
    **values: Any,
) -> None:
    """The band of a panel's or a structure's patterns under the scatter of its fabric's
    compensation values (or, with --sampled constants, of its fitted constants): the patterns
    solved for random samples of the values, and the pattern dimensions, seam lengths and the
    erected prestress (the nominal patterns erected with each sample's fabric) as nominal ±
    SIGMAS standard deviations (docs/fabrics.md)."""

    def body() -> None:
        import json

        from rich.table import Table

        from ...analysis.scatter import ScatterOptions, check_scatter
        from ...geometry.examples import STRUCTURE_EXAMPLES
        from ...io.files import check_writable, write_text
        from ...materials.presets import file_fabric
        from ...options import OptionsError
        from ...structures.options import StructureOptions
        from ..fabric_band import fabric_band
        from ..fabric_report import band_report
        from ..inputs import load_input
        from ..job import Job
        from ..sections import InputOptions
        from ..staging import listed

        files = list(inputs or [])
        if bool(files) == (example is not None):
            raise InputError("give mesh files or --example, not both and not neither")
        try:
            scatter = ScatterOptions(**values)
        except OptionsError as exc:
            key = exc.key or ""
            raise InputError(f"--{key.replace('_', '-')} {exc.problem}") from None
        check_parallel(workers, scheduler)
        if example is not None:
            source, several = {"example": example}, example in STRUCTURE_EXAMPLES
        elif len(files) == 1:
            source, several = {"mesh": str(files[0].resolve())}, False
        else:
            source, several = {"meshes": tuple(str(f.resolve()) for f in files)}, True
        structure = StructureOptions(match_seams=match) if several else None
        loaded = load_input(Job(input=InputOptions(**source), structure=structure))
        for warning in loaded.warnings:
            console.print(f"warning: {warning}")
        settings: dict[str, Any] = {"match_seams": match}
        if warp_direction is not None:
            settings["warp_direction"] = _vector(warp_direction, "--warp-direction")
        preset = file_fabric(fabric_file)
        check_scatter(preset, scatter.sampled)
        if scatter.sampled == "constants":
            s = preset.scatter
            title = (
                f"{preset.name}: E1 {preset.E1:.1f} ± {s.E1:.1f}, E2 {preset.E2:.1f} ± "
                f"{s.E2:.1f} kN/m, nu12 {preset.nu12:.3f} ± {s.nu12:.3f}"
            )
        else:
            c = preset.compensation
            title = (
                f"{preset.name}: warp {100 * c.warp:.3f} ± {100 * c.warp_std:.3f} %, fill "
                f"{100 * c.fill:.3f} ± {100 * c.fill_std:.3f} %"
            )
        targets = [] if output is None else [output / "summary.json", output / "report.html"]
        if output is not None:
            owned = {p.resolve() for p in listed(output)}
            if any(t.resolve() in owned for t in targets):
                raise InputError(
                    f"-o {output} is the folder of a run, whose files these would replace: "
                    "write the band into a folder of its own"
                )
        check_writable(targets, force)
        result = fabric_band(
            loaded.panels,
            preset,
            prestress=_pair(prestress, "--prestress"),
            scatter=scatter,
            erected=erect,
            workers=workers,
            scheduler=scheduler,
            **settings,
        )
        table = Table(
            "",
            "nominal",
            f"± {scatter.sigmas:g} std",
            "samples min … max",
            title=f"{title}, {scatter.samples} samples ({loaded.units}; prestress: the nominal "
            "patterns erected with each sample's fabric)",
        )
        for name, d in result.band.to_dict().items():
            table.add_row(
                name,
                f"{d['nominal']:.6g}",
                f"{d['spread']:.3g}",
                f"{d['min']:.6g} … {d['max']:.6g}",
            )
        console.print(table)
        console.print(
            f"nominal case {result.seconds['nominal']:.2f} s, {scatter.samples} samples "
            f"{result.seconds['samples']:.2f} s"
        )
        if output is not None:
            output.mkdir(parents=True, exist_ok=True)
            summary = {**result.to_dict(), "units": loaded.units}
            report = band_report(result, loaded.units)  # both made before either is written
            write_text(targets[0], json.dumps(summary, indent=2) + "\n")
            write_text(targets[1], report)
            console.print(f"wrote {targets[0]} and {targets[1]}")

    guarded(body)


def _vector(text: str, flag: str) -> tuple[float, float, float]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3:
        raise InputError(f"{flag} takes three numbers 'x,y,z'; got {text!r}")
    return values[0], values[1], values[2]
