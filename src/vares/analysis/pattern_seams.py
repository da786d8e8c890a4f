"""The patterns of a structure as one vector of unknowns (:class:`PatternLayout`), their welded
seams (:func:`seam_edges`) and the constraints that every seam edge be equally long in the two
patterns it joins (:func:`seam_constraints`, :func:`matched`): for the erection-aware
optimisation (:mod:`.erection_optimum`, :mod:`.erection_residuals`)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .erection import ErectionResult
from .erection_model import Pattern

__all__ = ["PatternLayout", "matched", "moved", "seam_constraints", "seam_edges"]

#: Seam edges are matched again after every step until their lengths differ by at most this
#: fraction of the patterns' size (at most MATCH_STEPS Gauss–Newton steps).
MATCHED = 1e-13
MATCH_STEPS = 5


class PatternLayout:
    """Where each pattern coordinate and erected force lives: the variables are the patterns'
    nodes, panel after panel (``offsets``); per membrane block its panel and panel-local cells."""

    def __init__(self, patterns: list[Pattern], erected: ErectionResult) -> None:
        counts = [p.mesh.num_points for p in patterns]
        self.offsets = np.concatenate([[0], np.cumsum(counts)])
        self.num_variables = 2 * int(self.offsets[-1])
        self.block_cells = []  # panel-local node ids of each block's cells
        for p, pattern in enumerate(patterns):
            for cells in pattern.mesh.cells.values():
                self.block_cells.append(self.offsets[p] + cells)
        self.cell_ids = erected.structure.block_cells

    def split(self, vector: np.ndarray) -> list[np.ndarray]:
        flat = vector.reshape(-1, 2)
        return [flat[a:b] for a, b in zip(self.offsets[:-1], self.offsets[1:], strict=True)]


def seam_edges(
    patterns: list[Pattern], erected: ErectionResult, layout: PatternLayout
) -> np.ndarray:
    """Welded seam edges as pairs of pattern edges ``(k, 2, 2)`` (variable node ids): boundary
    edges of two panels that weld onto one edge of the structure."""
    found: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for p, (pattern, node_map) in enumerate(zip(patterns, erected.node_maps, strict=True)):
        for a, b in pattern.mesh.boundary_edges():
            key = (min(node_map[a], node_map[b]), max(node_map[a], node_map[b]))
            found.setdefault(key, []).append((layout.offsets[p] + a, layout.offsets[p] + b))
    pairs = [v[:2] for v in found.values() if len(v) >= 2]
    return np.array(pairs, dtype=int).reshape(-1, 2, 2)


def seam_constraints(X: np.ndarray, seams: np.ndarray, num_variables: int):
    """``c = ℓ_P − ℓ_Q`` per seam edge (its lengths in the two patterns it joins, ``X`` all
    patterns' nodes ``(N, 2)``) and the Jacobian ``(k, num_variables)``."""
    if not len(seams):
        return np.zeros(0), sp.csr_matrix((0, num_variables))
    ends = X[seams]  # (k, 2 sides, 2 ends, 2)
    vectors = ends[:, :, 1] - ends[:, :, 0]  # (k, 2, 2)
    lengths = np.linalg.norm(vectors, axis=-1)  # (k, 2)
    units = vectors / lengths[..., None]  # d length / d end = ±unit
    rows, cols, vals = [], [], []
    for side, sign in ((0, 1.0), (1, -1.0)):
        for end, direction in ((0, -1.0), (1, 1.0)):
            for axis in range(2):
                rows.append(np.arange(len(lengths)))
                cols.append(2 * seams[:, side, end] + axis)
                vals.append(sign * direction * units[:, side, axis])
    jac = sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(len(lengths), num_variables),
    )
    return lengths[:, 0] - lengths[:, 1], jac


def matched(patterns: list[Pattern], seams: np.ndarray, layout: PatternLayout) -> list[Pattern]:
    """The patterns moved least (Gauss–Newton, minimum norm) to make every seam edge equally
    long in its two patterns, to round-off."""
    if not len(seams):
        return patterns
    X = np.concatenate([p.material_coordinates for p in patterns])
    size = float(np.ptp(X, axis=0).max())
    for _ in range(MATCH_STEPS):
        c, C = seam_constraints(X, seams, layout.num_variables)
        if np.abs(c).max() <= MATCHED * size:
            break
        gram = spla.splu((C @ C.T).tocsc())
        X = X - (C.T @ gram.solve(c)).reshape(-1, 2)
    return moved(
        patterns,
        layout.split((X - np.concatenate([p.material_coordinates for p in patterns])).ravel()),
    )


def moved(patterns: list[Pattern], steps: list[np.ndarray]) -> list[Pattern]:
    """The patterns, each moved by its step ``(n, 2)``."""
    return [
        replace(p, material_coordinates=p.material_coordinates + s)
        for p, s in zip(patterns, steps, strict=True)
    ]
