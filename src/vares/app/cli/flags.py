"""Command-line flags derived from the options classes: one flag per option, with the option's
default, bounds and help, and the values read back into the same options classes.

A command declares ``**values`` and gets its flags with :func:`with_flags`; the values it
receives become a :class:`vares.app.job.Job` with :func:`job_from_flags`.
"""

from __future__ import annotations

import inspect
from collections.abc import Iterable
from dataclasses import replace
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer

from ...analysis.drape_options import DrapeOptions
from ...analysis.options import ErectionOptions
from ...analysis.scatter_options import ScatterOptions
from ...options import Options, OptionsError, Spec
from ...solver.options import SolveOptions
from ...structures.options import CutOptions, StructureOptions
from ..job import Job
from ..sections import InputOptions, MaterialOptions, OutputOptions, PrestressOptions

__all__ = [
    "ERECTION_FLAGS",
    "ERECT_FLAG",
    "SCATTER_FLAG",
    "SCATTER_FLAGS",
    "InputError",
    "build",
    "erection_from_flags",
    "example_flag",
    "flag_name",
    "flags",
    "job_from_flags",
    "numbers",
    "option_parameter",
    "scatter_from_flags",
    "with_flags",
]

#: Help panel of each job-file section.
PANELS = {
    "input": "Input",
    "material": "Material",
    "fibres": "Fibres",
    "prestress": "Prestress",
    "solver": "Solver",
    "output": "Output",
    "structure": "Structure",
    "erection": "Erection",
    "cut": "Cutting and nesting",
    "drape": "Drape and producibility",
    "scatter": "Fabric scatter",
    "laminate": "Laminate",
}
#: Kinds given on the command line as one comma-separated string.
_TEXT_KINDS = {"vector", "plane", "floats", "strings", "paths"}


class InputError(Exception):
    """Bad input or options (exit status 2)."""


def option_parameter(
    name: str, default: Any, kind: Any, *names: str, help: str, panel: str, **extra: Any
) -> inspect.Parameter:
    """A keyword parameter that typer reads as the option ``names``."""
    annotation = Annotated[kind, typer.Option(*names, help=help, rich_help_panel=panel, **extra)]
    return inspect.Parameter(
        name, inspect.Parameter.KEYWORD_ONLY, default=default, annotation=annotation
    )


def example_flag(help: str) -> list[inspect.Parameter]:
    """A command's ``--example NAME``: a shipped input in place of the file argument."""
    return [option_parameter("example", None, str | None, "--example", help=help, panel="Input")]


def flag_name(name: str, spec: Spec, prefix: str = "") -> str:
    """The (first) command-line name of an option (``prefix``: before the option's own name,
    as ``--scatter-samples`` for ``samples``)."""
    if spec.flags:
        return spec.flags[0].split("/")[0]
    return "--" + (prefix + name).replace("_", "-")


def _enum(name: str, choices: tuple[str, ...]) -> type[StrEnum]:
    return StrEnum(name, {c: c for c in choices})


def flags(
    cls: type[Options],
    *,
    exclude: Iterable[str] = (),
    defaults: dict[str, Any] | None = None,
    prefix: str = "",
) -> list[inspect.Parameter]:
    """One parameter per option of ``cls`` that has a flag (``Spec.flags != ()``).

    ``defaults`` replaces an option's shown default (e.g. another output folder); ``prefix``
    goes before every parameter's and flag's name (``scatter_`` makes ``samples``
    ``--scatter-samples``), for options whose names other flags of the command have."""
    out = []
    for name, spec in cls.specs().items():
        if spec.flags == () or name in exclude:
            continue
        default = (defaults or {}).get(name, cls.defaults()[name])
        names = spec.flags or (flag_name(name, spec, prefix),)
        help_text = spec.help
        extra: dict[str, Any] = {}
        if spec.kind in _TEXT_KINDS:
            kind: Any = str | None
            if default not in (None, ()):
                help_text += f" [default: {_text(default)}]"
            default = None
            if spec.choices:
                help_text += f" (fields: {', '.join(spec.choices)})"
        elif spec.choices is not None:
            enum = _enum(name.title().replace("_", ""), spec.choices)
            kind = enum | None if spec.optional else enum
            default = None if default is None else enum(default)
            extra["case_sensitive"] = False
        else:
            kind = {"bool": bool, "int": int, "float": float, "str": str, "path": str}[spec.kind]
            kind = kind | None if spec.optional else kind
            if spec.bounds():
                help_text += f" ({spec.bounds()})"
        out.append(
            option_parameter(
                prefix + name,
                default,
                kind,
                *names,
                help=help_text,
                panel=PANELS[spec.section],
                **extra,
            )
        )
    return out


def _text(value: Any) -> str:
    return ",".join(str(v) for v in value) if isinstance(value, tuple) else str(value)


def with_flags(*parameter_lists: list[inspect.Parameter]):
    """Give a ``**values`` command the parameters of ``parameter_lists`` (in order)."""

    def decorate(func):
        signature = inspect.signature(func)
        own = [p for p in signature.parameters.values() if p.kind != p.VAR_KEYWORD]
        extra = [p for group in parameter_lists for p in group]
        func.__signature__ = signature.replace(parameters=own + extra)
        return func

    return decorate


def numbers(flag: str, text: str) -> tuple[float, ...]:
    """Numbers from ``"a,b,c"``."""
    try:
        return tuple(float(v) for v in text.split(","))
    except ValueError as exc:
        raise InputError(f"{flag}: cannot read numbers from {text!r}") from exc


def _parse(name: str, spec: Spec, text: str) -> Any:
    flag = flag_name(name, spec)
    if spec.kind == "vector" or (spec.kind == "plane" and "," in text):
        values = numbers(flag, text)
        if len(values) != 3:
            raise InputError(f"{flag}: expected three numbers 'x,y,z'; got {text!r}")
        return values
    if spec.kind == "floats":
        named = [c for c in spec.choices or () if c.lower() == text.strip().lower()]
        if named:
            return named[0]
        try:
            return numbers(flag, text)
        except InputError:
            if not spec.choices:
                raise
            raise InputError(
                f"{flag}: expected numbers 'a,b,…' or one of {', '.join(spec.choices)}; "
                f"got {text!r}"
            ) from None
    if spec.kind in ("strings", "paths"):
        return tuple(v.strip() for v in text.split(",") if v.strip())
    return text


def build(cls: type[Options], values: dict[str, Any], prefix: str = "", **fixed: Any) -> Options:
    """The options object the flag ``values`` describe (plus ``fixed`` settings; ``prefix``: that
    of :func:`flags`); a refused value is an :class:`InputError` naming its flag."""
    specs = cls.specs()
    settings: dict[str, Any] = {}
    for name, spec in specs.items():
        value = values.get(prefix + name)
        if value is None:
            continue
        if spec.kind in _TEXT_KINDS:
            value = _parse(name, spec, value)
        elif isinstance(value, StrEnum):
            value = str(value)
        elif spec.kind == "path":
            value = str(Path(value).resolve())
        settings[name] = value
    settings.update(fixed)
    try:
        return cls(**settings)
    except OptionsError as exc:
        if exc.key is None or exc.key not in specs:
            raise InputError(exc.problem) from None
        raise InputError(f"{flag_name(exc.key, specs[exc.key], prefix)} {exc.problem}") from None


#: The composite prestress flags (they set several options of :class:`PrestressOptions`).
PRESTRESS_FLAGS = [
    option_parameter(
        "prestress",
        None,
        str | None,
        "--prestress",
        help="Prestress along the yarns, force/length: 'WARP,FILL[,SHEAR]' or one value for both.",
        panel=PANELS["prestress"],
    ),
    option_parameter(
        "prestress_field",
        None,
        str | None,
        "--prestress-field",
        help="Per-cell prestress from the input's cell data: 'NAME' (columns warp, fill[, shear]) "
        "or 'WARP_NAME,FILL_NAME'.",
        panel=PANELS["prestress"],
    ),
]


#: ``--erect``: erect the structure from its patterns right after patterning.
ERECT_FLAG = [
    option_parameter(
        "erect",
        False,
        bool,
        "--erect",
        help="Erect the structure from its patterns afterwards (files in OUTPUT/erect/; see "
        "'vares erect').",
        panel=PANELS["erection"],
    )
]
#: The erection options' flags.
ERECTION_FLAGS = flags(ErectionOptions)


def erection_from_flags(values: dict[str, Any], *, erect: bool) -> ErectionOptions | None:
    """The erection options the flags describe, or None without ``erect``; an erection flag
    given without it is an error."""
    options = build(ErectionOptions, values)
    if erect:
        return options
    changed = [n for n, d in ErectionOptions.defaults().items() if getattr(options, n) != d]
    if changed:
        flag = flag_name(changed[0], ErectionOptions.specs()[changed[0]])
        raise InputError(f"{flag} is an erection option: add --erect")
    return None


#: ``--drape``: drape a ply kinematically beside the pattern (a single surface).
DRAPE_FLAG = [
    option_parameter(
        "drape",
        False,
        bool,
        "--drape",
        help="Drape a ply kinematically beside the pattern: its shear and producibility in "
        "summary.json and the VTU files (see 'vares drape').",
        panel=PANELS["drape"],
    )
]
#: The drape options' flags (its warp is the pattern's --warp-direction).
DRAPE_FLAGS = flags(DrapeOptions, exclude=("warp",))


def drape_from_flags(values: dict[str, Any], *, drape: bool) -> DrapeOptions | None:
    """The drape options the flags describe, or None without ``drape``; a drape flag given
    without it is an error."""
    options = build(DrapeOptions, values)
    if drape:
        return options
    changed = [n for n, d in DrapeOptions.defaults().items() if getattr(options, n) != d]
    if changed:
        flag = flag_name(changed[0], DrapeOptions.specs()[changed[0]])
        raise InputError(f"{flag} is a drape option: add --drape")
    return None


#: ``--scatter``: carry the fabric file's scatter into the patterns.
SCATTER_FLAG = [
    option_parameter(
        "scatter",
        False,
        bool,
        "--scatter",
        help="Pattern again at random samples of the fabric file's compensation values (or "
        "constants) and write the band of every pattern dimension, seam length and the erected "
        "prestress into summary.json / structure.json (and report.html); needs a fabric file "
        "with scatter (docs/fabrics.md).",
        panel=PANELS["scatter"],
    )
]
#: The scatter options' flags, ``--scatter-samples`` and the like.
SCATTER_FLAGS = flags(ScatterOptions, prefix="scatter_")


def scatter_from_flags(values: dict[str, Any], *, scatter: bool) -> ScatterOptions | None:
    """The scatter options the flags describe, or None without ``scatter``; a scatter flag
    given without it is an error."""
    options = build(ScatterOptions, values, prefix="scatter_")
    if scatter:
        return options
    changed = [n for n, d in ScatterOptions.defaults().items() if getattr(options, n) != d]
    if changed:
        flag = flag_name(changed[0], ScatterOptions.specs()[changed[0]], "scatter_")
        raise InputError(f"{flag} is a scatter option: add --scatter")
    return None


def _prestress(values: dict[str, Any]) -> dict[str, Any]:
    given, field = values.get("prestress"), values.get("prestress_field")
    if given is not None and field is not None:
        raise InputError("give --prestress or --prestress-field, not both")
    if given is not None:
        parts = numbers("--prestress", given)
        if len(parts) not in (1, 2, 3):
            raise InputError(f"--prestress: expected 'WARP,FILL' or one value; got {given!r}")
        out = {"warp": parts[0], "fill": parts[1 if len(parts) > 1 else 0]}
        return out | ({"shear": parts[2]} if len(parts) == 3 else {})
    if field is not None:
        return {"field": tuple(field.split(","))}
    return {}


#: The flags of a patterning job (pattern, example, panels, cut).
JOB_FLAGS = (
    flags(MaterialOptions)
    + flags(SolveOptions)
    + PRESTRESS_FLAGS
    + flags(PrestressOptions)
    + flags(OutputOptions)
    + ERECT_FLAG
    + ERECTION_FLAGS
    + SCATTER_FLAG
    + SCATTER_FLAGS
)


#: The composite flag of the cutting lines (it sets ``seams`` and ``curves``).
SEAMS_FLAG = [
    option_parameter(
        "seams",
        None,
        str | None,
        "--seams",
        help="Cutting lines: geodesic (default), planar, or a FILE of curves (polylines as "
        "'x y z' lines, or a 3dm file; see --curves-layer).",
        panel=PANELS["cut"],
    )
]


def _seams(values: dict[str, Any]) -> dict[str, Any]:
    given = values.get("seams")
    if given is None:
        return {}
    if given.lower() in ("geodesic", "planar"):
        return {"seams": given.lower()}
    path = Path(given)
    if not path.is_file():
        raise InputError(f"--seams: expected geodesic, planar or a curves file; no file {given!r}")
    return {"seams": "curves", "curves": str(path.resolve())}


def job_from_flags(
    values: dict[str, Any], *, structure: bool = False, cut: bool = False, **source: Any
) -> Job:
    """The job the command line describes; ``source`` are the input's settings (mesh, meshes or
    example, and the like) and paths on the command line are relative to the current folder.
    ``cut`` makes a cut job (and a structure)."""
    if cut:
        return replace(
            job_from_flags(values, structure=True, **source),
            cut=build(CutOptions, values, **_seams(values)),
        )
    return Job(
        input=build(InputOptions, values, **source),
        material=build(MaterialOptions, values),
        solve=build(SolveOptions, values),
        prestress=build(PrestressOptions, values, **_prestress(values)),
        output=build(OutputOptions, values),
        structure=build(StructureOptions, values) if structure else None,
        erection=erection_from_flags(values, erect=values.get("erect", False)),
        drape=drape_from_flags(values, drape=values.get("drape", False)),
        scatter=scatter_from_flags(values, scatter=values.get("scatter", False)),
        base=Path.cwd(),
    )
