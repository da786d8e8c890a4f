"""A pattern free to turn, with its rotation as an explicit unknown of Newton's system.

The energy of an anisotropic fabric changes with the pattern's rotation relative to the yarns
only slowly: it falls along a flat valley of rotation, and Newton's method on the coordinates
alone steps along that valley a little at a time (its linearised turn stretches the pattern by
``√(1 + φ²)``; a projected tangent is stiffer against turning than the energy is). Here the
pattern is written as a rigid rotation ``φ`` about its held node ``p`` of coordinates ``Y``
whose own mean rotation is held (``cᵀΔY = 0``, ``c`` the rigid rotation field about the
centroid):

    X(Y, φ) = p + R(φ) (Y − p)

At ``φ = 0``, with ``g`` and ``H`` the energy's gradient and Hessian in ``X``, ``a = J (X − p)``
the rotation field (``J`` the quarter turn) and ``J`` applied node by node,

    ∂E/∂φ = g·a,   ∂²E/∂φ² = aᵀ H a − g·(X − p),   ∂²E/∂Y∂φ = H a + Jᵀ g,

the exact Newton system in ``(ΔY, Δφ)``. It is solved with one factorisation of ``H``
bordered by ``c`` and two right-hand sides: ``ΔY = u + Δφ w``, and ``Δφ = −ĝ / s`` with the
reduced gradient ``ĝ`` and the Schur complement ``s`` (the curvature of the energy minimised
over ``Y`` at fixed rotation, along ``φ``: by the envelope theorem ``ĝ`` is the first-order
change of that minimum, the torque). Where ``s ≤ 0`` (the valley is concave in the rotation)
or the Newton turn is longer than the trust radius, the turn is the radius, downhill, and
``ΔY`` follows the valley floor (``u + Δφ w``); the radius doubles after a full step and
shrinks to the accepted turn after a shortened one. The step is taken along the curve
``X(α) = p + R(α Δφ)(X + α ΔY − p)`` and backtracked until the energy falls enough (Armijo).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .failure import Failure
from .line_search import StepPath, backtrack
from .linear import SingularMatrixError

__all__ = [
    "LARGEST_TURN",
    "TURN_RADIUS",
    "TurnState",
    "TurningSearch",
    "TurningSystem",
    "quarter_turn",
    "turning_minimum",
]

#: The first trust radius of the pattern's turn per iteration (radians).
TURN_RADIUS = np.pi / 8
#: The trust radius never grows beyond this (radians).
LARGEST_TURN = np.pi / 2


def quarter_turn(vectors: np.ndarray) -> np.ndarray:
    """Each row ``(x, y)`` of ``vectors`` ``(n, 2)`` turned by +90°: ``(−y, x)``."""
    return np.column_stack([-vectors[:, 1], vectors[:, 0]])


@dataclass
class TurnState:
    """What the turning steps of one Newton iteration carry from one to the next: the trust
    radius of the turn, and the last turn with the reduced gradient it was taken from (their
    secant is the energy's curvature along the rotation where the Schur complement, computed
    off the valley floor, overstates it)."""

    radius: float = TURN_RADIUS
    turn: float = 0.0
    reduced: float = 0.0


class TurningSearch:
    """One globalised Newton step in ``(Y, φ)`` (module docs) from ``x``: the same calls and
    the same answer as :class:`~vares.solver.line_search.LineSearch`; it updates ``state``
    (:class:`TurnState`) for the next iteration."""

    def __init__(self, problem, x, ctx, evaluation, matrix, residual_vector, state) -> None:
        self.problem, self.x, self.ctx = problem, x, ctx
        self.evaluation, self.matrix = evaluation, matrix
        self.energy = evaluation.energy
        self.residual_vector = residual_vector
        self.state = state
        #: the cells that would fold just beyond the step, when they bounded it
        self.bounded_by: np.ndarray | None = None

    def step(self):
        """``(new point, step length, tangent used, evaluation at the new point or None)``."""
        for tangent in ("exact", "projected"):
            if tangent == "projected":
                hessians = self.problem.projected_hessians(self.evaluation)
                self.matrix = self.ctx.assembler.matrix(hessians)
            try:
                direction = self._direction(self.matrix)
            except SingularMatrixError:
                continue
            if direction is None:
                continue
            self.evaluation = self.matrix = None
            rest, turn, slope, clipped, reduced = direction
            accepted = self._search(rest, turn, slope)
            if accepted is not None:
                trial, alpha, at_trial = accepted
                state = self.state
                if alpha == 1.0 and clipped:
                    state.radius = min(2.0 * state.radius, LARGEST_TURN)
                elif alpha < 1.0:
                    state.radius = max(alpha * abs(turn), 1e-8)
                state.turn, state.reduced = alpha * turn, reduced
                return trial, alpha, tangent, at_trial
            break
        raise Failure("the line search found no decrease of the energy", self.x)

    def _direction(self, matrix: sp.csr_matrix):
        """``(ΔY as (n, 2), Δφ, slope, whether the turn was set by the radius)``, or ``None``
        when ``matrix`` gives no descent (not positive definite where the rotation is held)."""
        x, g = self.x, self.residual_vector
        system = TurningSystem(x, self.ctx, matrix, g)
        if not system.held_curvature >= 0:
            return None
        reduced, schur, state = system.reduced, system.schur, self.state
        if state.turn != 0.0:  # off the valley floor the Schur complement overstates
            secant = (reduced - state.reduced) / state.turn
            if 0 < secant < schur:
                schur = secant
        newton_turn = -reduced / schur if schur > 0 else np.inf
        clipped = not abs(newton_turn) <= state.radius
        # downhill (at a stationary rotation that is no minimum, either way is downhill)
        downhill = -np.sign(reduced) if reduced != 0 else 1.0
        turn = downhill * state.radius if clipped else newton_turn
        rest = system.u + turn * system.w
        slope = float(g @ rest + system.torque * turn)
        if not min(slope, 0.0) + 0.5 * min(schur, 0.0) * turn**2 < 0:
            return None
        full = np.zeros(x.size)
        full[self.ctx.assembler.free] = rest
        return full.reshape(-1, 2), float(turn), min(slope, 0.0), clipped, reduced

    def _search(self, rest: np.ndarray, turn: float, slope: float):
        """Backtrack along the turning path: ``(point, α, its evaluation or None)`` or
        ``None`` when no step length lowers the energy enough."""
        problem, ctx, x = self.problem, self.ctx, self.x
        path = StepPath.turning(x, rest, ctx.turning_about, turn)
        bound = problem.admissible_step(x, rest)  # a rotation inverts no cell
        alpha = min(1.0, 0.9 * bound)
        self.bounded_by = (
            problem.inverted_cells(path.at(min(1.0, 1.01 * bound))) if bound < 1 else None
        )
        found = backtrack(problem, path, alpha, self.energy, slope, ctx.energy_noise)
        return None if found is None else found[:3]


class TurningSystem:
    """The Newton system in ``(Y, φ)`` at ``x`` (module docs), solved for its two right-hand
    sides with one factorisation of ``matrix`` (the Hessian over the free dofs) bordered by
    the held rotation: ``u`` and ``w`` (``ΔY = u + Δφ w``), the torque ``g·a``, the reduced
    gradient, the Schur complement ``schur`` and ``held_curvature = uᵀ H u``."""

    def __init__(self, x: np.ndarray, ctx, matrix: sp.csr_matrix, gradient: np.ndarray) -> None:
        free, pivot = ctx.assembler.free, ctx.turning_about
        g = gradient
        arm = x - x[pivot]
        a = quarter_turn(arm).ravel()[free]
        full = np.zeros(x.size)
        full[free] = g
        by_node = full.reshape(-1, 2)
        turned_gradient = np.column_stack([by_node[:, 1], -by_node[:, 0]]).ravel()[free]  # Jᵀg
        coupling = matrix @ a + turned_gradient
        curvature = float(a @ (matrix @ a) - g @ arm.ravel()[free])
        about_centroid = quarter_turn(x - x.mean(axis=0)).ravel()[free]
        held = about_centroid / np.linalg.norm(about_centroid)
        column = sp.csr_matrix(held[:, None])
        bordered = sp.bmat([[matrix, column], [column.T, None]], format="csr")
        self.u = ctx.systems.exact(bordered, np.append(-g, 0.0))[:-1]
        self.w = ctx.systems.solver.solve(np.append(-coupling, 0.0))[:-1]
        held_curvature = -float(g @ self.u)
        self.held_curvature = held_curvature if np.isfinite(held_curvature) else -np.inf
        self.torque = float(g @ a)
        self.reduced = self.torque + float(coupling @ self.u)
        self.schur = curvature + float(coupling @ self.w)


def turning_minimum(x: np.ndarray, ctx, matrix: sp.csr_matrix, gradient: np.ndarray) -> bool:
    """Whether a stationary ``x`` is a minimum in the pattern's rotation: the energy minimised
    at fixed rotation curves upwards along it (a symmetric surface's held pattern can be a
    stationary rotation of greatest energy, from which the pattern must turn away)."""
    try:
        return TurningSystem(x, ctx, matrix, gradient).schur > 0
    except SingularMatrixError:
        return True
