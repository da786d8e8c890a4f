"""The initial guess: where Newton's method starts, and which plane the pseudo-time path uses.

The paper's start is the orthogonal projection onto a plane; it is also the exact solution at
the beginning of the pseudo-time path. Where the surface is steep to the plane the projection
distorts or folds cells; the least-squares conformal map (LSCM) is then the better start. Both
can fold on rough or strongly curved meshes; Tutte's embedding never folds a disk, and the
automatic choice falls back to it.

Where the energy does not depend on the pattern's rotation (an isotropic law without prestress),
the automatic start is then taken one as-rigid-as-possible step further (:func:`arap_refined`):
on a rough scan the projection is far from the optimum cell by cell (7 Newton iterations on
the 20k-triangle scan-like example), one ARAP step is near it (3), and the optimum is the same.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace

import numpy as np

from ..geometry.arap import ArapFlattening
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
from ..geometry.rigid_fit import rigid_fit
from ..mechanics.rigid import rigid_modes
from ..options import OptionsError
from .linear import IndefiniteMatrixError, LinearSolver, get_solver, unsymmetric_factorizer
from .options import SolveOptions

__all__ = ["ARAP_STEPS", "PROJECTION_MIN_AREA_RATIO", "Start", "arap_refined", "initial_guess"]

#: Where the projection keeps less than this of the area (slopes above 78°) it squashes the
#: pattern; when more than :data:`STEEP_SHARE` of the surface is so steep, the conformal map
#: is the better start.
PROJECTION_MIN_AREA_RATIO = 0.2
STEEP_SHARE = 0.01
#: A start folding more cells than this is not mended locally (the next start is tried).
MEND_AT_MOST = 1000
#: Local–global ARAP steps the automatic start of an isotropic problem is taken further (more
#: gained no Newton iteration on the scan-like example, docs/benchmarks.md).
ARAP_STEPS = 1
_NAMES = {"projection": "the projection", "lscm": "the conformal map", "tutte": "Tutte's embedding"}


@dataclass(frozen=True)
class Start:
    """An initial pattern ``(n, 2)``, what it is (``"projection"``, ``"lscm"``, ``"tutte"`` or
    ``"given"``) and, for a projection, its plane (the pseudo-time path needs it).
    ``refinement``: ``"arap"`` when it was taken further by :func:`arap_refined`."""

    coordinates: np.ndarray
    kind: str
    plane: ProjectionPlane | None
    refinement: str = ""


def initial_guess(
    mesh: SurfaceMesh,
    options: SolveOptions,
    given: np.ndarray | None = None,
    *,
    isotropic: bool = False,
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

    ``isotropic``: the energy does not depend on the pattern's rotation (an isotropic law, no
    prestress); the automatic start is then refined by :func:`arap_refined` (not for
    pseudo-time stepping, whose path starts from the projection itself, nor where a plane is
    named: its projection is the start asked for).
    """
    if given is not None:
        return _given(mesh, options, given)
    plane = projection_plane(mesh, options.plane)
    solver = get_solver(options.linear_solver)
    if options.initial_guess != "auto":
        return _make(mesh, options.initial_guess, plane, solver=solver)
    start = _automatic(mesh, options, plane, solver)
    if isotropic and options.strategy != "pseudo-time" and not options.named_plane:
        return arap_refined(mesh, start, solver=solver)
    return start


def _automatic(
    mesh: SurfaceMesh, options: SolveOptions, plane: ProjectionPlane, solver: LinearSolver
) -> Start:
    steep = squashed_share(mesh, plane, PROJECTION_MIN_AREA_RATIO) > STEEP_SHARE
    order = ["projection", "lscm", "tutte"]
    if options.strategy == "pseudo-time":
        order = ["projection"]
    elif steep and not options.named_plane:
        order = ["lscm", "tutte"]
    folded, conformal = [], None
    for kind in order:
        start = _make(mesh, kind, plane, conformal, solver)
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
                warnings.warn(f"{'; '.join(folded)}: started from {_NAMES[kind]}", stacklevel=4)
            return start
        folded.append(f"{_NAMES[kind]} folds {inverted.size} cell(s)")
    return _make(mesh, order[0], plane, solver=solver)


def arap_refined(
    mesh: SurfaceMesh,
    start: Start,
    steps: int = ARAP_STEPS,
    solver: LinearSolver | None = None,
) -> Start:
    """``start`` taken ``steps`` local–global ARAP steps further (:mod:`vares.geometry.arap`)
    and moved rigidly back onto it: so that the nodes that hold an isotropic pattern's rigid
    modes (:func:`~vares.mechanics.rigid.rigid_modes`, ``"fixed"``: the node of least x, and
    the y of the node of greatest x) are where they were, when they are the same nodes (Newton's
    method then ends at the very pattern it reaches from ``start``); otherwise by least squares
    (the same pattern, moved by a small rigid motion). ``start`` itself where the steps fold a
    cell. ``solver``: the linear solver that factorises the Laplacian (default SciPy's SuperLU;
    PARDISO factorised the 100k-triangle hypar's in a fraction of SuperLU's 2.2 s)."""
    flat = ArapFlattening(mesh) if solver is None else ArapFlattening(mesh, _factorizer(solver))
    x = start.coordinates
    for _ in range(steps):
        x = flat.step(x)
    if inverted_cells(mesh, x).size:
        return start
    x = rigid_fit(x, start.coordinates)
    held = rigid_modes(start.coordinates, "fixed")[0]
    placed = _held_where_they_were(x, start.coordinates, held)
    if placed is not None and np.array_equal(rigid_modes(placed, "fixed")[0], held):
        x = placed
    return replace(start, coordinates=x, refinement="arap")


def _factorizer(solver: LinearSolver):
    """A function from a symmetric positive definite matrix to its solver ``rhs ↦ x``."""

    def factorize(matrix):
        try:
            solver.factorize(matrix.tocsr(), definite=True)
        except IndefiniteMatrixError:  # round-off made a definite-only back end refuse it
            solver.factorize(matrix.tocsr())
        return solver.solve

    return factorize


def _held_where_they_were(x: np.ndarray, target: np.ndarray, held: np.ndarray) -> np.ndarray | None:
    """``x`` moved rigidly so that the node whose dofs ``held`` holds is at its ``target``
    position and the node whose y alone it holds at its ``target`` y (``None`` if no rigid
    motion can)."""
    first = int(np.flatnonzero(~held[0::2])[0])
    second = np.flatnonzero(~held[1::2])
    second = second[second != first]
    if not second.size:
        return None
    second = int(second[0])
    arm = x[second] - x[first]
    rise = target[second, 1] - target[first, 1]
    length = float(np.hypot(*arm))
    if not abs(rise) < length:
        return None
    turn = np.arcsin(rise / length) - np.arctan2(arm[1], arm[0])
    c, s = np.cos(turn), np.sin(turn)
    placed = target[first] + (x - x[first]) @ np.array([[c, s], [-s, c]])
    placed[first] = target[first]
    placed[second, 1] = target[second, 1]  # exactly, not to round-off
    return placed


def _make(
    mesh: SurfaceMesh,
    kind: str,
    plane: ProjectionPlane,
    conformal=None,
    solver: LinearSolver | None = None,
) -> Start:
    """A start of the given kind (Tutte's reuses the ``conformal`` map when it was made). The
    conformal map's normal equations are factorised by ``solver`` (default SciPy's SuperLU);
    Tutte's (mean-value weights: not symmetric) by PARDISO's LU where ``solver`` is PARDISO,
    else by SuperLU."""
    if kind == "projection":
        return Start(plane.project(mesh.points), "projection", plane)
    if kind == "lscm":
        return Start(lscm(mesh, None if solver is None else _factorizer(solver)), "lscm", None)
    lu = None if solver is None else unsymmetric_factorizer(solver.name)
    return Start(tutte(mesh, conformal, lu), "tutte", None)


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
