"""The options of a job that are not the solver's: input, material, prestress and outputs.

Each is declared once (see :mod:`vares.options`); with :class:`vares.solver.SolveOptions` (the
``[fibres]`` and ``[solver]`` tables) and :class:`vares.structures.StructureOptions` they make up
a job file and the command line's flags.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..geometry.examples import CUT_EXAMPLES, EXAMPLES, STRUCTURE_EXAMPLES
from ..materials import LAWS, Hyperelastic, fabric, make_material
from ..materials.presets import file_fabric
from ..mechanics.fields import FIELD_DESCRIPTIONS
from ..options import Options, OptionsError, option
from ..units import METRES

__all__ = ["InputOptions", "MaterialOptions", "OutputOptions", "PrestressOptions"]


@dataclass(frozen=True)
class InputOptions(Options):
    """Where the surface comes from: one mesh file, one file per panel, or a shipped example."""

    title = "input option"

    mesh: str | None = option(
        None,
        "path",
        "Surface mesh file (OBJ, STL, PLY, VTU, Gmsh, Rhino 3dm …).",
        section="input",
        flags=(),
    )
    meshes: tuple[str, ...] | None = option(
        None, "paths", "One mesh file per panel of a structure.", section="input", flags=()
    )
    example: str | None = option(
        None,
        "str",
        "A shipped example surface (or structure) instead of a file.",
        section="input",
        choices=(*EXAMPLES, *STRUCTURE_EXAMPLES, *CUT_EXAMPLES),
        flags=(),
    )
    cell_type: str = option(
        "triangle",
        "str",
        "Cells of an example's mesh.",
        section="input",
        choices=("triangle", "quad"),
    )
    units: str | None = option(
        None,
        "str",
        "Units of the mesh coordinates (default: those the file declares, as a Rhino model "
        "does; else m).",
        section="input",
        choices=tuple(METRES),
    )
    repair: bool = option(
        True,
        "bool",
        "Repair clear defects of the mesh (weld coincident nodes, drop collapsed and duplicate "
        "cells, orient cells consistently); every change is reported.",
        section="input",
        flags=("--repair/--no-repair",),
    )
    initial_pattern: str | None = option(
        None,
        "path",
        "A pattern file (same nodes and faces, e.g. an earlier pattern.obj) to start from.",
        section="input",
    )
    name: str | None = option(
        None,
        "str",
        "Panel name for drawings and report (default: the file's stem).",
        section="input",
    )
    panel_field: str = option(
        "panel",
        "str",
        "Cell data holding a panel id per cell (a structure from one mesh file).",
        section="input",
    )

    def check(self) -> None:
        given = [k for k in ("mesh", "meshes", "example") if getattr(self, k) is not None]
        if len(given) != 1:
            raise OptionsError(None, "[input] needs exactly one of mesh, meshes or example")

    @property
    def paths(self) -> tuple[str, ...]:
        """The input files (none for an example)."""
        return self.meshes or ((self.mesh,) if self.mesh is not None else ())


#: The law of a job that names none, and the parameters a law takes by default.
DEFAULT_LAW = "neo-hooke"
LAW_DEFAULTS = {
    "neo-hooke": {"E": 1000.0, "nu": 0.3},
    "st-venant-kirchhoff": {"E": 1000.0, "nu": 0.3},
}
_LAW_PARAMETERS = ("E", "nu", "mu", "E1", "E2", "G12", "nu12", "A", "B", "C")


def _parameter(help: str, kind: str = "float", **extra) -> object:
    return option(None, kind, help, section="material", **extra)


@dataclass(frozen=True)
class MaterialOptions(Options):
    """The material: a law and its parameters, or a fabric preset; and the thickness."""

    title = "material option"

    law: str | None = option(
        None,
        "str",
        f"Hyperelastic law (default {DEFAULT_LAW}).",
        section="material",
        choices=tuple(LAWS),
        flags=("--material", "-m"),
    )
    fabric: str | None = option(
        None,
        "str",
        "Fabric preset (see 'vares fabrics'), or a fabric file (.toml, e.g. from 'vares fabric "
        "fit'); replaces the law.",
        section="material",
    )
    presets: str | None = option(
        None, "path", "TOML file with your own fabric presets.", section="material"
    )
    compensate_by: str | None = option(
        None,
        "str",
        "A fabric from biaxial tests compensates the pattern by its 'measured' compensation "
        "values or by its fitted 'law' (default: the fabric file's choice).",
        section="material",
        choices=("measured", "law"),
    )
    thickness: float = option(
        1.0,
        "float",
        "Thickness; 1 for laws given as force per length.",
        section="material",
        positive=True,
        flags=("--thickness", "-t"),
    )
    E: float | None = _parameter(
        "Young's modulus (neo-hooke, st-venant-kirchhoff; "
        f"default {LAW_DEFAULTS[DEFAULT_LAW]['E']:g}).",
        flags=("--E", "-E"),
    )
    nu: float | None = _parameter(
        f"Poisson's ratio, -1 < nu <= 0.5 (default {LAW_DEFAULTS[DEFAULT_LAW]['nu']:g})."
    )
    mu: float | None = _parameter("Shear modulus (incompressible-neo-hooke).")
    E1: float | None = _parameter("Warp modulus (orthotropic).")
    E2: float | None = _parameter("Fill modulus (orthotropic).")
    G12: float | None = _parameter("In-plane shear modulus (orthotropic).")
    nu12: float | None = _parameter("Poisson's ratio warp → fill (orthotropic).")
    A: tuple[float, ...] | None = _parameter("NCF warp coefficients 'A0,A1,…' (sum 0).", "floats")
    B: tuple[float, ...] | None = _parameter("NCF fill coefficients 'B0,B1,…' (sum 0).", "floats")
    C: tuple[float, ...] | None = _parameter("NCF shear coefficients 'C1,C2,…'.", "floats")

    def check(self) -> None:
        parameters = [k for k in _LAW_PARAMETERS if getattr(self, k) is not None]
        if self.fabric is not None and self.fabric.endswith(".toml"):
            if self.presets is not None:
                raise OptionsError(None, "give a fabric file or presets, not both")
            # a fabric file is a presets file of one fabric: kept as a path of the job
            object.__setattr__(self, "presets", self.fabric)
            object.__setattr__(self, "fabric", None)
        named = self.fabric is not None or self.presets is not None
        if named and (self.law is not None or parameters):
            raise OptionsError(None, "a fabric preset sets the material: give no law or parameters")
        if self.compensate_by is not None and not named:
            raise OptionsError(None, "compensate_by needs a fabric")

    def build(self, base: Path) -> Hyperelastic:
        """The material (``base``: the folder a relative presets path is relative to)."""
        if self.fabric is not None or self.presets is not None:
            presets = None if self.presets is None else base / self.presets
            if self.fabric is None:
                return file_fabric(presets).material(self.compensate_by)
            return fabric(self.fabric, presets).material(self.compensate_by)
        law = self.law or DEFAULT_LAW
        given = {k: getattr(self, k) for k in _LAW_PARAMETERS if getattr(self, k) is not None}
        parameters = LAW_DEFAULTS.get(law, {}) | {
            k: list(v) if isinstance(v, tuple) else v for k, v in given.items()
        }
        return make_material(law, parameters)


@dataclass(frozen=True)
class PrestressOptions(Options):
    """The intended prestress along the yarns (force per length), uniform or from cell data."""

    title = "prestress option"

    warp: float | None = option(None, "float", "Warp prestress.", section="prestress", flags=())
    fill: float | None = option(None, "float", "Fill prestress.", section="prestress", flags=())
    shear: float | None = option(None, "float", "Shear prestress.", section="prestress", flags=())
    field: tuple[str, ...] | None = option(
        None,
        "strings",
        "Per-cell prestress from the input's cell data: one array (columns warp, fill[, shear]) "
        "or one array per component.",
        section="prestress",
        flags=(),
    )
    slack_threshold: float = option(
        0.0,
        "float",
        "Report cells whose achieved yarn force is below this (force/length).",
        section="prestress",
    )

    def check(self) -> None:
        uniform = [k for k in ("warp", "fill", "shear") if getattr(self, k) is not None]
        if self.field is not None and uniform:
            raise OptionsError(None, "give warp/fill or field, not both")
        if (self.warp is None) != (self.fill is None):
            raise OptionsError(None, "needs both warp and fill")
        if self.shear is not None and self.warp is None:
            raise OptionsError(None, "shear needs warp and fill")
        if self.field is not None and not 1 <= len(self.field) <= 3:
            raise OptionsError("field", "takes one to three cell data names")

    @property
    def given(self) -> bool:
        return self.warp is not None or self.field is not None

    def value(self, cell_data: dict[str, np.ndarray]) -> np.ndarray | list[float] | None:
        """The prestress for :func:`vares.solve`: ``[warp, fill, shear]`` or one row per cell."""
        if self.warp is not None:
            return [self.warp, self.fill, self.shear or 0.0]
        if self.field is None:
            return None
        missing = [n for n in self.field if n not in cell_data]
        if missing:
            known = ", ".join(cell_data) or "none"
            raise OptionsError(
                "field", f"names no cell data {', '.join(missing)!r} of the input (it has: {known})"
            )
        if len(self.field) == 1:
            return cell_data[self.field[0]]
        return np.column_stack([np.asarray(cell_data[n], dtype=float).ravel() for n in self.field])


#: Match mark spacing of a structure's seams when none is given (DXF units).
STRUCTURE_MARK_SPACING = 500.0

#: The most match marks a run draws along its surfaces' boundaries: a spacing that would draw
#: more is a slip of a digit or of units (marks closer than a pencil line), refused before the
#: solve (``vares.app.outputs.check_mark_spacing``).
MAX_MARKS = 100_000


@dataclass(frozen=True)
class OutputOptions(Options):
    """What is written, and where."""

    title = "output option"

    directory: str = option(
        "vares-out", "path", "Output directory.", section="output", flags=("--output", "-o")
    )
    report: bool = option(
        False, "bool", "Also write report.html.", section="output", flags=("--report",)
    )
    dxf_units: str = option(
        "mm", "str", "Units of the DXF drawing.", section="output", choices=tuple(METRES)
    )
    allowance: float = option(
        0.0,
        "float",
        "Seam allowance for the DXF cut line (DXF units).",
        section="output",
        minimum=0,
    )
    mark_spacing: float | None = option(
        None,
        "float",
        "Match mark spacing along the seam line (DXF units); a structure's seams get marks every "
        f"{STRUCTURE_MARK_SPACING:g} unless given. At most {MAX_MARKS} marks fit along the "
        "surface's boundary.",
        section="output",
        positive=True,
    )
    allow_overlap: bool = option(
        False,
        "bool",
        "Write the DXF even of a pattern that overlaps itself or whose area is far from the "
        "surface's (it is then no cut file: the crossings are circled in the drawings).",
        section="output",
        flags=("--allow-overlap",),
    )
    previews: bool = option(
        True,
        "bool",
        "Write pattern.svg and pattern.png, pictures of the pattern with its warp and fill.",
        section="output",
        flags=("--previews/--no-previews",),
    )
    plots: tuple[str, ...] = option(
        (),
        "strings",
        "Fields to draw as pattern_FIELD.svg/.png and surface_FIELD.png, e.g. "
        "'det_F,warp_stress,shear_angle'.",
        section="output",
        choices=tuple(FIELD_DESCRIPTIONS),
        flags=("--plot",),
    )
