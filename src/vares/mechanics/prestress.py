"""Prestress: the intended membrane forces that the erected pattern should carry.

A prestress is given along the yarns, as force per length (e.g. kN/m): warp, fill and optionally
a shear component, uniform or per cell. In the energy it is the second Piola–Kirchhoff tensor in
the pattern frame (DESIGN.md eq. 1),

    S_pre = (σ_w Φ₁⊗Φ₁ + σ_f Φ₂⊗Φ₂ + τ (Φ₁⊗Φ₂ + Φ₂⊗Φ₁)) / t,

so it turns with the yarns and ``t S_pre`` is a force per length.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..materials import Fibres

__all__ = ["PrestressWarning", "prestress_components", "prestress_tensor"]


class PrestressWarning(UserWarning):
    """A prestress that is legal but probably not meant (compressive)."""


def prestress_components(prestress: float | np.ndarray | None, num_cells: int) -> np.ndarray | None:
    """Prestress as an array ``(k, 3)`` of (warp, fill, shear) force per length.

    Accepts a number (isotropic: warp = fill), ``(2,)`` or ``(3,)`` (uniform), or
    ``(num_cells, 2)`` / ``(num_cells, 3)`` (per cell, global cell order); ``k`` is 1 or
    ``num_cells``. Raises ``ValueError`` for a wrong shape or non-finite values; warns
    (:class:`PrestressWarning`) when warp or fill is compressive somewhere.
    """
    if prestress is None:
        return None
    values = np.asarray(prestress, dtype=float)
    if values.ndim == 0:
        values = np.array([values, values, 0.0])
    if values.ndim == 1:
        values = values[None]
    if values.ndim != 2 or values.shape[1] not in (2, 3) or len(values) not in (1, num_cells):
        raise ValueError(
            "prestress must be a number, (warp, fill[, shear]) or one such row per cell "
            f"({num_cells}, 2 or 3); got shape {np.shape(prestress)}"
        )
    if not np.all(np.isfinite(values)):
        bad = np.flatnonzero(~np.isfinite(values).all(axis=1))
        raise ValueError(f"prestress is not finite at cells {', '.join(map(str, bad[:8]))}")
    if values.shape[1] == 2:
        values = np.column_stack([values, np.zeros(len(values))])
    compressive = np.flatnonzero((values[:, :2] < 0).any(axis=1))
    if compressive.size:
        where = "everywhere" if len(values) == 1 else f"at {compressive.size} cell(s)"
        warnings.warn(
            f"the prestress is compressive {where} (min {values[:, :2].min():.4g}): "
            "a membrane cannot carry compression",
            PrestressWarning,
            stacklevel=2,
        )
    return values


def prestress_tensor(components: np.ndarray, fibres: Fibres, thickness: float) -> np.ndarray:
    """``S_pre`` ``(k, 2, 2)`` in the pattern frame from components ``(k, 3)``."""
    warp, fill = fibres.warp, fibres.fill
    cross = np.outer(warp, fill) + np.outer(fill, warp)
    tensor = (
        components[:, 0, None, None] * np.outer(warp, warp)
        + components[:, 1, None, None] * np.outer(fill, fill)
        + components[:, 2, None, None] * cross
    )
    return tensor / thickness
