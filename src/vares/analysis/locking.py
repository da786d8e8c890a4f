"""Stiff-yarn plies on linear cells: a solve with a chosen yarn-strain treatment, and the shear
along the meridians of a cap (the intra-ply shear locking check of DESIGN.md §8).

:func:`solve_yarn_strain` is :func:`vares.solve` with ``yarn_strain`` set (the solve assembles
over the problem's connectivity), returning the problem beside the pattern; with
``continuation`` it reaches a stiff law through softer ones (:class:`ScaledYarns`, the yarn
part of the law scaled; :mod:`vares.solver.continuation`), as ``vares.solve(...,
yarn_continuation=...)`` does. :func:`meridian_shear`
samples a per-cell field along meridians of a surface of revolution about the z axis;
:func:`blank_extent` measures a pattern along its yarns and diagonals.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..geometry.mesh import SurfaceMesh
from ..materials import Fibres, Hyperelastic
from ..mechanics.fields import cell_fields
from ..mechanics.problem import Problem
from ..mechanics.yarn_laws import ScaledYarns, yarn_to_shear_ratio
from ..solver.api import solve
from ..solver.continuation import ContinuationStage, solve_in_stages
from ..solver.options import SolveOptions
from ..solver.result import IterationRecord

__all__ = [
    "ContinuationStage",
    "ScaledYarns",
    "SmoothedSolve",
    "blank_extent",
    "cell_shear_angle",
    "meridian_shear",
    "solve_yarn_strain",
    "yarn_to_shear_ratio",
]


@dataclass
class SmoothedSolve:
    """A pattern ``(n, 2)`` (warp along +x when a warp direction was given), its fibres and
    problem, whether it converged, the Newton iterations, and the seconds it took."""

    coordinates: np.ndarray
    fibres: Fibres
    problem: Problem
    converged: bool
    reason: str | None
    iterations: int
    elapsed: float
    history: list[IterationRecord] = field(default_factory=list)
    stages: list[ContinuationStage] = field(default_factory=list)


def solve_yarn_strain(
    mesh: SurfaceMesh,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    prestress: float | Sequence[float] | np.ndarray | None = None,
    yarn_strain: str = "smoothed",
    yarn_stabilisation: float = 0.0,
    warp_direction: Sequence[float] | None = None,
    initial_guess: np.ndarray | None = None,
    options: SolveOptions | None = None,
    continuation: Sequence[float] = (),
    align_up_to: float | None = None,
    extrapolate: bool = True,
) -> SmoothedSolve:
    """The cutting pattern of ``mesh`` with the yarn strains treated as ``yarn_strain`` says
    (``"element"`` is the formulation :func:`vares.solve` uses) and ``yarn_stabilisation`` the
    share of the yarn part kept per cell (:class:`~vares.mechanics.yarn_smoothing.YarnSmoothing`).

    The strategy and initial guess of ``options`` (default :class:`SolveOptions`), or the given
    ``initial_guess`` ``(n, 2)`` (e.g. the kinematic net's pattern,
    :func:`vares.geometry.drape.kinematic_drape`); ``prestress`` as for :func:`vares.solve`;
    with ``warp_direction`` (a 3D direction) the yarns are turned until the mean erected warp
    follows it.

    ``continuation``: yarn-to-shear ratios ``E/G`` (ascending, below the law's own,
    :func:`yarn_to_shear_ratio`) solved first, the law's yarn part scaled to each
    (:class:`ScaledYarns`), each stage from the last pattern (from the third on, from the
    extrapolation in ``1/ratio`` of the two before), the law itself last (e.g.
    ``(1e2, 1e3, 1e4, 1e5)`` for a law of E/G = 1e6): :func:`vares.solve` with
    ``yarn_continuation`` (:func:`vares.solver.continuation.solve_in_stages`), which always
    aligns the warp. Each stage keeps the per-cell yarn stiffness
    ``yarn_stabilisation × E`` of the law (its share ``yarn_stabilisation × E/E_stage``, at most
    0.5). With ``warp_direction`` the warp is aligned at the stages of ratio up to
    ``align_up_to`` (default: every stage); the later ones hold the rotation and yarn angle of
    the last aligned pattern; ``extrapolate`` false starts every stage from the last pattern.
    The iterations and seconds returned are the stages' sums; each stage is in ``stages``.
    """
    settings = {"yarn_strain": yarn_strain, "yarn_stabilisation": yarn_stabilisation}
    if warp_direction is not None:
        settings["warp_direction"] = tuple(warp_direction)
    chosen = (options or SolveOptions()).replace(**settings, yarn_continuation=tuple(continuation))

    def solve_one(law, stage_options, start):
        return solve(
            mesh, law, thickness, prestress=prestress, options=stage_options, initial_guess=start
        )

    if chosen.yarn_continuation:
        result, stages = solve_in_stages(
            solve_one,
            mesh,
            material,
            chosen,
            initial_guess,
            align_up_to=align_up_to,
            extrapolate=extrapolate,
        )
    else:
        result = solve_one(material, chosen, initial_guess)
        stages = []
    problem = Problem(
        mesh,
        material,
        thickness,
        fibres=result.fibres,
        prestress=prestress,
        yarn_strain=yarn_strain,
        yarn_stabilisation=yarn_stabilisation,
    )
    return SmoothedSolve(
        result.material_coordinates,
        result.fibres,
        problem,
        result.converged,
        result.reason,
        result.iterations,
        result.elapsed,
        result.history,
        stages,
    )


def blank_extent(
    coordinates: np.ndarray, fibres: Fibres, angles: Sequence[float] = (0.0, 90.0, 45.0, -45.0)
) -> np.ndarray:
    """The extent ``max − min`` of a pattern ``(n, 2)`` along directions at ``angles`` [°] to
    its warp (0: the warp, 90: the fill, ±45: the diagonals), ``(len(angles),)`` in the
    pattern's length unit (NaN nodes, where a kinematic net does not reach, left out)."""
    warp = np.arctan2(fibres.warp[1], fibres.warp[0])
    out = []
    for angle in angles:
        t = warp + np.radians(angle)
        along = coordinates @ np.array([np.cos(t), np.sin(t)])
        out.append(float(np.nanmax(along) - np.nanmin(along)))
    return np.array(out)


def cell_shear_angle(
    mesh: SurfaceMesh, coordinates: np.ndarray, material: Hyperelastic, fibres: Fibres
) -> np.ndarray:
    """Yarn shear angle per cell [°] ``(m,)`` (``shear_angle`` of
    :func:`vares.mechanics.cell_fields`; the shear part is per cell in both treatments)."""
    return cell_fields(mesh, coordinates, material, 1.0, fibres=fibres)["shear_angle"]


def meridian_shear(
    mesh: SurfaceMesh,
    values: np.ndarray,
    azimuths: Sequence[float] = (45.0, 135.0, 225.0, 315.0),
    polar_angles: Sequence[float] = (30.0, 45.0, 60.0, 75.0),
    *,
    azimuth_width: float = 3.0,
    polar_width: float = 2.5,
    signed: bool = True,
) -> np.ndarray:
    """Mean of a per-cell field along meridians of a surface about the z axis,
    ``(len(azimuths), len(polar_angles))``.

    A meridian's sample at polar angle ``θ`` [°] is the mean over the cells whose centroid lies
    within ``azimuth_width`` degrees of the azimuth and ``polar_width`` degrees of ``θ``
    (NaN where none does). With ``signed`` the values are multiplied by the sign of
    ``sin 2φ``: the shear of a net seeded at the pole with the warp along x is
    ``γ = ∬ K dA`` over signed yarn lengths, of opposite signs in neighbouring quadrants.
    """
    cells = np.concatenate([c for c in mesh.cells.values()]) if len(mesh.cells) == 1 else None
    if cells is not None:
        centroids = mesh.points[cells].mean(axis=1)
    else:
        centroids = np.concatenate([mesh.points[c].mean(axis=1) for c in mesh.cells.values()])
    radius = np.linalg.norm(centroids, axis=1)
    polar = np.degrees(np.arccos(np.clip(centroids[:, 2] / radius, -1.0, 1.0)))
    azimuth = np.degrees(np.arctan2(centroids[:, 1], centroids[:, 0])) % 360.0
    out = np.full((len(azimuths), len(polar_angles)), np.nan)
    for i, phi in enumerate(azimuths):
        near = np.abs((azimuth - phi + 180.0) % 360.0 - 180.0) < azimuth_width
        sign = np.sign(np.sin(np.radians(2.0 * phi))) if signed else 1.0
        for j, theta in enumerate(polar_angles):
            chosen = near & (np.abs(polar - theta) < polar_width)
            if chosen.any():
                out[i, j] = sign * float(np.mean(values[chosen]))
    return out
