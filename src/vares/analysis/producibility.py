"""Producibility of a draped ply: its shear angles against the fabric's locking angle.

Each cell is **ok** below ``warn_fraction × locking_angle``, **warn** from there up to the locking
angle and **limit** at or beyond it (the fabric would wrinkle there: a dart or another seed or
orientation is needed). The magnitude of the shear counts, not its sign. Cells without a shear
value (outside the drape) are **none** and stay out of the fractions, which are of the area that
has a value; :attr:`Producibility.covered` is that area's share of the whole.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["CLASSES", "Producibility", "producibility"]

#: The classes, from good to bad, then the cells without a value.
CLASSES = ("ok", "warn", "limit", "none")


@dataclass(frozen=True)
class Producibility:
    """Per cell ``(m,)``: ``classes`` (one of :data:`CLASSES`); ``fractions``: the area share of
    ok, warn and limit (of the area with a shear value); ``covered``: that area's share of the
    total; ``max_shear``: the largest shear magnitude (degrees, NaN if none); the thresholds
    ``warn_angle`` and ``locking_angle`` (degrees)."""

    classes: np.ndarray
    fractions: dict[str, float]
    covered: float
    max_shear: float
    warn_angle: float
    locking_angle: float

    def summary(self) -> dict[str, float]:
        """The numbers for a summary file: fractions (as ``ok_fraction`` …), coverage, the
        largest shear and the thresholds."""
        out = {f"{name}_fraction": value for name, value in self.fractions.items()}
        return out | {
            "covered_fraction": self.covered,
            "max_shear": self.max_shear,
            "warn_angle": self.warn_angle,
            "locking_angle": self.locking_angle,
        }


def producibility(
    shear_angles: np.ndarray,
    areas: np.ndarray,
    locking_angle: float,
    warn_fraction: float = 0.8,
) -> Producibility:
    """Classify cells by their shear angle ``(m,)`` (degrees, signed; NaN where unknown), with
    their areas ``(m,)``, against ``locking_angle`` (degrees, in (0, 90]) and the warning at
    ``warn_fraction`` of it (in (0, 1])."""
    if not 0.0 < locking_angle <= 90.0:
        raise ValueError(f"the locking angle must lie in (0, 90] degrees; got {locking_angle}")
    if not 0.0 < warn_fraction <= 1.0:
        raise ValueError(f"warn_fraction must lie in (0, 1]; got {warn_fraction}")
    shear = np.abs(np.asarray(shear_angles, dtype=float))
    areas = np.asarray(areas, dtype=float)
    if shear.shape != areas.shape or shear.ndim != 1:
        raise ValueError(f"shear angles {shear.shape} and areas {areas.shape} must be (m,) each")
    warn_angle = warn_fraction * locking_angle
    known = np.isfinite(shear)
    classes = np.full(shear.shape, "none", dtype="<U5")
    classes[known] = np.where(
        shear[known] >= locking_angle, "limit", np.where(shear[known] >= warn_angle, "warn", "ok")
    )
    known_area = float(areas[known].sum())
    fractions = {
        name: float(areas[classes == name].sum()) / known_area if known_area > 0 else float("nan")
        for name in CLASSES[:3]
    }
    total = float(areas.sum())
    return Producibility(
        classes,
        fractions,
        known_area / total if total > 0 else float("nan"),
        float(shear[known].max()) if known.any() else float("nan"),
        warn_angle,
        float(locking_angle),
    )
