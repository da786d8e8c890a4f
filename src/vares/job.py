"""Jobs: the whole patterning task — input, material, fibres, prestress, solver, outputs.

A job is what ``vares pattern`` and ``vares example`` do, written down so it can be rerun:
``vares run job.toml``. ``vares pattern … --save-job job.toml`` writes the job it ran. Every key
is checked; an unknown key or a value of the wrong kind is an error that names it::

    [input]
    mesh = "roof.obj"            # or: example = "sail" (see `vares example --help`)
    units = "m"                  # units of the mesh coordinates
    name = "roof"                # panel name in the drawings (default: the file's stem)

    [material]
    fabric = "pes-pvc-type-2"    # a preset, or: law = "orthotropic", E1 = …, E2 = …, …
    thickness = 1.0

    [fibres]
    warp_direction = [1.0, 1.0, 0.0]   # or: warp_angle = 0.0 (pattern frame)
    orientation = "held"

    [prestress]
    warp = 2.0                   # force per length; or: field = "n" / ["n_warp", "n_fill"]
    fill = 1.5
    slack_threshold = 0.0

    [solver]
    strategy = "auto"
    tolerance = 1e-10

    [output]
    directory = "roof-pattern"
    report = true
    dxf_units = "mm"
    allowance = 20.0             # seam allowance, DXF units
    mark_spacing = 500.0         # match marks, DXF units
    plots = ["det_F", "warp_stress"]   # also pattern_FIELD.svg/.png and surface_FIELD.png

Relative paths are relative to the job file.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["SCHEMA", "Job", "JobError", "load_job"]


class JobError(ValueError):
    """A job file or job setting is not valid; the message names the key."""


_NUMBER = (int, float)
_LAW_PARAMETERS = {
    "E": _NUMBER,
    "nu": _NUMBER,
    "mu": _NUMBER,
    "E1": _NUMBER,
    "E2": _NUMBER,
    "G12": _NUMBER,
    "nu12": _NUMBER,
    "A": list,
    "B": list,
    "C": list,
}

#: Section → key → accepted type(s).
SCHEMA: dict[str, dict[str, Any]] = {
    "input": {"mesh": str, "example": str, "cell_type": str, "units": str, "name": str},
    "material": {
        "law": str,
        "fabric": str,
        "presets": str,
        "thickness": _NUMBER,
        **_LAW_PARAMETERS,
    },
    "fibres": {
        "warp_angle": _NUMBER,
        "fill_angle": _NUMBER,
        "warp_direction": list,
        "orientation": str,
    },
    "prestress": {
        "warp": _NUMBER,
        "fill": _NUMBER,
        "shear": _NUMBER,
        "field": (str, list),
        "slack_threshold": _NUMBER,
    },
    "solver": {
        "strategy": str,
        "steps": int,
        "plane": (str, list),
        "initial_guess": str,
        "tolerance": _NUMBER,
        "max_iterations": int,
        "linear_solver": str,
    },
    "output": {
        "directory": str,
        "report": bool,
        "dxf_units": str,
        "allowance": _NUMBER,
        "mark_spacing": _NUMBER,
        "plots": list,
    },
}


@dataclass
class Job:
    """A patterning job: one dictionary per section of :data:`SCHEMA`."""

    input: dict[str, Any] = field(default_factory=dict)
    material: dict[str, Any] = field(default_factory=dict)
    fibres: dict[str, Any] = field(default_factory=dict)
    prestress: dict[str, Any] = field(default_factory=dict)
    solver: dict[str, Any] = field(default_factory=dict)
    output: dict[str, Any] = field(default_factory=dict)
    base: Path = field(default_factory=Path)

    @classmethod
    def from_dict(cls, data: dict[str, Any], origin: str = "job", base: Path | None = None) -> Job:
        """A job from parsed TOML, every key checked against :data:`SCHEMA`."""
        unknown = sorted(set(data) - set(SCHEMA))
        if unknown:
            raise JobError(f"{origin}: unknown section [{unknown[0]}] (known: {', '.join(SCHEMA)})")
        sections = {}
        for section, keys in SCHEMA.items():
            values = data.get(section, {})
            if not isinstance(values, dict):
                raise JobError(f"{origin}: [{section}] must be a table")
            for key, value in values.items():
                if key not in keys:
                    raise JobError(
                        f"{origin}: [{section}] unknown key {key!r} (known: {', '.join(keys)})"
                    )
                expected = keys[key]
                if isinstance(value, bool) and expected is not bool:
                    raise JobError(f"{origin}: [{section}] {key} must not be true/false")
                if not isinstance(value, expected):
                    kind = {
                        str: "a string",
                        int: "an integer",
                        bool: "true or false",
                        list: "a list",
                    }.get(expected, "a number")
                    raise JobError(f"{origin}: [{section}] {key} must be {kind}; got {value!r}")
            sections[section] = dict(values)
        job = cls(**sections, base=base or Path.cwd())
        job.check(origin)
        return job

    def check(self, origin: str = "job") -> None:
        """Cross-key rules (one input, one material definition, one prestress)."""
        if ("mesh" in self.input) == ("example" in self.input):
            raise JobError(f"{origin}: [input] needs exactly one of mesh or example")
        has_law, has_fabric = "law" in self.material, "fabric" in self.material
        if has_law and has_fabric:
            raise JobError(f"{origin}: [material] give law or fabric, not both")
        if has_fabric and set(self.material) & set(_LAW_PARAMETERS):
            raise JobError(f"{origin}: [material] a fabric preset takes no law parameters")
        if "presets" in self.material and not has_fabric:
            raise JobError(f"{origin}: [material] presets needs fabric")
        if "field" in self.prestress and set(self.prestress) & {"warp", "fill", "shear"}:
            raise JobError(f"{origin}: [prestress] give warp/fill or field, not both")
        if ("warp" in self.prestress) != ("fill" in self.prestress):
            raise JobError(f"{origin}: [prestress] needs both warp and fill")
        from .analysis import FIELD_DESCRIPTIONS

        unknown = [f for f in self.output.get("plots", []) if f not in FIELD_DESCRIPTIONS]
        if unknown:
            raise JobError(
                f"{origin}: [output] plots: unknown field {unknown[0]!r} (fields: "
                f"{', '.join(FIELD_DESCRIPTIONS)})"
            )

    def path(self, value: str) -> Path:
        """A path from the job, relative to the job file's folder."""
        path = Path(value)
        return path if path.is_absolute() else self.base / path

    def to_toml(self) -> str:
        """The job as TOML text (readable by :func:`load_job`)."""
        lines = []
        for section in SCHEMA:
            values = getattr(self, section)
            if not values:
                continue
            lines.append(f"[{section}]")
            lines.extend(f"{key} = {_toml_value(value)}" for key, value in values.items())
            lines.append("")
        return "\n".join(lines)


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(float(value)) if isinstance(value, float) else str(value)
    if isinstance(value, str | Path):
        text = str(value).replace("\\", "\\\\").replace('"', '\\"')
        return f'"{text}"'
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise JobError(f"cannot write {value!r} to a job file")


def load_job(path: str | Path) -> Job:
    """Read and check a job file."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise JobError(f"{path}: not valid TOML: {exc}") from exc
    return Job.from_dict(data, str(path), path.parent.resolve())
