"""What running a job produced: per panel, its pattern, report figures, warnings and files."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ..units import unit_factor
from .sections import STRUCTURE_MARK_SPACING

if TYPE_CHECKING:  # made (and their modules imported) only when a job asks for them
    from ..analysis.compensation import CompensationReport
    from ..analysis.drape import PlyDrape
    from ..analysis.erection import ErectionResult
    from ..analysis.erection_optimum import OptimisedPatterns
    from ..geometry.mesh import SurfaceMesh
    from ..materials import Hyperelastic
    from ..solver.result import PatternResult
    from ..structures.cutting import CutResult
    from ..structures.matching import StructureResult
    from .band_result import RunBand
    from .job import Job

__all__ = ["JobOutcome", "PanelOutcome"]


@dataclass
class PanelOutcome:
    """One pattern of a job: the panel's name, mesh and result, its compensation report (for a
    converged solve), its warnings, the files written for it (in ``directory``) and the ply's
    kinematic drape (when the job asks for one)."""

    name: str
    mesh: SurfaceMesh
    result: PatternResult
    compensation: CompensationReport | None
    directory: Path
    units: str = "m"
    warnings: list[str] = field(default_factory=list)
    files: list[Path] = field(default_factory=list)
    drape: PlyDrape | None = None


@dataclass
class JobOutcome:
    """What a job produced: one :class:`PanelOutcome` per pattern (one for a single surface),
    the structure's result for a structure (and the cut's for a cut job), the erection (when
    asked for; of the optimised patterns with ``[erection] optimise``, ``optimum`` holding the
    optimisation and the VaReS patterns' erection), the output folder, the length units, what
    the input's repair changed, the band of the patterns under the fabric's scatter (with
    ``[scatter]``) and every file written."""

    job: Job
    material: Hyperelastic
    panels: list[PanelOutcome]
    structure: StructureResult | None = None
    directory: Path = Path()
    units: str = "m"
    repairs: dict[str, dict[str, object]] = field(default_factory=dict)
    cut: CutResult | None = None
    erection: ErectionResult | None = None
    optimum: OptimisedPatterns | None = None
    scatter: RunBand | None = None
    files: list[Path] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def mark_spacing(self) -> float:
        """The spacing of a structure's match marks in the mesh's units (the job gives it in
        DXF units, else :data:`~vares.app.sections.STRUCTURE_MARK_SPACING`)."""
        spacing = self.job.output.mark_spacing or STRUCTURE_MARK_SPACING
        return spacing * unit_factor(self.job.output.dxf_units, self.units)

    @property
    def patterned(self) -> bool:
        """The patterns converged (every panel's, and the seam matching)."""
        if self.structure is not None:
            return self.structure.converged
        return self.panels[0].result.converged

    @property
    def converged(self) -> bool:
        """The patterns converged, and so did the erection when there was one."""
        return self.patterned and (self.erection is None or self.erection.converged)

    @property
    def reason(self) -> str | None:
        if not self.patterned:
            return self.structure.reason if self.structure else self.panels[0].result.reason
        if self.erection is not None and not self.erection.converged:
            return f"the erection did not converge: {self.erection.reason}"
        return None

    @property
    def unfit(self) -> str | None:
        """Why a cut whose patterns converged is of no use on its roll (pieces wider than the
        roll takes, so nothing was nested), or None."""
        cut = self.cut
        if cut is None or not cut.too_wide:
            return None
        names = ", ".join(cut.plan.panels[k].name for k in cut.too_wide)
        plans = "1 plan" if len(cut.rounds) == 1 else f"{len(cut.rounds)} plans"
        return (
            f"the cut does not fit the roll: {names} wider than it takes "
            f"({cut.usable_width:.6g} {self.units}) after {plans}, so nothing was nested: try "
            "another strip direction or layout, or a wider roll"
        )

    @property
    def result(self) -> PatternResult:
        """The pattern of a single-surface job."""
        if self.structure is not None:
            raise AttributeError("a structure has one result per panel: use .panels")
        return self.panels[0].result
