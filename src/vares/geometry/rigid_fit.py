"""The proper rigid motion of the plane that best fits one pattern onto another."""

from __future__ import annotations

import numpy as np

__all__ = ["rigid_fit"]


def rigid_fit(moving: np.ndarray, target: np.ndarray) -> np.ndarray:
    """``moving`` ``(n, 2)`` after the rotation and translation (no reflection) that fit it onto
    ``target`` ``(n, 2)`` in least squares (Kabsch): the same nodes, the same units."""
    centre, target_centre = moving.mean(axis=0), target.mean(axis=0)
    u, _, vt = np.linalg.svd((moving - centre).T @ (target - target_centre))
    rotation = u @ np.diag([1.0, np.sign(np.linalg.det(u @ vt))]) @ vt
    return target_centre + (moving - centre) @ rotation
