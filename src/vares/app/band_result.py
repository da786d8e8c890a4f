"""What a run's band gave (:func:`vares.app.run_band.run_band`): the band of the run's own
patterns under the scatter of its fabric file, or why there is none. Its own module so that a
job's outcome (:mod:`.outcome`) can hold it without importing the band's solves."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .fabric_band import FabricBand

__all__ = ["RunBand"]


@dataclass(frozen=True)
class RunBand:
    """The band of a run (:func:`vares.app.run_band.run_band`), or why there is none
    (``reason``)."""

    path: Path
    band: FabricBand | None
    reason: str | None = None
    nominal_difference: float | None = None

    def to_dict(self, units: str) -> dict[str, Any]:
        """The ``scatter`` section of ``summary.json`` / ``structure.json``."""
        head: dict[str, Any] = {"fabric_file": str(self.path)}
        if self.band is None:
            return head | {"converged": False, "reason": self.reason}
        return (
            head
            | self.band.to_dict()
            | {
                "units": units,
                "nominal_case": "the run's own patterns solved again with the same law and options",
                "nominal_difference": self.nominal_difference,
                "where": "in this process",
            }
        )
