"""Statistics of per-cell fields: minimum, maximum and area-weighted mean."""

from __future__ import annotations

import numpy as np

__all__ = ["field_statistics"]


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
