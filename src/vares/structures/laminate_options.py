"""The options of a laminate and of each of its plies, declared once (see :mod:`vares.options`):
the ``[laminate]`` table and the ``[[ply]]`` tables of a laminate job, and the keywords of
:func:`vares.structures.laminate.drape_laminate` and :class:`vares.structures.laminate.Ply`.
The darts, the locking angle and the blank's allowances are those of a single ply's drape
(:class:`~vares.analysis.dart_options.DartOptions`,
:class:`~vares.analysis.drape_options.DrapeOptions`,
:class:`~vares.structures.blank_options.BlankOptions`), taken over with
:func:`vares.options.reused`."""

from __future__ import annotations

from dataclasses import dataclass

from ..analysis.dart_options import DartOptions
from ..analysis.drape_options import DrapeOptions
from ..materials.forming import FABRIC_KINDS
from ..options import Options, OptionsError, option, reused
from .blank_options import BlankOptions

__all__ = ["LaminateOptions", "PlyOptions"]


@dataclass(frozen=True)
class LaminateOptions(Options):
    """What the plies of a laminate share: the reference direction on the mould, the default
    seed, the kinematic net's spacing, the ply-stack check's threshold, the darts and where the
    plies are draped (local workers or a Dask scheduler)."""

    title = "laminate option"

    reference: tuple[float, float, float] = option(
        (1.0, 0.0, 0.0),
        "vector",
        "Reference direction 'x,y,z' on the mould: a ply's orientation is measured from it "
        "(projected onto the mould at the seed), counter-clockwise about the surface normal.",
        section="laminate",
    )
    seed: tuple[float, float, float] | None = option(
        None,
        "vector",
        "Seed point 'x,y,z' of every ply that names none (default: the mould's node nearest the "
        "nodes' centroid).",
        section="laminate",
    )
    spacing: float | None = option(
        None,
        "float",
        "Yarn spacing of the kinematic net, mesh length units (default: half the mean edge "
        "length).",
        section="laminate",
        positive=True,
    )
    fabric_kind: str = option(
        "ncf-biaxial",
        "str",
        "Fabric kind of every ply that names none: its typical locking angle (docs/composites.md).",
        section="laminate",
        choices=tuple(FABRIC_KINDS),
    )
    kinematic: bool = option(
        True,
        "bool",
        "Drape every ply kinematically (pin-jointed net) beside the mechanical pattern.",
        section="laminate",
        flags=("--kinematic/--no-kinematic",),
    )
    fe_directions: str = option(
        "mechanical",
        "str",
        "The yarn directions written for FE (orientations.inp, orientations.csv): those of the "
        "mechanical drape, or of the kinematic net (only the cells it reaches).",
        section="laminate",
        choices=("mechanical", "kinematic"),
    )
    compression_strain: float = option(
        1e-3,
        "float",
        "Ply-stack check: a yarn shortened by more than this strain (1e-3 = 0.1 %) counts as "
        "compressed.",
        section="laminate",
        positive=True,
    )
    workers: int | None = option(
        None,
        "int",
        "Processes that drape the plies at once, at most one per distinct ply (default: one per "
        "core for a mould of at least 4000 cells, else 1: in this process).",
        section="laminate",
        positive=True,
    )
    scheduler: str | None = option(
        None,
        "str",
        "Address of a Dask distributed scheduler (tcp://host:port): the plies are draped as "
        "tasks on its workers instead of local processes.",
        section="laminate",
    )
    darts: str = reused(
        DartOptions,
        "darts",
        section="laminate",
        help="Darts in every ply that names none: 'auto' places them where a ply's shear reaches "
        "its locking angle and solves the ply again with them open (docs/composites.md, Darts).",
    )
    splices: str = reused(
        DartOptions,
        "splices",
        section="laminate",
        help="Splices in every ply that names no darts or splices of its own: 'auto' cuts a ply "
        "through its seed where its shear reaches its locking angle, along the warp or the "
        "fill (docs/composites.md, Splices placed through the seed).",
    )
    locking_angle: float | None = reused(
        DrapeOptions,
        "locking_angle",
        section="laminate",
        help="Locking angle in degrees, at most 90, of every ply that names none (default: the "
        "fabric kind's): producibility and darts.",
    )

    areal_weight: float | None = option(
        None,
        "float",
        "Areal weight of the dry fabric, g/m², of every ply that names none: the ply book's "
        "masses (of the flat blank; none when not given).",
        section="laminate",
        positive=True,
    )
    ply_thickness: float | None = option(
        None,
        "float",
        "Cured thickness of every ply that names none, mm: the ply book's stacking sequence.",
        section="laminate",
        positive=True,
    )
    trim_allowance: float = reused(
        BlankOptions,
        "trim_allowance",
        section="laminate",
        help="Excess round each ply's net boundary along the mould's edge, mesh length units: "
        "the extended (trim) boundary of the cutter files and the outline nested on the roll.",
    )
    splice_overlap: float = reused(
        BlankOptions,
        "splice_overlap",
        section="laminate",
        help="Overlap at the splices of every ply that names none, mesh length units: each "
        "piece after the first laps over the pieces before it by this much (its edge along "
        "those splices moved out); 0: butt splices, every piece cut to the splice line.",
    )
    dart_overlap: float = reused(
        BlankOptions,
        "dart_overlap",
        section="laminate",
        help="Overlap at the darts of every ply that names none, mesh length units: a dart's "
        "left lip (as the dart runs in from its mouth) laps over the right one by this much "
        "when it closes; 0: the lips butt, both cut to the dart line.",
    )
    roll_width: float | None = option(
        None,
        "float",
        "Width of the fabric roll, mesh length units: every ply is nested on it with its warp "
        "along the roll (default: no nest).",
        section="laminate",
        positive=True,
    )
    nest_time: float = option(
        10.0,
        "float",
        "Bound on the time for nesting the plies on the roll (seconds); a search that ends "
        "by itself within it gives the same nest for the same plies.",
        section="laminate",
        positive=True,
    )

    def check(self) -> None:
        if self.fe_directions == "kinematic" and not self.kinematic:
            raise OptionsError("fe_directions", "'kinematic' needs kinematic = true")
        if self.scheduler is not None and self.workers is not None:
            raise OptionsError(None, "give workers or a scheduler, not both")
        if self.locking_angle is not None and self.locking_angle > 90.0:
            raise OptionsError(
                "locking_angle", f"must be at most 90 degrees; got {self.locking_angle}"
            )
        if self.darts == "auto" and self.splices == "auto":
            raise OptionsError(None, "give the laminate darts = 'auto' or splices = 'auto'")


@dataclass(frozen=True)
class PlyOptions(Options):
    """One ply of a laminate: its name, fabric, orientation, seed, region, drop-off order,
    darts and splices."""

    title = "ply option"

    name: str = option(None, "str", "The ply's name (unique in the laminate).", section="ply")
    orientation: float = option(
        0.0,
        "float",
        "Warp angle in degrees from the laminate's reference direction, counter-clockwise about "
        "the mould's normal at the seed.",
        section="ply",
    )
    fabric: str | None = option(
        None,
        "str",
        "Fabric preset or fabric file (.toml) of the ply (default: the job's [material]).",
        section="ply",
    )
    material: str | None = option(
        None,
        "str",
        "Name of a [materials.NAME] table of the job that holds the ply's material.",
        section="ply",
    )
    fabric_kind: str | None = option(
        None,
        "str",
        "Fabric kind for the locking angle (default: the laminate's).",
        section="ply",
        choices=tuple(FABRIC_KINDS),
    )
    seed: tuple[float, float, float] | None = option(
        None,
        "vector",
        "Seed point 'x,y,z' (default: the laminate's; for a ply with a region, the region's node "
        "nearest the laminate's seed, or without one the region's node nearest its nodes' "
        "centroid).",
        section="ply",
    )
    region: str | None = option(
        None,
        "str",
        "Cell field of the mould that marks the ply's cells (default: the whole mould).",
        section="ply",
    )
    region_value: float | None = option(
        None,
        "float",
        "The value of the region field on the ply's cells (default: every non-zero value).",
        section="ply",
    )
    drop_off: int | None = option(
        None,
        "int",
        "Drop-off order: 1 for the ply that ends first, 2 the next, … (default: runs over the "
        "whole part).",
        section="ply",
        positive=True,
    )

    areal_weight: float | None = option(
        None,
        "float",
        "Areal weight of the ply's dry fabric, g/m² (default: the laminate's).",
        section="ply",
        positive=True,
    )
    thickness: float | None = option(
        None,
        "float",
        "Cured thickness of the ply, mm (default: the laminate's ply_thickness).",
        section="ply",
        positive=True,
    )

    darts: str | None = reused(
        DartOptions,
        "darts",
        section="ply",
        default=None,
        help="Darts in this ply: 'auto' or 'none' (default: the laminate's).",
    )
    splices: str | None = reused(
        DartOptions,
        "splices",
        section="ply",
        default=None,
        help="Splices in this ply: 'auto' (through its seed where it reaches its locking angle) "
        "or 'none' (default: the laminate's).",
    )
    dart_lines: str | None = reused(
        DartOptions,
        "dart_lines",
        section="ply",
        help="Dart lines of the ply's own: a curves file (points 'x y z', a blank line between two "
        "lines, or a 3dm file), each from the ply's boundary into it; opened as they are.",
    )
    splice_lines: str | None = reused(
        DartOptions,
        "splice_lines",
        section="ply",
        help="Splice lines of the ply: a curves file (as dart_lines), each from the ply's boundary "
        "across it to the boundary; the ply is cut into pieces along them, each draped, cut and "
        "nested on its own (where darts cannot relieve the shear: negatively curved moulds).",
    )
    splice_overlap: float | None = reused(
        BlankOptions,
        "splice_overlap",
        section="ply",
        default=None,
        help="Overlap at the ply's splices, mesh length units: each piece after the first laps "
        "over the pieces before it by this much; 0: butt splices (default: the laminate's).",
    )
    dart_overlap: float | None = reused(
        BlankOptions,
        "dart_overlap",
        section="ply",
        default=None,
        help="Overlap at the ply's darts, mesh length units: the left lip laps over the right one "
        "by this much; 0: the lips butt (default: the laminate's).",
    )
    locking_angle: float | None = reused(
        DrapeOptions,
        "locking_angle",
        section="ply",
        help="Locking angle of the ply in degrees, at most 90 (default: the laminate's, else its "
        "fabric kind's).",
    )

    def check(self) -> None:
        if not self.name:
            raise OptionsError("name", "must be a non-empty string")
        if self.fabric is not None and self.material is not None:
            raise OptionsError(None, "give a ply a fabric or a material, not both")
        if self.region_value is not None and self.region is None:
            raise OptionsError("region_value", "needs a region field")
        if self.darts == "auto" and self.dart_lines is not None:
            raise OptionsError(None, "give a ply darts = 'auto' or dart_lines, not both")
        if self.splice_lines is not None and (self.darts == "auto" or self.dart_lines is not None):
            raise OptionsError(None, "give a ply darts or splice_lines, not both")
        if self.splices == "auto" and (
            self.darts == "auto" or self.dart_lines is not None or self.splice_lines is not None
        ):
            raise OptionsError(None, "give a ply splices = 'auto', darts or splice_lines")
        if self.locking_angle is not None and self.locking_angle > 90.0:
            raise OptionsError(
                "locking_angle", f"must be at most 90 degrees; got {self.locking_angle}"
            )
