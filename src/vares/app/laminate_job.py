"""Laminate jobs: a mould, its plies and what is written, as one TOML file (``vares laminate``).

A laminate job is a job file (:mod:`vares.app.job`: ``[input]``, ``[material]``, ``[solver]``,
``[output]``) with a ``[laminate]`` table
(:class:`~vares.structures.laminate_options.LaminateOptions`), one ``[[ply]]`` table per ply,
bottom first (:class:`~vares.structures.laminate_options.PlyOptions`), and optional named
materials::

    [input]
    mesh = "mould.obj"

    [material]                  # every ply's material unless it names its own
    law = "ncf"
    A = [-250.0, 250.0]
    B = [-250.0, 250.0]
    C = [0.5]

    [materials.glass]           # a named material: a [material] table of its own
    fabric = "glass-ptfe"

    [laminate]
    reference = [1.0, 0.0, 0.0] # the 0° direction on the mould
    compression_strain = 1e-3

    [[ply]]
    name = "P1"
    orientation = 0.0
    [[ply]]
    name = "P2"
    orientation = 45.0
    seed = [0.0, 0.0, 2.5]
    region = "zone"             # a cell field of the mould; region_value = 2 picks one value
    drop_off = 1
    darts = "auto"              # or dart_lines = "darts.txt"; default: the laminate's darts
    [[ply]]
    name = "P3"
    splice_lines = "splices.txt"  # the ply cut into pieces along these lines (no darts then)

Every table and key is checked against its options class; an unknown one is an error naming the
closest valid spelling. ``[fibres] warp_direction`` is refused (each ply's orientation sets it),
as are the tables and keys a laminate job does not use (``[prestress]``, ``[output] report``, …).
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from ..options import Options, OptionsError, suggest
from ..structures.laminate import Ply
from ..structures.laminate_options import LaminateOptions, PlyOptions
from .job import SECTIONS, Job, JobError, read_job_file
from .sections import MaterialOptions

__all__ = ["LAMINATE_TABLES", "LaminateJob", "load_laminate_job"]

#: The tables a laminate job adds to those of a job.
LAMINATE_TABLES = ("laminate", "ply", "materials")
#: Tables of a job that a laminate job does not take.
_REFUSED = ("structure", "cut", "erection", "drape", "prestress")
#: Keys of a job's tables that a laminate job does not use.
_UNUSED = {
    "input": ("initial_pattern", "name", "panel_field"),
    "output": (
        "report",
        "dxf_units",
        "allowance",
        "mark_spacing",
        "allow_overlap",
        "previews",
        "plots",
    ),
}


@dataclass(frozen=True)
class LaminateJob:
    """A laminate job: the :class:`Job` of the mould (input, material, solver, output), the
    :class:`LaminateOptions`, the plies' :class:`PlyOptions` (bottom first) and the named
    materials."""

    job: Job
    laminate: LaminateOptions = field(default_factory=LaminateOptions)
    plies: tuple[PlyOptions, ...] = ()
    materials: dict[str, MaterialOptions] = field(default_factory=dict)

    @classmethod
    def from_dict(
        cls, data: dict[str, Any], origin: str = "laminate job", base: Path | None = None
    ) -> LaminateJob:
        """A laminate job from parsed TOML, every table and key checked."""
        known = (*SECTIONS, *LAMINATE_TABLES)
        for section in data:
            if section not in known:
                close = difflib.get_close_matches(section, list(known), n=1, cutoff=0.6)
                hint = f" (did you mean [{close[0]}]?)" if close else f"; known: {', '.join(known)}"
                raise JobError(f"{origin}: unknown table [{section}]{hint}")
            if section in _REFUSED:
                raise JobError(f"{origin}: [{section}] is not for a laminate job")
        for section, keys in _UNUSED.items():
            values = data.get(section)
            used = [k for k in keys if isinstance(values, dict) and k in values]
            if used:
                raise JobError(f"{origin}: [{section}] {used[0]} is not used by a laminate job")
        rest = {k: v for k, v in data.items() if k not in LAMINATE_TABLES}
        job = Job.from_dict(rest, origin, base)
        if job.solve.warp_direction is not None:
            raise JobError(
                f"{origin}: [fibres] warp_direction is set by each ply's orientation: remove it"
            )
        laminate = _table(LaminateOptions, data.get("laminate", {}), origin, "[laminate]")
        plies_data = data.get("ply")
        if not plies_data:
            raise JobError(f"{origin}: a laminate job needs [[ply]] tables, one per ply")
        if not isinstance(plies_data, list):
            raise JobError(f"{origin}: plies are [[ply]] tables (an array of tables)")
        plies = tuple(
            _table(PlyOptions, values, origin, f"[[ply]] {index}")
            for index, values in enumerate(plies_data, start=1)
        )
        materials_data = data.get("materials", {})
        if not isinstance(materials_data, dict):
            raise JobError(f"{origin}: [materials] holds [materials.NAME] tables")
        materials = {
            name: _table(MaterialOptions, values, origin, f"[materials.{name}]")
            for name, values in materials_data.items()
        }
        for index, ply in enumerate(plies, start=1):
            if ply.material is not None and ply.material not in materials:
                hint = suggest(ply.material, list(materials)) or (
                    f"; the job has: {', '.join(materials) or 'none'}"
                )
                raise JobError(
                    f"{origin}: [[ply]] {index} material {ply.material!r} names no "
                    f"[materials.NAME] table{hint}"
                )
        return cls(job, laminate, plies, materials)

    def build_plies(self) -> list[Ply]:
        """The plies with their materials (built once per distinct material)."""
        base = self.job.base
        default = self.job.material.build(base)
        named = {name: options.build(base) for name, options in self.materials.items()}
        fabrics: dict[str, Any] = {}
        plies = []
        for options in self.plies:
            if options.fabric is not None:
                if options.fabric not in fabrics:
                    fabrics[options.fabric] = MaterialOptions(fabric=options.fabric).build(base)
                material = fabrics[options.fabric]
            elif options.material is not None:
                material = named[options.material]
            else:
                material = default
            lines = {
                key: self._curves(options.name, key, getattr(options, key))
                for key in ("dart_lines", "splice_lines")
            }
            plies.append(Ply(options, material, lines["dart_lines"], lines["splice_lines"]))
        return plies

    def _curves(self, ply: str, key: str, file: str | None) -> tuple[np.ndarray, ...] | None:
        """The lines of a ply's curves file ``file`` (its ``key``), or None without one."""
        if file is None:
            return None
        from ..io.curves import read_curves

        try:
            return tuple(read_curves(self.job.path(file)))
        except (OSError, ValueError) as exc:
            raise JobError(f"[[ply]] {ply} {key}: {exc}") from None

    def with_output(self, directory: str | Path) -> LaminateJob:
        """The same job writing into ``directory``."""
        return replace(self, job=self.job.with_output(directory))

    @property
    def directory(self) -> Path:
        return self.job.directory


def _table(cls: type[Options], values: Any, origin: str, where: str) -> Any:
    if not isinstance(values, dict):
        raise JobError(f"{origin}: {where} must be a table")
    specs = cls.specs()
    for key in values:
        if key not in specs:
            hint = suggest(key, list(specs)) or f"; known: {', '.join(specs)}"
            raise JobError(f"{origin}: {where} unknown key {key!r}{hint}")
    try:
        return cls(**values)
    except OptionsError as exc:
        key = f" {exc.key}" if exc.key else ""
        raise JobError(f"{origin}: {where}{key} {exc.problem}") from None


def load_laminate_job(path: str | Path) -> LaminateJob:
    """Read and check a laminate job file (relative paths are relative to its folder)."""
    path = Path(path)
    job = LaminateJob.from_dict(read_job_file(path), str(path), path.parent.resolve())
    return replace(job, job=replace(job.job, location=path.resolve()))
