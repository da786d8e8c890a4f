"""Statistics of per-cell fields: minimum, maximum, area-weighted mean, and a yarn force's
deviation from its intended value."""

from __future__ import annotations

import numpy as np

__all__ = ["field_statistics", "stress_statistics"]


def _statistics(values: np.ndarray, weights: np.ndarray) -> dict[str, float]:
    finite = np.isfinite(values)
    if not finite.any():
        return {"min": float("nan"), "max": float("nan"), "mean": float("nan")}
    v, w = values[finite], weights[finite]
    return {"min": float(v.min()), "max": float(v.max()), "mean": float(v @ w / w.sum())}


def field_statistics(fields: dict[str, np.ndarray]) -> dict[str, dict[str, float]]:
    """Min, max and pattern-area-weighted mean of every per-cell field (areas excluded).

    For the 0/1 flags (``compressed_yarns``, ``wrinkling``) the mean is the area fraction.
    """
    weights = fields["pattern_area"]
    return {
        name: _statistics(values, weights)
        for name, values in fields.items()
        if name not in ("pattern_area", "surface_area", "energy")
    }


def stress_statistics(
    values: np.ndarray, intended: np.ndarray, area: np.ndarray
) -> dict[str, float]:
    """``mean``, ``min``, ``max``, ``intended`` (mean) and ``rms_deviation`` of one yarn's forces,
    weighted by ``area``."""
    total = area.sum()
    return {
        "mean": float(values @ area / total),
        "min": float(values.min()),
        "max": float(values.max()),
        "intended": float(intended @ area / total),
        "rms_deviation": float(np.sqrt((values - intended) ** 2 @ area / total)),
    }
