"""Solution strategies: Newton–Raphson, pseudo-time stepping, damping and the automatic default.

All strategies minimise the same energy (:class:`vares.problem.Problem`) over the pattern
coordinates with the consistent tangent; they differ in the path they take:

``"newton"``
    Full Newton steps on the final surface from the initial guess.
``"pseudo-time"``
    The homotopy of DESIGN.md §1: the surface is raised from its projection onto the initial
    guess plane (where the projection is the exact solution) to its true shape in ``steps``
    equal steps, prestress ramped alike; each step is solved by Newton from the previous pattern.
    A step that fails is halved (cut back) and retried.
``"damping"``
    Newton with a proximal term ``(c/2)‖X − X_k‖²`` (Levenberg–Marquardt): steps that would
    raise the energy or invert a cell are rejected and ``c`` grows; ``c`` shrinks with the
    residual so the final convergence stays quadratic.
``"auto"`` (default)
    Pseudo-time stepping that starts with a single step (plain Newton) and cuts back only where
    needed; if even small steps fail, damped pseudo-time stepping. The history records the path.

Inverted pattern cells (``det J ≤ 0``) are never accepted.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp

from .assembly import Assembler
from .elements import ELEMENTS
from .initial import (
    PlaneSpec,
    ProjectionPlane,
    lscm,
    projection_distortion,
    projection_plane,
    signed_area,
)
from .kernels import determinant
from .linalg import LinearSolver, SingularMatrixError, get_solver
from .materials import Fibres, Hyperelastic
from .mesh import SurfaceMesh
from .orientation import warp_deviation
from .problem import Problem

__all__ = ["STRATEGIES", "IterationRecord", "PatternResult", "StepRecord", "solve"]

STRATEGIES = ("auto", "newton", "pseudo-time", "damping")
ORIENTATIONS = ("held", "free")
INITIAL_GUESSES = ("auto", "projection", "lscm")
#: Below this smallest projected/3D area ratio (about 78° of slope) the projection is no start.
_PROJECTION_MIN_AREA_RATIO = 0.2
#: The mean erected warp follows a prescribed direction to this angle (radians).
_ALIGNMENT_TOLERANCE = 1e-10
#: Relative residual below which globalised Newton returns from projected to exact tangents.
_EXACT_TANGENT_BELOW = 1e-2


@dataclass(frozen=True)
class IterationRecord:
    """State at one Newton iteration (iteration 0 is the state a step starts from).

    ``damping`` is the damping coefficient used to reach this state, ``step_length`` the line
    search's step length and ``tangent`` the matrix of that step (``"exact"``, ``"projected"``
    or ``"damped"``); the last three are 0 or empty at iteration 0.
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
    fibres
        Warp and fill directions in the pattern frame.
    initial_guess
        Where the solve started: ``"projection"``, ``"lscm"`` or ``"given"``.
    warp_direction, warp_deviation
        The prescribed 3D warp direction (or None) and the final 3D-area-weighted mean angle
        (degrees) between it and the erected warp.
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
    fibres: Fibres | None = None
    prestress: np.ndarray | None = None
    plane: ProjectionPlane | None = None
    orientation: str = "held"
    initial_guess: str = "projection"
    warp_direction: np.ndarray | None = None
    warp_deviation: float | None = None
    _fields: dict[str, np.ndarray] | None = field(default=None, repr=False)

    @property
    def iterations(self) -> int:
        """Number of Newton iterations (linear solves) over all steps."""
        return sum(1 for r in self.history if r.iteration > 0)

    @property
    def surface_area(self) -> float:
        return self.mesh.area

    @property
    def pattern_area(self) -> float:
        return signed_area(self.mesh, self.material_coordinates)

    @property
    def fields(self) -> dict[str, np.ndarray]:
        """Per-cell results (global cell order); see :func:`vares.analysis.cell_fields`."""
        if self._fields is None:
            from .analysis import cell_fields

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


class _Failure(Exception):
    def __init__(self, reason: str, coordinates: np.ndarray) -> None:
        super().__init__(reason)
        self.reason = reason
        self.coordinates = coordinates


def _describe(ids: np.ndarray, limit: int = 5) -> str:
    shown = ", ".join(str(int(i)) for i in ids[:limit])
    return f"{ids.size} cell(s) ({shown}{', …' if ids.size > limit else ''})"


@dataclass
class _Context:
    """What every step of one solve shares."""

    assembler: Assembler
    linear_solver: LinearSolver
    residual_tolerance: float
    energy_noise: float
    force_scale: float
    max_iterations: int
    history: list[IterationRecord]
    steps: list[StepRecord]
    callback: Callable[[IterationRecord], None] | None
    constraint: np.ndarray | None = None

    def residual(self, gradient: np.ndarray) -> np.ndarray:
        """The residual over the free dofs, less its component along the linear constraint."""
        r = gradient.ravel()[self.assembler.free]
        if self.constraint is not None:
            r = r - self.constraint * (self.constraint @ r)
        return r

    def step(self, matrix: sp.csr_matrix, rhs: np.ndarray) -> np.ndarray:
        """Solve the Newton system, bordered by the linear constraint when there is one."""
        if self.constraint is None:
            self.linear_solver.factorize(matrix)
            return self.linear_solver.solve(rhs)
        column = sp.csr_matrix(self.constraint[:, None])
        bordered = sp.bmat([[matrix, column], [column.T, None]], format="csr")
        self.linear_solver.factorize(bordered)
        return self.linear_solver.solve(np.append(rhs, 0.0))[:-1]


def _step_bound(problem: Problem, x: np.ndarray, delta: np.ndarray) -> float:
    """Largest α such that ``x + α Δ`` keeps every ``det J`` positive (``inf`` if any α does).

    ``det(J + α D) = det J + α (J₀₀D₁₁ + D₀₀J₁₁ − J₀₁D₁₀ − D₀₁J₁₀) + α² det D`` at each check point.
    """
    bound = np.inf
    for cell_type, cells in problem.mesh.cells.items():
        element = ELEMENTS[cell_type]
        J = element.jacobians(x, cells, at="check")
        D = element.jacobians(delta, cells, at="check")
        a = determinant(D)
        b = J[..., 0, 0] * D[..., 1, 1] + D[..., 0, 0] * J[..., 1, 1]
        b = b - J[..., 0, 1] * D[..., 1, 0] - D[..., 0, 1] * J[..., 1, 0]
        c = determinant(J)
        with np.errstate(divide="ignore", invalid="ignore"):
            root = np.sqrt(np.maximum(b * b - 4 * a * c, 0.0))
            # the two roots, written to avoid cancellation; keep the positive ones
            q = -0.5 * (b + np.copysign(root, b))
            candidates = np.stack([q / a, c / q])
        real = (b * b - 4 * a * c >= 0) | (np.abs(a) < 1e-300)
        linear = np.where(np.abs(a) < 1e-300, -c / np.where(b == 0, np.inf, b), np.inf)
        candidates = np.where(real, candidates, np.inf)
        candidates = np.concatenate([candidates, linear[None]])
        candidates = np.where((candidates > 0) & np.isfinite(candidates), candidates, np.inf)
        bound = min(bound, float(candidates.min(initial=np.inf)))
    return bound


def _newton(
    problem: Problem,
    coordinates: np.ndarray,
    ctx: _Context,
    *,
    strategy: str,
    step: int,
    tau: float,
    method: str = "line-search",
    damping: float = 1.0,
) -> np.ndarray:
    """Newton–Raphson on one surface from ``coordinates``; returns the converged pattern.

    ``method`` is

    - ``"full"``: plain Newton, full steps; a step that inverts a cell ends it.
    - ``"line-search"``: globalised Newton. The step is bounded so that every ``det J`` stays
      positive and backtracked until the energy decreases enough (Armijo). Far from the
      solution (relative residual at or above ``_EXACT_TANGENT_BELOW``) the tangent is the
      quadrature-point-wise positive semi-definite projection of the exact one (projected
      Newton: always a descent direction); below it the exact tangent, so the final convergence
      is quadratic, with the projection as fallback whenever the exact step is no descent.
    - ``"damped"``: each iteration solves ``(K + c I) ΔX = −r`` and accepts the step only if it
      lowers the energy without inverting a cell; ``c`` (starting at ``damping`` × the mean
      tangent diagonal) follows the gain ratio of actual to predicted decrease (Nielsen's rule)
      and is capped in proportion to the residual, so it vanishes as the iteration converges.

    Raises :class:`_Failure` when it does not converge.
    """
    free = ctx.assembler.free
    x = coordinates.copy()
    initial_residual = None
    identity = sp.identity(ctx.assembler.num_free, format="csr")
    c, growth = None, 2.0
    step_length, tangent = 0.0, ""
    for iteration in range(ctx.max_iterations + 1):
        evaluation = problem.evaluate(x, order=2)
        residual_vector = ctx.residual(ctx.assembler.vector(evaluation.gradients))
        residual = float(np.linalg.norm(residual_vector))
        initial_residual = residual if initial_residual is None else initial_residual
        converged = residual <= ctx.residual_tolerance
        # far from the solution (by the residual) the projected tangent, near it the exact one
        projected = (
            method == "line-search"
            and not converged
            and residual >= _EXACT_TANGENT_BELOW * ctx.force_scale
        )
        hessians = problem.projected_hessians(evaluation) if projected else evaluation.hessians
        matrix = None if converged else ctx.assembler.matrix(hessians)
        if method == "damped" and matrix is not None:
            scale = damping * float(np.mean(np.abs(matrix.diagonal())))
            cap = scale * min(1.0, residual / initial_residual) if initial_residual > 0 else scale
            c = cap if c is None else min(c, cap)
        record = IterationRecord(
            strategy,
            step,
            tau,
            iteration,
            residual,
            residual / ctx.force_scale,
            evaluation.energy,
            c or 0.0,
            step_length,
            tangent,
        )
        ctx.history.append(record)
        if ctx.callback is not None:
            ctx.callback(record)
        if not (np.isfinite(residual) and np.isfinite(evaluation.energy)):
            raise _Failure("non-finite energy or residual", x)
        if converged:
            return x
        if iteration == ctx.max_iterations:
            raise _Failure(f"iteration limit ({ctx.max_iterations}) reached", x)

        if method == "full":
            try:
                delta = ctx.step(matrix, -residual_vector)
            except SingularMatrixError as exc:
                raise _Failure(f"singular tangent ({exc})", x) from exc
            trial = x.copy()
            trial.ravel()[free] += delta
            inverted = problem.inverted_cells(trial)
            if inverted.size:
                raise _Failure(f"inverted elements: {_describe(inverted)}", x)
            x, step_length, tangent = trial, 1.0, "exact"
            continue

        if method == "damped":
            for _attempt in range(60):
                try:
                    delta = ctx.step(matrix + c * identity, -residual_vector)
                except SingularMatrixError:
                    c, growth = c * growth, 2.0 * growth
                    continue
                trial = x.copy()
                trial.ravel()[free] += delta
                predicted = -(residual_vector @ delta + 0.5 * delta @ (matrix @ delta))
                actual = evaluation.energy - problem.energy(trial)
                if predicted > 0 and actual >= -ctx.energy_noise:
                    gain = actual / predicted
                    c *= max(1.0 / 3.0, 1.0 - (2.0 * gain - 1.0) ** 3)
                    growth = 2.0
                    break
                c, growth = c * growth, 2.0 * growth
            else:
                raise _Failure("damping could not find an admissible step", x)
            x, step_length, tangent = trial, 1.0, "damped"
            continue

        # globalised Newton: exact tangent first, projected where it gives no descent
        for attempt in ("projected",) if projected else ("exact", "projected"):
            if attempt == "projected" and not projected:
                projected = True
                matrix = ctx.assembler.matrix(problem.projected_hessians(evaluation))
            try:
                delta = ctx.step(matrix, -residual_vector)
            except SingularMatrixError:
                continue
            slope = float(residual_vector @ delta)
            if not slope < 0:
                continue
            full = np.zeros_like(x)
            full.ravel()[free] = delta
            alpha = min(1.0, 0.9 * _step_bound(problem, x, full))
            accepted = False
            for _backtrack in range(40):
                trial = x + alpha * full
                energy = problem.energy(trial)
                if energy <= evaluation.energy + 1e-4 * alpha * slope + ctx.energy_noise:
                    accepted = True
                    break
                alpha *= 0.5
            if accepted:
                break
        else:
            raise _Failure("the line search found no decrease of the energy", x)
        tangent = "projected" if projected else "exact"
        x, step_length = trial, alpha
    raise AssertionError("unreachable")


def _run_steps(
    base: Problem,
    plane: ProjectionPlane,
    start: np.ndarray,
    taus: Sequence[float],
    ctx: _Context,
    *,
    strategy: str,
    method: str,
    damping: float,
    min_step: float,
) -> np.ndarray:
    """Pseudo-time stepping over the planned ``taus`` with cut-back on failure."""
    planned = [float(t) for t in taus]
    x, tau = start, 0.0
    step = 0
    while planned:
        target = planned[0]
        step += 1
        problem = (
            base
            if target == 1.0
            else base.with_surface(plane.lift(base.points, target), prestress_factor=target)
        )
        before = len(ctx.history)
        try:
            x = _newton(
                problem,
                x,
                ctx,
                strategy=strategy,
                step=step,
                tau=target,
                method=method,
                damping=damping,
            )
        except _Failure as failure:
            ctx.steps.append(
                StepRecord(
                    strategy, step, target, len(ctx.history) - before - 1, False, failure.reason
                )
            )
            if target - tau <= min_step:
                raise _Failure(
                    f"{failure.reason} at τ = {target:.4g}; step size fell below {min_step:.3g}",
                    x,
                ) from None
            planned.insert(0, 0.5 * (tau + target))
            continue
        ctx.steps.append(
            StepRecord(strategy, step, target, len(ctx.history) - before - 1, True, None, x)
        )
        tau = planned.pop(0)
    return x


def _rigid_modes(coordinates: np.ndarray, rotation: str) -> tuple[np.ndarray, np.ndarray | None]:
    """Free-dof mask and linear rotation constraint that remove the pattern's rigid modes.

    The node with the smallest pattern x is held (translations). The rotation is

    - ``"fixed"`` (isotropic laws, for which it is a zero mode): the y coordinate of the node
      with the largest x is held too;
    - ``"held"`` (anisotropic laws with a given orientation): the mean rotation about the
      centroid stays that of ``coordinates``, a linear constraint ``cᵀΔX = 0`` (``c`` the rigid
      rotation field, blind to translations, so the choice of the held node does not matter)
      whose reaction is a torque spread over the pattern like a rigid rotation, not a point
      force;
    - ``"free"``: the energy chooses it.
    """
    free = np.ones(coordinates.size, dtype=bool)
    first = int(np.argmin(coordinates[:, 0]))
    free[2 * first : 2 * first + 2] = False
    if rotation == "fixed":
        free[2 * int(np.argmax(coordinates[:, 0])) + 1] = False
        return free, None
    if rotation == "free":
        return free, None
    arm = coordinates - coordinates.mean(axis=0)
    field_ = np.column_stack([-arm[:, 1], arm[:, 0]]).ravel()[free]
    return free, field_ / np.linalg.norm(field_)


def _align_warp(
    make_problem: Callable[[Fibres], Problem],
    coordinates: np.ndarray,
    fibres: Fibres,
    direction: np.ndarray,
    ctx: _Context,
    damping: float,
) -> tuple[np.ndarray, Fibres, float]:
    """Turn the fibres in the pattern until the mean erected warp follows ``direction``.

    Secant iteration on the warp angle (the deviation changes by about the same angle as the
    warp); each new angle is solved by Newton from the previous pattern, whose rotation stays
    held. Returns the pattern, the fibres and the final mean deviation (radians).
    """
    problem = make_problem(fibres)
    offset = _angle(fibres.fill) - _angle(fibres.warp)
    theta = _angle(fibres.warp)
    deviation, _ = warp_deviation(problem.mesh, coordinates, fibres.warp, direction)
    slope = 1.0
    for outer in range(1, 16):
        if abs(deviation) <= _ALIGNMENT_TOLERANCE:
            break
        new_theta = theta - np.degrees(deviation / slope)
        fibres = Fibres.from_angles(new_theta, new_theta + offset)
        if problem.orientation_matters:
            problem = make_problem(fibres)
            before = len(ctx.history)
            try:
                coordinates = _newton(
                    problem, coordinates, ctx, strategy="warp alignment", step=outer, tau=1.0
                )
            except _Failure:
                coordinates = _newton(
                    problem,
                    coordinates,
                    ctx,
                    strategy="warp alignment",
                    step=outer,
                    tau=1.0,
                    method="damped",
                    damping=damping,
                )
            ctx.steps.append(
                StepRecord(
                    "warp alignment",
                    outer,
                    1.0,
                    len(ctx.history) - before - 1,
                    True,
                    None,
                    coordinates,
                )
            )
        new_deviation, _ = warp_deviation(problem.mesh, coordinates, fibres.warp, direction)
        if new_theta != theta and new_deviation != deviation:
            slope = (new_deviation - deviation) / np.radians(new_theta - theta)
        theta, deviation = new_theta, new_deviation
    if abs(deviation) > _ALIGNMENT_TOLERANCE:
        raise _Failure(
            f"the warp could not be aligned with the direction (mean deviation "
            f"{np.degrees(deviation):.3g}°)",
            coordinates,
        )
    return coordinates, fibres, deviation


def _angle(vector: np.ndarray) -> float:
    return float(np.degrees(np.arctan2(vector[1], vector[0])))


def _rotated(coordinates: np.ndarray, degrees: float) -> np.ndarray:
    """Points ``(n, 2)`` turned counter-clockwise by ``degrees`` about the origin."""
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return coordinates @ np.array([[c, s], [-s, c]])


def solve(
    mesh: SurfaceMesh,
    material: Hyperelastic,
    thickness: float = 1.0,
    *,
    warp_angle: float = 0.0,
    fill_angle: float | None = None,
    warp_direction: Sequence[float] | np.ndarray | None = None,
    orientation: str = "held",
    prestress: float | Sequence[float] | np.ndarray | None = None,
    strategy: str = "auto",
    steps: int = 3,
    initial_guess: str | np.ndarray | None = None,
    plane: PlaneSpec = None,
    tolerance: float = 1e-10,
    max_iterations: int = 50,
    damping: float = 1.0,
    linear_solver: str | None = None,
    callback: Callable[[IterationRecord], None] | None = None,
) -> PatternResult:
    """Compute the cutting pattern of ``mesh`` that minimises the erection energy.

    Parameters
    ----------
    mesh
        The 3D surface.
    material, thickness
        Hyperelastic law and membrane thickness (use 1 for laws given as force per length).
    warp_angle, fill_angle
        Yarn directions in the pattern plane, degrees from the pattern x-axis (the first axis of
        the initial-guess plane); the fill defaults to 90° from the warp.
    warp_direction
        A 3D direction the warp must follow on the erected surface: the fibres are turned in
        the pattern until the 3D-area-weighted mean angle between the erected warp ``F Φ₁`` and
        this direction (projected on the surface) is zero, and the pattern is returned with the
        warp along +x. Overrides ``warp_angle`` (the fill keeps its angle to the warp).
    orientation
        For anisotropic laws or a prestress (whenever the energy depends on the yarn
        directions) without ``warp_direction``: ``"held"`` (default) keeps the pattern's
        rotation that of the initial guess, so the yarns run at ``warp_angle`` to the
        initial-guess plane's axes; ``"free"`` lets the energy choose the rotation.
    prestress
        Intended prestress along the yarns, force per length (e.g. kN/m): a number
        (isotropic), ``(warp, fill)``, ``(warp, fill, shear)``, or one such row per cell. It
        enters the energy as ``− S_pre : E`` and is ramped with the pseudo-time steps.
    strategy
        ``"auto"`` (default), ``"newton"``, ``"pseudo-time"`` or ``"damping"`` (module docs).
    steps
        Number of equal pseudo-time steps for ``"pseudo-time"``.
    initial_guess
        ``None``/``"auto"`` (default): the projection onto ``plane``, unless no plane is named
        and the best-fit projection folds a cell or flattens one below 0.2 of its area (slopes
        above about 78°), then the least-squares conformal map; ``"projection"``; ``"lscm"``;
        or pattern coordinates ``(n, 2)``. Pseudo-time stepping needs the projection.
    plane
        Plane of the projection: ``None``/``"best-fit"``, ``"xy"``, ``"yz"``, ``"zx"`` or a normal.
    tolerance
        Convergence when ‖residual‖ ≤ tolerance × stiffness × thickness × √area (the residual is
        a force; this reference force makes the tolerance independent of units and mesh size).
    max_iterations
        Newton iterations per step.
    damping
        Initial damping factor of the ``"damping"`` strategy, relative to the mean tangent diagonal.
    linear_solver
        Name of a linear solver (:func:`vares.linalg.available_solvers`); default: the fastest.
    callback
        Called with every :class:`IterationRecord` as the solve proceeds (progress display).

    Returns
    -------
    PatternResult
        Always returned; ``converged`` and ``reason`` tell whether and why not.
    """
    if strategy not in STRATEGIES:
        raise ValueError(f"unknown strategy {strategy!r}; choose from {', '.join(STRATEGIES)}")
    if orientation not in ORIENTATIONS:
        raise ValueError(
            f"unknown orientation {orientation!r}; choose from {', '.join(ORIENTATIONS)}"
        )
    if warp_direction is not None and orientation == "free":
        raise ValueError("a warp direction fixes the orientation; it cannot also be free")
    if not (isinstance(steps, int | np.integer) and steps >= 1):
        raise ValueError(f"steps must be a positive integer; got {steps!r}")
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"tolerance must be positive; got {tolerance!r}")
    if not (isinstance(max_iterations, int | np.integer) and max_iterations >= 1):
        raise ValueError(f"max_iterations must be a positive integer; got {max_iterations!r}")
    if not (np.isfinite(damping) and damping > 0):
        raise ValueError(f"damping must be positive; got {damping!r}")
    for name, value in (("warp_angle", warp_angle), ("fill_angle", fill_angle)):
        if value is not None and not np.isfinite(value):
            raise ValueError(f"{name} must be a finite angle in degrees; got {value!r}")
    started = time.perf_counter()
    fibres = Fibres.from_angles(warp_angle, fill_angle)

    def make_problem(fibres: Fibres) -> Problem:
        return Problem(mesh, material, thickness, fibres=fibres, prestress=prestress)

    problem = make_problem(fibres)
    projection = None
    if initial_guess is None or isinstance(initial_guess, str):
        guess = initial_guess or "auto"
        if guess not in INITIAL_GUESSES:
            raise ValueError(
                f"unknown initial guess {guess!r}; choose from {', '.join(INITIAL_GUESSES)} "
                "or give coordinates"
            )
        if strategy == "pseudo-time" and guess == "lscm":
            raise ValueError("pseudo-time stepping starts from the projection, not from LSCM")
        projection = projection_plane(mesh, plane)
        if guess == "auto":
            steep = projection_distortion(mesh, projection) < _PROJECTION_MIN_AREA_RATIO
            use_lscm = plane is None and strategy != "pseudo-time" and steep
            guess = "lscm" if use_lscm else "projection"
        if guess == "projection":
            start = projection.project(mesh.points)
        else:
            start, projection = lscm(mesh), None
    else:
        if strategy == "pseudo-time":
            raise ValueError(
                "pseudo-time stepping starts from the projection; "
                "drop initial_guess or choose another strategy"
            )
        guess = "given"
        start = np.array(initial_guess, dtype=float)
        if start.shape != (mesh.num_points, 2) or not np.all(np.isfinite(start)):
            raise ValueError(
                f"initial_guess must be finite with shape ({mesh.num_points}, 2); got {start.shape}"
            )
    direction = None
    if warp_direction is not None:
        direction = np.asarray(warp_direction, dtype=float)
        if direction.shape != (3,) or not np.all(np.isfinite(direction)) or not direction.any():
            raise ValueError(f"warp_direction must be a non-zero 3-vector; got {warp_direction!r}")

    rotation = orientation if problem.orientation_matters else "fixed"
    free, constraint = _rigid_modes(start, rotation)
    ctx = _Context(
        assembler=Assembler(mesh, free),
        linear_solver=get_solver(linear_solver),
        residual_tolerance=tolerance * problem.force_scale,
        energy_noise=1e-13 * material.stiffness_scale * problem.thickness * mesh.area,
        force_scale=problem.force_scale,
        max_iterations=max_iterations,
        history=[],
        steps=[],
        callback=callback,
        constraint=constraint,
    )

    path: list[str] = []
    reason = None
    x = start
    deviation = None
    inverted = problem.inverted_cells(start)
    if inverted.size:
        source = {"projection": "the projection onto the plane", "lscm": "the conformal map"}.get(
            guess, "the initial guess"
        )
        reason = (
            f"{source} inverts {_describe(inverted)}; choose another plane or supply an "
            "initial guess that does not fold"
        )
    else:
        if direction is not None:
            # Start with the fibres turned so that the initial guess meets the direction.
            initial_deviation, _ = warp_deviation(mesh, start, fibres.warp, direction)
            theta = warp_angle - np.degrees(initial_deviation)
            offset = _angle(fibres.fill) - _angle(fibres.warp)
            fibres = Fibres.from_angles(theta, theta + offset)
            problem = make_problem(fibres)
        resume = start  # a whole-surface attempt goes on from where the last one stopped
        for name, taus, method in _plan(strategy, steps, projection is not None):
            path.append(name)
            try:
                if taus is None:
                    x = _single(problem, resume, ctx, name, method, damping)
                else:
                    x = _run_steps(
                        problem,
                        projection,
                        start,
                        taus,
                        ctx,
                        strategy=name,
                        method=method,
                        damping=damping,
                        min_step=1.0 / 1024,
                    )
                reason = None
                break
            except _Failure as failure:
                reason = failure.reason
                x = failure.coordinates
                if taus is None:
                    resume = x  # never inverted, lower energy than the start
        if reason is None and direction is not None:
            path.append("warp alignment")
            try:
                x, fibres, deviation = _align_warp(make_problem, x, fibres, direction, ctx, damping)
            except _Failure as failure:
                reason, x = failure.reason, failure.coordinates
            # Present the pattern with the warp along +x, as it comes off the roll.
            turn = _angle(fibres.warp)
            x = _rotated(x, -turn)
            for index, record in enumerate(ctx.steps):
                if record.coordinates is not None:
                    ctx.steps[index] = replace(
                        record, coordinates=_rotated(record.coordinates, -turn)
                    )
            fibres = Fibres.from_angles(0.0, _angle(fibres.fill) - turn)
            problem = make_problem(fibres)
    converged = reason is None
    energy = problem.energy(x)
    return PatternResult(
        mesh=mesh,
        material=material,
        thickness=problem.thickness,
        material_coordinates=x,
        converged=converged,
        reason=reason,
        energy=energy,
        history=ctx.history,
        steps=ctx.steps,
        strategy=path,
        linear_solver=ctx.linear_solver.name,
        elapsed=time.perf_counter() - started,
        fibres=fibres,
        prestress=problem.prestress,
        plane=projection,
        orientation="direction" if direction is not None else rotation,
        initial_guess=guess,
        warp_direction=direction,
        warp_deviation=None if deviation is None else float(np.degrees(deviation)),
    )


def _plan(strategy: str, steps: int, have_plane: bool) -> list[tuple[str, list[float] | None, str]]:
    """The sequence of attempts: (name, pseudo-time targets or None, Newton method)."""
    uniform = list(np.arange(1, steps + 1) / steps)
    if strategy == "newton":
        return [("newton", None, "full")]
    if strategy == "damping":
        return [("damping", None, "damped")]
    if strategy == "pseudo-time":
        return [("pseudo-time", uniform, "full")]
    quarters = [0.25, 0.5, 0.75, 1.0]
    if have_plane:  # auto
        return [
            ("globalised newton", None, "line-search"),
            ("pseudo-time", quarters, "line-search"),
            ("damped pseudo-time", quarters, "damped"),
        ]
    return [("globalised newton", None, "line-search"), ("damping", None, "damped")]


def _single(
    problem: Problem, start: np.ndarray, ctx: _Context, name: str, method: str, damping: float
) -> np.ndarray:
    before = len(ctx.history)
    try:
        x = _newton(
            problem, start, ctx, strategy=name, step=1, tau=1.0, method=method, damping=damping
        )
    except _Failure as failure:
        ctx.steps.append(
            StepRecord(name, 1, 1.0, len(ctx.history) - before - 1, False, failure.reason)
        )
        raise
    ctx.steps.append(StepRecord(name, 1, 1.0, len(ctx.history) - before - 1, True, None, x))
    return x
