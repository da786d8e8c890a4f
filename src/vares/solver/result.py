"""What a solve returns: the pattern, how it was found, and its per-cell results."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..geometry.flatten import ProjectionPlane, signed_area
from ..geometry.injectivity import AreaMisfit, Overlap
from ..geometry.mesh import SurfaceMesh
from ..materials import Fibres, Hyperelastic
from ..mechanics.fields import cell_fields
from .options import SolveOptions

__all__ = ["IterationRecord", "PatternResult", "StepRecord"]


@dataclass(frozen=True)
class IterationRecord:
    """State at one Newton iteration (iteration 0 is the state a step starts from).

    ``damping`` is the damping coefficient used to reach this state, ``step_length`` the line
    search's step length and ``tangent`` the matrix of that step (``"exact"``, ``"projected"``
    — ``"projected, turned"`` when a pattern free to turn was turned further than the step —
    or ``"damped"``); the last three are 0 or empty at iteration 0. ``factorisations`` and
    ``cg_iterations`` count the linear solver's work since the record before: numeric
    factorisations and conjugate-gradient iterations preconditioned by an earlier
    factorisation (:mod:`vares.solver.reuse`).
    """

    strategy: str
    step: int
    tau: float
    iteration: int
    residual: float
    relative_residual: float
    energy: float
    damping: float
    step_length: float = 0.0
    tangent: str = ""
    factorisations: int = 0
    cg_iterations: int = 0


@dataclass(frozen=True)
class StepRecord:
    """Outcome of one pseudo-time step (a single step for the plain strategies)."""

    strategy: str
    step: int
    tau: float
    iterations: int
    converged: bool
    reason: str | None
    coordinates: np.ndarray | None = field(default=None, repr=False, compare=False)


@dataclass
class PatternResult:
    """A cutting pattern and how it was found.

    Attributes
    ----------
    material_coordinates
        The pattern: 2D coordinates of every mesh node, ``(n, 2)``.
    converged
        True when the final residual met the tolerance on the true surface.
    reason
        Why the solve failed (``None`` when converged).
    energy
        Energy of the pattern erected onto the surface (thickness × ∫Ψ̃ dA).
    history
        One :class:`IterationRecord` per Newton iteration of every step tried.
    steps
        One :class:`StepRecord` per pseudo-time step tried, failed ones included.
    strategy
        The path taken, e.g. ``["pseudo-time"]`` or ``["pseudo-time", "damping"]``.
    options
        The options of the solve (:class:`SolveOptions`), defaults included.
    fibres
        Warp and fill directions in the pattern frame.
    initial_guess
        Where the solve started: ``"projection"``, ``"lscm"`` or ``"given"``.
    warp_direction, warp_deviation
        The prescribed 3D warp direction (or None) and the final 3D-area-weighted mean angle
        (degrees) between it and the erected warp.
    overlap
        Where the pattern overlaps itself (:class:`vares.geometry.injectivity.Overlap`), when
        it does: such a pattern is not converged (it cannot be cut in one piece).
    area_misfit
        How far the pattern's area is from the surface's
        (:class:`vares.geometry.injectivity.AreaMisfit`), when it is not within a factor 1.5
        of it: such a pattern is not converged either (no fabric can be erected from it).
    linear_solver, elapsed
        The sparse solver used and the wall time of the solve (seconds).
    warm_up
        Seconds spent before the solve loading the compiled kernels (compiling them, the first
        time on a machine): 0 once this process has solved a mesh of the same kind.
    """

    mesh: SurfaceMesh
    material: Hyperelastic
    thickness: float
    material_coordinates: np.ndarray
    converged: bool
    reason: str | None
    energy: float
    history: list[IterationRecord]
    steps: list[StepRecord]
    strategy: list[str]
    linear_solver: str
    elapsed: float
    options: SolveOptions = field(default_factory=SolveOptions)
    fibres: Fibres | None = None
    prestress: np.ndarray | None = None
    plane: ProjectionPlane | None = None
    orientation: str = "held"
    initial_guess: str = "projection"
    warp_direction: np.ndarray | None = None
    warp_deviation: float | None = None
    overlap: Overlap | None = None
    area_misfit: AreaMisfit | None = None
    warm_up: float = 0.0
    _fields: dict[str, np.ndarray] | None = field(default=None, repr=False)

    @property
    def iterations(self) -> int:
        """Number of Newton iterations (linear solves) over all steps."""
        return sum(1 for r in self.history if r.iteration > 0)

    @property
    def factorisations(self) -> int:
        """Numeric factorisations of the tangent over all steps."""
        return sum(r.factorisations for r in self.history)

    @property
    def cg_iterations(self) -> int:
        """Conjugate-gradient iterations (preconditioned by an earlier factorisation)."""
        return sum(r.cg_iterations for r in self.history)

    @property
    def uncuttable(self) -> bool:
        """The solve found a pattern that is no cutting pattern: it overlaps itself, or its
        area is far from the surface's. Its files are written, its DXF only when asked for."""
        return self.overlap is not None or self.area_misfit is not None

    @property
    def surface_area(self) -> float:
        return self.mesh.area

    @property
    def pattern_area(self) -> float:
        return signed_area(self.mesh, self.material_coordinates)

    @property
    def final_relative_residual(self) -> float | None:
        return self.history[-1].relative_residual if self.history else None

    @property
    def fields(self) -> dict[str, np.ndarray]:
        """Per-cell results (global cell order); see :func:`vares.mechanics.cell_fields`."""
        if self._fields is None:
            self._fields = cell_fields(
                self.mesh,
                self.material_coordinates,
                self.material,
                self.thickness,
                fibres=self.fibres,
                prestress=self.prestress,
                warp_direction=self.warp_direction,
            )
        return self._fields
