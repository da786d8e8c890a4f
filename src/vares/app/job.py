"""Jobs: the whole patterning task — input, material, fibres, prestress, solver, outputs — as one
value that a TOML file, the command line and the Python API all describe alike.

``vares pattern … --save-job job.toml`` writes the job it ran; ``vares run job.toml`` runs it
again. Each table of the file is one options class (every key, default and bound declared once,
in :mod:`vares.options`); an unknown table or key is an error naming the closest valid one::

    [input]
    mesh = "roof.obj"            # or: meshes = ["a.obj", "b.obj"], example = "sail"
    units = "m"                  # units of the mesh coordinates

    [material]
    fabric = "pes-pvc-type-2"    # a preset, or: law = "orthotropic", E1 = …, E2 = …, …
    thickness = 1.0

    [fibres]
    warp_direction = [1.0, 1.0, 0.0]   # or: warp_angle = 0.0 (pattern frame)

    [prestress]
    warp = 2.0                   # force per length; or: field = "n" / ["n_warp", "n_fill"]
    fill = 1.5

    [solver]
    strategy = "auto"
    tolerance = 1e-10

    [output]
    directory = "roof-pattern"
    report = true
    allowance = 20.0             # seam allowance, DXF units

    [structure]                  # present: the input is a structure of several panels
    match_seams = true

    [erection]                   # present: erect the structure from its patterns afterwards
    wrinkling = true
    pressure = 0.0

    [drape]                      # present: drape a ply kinematically beside the pattern
    seed = [0.0, 0.0, 100.0]     # on the surface; the warp is the pattern's warp direction
    fabric_kind = "woven-twill"  # its locking angle, or: locking_angle = 45.0

    [cut]                        # present: cut the surface into strips of roll width
    roll_width = 2.5             # mesh units
    seams = "geodesic"           # or "planar", or "curves" with curves = "lines.3dm"

    [scatter]                    # present: the fabric file's scatter carried into the patterns
    samples = 16                 # random samples, each patterned (and erected) on its own
    sigmas = 2.0                 # the band: nominal ± sigmas standard deviations

Relative paths are relative to the job file's folder, so a job folder can be moved or shared.
"""

from __future__ import annotations

import difflib
import hashlib
import os
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ..analysis.drape_options import DrapeOptions
from ..analysis.options import ErectionOptions
from ..analysis.scatter_options import ScatterOptions
from ..materials.fabric_file import toml_string
from ..options import Options, OptionsError, Spec, suggest
from ..solver.options import SolveOptions
from ..structures.options import CutOptions, StructureOptions
from .sections import InputOptions, MaterialOptions, OutputOptions, PrestressOptions

__all__ = ["SECTIONS", "Job", "JobError", "load_job"]


class JobError(ValueError):
    """A job file or job setting is not valid; the message names the table and the key."""


#: The options object of a job that holds each table's keys.
SECTIONS: dict[str, str] = {
    "input": "input",
    "material": "material",
    "fibres": "solve",
    "prestress": "prestress",
    "solver": "solve",
    "output": "output",
    "structure": "structure",
    "cut": "cut",
    "erection": "erection",
    "drape": "drape",
    "scatter": "scatter",
}
#: Tables whose presence means something even when empty.
_PRESENCE = ("structure", "cut", "erection", "drape", "scatter")


@dataclass(frozen=True)
class Job:
    """A patterning job: one options object per part; ``structure`` is set for a structure of
    several panels, ``cut`` (and ``structure``) for a surface cut into strips of roll width,
    ``erection`` when the structure is to be erected from its patterns after patterning,
    ``drape`` when a ply is draped kinematically beside the pattern (a single surface),
    ``scatter`` when the scatter of a fabric file is carried into the patterns (a band of
    sampled patterns beside the run's own, :mod:`vares.app.run_band`).
    ``base`` is the folder relative paths are relative to; ``location`` the job file it was
    read from (if any)."""

    input: InputOptions
    material: MaterialOptions = field(default_factory=MaterialOptions)
    solve: SolveOptions = field(default_factory=SolveOptions)
    prestress: PrestressOptions = field(default_factory=PrestressOptions)
    output: OutputOptions = field(default_factory=OutputOptions)
    structure: StructureOptions | None = None
    cut: CutOptions | None = None
    erection: ErectionOptions | None = None
    drape: DrapeOptions | None = None
    scatter: ScatterOptions | None = None
    base: Path = field(default_factory=Path.cwd)
    location: Path | None = None

    @classmethod
    def from_dict(cls, data: dict[str, Any], origin: str = "job", base: Path | None = None) -> Job:
        """A job from parsed TOML, every table and key checked."""
        for section in data:
            if section not in SECTIONS:
                close = difflib.get_close_matches(section, list(SECTIONS), n=1, cutoff=0.6)
                hint = (
                    f" (did you mean [{close[0]}]?)" if close else f"; known: {', '.join(SECTIONS)}"
                )
                raise JobError(f"{origin}: unknown table [{section}]{hint}")
        parts: dict[str, dict[str, Any]] = {}
        for section, values in data.items():
            if not isinstance(values, dict):
                raise JobError(f"{origin}: [{section}] must be a table")
            specs = _PARTS[SECTIONS[section]].specs()
            own = {k for k, s in specs.items() if s.section == section}
            for key in values:
                if key not in own:
                    _unknown(origin, section, key, own)
            parts.setdefault(SECTIONS[section], {}).update(values)
        built = {}
        for part, values in parts.items():
            if part in _PRESENCE or values or part == "input":
                built[part] = _build(_PARTS[part], values, origin)
        if "input" not in built:
            raise JobError(f"{origin}: [input] needs exactly one of mesh, meshes or example")
        if "cut" in built and "structure" not in built:
            built["structure"] = StructureOptions()
        if "cut" in built and built["structure"].roll_width not in (None, built["cut"].roll_width):
            raise JobError(
                f"{origin}: [structure] roll_width differs from [cut] roll_width: a cut job has "
                "one roll width, [cut] roll_width (every strip, allowances included, fits it)"
            )
        return cls(**built, base=base or Path.cwd())

    def to_dict(self, location: Path | None = None) -> dict[str, dict[str, Any]]:
        """Table → keys, with paths relative to the folder of the file at ``location`` (or
        absolute when it is None)."""
        out: dict[str, dict[str, Any]] = {}
        for section, part in SECTIONS.items():
            options = getattr(self, part)
            if options is None:
                continue
            values = options.to_dict(section=section)
            for key, spec in options.specs().items():
                if key in values and spec.kind in ("path", "paths"):
                    values[key] = _relocated(values[key], self.base, location)
            if values or section in _PRESENCE:
                out[section] = values
        return out

    def to_toml(self, location: Path | None = None) -> str:
        """The job as TOML text (see :meth:`to_dict` for the paths)."""
        lines = []
        for section, values in self.to_dict(location).items():
            lines.append(f"[{section}]")
            lines.extend(f"{key} = {_toml_value(value)}" for key, value in values.items())
            lines.append("")
        return "\n".join(lines)

    def path(self, value: str) -> Path:
        """A path of the job, relative to its base folder."""
        path = Path(value)
        return path if path.is_absolute() else self.base / path

    @property
    def directory(self) -> Path:
        """The output directory."""
        return self.path(self.output.directory)

    def with_output(self, directory: str | Path) -> Job:
        """The same job writing into ``directory`` (absolute, or relative to the current folder)."""
        return replace(self, output=self.output.replace(directory=str(Path(directory).resolve())))

    def digest(self) -> str:
        """A fingerprint of everything that determines the job's results."""
        from .._version import __version__

        text = f"{__version__}\n{self.to_toml()}"
        return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


_PARTS: dict[str, type[Options]] = {
    "input": InputOptions,
    "material": MaterialOptions,
    "solve": SolveOptions,
    "prestress": PrestressOptions,
    "output": OutputOptions,
    "structure": StructureOptions,
    "cut": CutOptions,
    "erection": ErectionOptions,
    "drape": DrapeOptions,
    "scatter": ScatterOptions,
}


def _build(cls: type[Options], values: dict[str, Any], origin: str) -> Options:
    try:
        return cls(**values)
    except OptionsError as exc:
        if exc.key is None:
            section = next(iter(cls.specs().values())).section
            raise JobError(f"{origin}: [{section}] {exc.problem}") from None
        section = cls.specs()[exc.key].section
        raise JobError(f"{origin}: [{section}] {exc.key} {exc.problem}") from None


def _unknown(origin: str, section: str, key: str, own: set[str]) -> None:
    others = [s for s in SECTIONS if s != section and key in _specs_of(s)]
    if others:
        hint = f"; it belongs in [{others[0]}]"
    else:
        hint = suggest(key, sorted(own)) or f"; known: {', '.join(sorted(own))}"
    raise JobError(f"{origin}: [{section}] unknown key {key!r}{hint}")


def _specs_of(section: str) -> dict[str, Spec]:
    specs = _PARTS[SECTIONS[section]].specs()
    return {k: s for k, s in specs.items() if s.section == section}


def _relocated(value: str | list[str], base: Path, location: Path | None) -> str | list[str]:
    if isinstance(value, list):
        return [_relocated(v, base, location) for v in value]
    path = Path(value) if Path(value).is_absolute() else base / value
    if location is None:
        return str(path.resolve())
    return os.path.relpath(path.resolve(), Path(location).resolve().parent)


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(float(value)) if isinstance(value, float) else str(value)
    if isinstance(value, str | Path):
        return _toml_string(str(value))
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise JobError(f"cannot write {value!r} to a job file")


def _toml_string(text: str) -> str:
    """``text`` as an escaped TOML basic string (:func:`~vares.materials.fabric_file.toml_string`)
    in a job file."""
    try:
        return toml_string(text)
    except ValueError:
        raise JobError(f"cannot write {text!r} to a job file: it is not valid Unicode") from None


def read_job_file(path: str | Path) -> dict[str, Any]:
    """The tables of a job file (TOML), with one-line errors for a missing or unreadable one."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise JobError(f"{path}: not valid TOML: {exc}") from exc


def load_job(path: str | Path) -> Job:
    """Read and check a job file."""
    path = Path(path)
    job = Job.from_dict(read_job_file(path), str(path), path.parent.resolve())
    return replace(job, location=path.resolve())
