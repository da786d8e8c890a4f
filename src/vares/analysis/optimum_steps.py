"""The steps of the erection-aware optimisation (:mod:`.erection_optimum`): a Levenberg–Marquardt
step of the patterns by LSQR on the residual model's Jacobian, held where a shape bound is
reached, and an estimate of ``|J|²``."""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

from .erection_bound import AT_BOUND, HeldNodes

__all__ = [
    "HOLD_PASSES",
    "LSQR_LIMIT",
    "LSQR_TOLERANCE",
    "lsqr_step",
    "norm_squared",
    "step_direction",
]

#: With a shape bound: how many times a step is solved again with more nodes held at the
#: bound (:func:`step_direction`).
HOLD_PASSES = 2
#: LSQR's relative tolerance and iteration limit for each step's least-squares problem.
LSQR_TOLERANCE = 1e-3
LSQR_LIMIT = 15


def step_direction(model, mu, preconditioner, strain_of, held=None, radius=None):
    """A Levenberg–Marquardt step (seams kept matched to first order), its largest edge strain
    and LSQR's iterations. With a bound ``held``: the nodes at the bound that the step (cut to
    the trust region ``radius``) would move outwards by its linearised prediction are held where
    they are (:class:`HeldNodes`: the step solved again on the null space of their constraints),
    at most :data:`HOLD_PASSES` times; the step then slides along the bound."""
    project = model.projection() if len(model.seams) else (lambda v: v)
    d = model.erected.normal_deviation
    at_bound = np.abs(d) >= (1.0 - AT_BOUND) * held.bound if held is not None else None
    nodes, constraints, total = np.zeros(0, dtype=int), None, 0
    for attempt in range(HOLD_PASSES + 1):
        step, iterations = lsqr_step(
            model.operator(), model.residual, mu, preconditioner, constraints
        )
        total += iterations
        step = project(step)
        strain = strain_of(step)
        if held is None or not at_bound.any() or attempt == HOLD_PASSES:
            break
        scale = min(1.0, radius / strain) if strain > 0 else 1.0
        change = model.deviation_change(model.response(scale * step)[1]) - d
        outwards = np.flatnonzero(at_bound & (np.sign(d) * change > 0))
        outwards = outwards[~np.isin(outwards, nodes)]
        if not len(outwards):
            break
        nodes = np.concatenate([nodes, outwards])
        constraints = HeldNodes(model.deviation_gradients(nodes), project, preconditioner)
    return step, strain, total


def lsqr_step(op, residual, mu, preconditioner=None, constraints=None):
    """The Levenberg–Marquardt step ``min |J Δ + r|² + μ |Δ|²`` (to LSQR's loose tolerance: the
    step is inexact) and LSQR's iterations; with a right ``preconditioner`` ``P`` (symmetric),
    ``Δ = P y`` and LSQR solves for ``y`` the same problem, ``min |J P y + r|² + μ |P y|²``;
    with ``constraints`` (:class:`HeldNodes`), for ``y`` on their null space."""
    tol = LSQR_TOLERANCE
    if preconditioner is None and constraints is None:
        out = spla.lsqr(op, -residual, damp=np.sqrt(mu), atol=tol, btol=tol, iter_lim=LSQR_LIMIT)
        return out[0], out[2]
    rows, root = len(residual), np.sqrt(mu)

    def metric(y):
        y = y if constraints is None else constraints.project(y)
        return y if preconditioner is None else preconditioner.matvec(y)

    def matvec(y):
        step = metric(y)
        return np.concatenate([op.matvec(step), root * step])

    def rmatvec(u):
        v = op.rmatvec(u[:rows]) + root * u[rows:]
        v = v if preconditioner is None else preconditioner.matvec(v)
        return v if constraints is None else constraints.project(v)

    augmented = spla.LinearOperator((rows + op.shape[1], op.shape[1]), matvec, rmatvec, dtype=float)
    rhs = np.concatenate([-residual, np.zeros(op.shape[1])])
    out = spla.lsqr(augmented, rhs, atol=tol, btol=tol, iter_lim=LSQR_LIMIT)
    return metric(out[0]), out[2]


def norm_squared(op, iterations: int = 4) -> float:
    """An estimate of ``|J|²`` (power iteration on ``JᵀJ``)."""
    v = np.random.default_rng(0).normal(size=op.shape[1])
    value = 0.0
    for _ in range(iterations):
        v /= np.linalg.norm(v)
        w = op.rmatvec(op.matvec(v))
        value = float(np.linalg.norm(w))
        v = w
    return value
