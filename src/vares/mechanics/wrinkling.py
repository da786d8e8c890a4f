"""Tension-field (relaxed) energy: membranes carry no compression.

A membrane under compression does not store the elastic energy of the compressed state: it
wrinkles at a scale finer than any mesh, and the averaged (mesh-scale) deformation ``C`` is
shorter than the fabric really is. Following Pipkin (1986, IMA J. Appl. Math. 36:85–99), the
relaxed energy density is the least energy of any state that is *longer* than ``C`` in every
direction,

    Ψ_rel(C) = min { Ψ(C + D) : D ⪰ 0 },

the minimum over positive semi-definite 2×2 "wrinkling strains" ``D``. The minimiser ``C* = C + D``
has a positive semi-definite stress ``S(C*)`` with ``S(C*) : D = 0``, which gives three states:

- **taut**: ``S(C) ⪰ 0``; ``D = 0`` and nothing changes;
- **slack**: ``C ⪯ I`` (no direction is stretched); ``C* = I``, no energy, no stress;
- **wrinkled**: otherwise ``D = v ⊗ v`` has rank one (the wrinkles run across ``v``);
  ``S(C*) v = 0`` and ``S(C*)`` is a uniaxial tension.

The same minimisation is written for any law, isotropic or not: for isotropic laws ``v`` is the
principal direction of the smaller stretch (the classical tension-field theory); for the
orthotropic fabric laws the wrinkling direction turns away from the principal directions of
``C`` as the yarn stiffnesses dictate (Mosler & Cirak 2009, Comput. Methods Appl. Mech. Engrg.
198:2188–2198, solve the same minimisation over rank-one wrinkling strains). The wrinkled state is
found per quadrature point by Newton's method on ``f(v) = Ψ(C + v vᵀ)``.

By the envelope theorem the relaxed stress is ``S_rel = S(C*)``; differentiating ``S(C*) v = 0``
gives the exact relaxed tangent

    ℂ_rel = ℂ* − T H⁻¹ Tᵀ,   T_abk = ℂ*_abkl v_l,   H_ik = S*_ik + ℂ*_ijkl v_j v_l

(``H`` is the Hessian of ``f``). ``tests/test_wrinkling.py`` checks stress and tangent against
finite differences in all three states for every law.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..materials import Fibres, Hyperelastic

__all__ = [
    "SLACK",
    "STATES",
    "TAUT",
    "WRINKLED",
    "RelaxedResponse",
    "WrinklingError",
    "relaxed_response",
]

#: Per-point states.
TAUT, WRINKLED, SLACK = 0, 1, 2
STATES = ("taut", "wrinkled", "slack")

#: Stresses above −this × the law's stiffness count as non-negative (round-off of a stress-free
#: state); stretches below 1 + this as not stretched.
STATE_TOLERANCE = 1e-12
#: A wrinkled state is found when the stress across the wrinkles is below this × the stiffness.
ACROSS_TOLERANCE = 1e-13
_NEWTON_STEPS = 60
#: Directions, evenly spaced over 180°, from which the search for a wrinkled state may start.
_START_DIRECTIONS = 12


class WrinklingError(RuntimeError):
    """The wrinkled state of some point was not found."""


@dataclass(frozen=True)
class RelaxedResponse:
    """The relaxed response at a set of states ``C`` ``(..., 2, 2)``: ``psi`` ``(...)``,
    ``stress`` ``S_rel`` ``(..., 2, 2)``, ``tangent`` ``ℂ_rel`` ``(..., 2, 2, 2, 2)`` (or None),
    ``state`` ``(...)`` (:data:`TAUT`, :data:`WRINKLED`, :data:`SLACK`) and ``wrinkle`` ``v``
    ``(..., 2)`` (zero unless wrinkled; ``D = v vᵀ``)."""

    psi: np.ndarray
    stress: np.ndarray
    tangent: np.ndarray | None
    state: np.ndarray
    wrinkle: np.ndarray


def _smallest_eigenpair(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Smaller eigenvalue and a unit eigenvector of symmetric 2×2 matrices ``(k, 2, 2)``."""
    a, b, d = A[:, 0, 0], 0.5 * (A[:, 0, 1] + A[:, 1, 0]), A[:, 1, 1]
    half = 0.5 * (a + d)
    root = np.hypot(0.5 * (a - d), b)
    value = half - root
    # the eigenvector is orthogonal to the rows of A − value I; use the longer row
    row1 = np.stack([a - value, b], axis=-1)
    row2 = np.stack([b, d - value], axis=-1)
    row = np.where(
        (np.linalg.norm(row1, axis=-1) >= np.linalg.norm(row2, axis=-1))[:, None], row1, row2
    )
    vector = np.stack([-row[:, 1], row[:, 0]], axis=-1)
    length = np.linalg.norm(vector, axis=-1)
    isotropic = length <= 1e-300
    vector[isotropic] = (1.0, 0.0)
    length[isotropic] = 1.0
    return value, vector / length[:, None]


def _largest_eigenvalue(A: np.ndarray) -> np.ndarray:
    half = 0.5 * (A[..., 0, 0] + A[..., 1, 1])
    return half + np.hypot(0.5 * (A[..., 0, 0] - A[..., 1, 1]), A[..., 0, 1])


def relaxed_response(
    material: Hyperelastic, C: np.ndarray, fibres: Fibres | None = None, *, tangent: bool = True
) -> RelaxedResponse:
    """Relaxed energy, stress and (optionally) tangent of ``material`` at ``C`` ``(..., 2, 2)``
    (real arithmetic; module docs)."""
    shape = C.shape[:-2]
    flat = np.ascontiguousarray(C.reshape(-1, 2, 2), dtype=float)
    full = material.response(flat, fibres, tangent=tangent)
    psi = np.array(np.broadcast_to(full.psi, flat.shape[:1]), dtype=float)
    stress = np.array(np.broadcast_to(full.stress, flat.shape), dtype=float)
    cc = None if not tangent else np.array(np.broadcast_to(full.tangent, (*flat.shape, 2, 2)))
    tolerance = STATE_TOLERANCE * material.stiffness_scale
    lowest, _ = _smallest_eigenpair(stress)
    state = np.full(flat.shape[0], TAUT, dtype=np.int8)
    compressed = lowest < -tolerance
    slack = compressed & (_largest_eigenvalue(flat) <= 1.0 + STATE_TOLERANCE)
    wrinkled = compressed & ~slack
    state[slack], state[wrinkled] = SLACK, WRINKLED
    psi[slack], stress[slack] = 0.0, 0.0
    if cc is not None:
        cc[slack] = 0.0
    wrinkle = np.zeros((flat.shape[0], 2))
    if wrinkled.any():
        v, relaxed = _wrinkled_states(material, flat[wrinkled], stress[wrinkled], fibres, tangent)
        wrinkle[wrinkled] = v
        psi[wrinkled], stress[wrinkled] = relaxed.psi, relaxed.stress
        if cc is not None:
            cc[wrinkled] = _relaxed_tangent(relaxed.stress, relaxed.tangent, v)
    return RelaxedResponse(
        psi.reshape(shape),
        stress.reshape((*shape, 2, 2)),
        None if cc is None else cc.reshape((*shape, 2, 2, 2, 2)),
        state.reshape(shape),
        wrinkle.reshape((*shape, 2)),
    )


def _hessian_of_f(stress: np.ndarray, cc: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``H_ik = S_ik + ℂ_ijkl v_j v_l``: the Hessian of ``f(v) = Ψ(C + v vᵀ)``."""
    return stress + np.einsum("pijkl,pj,pl->pik", cc, v, v)


def _relaxed_tangent(stress: np.ndarray, cc: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``ℂ_rel = ℂ* − T H⁻¹ Tᵀ`` at wrinkled points (module docs)."""
    T = np.einsum("pabkl,pl->pabk", cc, v)
    H_inv = np.linalg.inv(_hessian_of_f(stress, cc, v))
    return cc - np.einsum("pabm,pmi,pcdi->pabcd", T, H_inv, T)


def _wrinkled_states(material, C, stress, fibres, tangent):
    """The wrinkle ``v`` ``(k, 2)`` minimising ``Ψ(C + v vᵀ)`` and the response there.

    Start: the best of :data:`_START_DIRECTIONS` directions (and that of the most compressive
    stress), each with the amplitude that minimises ``f`` along it; then Newton's method in ``v``
    (its Hessian shifted where not positive definite, steps backtracked on ``f`` far from the
    solution) until the stress across the wrinkle, ``|S(C + v vᵀ) v| / |v|``, is round-off
    (:data:`ACROSS_TOLERANCE` × the law's stiffness).
    """
    limit = ACROSS_TOLERANCE * material.stiffness_scale
    v = _start(material, C, stress, fibres, limit)
    for _ in range(_NEWTON_STEPS):
        response = material.response(C + np.einsum("pi,pj->pij", v, v), fibres)
        gradient = np.einsum("pij,pj->pi", response.stress, v)
        length = np.linalg.norm(v, axis=-1)
        open_ = np.linalg.norm(gradient, axis=-1) > limit * length
        if not open_.any():
            break
        hessian = _hessian_of_f(response.stress[open_], response.tangent[open_], v[open_])
        lowest = np.linalg.eigvalsh(hessian)[:, 0]
        # not positive definite (far from the solution): shift to a descent direction
        shift = np.where(lowest > 0, 0.0, 1e-3 * np.abs(hessian).max(axis=(1, 2)) - lowest)
        step = -np.linalg.solve(
            hessian + shift[:, None, None] * np.eye(2), gradient[open_][..., None]
        )[..., 0]
        # far from the solution, steps that do not lower f are backtracked
        far = (np.linalg.norm(step, axis=-1) > 1e-3 * length[open_]) | (shift > 0)
        trial = v[open_] + step
        if far.any():
            trial[far] = _backtracked(
                material,
                C[open_][far],
                fibres,
                v[open_][far],
                step[far],
                response.psi[open_][far],
                gradient[open_][far],
            )
        v[open_] = trial
    else:
        worst = float((np.linalg.norm(gradient, axis=-1) / length).max())
        if worst > 1e3 * limit:
            raise WrinklingError(
                f"the wrinkled state was not found: stress across the wrinkles {worst:.3g}"
            )
    response = material.response(C + np.einsum("pi,pj->pij", v, v), fibres, tangent=tangent)
    return v, response


def _start(material, C, stress, fibres, limit):
    """For each point the best start ``v = √β n``: over the candidate directions ``n``, the
    amplitude ``β`` minimising ``f`` along ``n`` (one-dimensional Newton), the lowest ``f``."""
    k = len(C)
    angles = np.linspace(0.0, np.pi, _START_DIRECTIONS, endpoint=False)
    fixed = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
    _, compressive = _smallest_eigenpair(stress)
    directions = np.concatenate(
        [compressive[:, None], np.broadcast_to(fixed, (k, *fixed.shape))], 1
    )
    count = directions.shape[1]
    n = directions.reshape(-1, 2)
    Cn = np.repeat(C, count, axis=0)
    outer = np.einsum("pi,pj->pij", n, n)
    beta = np.zeros(len(n))
    for _ in range(_NEWTON_STEPS):
        response = material.response(Cn + beta[:, None, None] * outer, fibres)
        across = np.einsum("pi,pij,pj->p", n, response.stress, n)
        slope = 0.5 * np.einsum("pij,pijkl,pkl->p", outer, response.tangent, outer)
        # f decreases along n while the stress across it is compressive; stop where it is not
        moving = (across < -limit) | ((beta > 0) & (np.abs(across) > limit))
        if not moving.any():
            break
        change = np.where(moving & (slope > 0), -across / np.where(slope > 0, slope, 1.0), 0.0)
        beta = np.maximum(beta + change, 0.1 * beta)
    energy = material.energy_density(Cn + beta[:, None, None] * outer, fibres).reshape(k, count)
    best = np.argmin(energy, axis=1)
    chosen = np.arange(k) * count + best
    return np.sqrt(beta[chosen])[:, None] * n[chosen]


def _backtracked(material, C, fibres, v, step, energy, gradient):
    """``v + α step`` with ``α`` halved until ``f`` does not increase (per point)."""
    alpha = np.ones(len(v))
    descent = np.einsum("pi,pi->p", gradient, step) < 0
    alpha[~descent] = 0.0  # no descent direction: this point has converged to round-off
    for _ in range(30):
        trial = v + alpha[:, None] * step
        value = material.energy_density(C + np.einsum("pi,pj->pij", trial, trial), fibres)
        worse = (value > energy + 1e-12 * np.abs(energy)) & (alpha > 0)
        if not worse.any():
            return trial
        alpha[worse] *= 0.5
    return v + alpha[:, None] * step
