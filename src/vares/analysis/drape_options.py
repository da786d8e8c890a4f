"""The options of a ply's kinematic drape and producibility check, declared once (see
:mod:`vares.options`): the ``[drape]`` table of a job, the keywords of
:func:`vares.analysis.drape.drape_ply` and the flags of ``vares drape`` (and of ``--drape`` on
``vares pattern`` and ``vares example``)."""

from __future__ import annotations

from dataclasses import dataclass

from ..materials.forming import FABRIC_KINDS
from ..options import Options, OptionsError, option

__all__ = ["DrapeOptions"]


@dataclass(frozen=True)
class DrapeOptions(Options):
    """Where a ply is laid and how its shear is judged (see
    :func:`vares.analysis.drape.drape_ply`)."""

    title = "drape option"

    seed: tuple[float, float, float] | None = option(
        None,
        "vector",
        "Seed point 'x,y,z' on the mould (default: the node nearest the nodes' centroid).",
        section="drape",
    )
    warp: tuple[float, float, float] | None = option(
        None,
        "vector",
        "Warp direction 'x,y,z' at the seed, projected onto the mould (default: the pattern's "
        "warp direction, else x).",
        section="drape",
    )
    spacing: float | None = option(
        None,
        "float",
        "Yarn spacing of the net, mesh length units (default: half the mean edge length).",
        section="drape",
        positive=True,
    )
    fabric_kind: str = option(
        "woven-twill",
        "str",
        "Fabric kind: its typical locking angle (docs/composites.md).",
        section="drape",
        choices=tuple(FABRIC_KINDS),
    )
    locking_angle: float | None = option(
        None,
        "float",
        "Locking angle in degrees, at most 90 (default: the fabric kind's).",
        section="drape",
        positive=True,
    )
    warn_fraction: float = option(
        0.8,
        "float",
        "Warn from this fraction (at most 1) of the locking angle on.",
        section="drape",
        positive=True,
    )

    def check(self) -> None:
        if self.locking_angle is not None and self.locking_angle > 90.0:
            raise OptionsError(
                "locking_angle", f"must be at most 90 degrees; got {self.locking_angle}"
            )
        if self.warn_fraction > 1.0:
            raise OptionsError("warn_fraction", f"must be at most 1; got {self.warn_fraction}")

    @property
    def locking(self) -> tuple[float, str]:
        """The locking angle (degrees) and where it comes from."""
        if self.locking_angle is not None:
            return self.locking_angle, "given"
        kind = FABRIC_KINDS[self.fabric_kind]
        return kind.locking_angle, kind.source
