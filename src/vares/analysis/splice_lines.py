"""Where a ply is spliced when nobody draws the lines (``--splices auto``): through its seed.

Darts cannot relieve a negatively curved region (:mod:`vares.analysis.splices`); a splice cuts
the ply through, and each piece is laid on its own. The pieces are laid from the ply's seed out,
so the splice goes through the seed: the plane section of the mould through the seed that
contains the mould's draw direction (the mean of its cells' normals, the direction a punch
closes in; where it has none, or where the warp runs within :data:`STEEP_WARP` of it, the
normal at the seed) and runs along the warp, the fill or one
of the diagonals between them (:data:`ANGLES`, degrees from the warp about the draw direction).
Each is solved (:func:`~vares.analysis.splices.solve_with_splices`), the two along the yarns
first: of those that bring every piece below the locking angle the one with the least largest
shear is taken, and the diagonals are tried only where neither yarn's does (a splice along a
yarn is the easier one to lay). Where no single line does, the best one and the line across it
(90° on) are solved together: the ply in four pieces, as a designer splices a double-curved
part along both its axes. What was tried is kept beside the choice
(:class:`SpliceTrial`).

On the shipped double dome (the non-crimp fabric of the README, warp along x, the seed at the
saddle's centre) the splice along the warp (its long axis) takes the largest shear from 57.8° to
30.0°, across it 44.2°, along the diagonals (were they tried) 83.7° and 72.1°: the diagonals cut
the domes' walls where they are sheared most. A splice through a point chosen otherwise, the
most sheared cell (on a dome's wall), raised it to 58–76° (docs/composites.md)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..geometry.face_walk import node_normals
from ..geometry.mesh import SurfaceMesh
from ..geometry.surface_lines import CuttingError, plane_sections, triangulated
from ..geometry.surface_points import FaceLocator
from ..materials import Hyperelastic
from ..solver.api import solve
from ..solver.result import PatternResult
from .dart_lines import DRAWN
from .splices import SplicedPly, solve_with_splices

__all__ = [
    "ANGLES",
    "PlacedSplices",
    "SpliceTrial",
    "place_splices",
    "placed_text",
    "seed_splice_lines",
]

#: The directions of the splice lines tried through the seed, degrees from the warp about the
#: draw direction: along the yarns first, then the diagonals.
ANGLES = (0.0, 90.0, 45.0, 135.0)
#: Where the warp at the seed runs within this many degrees of the draw direction (a ply laid
#: from a mould's rim up its wall), the planes contain the normal at the seed instead.
STEEP_WARP = 30.0


@dataclass(frozen=True)
class SpliceTrial:
    """One set of splice lines tried: their ``angles`` (degrees from the warp), the largest shear
    of the pieces (degrees; None where the lines could not be cut or solved: ``reason``) and
    whether every piece converged."""

    angles: tuple[float, ...]
    max_shear: float | None
    converged: bool
    reason: str | None = None

    def summary(self) -> dict[str, Any]:
        return {
            "angles": list(self.angles),
            "max_shear": self.max_shear,
            "converged": self.converged,
            "reason": self.reason,
        }


@dataclass(frozen=True)
class PlacedSplices:
    """What :func:`place_splices` found: ``spliced`` the ply cut along the lines taken, at
    ``angles`` (None where the ply needs no splice: ``before`` converged below the locking
    angle), ``trials`` every set of lines tried, in order, and ``before`` the pattern of the
    whole ply."""

    spliced: SplicedPly | None
    angles: tuple[float, ...] | None
    trials: list[SpliceTrial]
    before: PatternResult

    @property
    def needed(self) -> bool:
        """Whether the whole ply reaches the locking angle (or does not converge)."""
        return bool(self.trials)

    def summary(self) -> dict[str, Any]:
        """Whether a splice was ``needed``, the trials and the ``angles`` taken."""
        return {
            "needed": self.needed,
            "trials": [t.summary() for t in self.trials],
            "angles": None if self.angles is None else list(self.angles),
        }


def placed_text(placed: dict[str, Any]) -> str:
    """How splices were placed, in words, from :meth:`PlacedSplices.summary` (as ``drape.json``
    and ``laminate.json`` keep it): "through the seed at 0° from the warp (tried 0° 30.00°, 90°
    44.22°)", "through the seed none could be cut (tried …)" or "no splice needed"."""
    if not placed["needed"]:
        return "no splice needed"

    def trial(t: dict[str, Any]) -> str:
        angles = "+".join(f"{a:g}°" for a in t["angles"])
        if t["max_shear"] is None:
            return f"{angles} not cut ({t['reason']})"
        return f"{angles} {t['max_shear']:.2f}°" + ("" if t["converged"] else " not converged")

    tried = ", ".join(trial(t) for t in placed["trials"])
    if placed["angles"] is None:
        return f"through the seed none could be cut (tried {tried})"
    taken = "+".join(f"{a:g}°" for a in placed["angles"])
    return f"through the seed at {taken} from the warp (tried {tried})"


def seed_splice_lines(
    mesh: SurfaceMesh,
    seed: Sequence[float],
    warp_direction: Sequence[float],
    angles: Sequence[float] = ANGLES,
) -> list[np.ndarray | None]:
    """The splice line ``(k, 3)`` through the ``seed`` at each of the ``angles`` (degrees from
    ``warp_direction`` about the mould's draw direction; module docs): the piece of the plane
    section through the seed, from the boundary to the boundary; None where the section through
    the seed is no such line (it closes on itself)."""
    surface = triangulated(mesh)
    face, _, point = FaceLocator(surface).locate(np.asarray(seed, dtype=float))
    at, face = point[0], int(face[0])
    vectors = surface.area_vectors()
    normal_at = node_normals(surface)[surface.cells["triangle"][face]].sum(axis=0)
    up = vectors.sum(axis=0)
    if not np.linalg.norm(up) > DRAWN * np.linalg.norm(vectors, axis=1).sum():
        up = normal_at  # no draw direction (a nearly closed mould): the normal at the seed
    up = up / np.linalg.norm(up)
    warp = np.asarray(warp_direction, dtype=float) / np.linalg.norm(warp_direction)
    if abs(warp @ up) > np.cos(np.radians(STEEP_WARP)):  # the warp runs up the draw direction
        up = normal_at / np.linalg.norm(normal_at)
    along = warp - (warp @ up) * up
    along /= np.linalg.norm(along)  # (a warp along the normal at the seed is refused before)
    across = np.cross(up, along)
    edge = float(np.linalg.norm(np.diff(surface.points[surface.edges()], axis=1), axis=2).mean())
    lines: list[np.ndarray | None] = []
    for angle in angles:
        turn = np.radians(angle)
        normal = np.cross(np.cos(turn) * along + np.sin(turn) * across, up)
        sections = plane_sections(surface, normal, float(normal @ at))
        near = [s for s in sections if np.linalg.norm(s.points - at, axis=1).min() < edge]
        lines.append(
            min(near, key=lambda s: np.linalg.norm(s.points - at, axis=1).min()).points
            if near
            else None
        )
    return lines


def place_splices(
    mesh: SurfaceMesh,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    locking_angle: float,
    seed: Sequence[float],
    warp_direction: Sequence[float],
    **settings: Any,
) -> PlacedSplices:
    """Splice the ply on ``mesh`` (the mould) through its ``seed`` where its pattern reaches the
    ``locking_angle`` (module docs): the pattern of the whole ply is solved first
    (:func:`vares.solve` with ``material``, ``thickness``, ``warp_direction`` and the keyword
    ``settings``); below the locking angle, and converged, it needs no splice."""
    settings = {**settings, "warp_direction": tuple(float(v) for v in warp_direction)}
    before = solve(triangulated(mesh), material, thickness, **settings)
    shear = float(np.nanmax(np.abs(before.fields["shear_angle"])))
    if before.converged and shear < locking_angle:
        return PlacedSplices(None, None, [], before)
    lines = dict(zip(ANGLES, seed_splice_lines(mesh, seed, warp_direction), strict=True))
    trials: list[SpliceTrial] = []
    solved: list[tuple[SpliceTrial, SplicedPly]] = []

    def attempt(angles: tuple[float, ...]) -> None:
        polylines = [lines[a] for a in angles]
        if any(line is None for line in polylines):
            trials.append(SpliceTrial(angles, None, False, "no line through the seed"))
            return
        try:
            spliced = solve_with_splices(
                mesh,
                material,
                thickness,
                locking_angle=locking_angle,
                polylines=polylines,
                before=before,
                **settings,
            )
        except CuttingError as error:
            trials.append(SpliceTrial(angles, None, False, str(error)))
            return
        trials.append(SpliceTrial(angles, spliced.max_shear_after, spliced.converged))
        solved.append((trials[-1], spliced))

    for pair in (ANGLES[:2], ANGLES[2:]):  # along the yarns; the diagonals where they fail
        if not any(spliced.relieved for _, spliced in solved):
            for angle in pair:
                attempt((angle,))
    if solved and not any(spliced.relieved for _, spliced in solved):
        best = min(solved, key=lambda pair: pair[1].max_shear_after)[0].angles[0]
        attempt((best, (best + 90.0) % 180.0))  # the ply in four pieces
    ranked = (
        [pair for pair in solved if pair[1].relieved]
        or [pair for pair in solved if pair[1].converged]
        or solved
    )
    if not ranked:
        return PlacedSplices(None, None, trials, before)
    trial, spliced = min(ranked, key=lambda pair: pair[1].max_shear_after)
    return PlacedSplices(spliced, trial.angles, trials, before)
