"""Darts: cuts from a ply's boundary into the region whose shear exceeds the locking angle, and
the pattern solved again with the darts open (DESIGN.md §8).

**Where.** The cells at or beyond the locking angle form regions (neighbours across edges),
joined through the cells whose :func:`smoothed` shear is within :data:`JOIN_FRACTION` of it: the
cell-to-cell scatter of linear triangles with stiff yarns does not split a region. A region that
reaches the boundary gets one dart from the boundary side nearest the region's shear-weighted
centre there (weights: the shear beyond the locking angle); a region inside the surface, from
the boundary side nearest its most sheared cell.

**Where the bisector leads nowhere** (a region inside the ply, whose cells between it and the
boundary are sheared less than the tip angle: the corners of a box-shaped part), or its darts
leave the shear at or beyond the locking angle, every region gets a dart along a **fall line**
(:func:`fall_line_darts`), in rounds of their own: from the boundary up the slope of the
mould to the positively curved patch beside the region (the excess fabric a dart takes out lies
there; the region itself is often negatively curved, at the foot of a corner), and through it.
The slope is that of the mould's draw direction, the mean of its cells' normals (the direction
a punch closes in); the line goes straight on where the mould is flat (a flange) and where it
would turn by more than :data:`FALL_TURN` from one cell to the next. Its tip is where the
smoothed shear is below the tip angle beyond the positively curved patch.

**Which way.** Sheared yarns at an angle ``θ < 90°`` lengthen the bisector of their acute angle
(``2 cos(θ/2)``) and shorten the other diagonal (``2 sin(θ/2)``): the fabric is squeezed across
the bisector. A cut along the bisector opens against that squeeze, and relieves the most shear.
The dart follows the bisector of the erected yarns (``F Φ₁``, ``F Φ₂`` of the pattern) from cell
to cell (:func:`vares.geometry.slits.walk_line`) until the smoothed shear falls below the
dart's **tip angle**, or to ``max_length``. On a sphere, with the warp along a symmetry plane, the
bisector on the 45° meridians is the meridian itself.

**How far.** :func:`solve_with_darts` solves the pattern, places the darts with the tip angle
``dart_tip × locking angle``, opens them (:func:`vares.geometry.slits.open_slits`: both lips
free boundary, joined at the tip) and solves again, started from the first pattern; while the
largest shear is still at or beyond the locking angle it lengthens the darts (the tip angle
lowered by ``dart_step × locking angle``) for at most ``dart_rounds`` rounds
(:class:`~vares.analysis.dart_options.DartOptions`). Where the bisector's darts leave it there,
the fall lines' darts are solved in rounds as well; the round kept is the first below the
locking angle, else the converged one with the least largest shear, of either rule. Dart lines
a user gives (polylines near the mould, :func:`darts_from_polylines`) are opened as they are,
once.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..geometry.curvature import curvature_sign_shares
from ..geometry.mesh import SurfaceMesh
from ..geometry.slits import SlitMesh, open_slits
from ..geometry.surface_lines import SurfaceLine, triangulated
from ..geometry.surface_points import FaceLocator
from ..materials import Hyperelastic
from ..options import split_settings, takes_options
from ..solver.api import solve
from ..solver.result import PatternResult
from .dart_lines import (
    darts_from_polylines,
    erected_yarns,
    fall_line_darts,
    place_darts,
    smoothed,
    to_segments,
)
from .dart_options import DartOptions

#: Darts that leave the shear at or beyond the locking angle where more than this share of the
#: area beyond it is negatively curved are answered with the advice to splice the ply.
NEGATIVE_SHARE = 0.5
#: The rules of automatic darts, in the order they are tried (module docs).
RULES = ("bisector", "fall line")

__all__ = [
    "NEGATIVE_SHARE",
    "RULES",
    "DartOptions",
    "DartRound",
    "DartedPattern",
    "darts_from_polylines",
    "erected_yarns",
    "fall_line_darts",
    "over_locking_curvature",
    "place_darts",
    "smoothed",
    "solve_with_darts",
    "to_segments",
]


def over_locking_curvature(result: PatternResult, locking_angle: float) -> dict[str, float]:
    """The shares of the area at or beyond ``locking_angle`` of a pattern that lie on positively
    curved, negatively curved and flat parts of its mould
    (:func:`vares.geometry.curvature.curvature_sign_shares`): darts relieve the first kind, not
    the second (:mod:`vares.analysis.splices`)."""
    shear = np.abs(np.nan_to_num(np.asarray(result.fields["shear_angle"], dtype=float)))
    return curvature_sign_shares(result.mesh, shear >= locking_angle)


@dataclass(frozen=True)
class DartRound:
    """One solve with darts: the tip angle (degrees; None for given lines), the darts' lengths
    (mesh units), the largest shear after (degrees), Newton iterations, seconds, converged, and
    the rule that placed the darts (:data:`RULES`: ``"bisector"``, ``"fall line"``, or
    ``"given"``)."""

    tip_angle: float | None
    lengths: list[float]
    max_shear: float
    iterations: int
    seconds: float
    converged: bool
    rule: str = "bisector"


@dataclass(frozen=True)
class DartedPattern:
    """A pattern before and after its darts were opened.

    ``before``: the pattern of the mesh without darts; ``after``: of ``slits.mesh`` with the
    darts of the round ``chosen`` open (None when no dart was needed or placed): the first
    round below the locking angle, else the converged one with the least largest shear;
    ``slits``: the opened mesh, its lips and the dart lines ``(k, 3)`` on the mould; ``rounds``:
    every solve with darts; ``locking_angle`` in degrees.
    """

    before: PatternResult
    after: PatternResult | None
    slits: SlitMesh | None
    locking_angle: float
    rounds: list[DartRound] = field(default_factory=list)
    chosen: int = -1

    @property
    def dart_lines(self) -> list[np.ndarray]:
        """The dart lines on the mould, mouth first, ``(k, 3)`` each."""
        return [] if self.slits is None else self.slits.lines

    @property
    def max_shear_before(self) -> float:
        return float(np.nanmax(np.abs(self.before.fields["shear_angle"])))

    @property
    def max_shear_after(self) -> float | None:
        return None if self.after is None else self.rounds[self.chosen].max_shear

    @property
    def final(self) -> PatternResult:
        """The pattern with the darts open, or without darts when none was opened."""
        return self.before if self.after is None else self.after

    @property
    def kept(self) -> bool:
        """Whether the ply is cut with the darts: some were opened, the solve with them
        converged, and they lower its largest shear (darts that leave it as high or higher are
        reported, not cut)."""
        if self.after is None or not self.after.converged:
            return False
        return bool(self.max_shear_after < self.max_shear_before)

    @property
    def relieved(self) -> bool:
        """Whether the largest shear ends below the locking angle (with or without darts)."""
        shear = self.max_shear_before if self.after is None else self.max_shear_after
        return bool(self.final.converged and shear < self.locking_angle)

    def dart_pattern_lines(self) -> list[np.ndarray]:
        """Both lips of every dart in the final pattern ``(k, 2)`` each: mouth → tip → mouth."""
        if self.after is None or self.slits is None:
            return []
        X = self.after.material_coordinates
        return [np.vstack([X[a], X[b][::-1][1:]]) for a, b in self.slits.lips]

    def summary(self) -> dict[str, Any]:
        """The numbers for a summary file."""
        gaps = [] if self.after is None else self.slits.lip_gaps(self.after.material_coordinates)
        return {
            "locking_angle": self.locking_angle,
            "max_shear_before": self.max_shear_before,
            "max_shear_after": self.max_shear_after,
            "relieved": self.relieved,
            "kept": self.kept,
            "darts": len(self.dart_lines),
            "dart_lengths": [
                float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) for p in self.dart_lines
            ],
            "mouth_openings": [float(g[0]) for g in gaps],
            "iterations_before": self.before.iterations,
            "seconds_before": self.before.elapsed,
            "rounds": [vars(r) for r in self.rounds],
            "chosen_round": None if self.after is None else self.chosen % len(self.rounds),
            "chosen_rule": None if self.after is None else self.rounds[self.chosen].rule,
            "over_locking_curvature": self.over_locking_curvature(),
        }

    def over_locking_curvature(self) -> dict[str, float] | None:
        """The shares of the area at or beyond the locking angle in the pattern without darts
        that lie on positively curved, negatively curved and flat parts of the mould (None when
        there is none): darts relieve the first kind, not the second
        (:mod:`vares.analysis.splices`)."""
        if not self.max_shear_before >= self.locking_angle:
            return None
        return over_locking_curvature(self.before, self.locking_angle)

    @property
    def needs_splices(self) -> bool:
        """Whether the darts left the shear at or beyond the locking angle where most of the
        area beyond it is negatively curved (more than :data:`NEGATIVE_SHARE`)."""
        shares = self.over_locking_curvature()
        return bool(
            not self.relieved and shares is not None and shares["negative"] > NEGATIVE_SHARE
        )


@takes_options(DartOptions)
def solve_with_darts(
    mesh: SurfaceMesh,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    locking_angle: float,
    polylines: Sequence[np.ndarray] | None = None,
    options: DartOptions | None = None,
    **settings: Any,
) -> DartedPattern:
    """Solve the pattern of ``mesh`` (:func:`vares.solve` with ``material`` and ``thickness``),
    place darts where its shear reaches ``locking_angle`` (degrees) with ``darts="auto"``, or
    open the dart lines ``polylines`` (``(k, 3)`` each, on or near the mould; e.g. a curves
    file's, :func:`vares.io.curves.read_curves`), and solve again with the darts open, started
    from the first pattern (module docs). Quads are split into triangles first.

    ``options``: a :class:`DartOptions` to start from; keyword ``settings`` that are dart
    options (below) change it, the others go to :func:`vares.solve` (e.g. ``warp_direction``).
    """
    dart_keys = DartOptions.specs()
    (options,) = split_settings(
        {k: v for k, v in settings.items() if k in dart_keys}, [options or DartOptions()]
    )
    solve_settings = {k: v for k, v in settings.items() if k not in dart_keys}
    if options.dart_lines is not None and polylines is None:
        raise ValueError("dart_lines names a file: pass its lines as polylines (read_curves)")
    if options.splice_lines is not None:
        raise ValueError("splice_lines are for solve_with_splices (vares.analysis.splices)")
    mesh = triangulated(mesh)
    given = None if polylines is None else darts_from_polylines(mesh, polylines)  # refused early
    before = solve(mesh, material, thickness, **solve_settings)
    result = DartedPattern(before, None, None, locking_angle)
    if not before.converged or (polylines is None and options.darts == "none"):
        return result
    fibres = before.fibres
    warp, fill = erected_yarns(mesh, before.material_coordinates, fibres.warp, fibres.fill)
    shear = before.fields["shear_angle"]
    plans: list[tuple[float | None, str, list[SurfaceLine] | None]]
    if given is not None:
        plans = [(None, "given", given)]
    else:
        if not np.nanmax(np.abs(shear)) >= locking_angle:
            return result
        fractions = [options.dart_tip - r * options.dart_step for r in range(options.dart_rounds)]
        tips = [max(f, 0.0) * locking_angle for f in fractions]
        plans = [(tip, rule, None) for rule in RULES for tip in tips]
    locator = FaceLocator(mesh)
    done: list[DartRound] = []
    best: tuple[float, PatternResult, SlitMesh, int] | None = None
    finished: set[str] = set()  # rules whose darts grow no longer
    for tip, rule, lines in plans:
        if rule in finished:
            continue
        if lines is None and rule == "bisector":
            lines = place_darts(
                mesh, shear, warp, fill, locking_angle, tip, options.dart_max_length
            )
        elif lines is None:
            lines = fall_line_darts(mesh, shear, locking_angle, tip, options.dart_max_length)
        lengths = [line.length for line in lines]
        previous = next((r.lengths for r in reversed(done) if r.rule == rule), [])
        if not lines or (len(previous) == len(lengths) and np.allclose(lengths, previous)):
            finished.add(rule)  # none, or no longer than the last round's: nothing new to solve
            continue
        slits = open_slits(mesh, lines)
        start = _carried(locator, mesh, before.material_coordinates, slits.mesh.points)
        clock = time.perf_counter()
        after = solve(slits.mesh, material, thickness, **{**solve_settings, "initial_guess": start})
        seconds = time.perf_counter() - clock
        largest = float(np.nanmax(np.abs(after.fields["shear_angle"])))
        done.append(
            DartRound(tip, lengths, largest, after.iterations, seconds, after.converged, rule)
        )
        rank = largest if after.converged else np.inf
        if best is None or rank < best[0]:
            best = (rank, after, slits, len(done) - 1)
        if after.converged and largest < locking_angle:
            break
    if best is None:
        return DartedPattern(before, None, None, locking_angle, done)
    return DartedPattern(before, best[1], best[2], locking_angle, done, best[3])


def _carried(
    locator: FaceLocator, mesh: SurfaceMesh, coordinates: np.ndarray, points: np.ndarray
) -> np.ndarray:
    """The pattern ``coordinates`` of ``mesh`` read at ``points`` ``(k, 3)`` on it (linear in
    the cell each lies in): the start of the solve with the darts open (their lips together)."""
    faces, weights, _ = locator.locate(points)
    return np.einsum("kc,kcd->kd", weights, coordinates[mesh.cells["triangle"][faces]])
