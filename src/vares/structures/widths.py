"""How much roll a strip needs: alone, or beside another one turned head to tail.

A strip of a conic tent is wide at the ground and narrow at the ring. Laid on the roll alone it
takes the roll's width for its whole length, and about half of that width is cut away. Two such
strips, one turned by 180° (the warp stays along the roll), lie side by side when the wide end
of each is beside the narrow end of the other: they need the width of the *pair*, the largest
sum of the two widths at the same place along the roll, not twice the widest. With the warp
along one of a strip's seams that seam is straight along the roll and the other carries the
whole taper, and the pair closes up to a band as wide as the wide end plus the narrow end.

:func:`pair_width` measures that band for a piece beside a turned copy of itself, ends aligned
(neighbouring strips are nearly alike); :func:`roll_estimate` the roll length a plan needs when
its pieces lie one after the other, or in pairs.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..geometry.flatten import lscm
from ..geometry.mesh import SurfaceMesh
from ..geometry.surface_lines import triangulated
from .panels import width_across_warp

if TYPE_CHECKING:
    from .strip_plan import StripPlan

__all__ = [
    "along_straight_side",
    "envelopes",
    "pair_width",
    "pattern_direction",
    "profiles",
    "roll_estimate",
    "strip_widths",
]

#: Places along the warp where a piece's envelopes are sampled.
SAMPLES = 200


def envelopes(
    outline: np.ndarray, warp: Sequence[float] | None = None, samples: int = SAMPLES
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The piece's extent across the warp along it: positions ``s (samples,)`` along the warp
    from one end of the ring ``(k, 2)`` to the other, and the highest and lowest points of
    the ring across the warp there, ``upper`` and ``lower (samples,)`` (pattern units)."""
    warp = np.array([1.0, 0.0]) if warp is None else np.asarray(warp, dtype=float)
    warp = warp / np.linalg.norm(warp)
    ring = np.asarray(outline, dtype=float)
    along = ring @ warp
    s = np.linspace(along.min(), along.max(), samples)
    across = ring @ np.array([-warp[1], warp[0]])
    upper, lower = profiles(np.column_stack([along, across]), s)
    return s, upper, lower


def profiles(ring: np.ndarray, stations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The highest and lowest point (second coordinate) of a ring ``(k, 2)`` across each of
    the ``stations`` along its first coordinate: ``upper`` and ``lower``, −inf and +inf where
    the ring does not reach."""
    a0, c0 = ring[:, 0], ring[:, 1]
    a1, c1 = np.roll(a0, -1), np.roll(c0, -1)
    low, high = np.minimum(a0, a1), np.maximum(a0, a1)
    # every edge's crossing with every station (vertical edges give both of their ends)
    inside = (low[None, :] <= stations[:, None]) & (stations[:, None] <= high[None, :])
    t = np.clip((stations[:, None] - a0[None, :]) / np.where(a1 != a0, a1 - a0, 1.0)[None, :], 0, 1)
    y = c0[None, :] + t * (c1 - c0)[None, :]
    flat = (a1 == a0)[None, :] & inside
    upper = np.where(inside, np.where(flat, np.maximum(c0, c1)[None, :], y), -np.inf).max(axis=1)
    lower = np.where(inside, np.where(flat, np.minimum(c0, c1)[None, :], y), np.inf).min(axis=1)
    return upper, lower


def pair_width(
    outline: np.ndarray,
    warp: Sequence[float] | None = None,
    *,
    straight: bool = False,
    other: np.ndarray | None = None,
    other_warp: Sequence[float] | None = None,
) -> float:
    """The width of roll a piece (ring ``(k, 2)``, warp ``(2,)``) and a copy of it turned by
    180° need side by side, their ends aligned: the copy's turned edge against the piece's upper
    edge, or against its lower one, whichever is narrower (module docs). For a rectangle it is
    twice the width; for a trapezoid with one edge along the warp, the two ends' widths added.
    ``straight``: the width the pair would need if one long edge of the piece ran along the
    warp (the largest sum of its widths at mirrored places along it). With ``other`` (a ring,
    warp ``other_warp``) the turned piece is that one, laid along the same length."""
    _, upper, lower = envelopes(outline, warp)
    if straight:
        across = upper - lower
        return float(np.max(across + across[::-1]))
    if other is None:
        other_upper, other_lower = upper, lower
    else:
        _, other_upper, other_lower = envelopes(other, other_warp)
    on_top = np.max(upper + other_upper[::-1]) - lower.min() - other_lower.min()
    below = upper.max() + other_upper.max() - np.min(lower + other_lower[::-1])
    return float(min(on_top, below))


def roll_estimate(lengths: Sequence[float], across: int) -> float:
    """Roll length for pieces of ``lengths`` along the warp laid ``across`` (1: one after the
    other; 2: in pairs side by side, the longer two together)."""
    ordered = np.sort(np.asarray(lengths, dtype=float))[::-1]
    return float(ordered[::across].sum())


def _mean_mapping(mesh: SurfaceMesh, coordinates: np.ndarray) -> np.ndarray:
    """The 3D-area-weighted mean ``(2, 3)`` of the cells' maps from the tangent plane to the
    pattern ``(n, 2)``."""
    cells = triangulated(mesh).cells["triangle"]
    p, x = mesh.points[cells], coordinates[cells]
    edges_3d = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]], axis=-1)  # (m, 3, 2)
    edges_2d = np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]], axis=-1)  # (m, 2, 2)
    mapping = edges_2d @ np.linalg.pinv(edges_3d)  # (m, 2, 3): tangent plane → pattern
    area = 0.5 * np.linalg.norm(np.cross(edges_3d[..., 0], edges_3d[..., 1]), axis=1)
    return np.einsum("m,mij->ij", area, mapping)


def pattern_direction(mesh: SurfaceMesh, coordinates: np.ndarray, direction) -> np.ndarray:
    """The unit 2D direction ``(2,)`` of a pattern ``(n, 2)`` that maps onto the 3D
    ``direction`` (projected on each cell; 3D-area-weighted mean over the triangles)."""
    total = _mean_mapping(mesh, coordinates) @ np.asarray(direction, dtype=float)
    return total / np.linalg.norm(total)


def along_straight_side(
    mesh: SurfaceMesh, coordinates: np.ndarray, direction
) -> tuple[np.ndarray, np.ndarray]:
    """The 2D direction ``(2,)`` of the straighter long side of a pattern ``(n, 2)`` near the
    3D ``direction`` (a line fitted to the side's envelope along it, the ends' tenths left
    out), and a 3D direction ``(3,)`` that maps onto it (:func:`pattern_direction`)."""
    along = pattern_direction(mesh, coordinates, direction)
    s, upper, lower = envelopes(coordinates[mesh.boundary_loops()[0]], along)
    inner = slice(len(s) // 10, len(s) - len(s) // 10)
    side = min((upper, lower), key=lambda e: np.ptp(e[inner]))
    slope = np.polyfit(s[inner], side[inner], 1)[0]
    turned = along + slope * np.array([-along[1], along[0]])
    turned /= np.linalg.norm(turned)
    direction_3d = np.linalg.pinv(_mean_mapping(mesh, coordinates)) @ turned
    return turned, direction_3d / np.linalg.norm(direction_3d)


def strip_widths(
    plan: StripPlan, family, seam_allowance: float, edge_allowance: float
) -> list[float]:
    """Flattened width of every strip of ``plan`` (least-squares conformal map) with its two
    side allowances, or with ``plan.interlock`` the width two of them need side by side, head
    to tail (:func:`pair_width`, both strips' allowances; with ``plan.straight_warp`` each
    strip's warp turned along its straighter side first, :func:`along_straight_side`). Sets
    ``plan.lengths`` (extents along the warp) and ``plan.straight_pairs`` (:func:`pair_width`
    with ``straight``, allowances included), mesh units."""
    out, plan.lengths, plan.straight_pairs = [], [], []
    strips = plan.strip_of or list(range(len(plan.panels)))  # pieces of strips cut across
    last = max(strips, default=0)
    for index, (panel, warp) in enumerate(zip(plan.panels, plan.warps, strict=True)):
        flat = lscm(panel.mesh)
        if plan.interlock and plan.straight_warp:
            along, plan.warps[index] = along_straight_side(panel.mesh, flat, warp)
        else:
            along = pattern_direction(panel.mesh, flat, warp)
        ring = flat[panel.mesh.boundary_loops()[0]]
        plan.lengths.append(float(np.ptp(flat @ along)))
        outer = family is not None and not family.closed and strips[index] in (0, last)
        sides = 2 if last == 0 else 1
        allowance = (
            sides * edge_allowance + (2 - sides) * seam_allowance if outer else 2 * seam_allowance
        )
        plan.straight_pairs.append(pair_width(ring, along, straight=True) + 2 * allowance)
        if plan.interlock:
            out.append(pair_width(ring, along) + 2 * allowance)
        else:
            out.append(width_across_warp(flat, along) + allowance)
    return out
