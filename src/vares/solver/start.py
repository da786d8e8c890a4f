"""The initial guess: where Newton's method starts, and which plane the pseudo-time path uses.

The paper's start is the orthogonal projection onto a plane; it is also the exact solution at
the beginning of the pseudo-time path. Where the surface is steep to the plane the projection
distorts or folds cells; the least-squares conformal map (LSCM) is then the better start. Both
can fold on rough or strongly curved meshes; Tutte's embedding never folds a disk, and the
automatic choice falls back to it.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..geometry.flatten import (
    ProjectionPlane,
    inverted_cells,
    lscm,
    projection_plane,
    squashed_share,
    tutte,
    untangle,
)
from ..geometry.mesh import SurfaceMesh
from ..options import OptionsError
from .options import SolveOptions

__all__ = ["PROJECTION_MIN_AREA_RATIO", "Start", "initial_guess"]

#: Where the projection keeps less than this of the area (slopes above 78°) it squashes the
#: pattern; when more than :data:`STEEP_SHARE` of the surface is so steep, the conformal map
#: is the better start.
PROJECTION_MIN_AREA_RATIO = 0.2
STEEP_SHARE = 0.01
#: A start folding more cells than this is not mended locally (the next start is tried).
MEND_AT_MOST = 1000
_NAMES = {"projection": "the projection", "lscm": "the conformal map", "tutte": "Tutte's embedding"}


@dataclass(frozen=True)
class Start:
    """An initial pattern ``(n, 2)``, what it is (``"projection"``, ``"lscm"``, ``"tutte"`` or
    ``"given"``) and, for a projection, its plane (the pseudo-time path needs it)."""

    coordinates: np.ndarray
    kind: str
    plane: ProjectionPlane | None


def initial_guess(
    mesh: SurfaceMesh, options: SolveOptions, given: np.ndarray | None = None
) -> Start:
    """The start that ``options.initial_guess`` asks for, or the ``given`` coordinates.

    ``"auto"`` takes the projection onto ``options.plane``, unless no plane is named and the
    best-fit projection flattens more than :data:`STEEP_SHARE` of the surface below
    :data:`PROJECTION_MIN_AREA_RATIO` of its area; then the conformal map. A projection that
    folds up to :data:`MEND_AT_MOST` cells (a scan's noisy slivers, a local overhang) is mended
    where it folds (:func:`untangle`). A start that still folds is passed over (with a warning)
    for the next, down to Tutte's embedding (not with pseudo-time stepping, whose path needs the
    projection). The conformal map is not mended: where it folds, it is distorted far around
    (a steep saddle mended from it ended in a minimum that laps over itself, found again from
    Tutte's embedding at twice the cost).
    """
    if given is not None:
        return _given(mesh, options, given)
    plane = projection_plane(mesh, options.plane)
    if options.initial_guess != "auto":
        return _make(mesh, options.initial_guess, plane)
    steep = squashed_share(mesh, plane, PROJECTION_MIN_AREA_RATIO) > STEEP_SHARE
    order = ["projection", "lscm", "tutte"]
    if options.strategy == "pseudo-time":
        order = ["projection"]
    elif steep and not options.named_plane:
        order = ["lscm", "tutte"]
    folded, conformal = [], None
    for kind in order:
        start = _make(mesh, kind, plane, conformal)
        conformal = start.coordinates if kind == "lscm" else conformal
        inverted = inverted_cells(mesh, start.coordinates)
        if inverted.size and kind == "projection" and inverted.size <= MEND_AT_MOST:
            mended = untangle(mesh, start.coordinates)
            if mended is not None:
                folded.append(
                    f"{_NAMES[kind]} folds {inverted.size} cell(s), mended where they are"
                )
                start, inverted = Start(mended, kind, start.plane), inverted[:0]
        if not inverted.size:
            if folded:
                warnings.warn(f"{'; '.join(folded)}: started from {_NAMES[kind]}", stacklevel=3)
            return start
        folded.append(f"{_NAMES[kind]} folds {inverted.size} cell(s)")
    return _make(mesh, order[0], plane)


def _make(mesh: SurfaceMesh, kind: str, plane: ProjectionPlane, conformal=None) -> Start:
    """A start of the given kind (Tutte's reuses the ``conformal`` map when it was made)."""
    if kind == "projection":
        return Start(plane.project(mesh.points), "projection", plane)
    if kind == "lscm":
        return Start(lscm(mesh), "lscm", None)
    return Start(tutte(mesh, conformal), "tutte", None)


def _given(mesh: SurfaceMesh, options: SolveOptions, given: np.ndarray) -> Start:
    if options.strategy == "pseudo-time":
        raise OptionsError(
            None,
            "pseudo-time stepping starts from the projection; drop the initial guess or "
            "choose another strategy",
        )
    start = np.array(given, dtype=float)
    if start.shape != (mesh.num_points, 2) or not np.all(np.isfinite(start)):
        raise OptionsError(
            "initial_guess",
            f"must be finite coordinates of shape ({mesh.num_points}, 2); got {start.shape}",
        )
    return Start(start, "given", None)
