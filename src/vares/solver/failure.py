"""How a Newton iteration or a strategy says it did not converge."""

from __future__ import annotations

import numpy as np

__all__ = ["Failure", "describe_cells"]


class Failure(Exception):
    """A Newton iteration (or a strategy) did not converge; ``coordinates`` is where it stopped
    (never inverted)."""

    def __init__(self, reason: str, coordinates: np.ndarray, folding: bool = False) -> None:
        super().__init__(reason)
        self.reason = reason
        self.coordinates = coordinates
        self.folding = folding  # the energy's minimum lies beyond a fold: no strategy helps


def describe_cells(ids: np.ndarray, limit: int = 5) -> str:
    """``"3 cell(s) (4, 7, 9)"`` for messages."""
    shown = ", ".join(str(int(i)) for i in ids[:limit])
    return f"{ids.size} cell(s) ({shown}{', …' if ids.size > limit else ''})"
