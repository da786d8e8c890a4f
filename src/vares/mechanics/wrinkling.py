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

from ..materials import Fibres, Hyperelastic, InadmissibleState

__all__ = [
    "SLACK",
    "TAUT",
    "WRINKLED",
    "RelaxedResponse",
    "WrinklingError",
    "relaxed_response",
]

#: Per-point states.
TAUT, WRINKLED, SLACK = 0, 1, 2

#: Stresses above −this × the law's stiffness count as non-negative (round-off of a stress-free
#: state); stretches below 1 + this as not stretched.
STATE_TOLERANCE = 1e-12
#: A wrinkled state is found when the stress across the wrinkles is below this × the stiffness.
ACROSS_TOLERANCE = 1e-13
_NEWTON_STEPS = 60
#: Directions on which the wrinkling direction is bracketed: offsets (radians) from the most
#: compressive stress direction over 180°, geometrically finer towards it (where the stress is
#: barely compressive, only directions very close to it relax it).
_OFFSETS = np.pi * np.concatenate(
    [-np.geomspace(0.5, 1e-6, 20), [0.0], np.geomspace(1e-6, 0.5, 20)]
)


class WrinklingError(InadmissibleState):
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
    material: Hyperelastic,
    C: np.ndarray,
    fibres: Fibres | None = None,
    *,
    tangent: bool = True,
    guess: np.ndarray | None = None,
) -> RelaxedResponse:
    """Relaxed energy, stress and (optionally) tangent of ``material`` at ``C`` ``(..., 2, 2)``
    (real arithmetic; module docs). ``guess`` ``(..., 2)``: wrinkles ``v`` of nearby states (a
    previous Newton iterate's) to start from; where Newton's method from them does not reach
    the wrinkled state, it is searched for as without."""
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
        start = None if guess is None else np.asarray(guess).reshape(-1, 2)[wrinkled]
        v, relaxed = _wrinkled_states(
            material, flat[wrinkled], stress[wrinkled], fibres, tangent, start
        )
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


def _wrinkled_states(material, C, stress, fibres, tangent, start=None):
    """The wrinkle ``v = √β n`` ``(k, 2)`` minimising ``f(v) = Ψ(C + v vᵀ)`` and the response
    there.

    Along a direction ``n(θ)``, the least ``f`` is where the stress across ``n`` vanishes: a
    one-dimensional Newton iteration gives that ``β(θ)`` (the stress across grows with β). The
    least of these over ``θ`` is where the shear ``t(θ) = n⊥·S n`` turns from negative to
    positive (``d f/dθ = β t``): bracketed on the angles :data:`_OFFSETS` about the most
    compressive direction, the lowest such bracket is refined by the Illinois method until
    ``|t|`` is round-off (:data:`ACROSS_TOLERANCE` × the law's stiffness). Only roots are sought,
    never energy decreases, so states whose energy differences are below round-off are found as
    well. Points with a ``start`` (non-zero) try Newton's method from it first.
    """
    limit = ACROSS_TOLERANCE * material.stiffness_scale
    v = np.zeros((len(C), 2))
    searched = np.ones(len(C), dtype=bool)
    if start is not None:
        warm = np.linalg.norm(start, axis=-1) > 0
        if warm.any():
            v[warm], found = _polished(material, C[warm], fibres, start[warm], limit, steps=8)
            searched[np.flatnonzero(warm)[found]] = False
    if searched.any():
        v[searched] = _searched(material, C[searched], stress[searched], fibres, limit)
    response = material.response(C + np.einsum("pi,pj->pij", v, v), fibres, tangent=tangent)
    return v, response


def _searched(material, C, stress, fibres, limit):
    """The wrinkles ``v`` by bracketing their direction (see :func:`_wrinkled_states`)."""
    k = len(C)
    _, compressive = _smallest_eigenpair(stress)
    grid = np.arctan2(compressive[:, 1], compressive[:, 0])[:, None] + _OFFSETS  # (k, count)
    count = grid.shape[1]
    beta, shear, psi = _across(material, np.repeat(C, count, axis=0), grid.ravel(), fibres, limit)
    beta, shear, psi = (a.reshape(k, count) for a in (beta, shear, psi))
    # brackets [θ_j, θ_j+1] with t(θ_j) < 0 ≤ t(θ_j+1) and β > 0 at both ends
    valid = (beta[:, :-1] > 0) & (beta[:, 1:] > 0) & (shear[:, :-1] < 0) & (shear[:, 1:] >= 0)
    if not valid.any(axis=1).all():
        raise WrinklingError("the wrinkled state was not found: no direction relaxes the stress")
    lowest = np.where(valid, np.minimum(psi[:, :-1], psi[:, 1:]), np.inf)
    j = np.argmin(lowest, axis=1)
    rows = np.arange(k)
    a, b = grid[rows, j], grid[rows, j + 1]
    fa, fb = shear[rows, j], shear[rows, j + 1]
    beta_b = beta[rows, j + 1]
    for _ in range(_NEWTON_STEPS):
        open_ = np.abs(fb) > limit
        if not open_.any():
            break
        c = np.where(open_, (a * fb - b * fa) / np.where(fb != fa, fb - fa, 1.0), b)
        c = np.where((c > np.minimum(a, b)) & (c < np.maximum(a, b)), c, 0.5 * (a + b))
        beta_c, fc, _ = _across(material, C[open_], c[open_], fibres, limit, beta_b[open_])
        fc_all = fb.copy()
        fc_all[open_] = fc
        flip = open_ & (fc_all * fb < 0)
        keep = open_ & ~flip
        a = np.where(flip, b, a)
        fa = np.where(flip, fb, np.where(keep, 0.5 * fa, fa))  # Illinois
        b = np.where(open_, c, b)
        fb = fc_all
        beta_b[open_] = beta_c
    else:
        worst = float(np.abs(fb).max())
        if worst > 1e3 * limit:
            raise WrinklingError(
                f"the wrinkled state was not found: shear across the wrinkles {worst:.3g}"
            )
    v = np.sqrt(beta_b)[:, None] * np.stack([np.cos(b), np.sin(b)], -1)
    return _polished(material, C, fibres, v, limit, steps=2)[0]


def _polished(material, C, fibres, v, limit, steps):
    """Newton steps on ``∇f(v) = S(C + v vᵀ) v = 0`` where its Hessian is positive definite,
    each kept only where it makes ``|∇f|`` smaller: from a bracketed solution two take it to
    round-off (the exact tangent needs that accuracy); from a previous iterate's wrinkle a few
    find the new one. Returns ``v`` and where ``|∇f| / |v|`` is within ``limit``."""
    response = material.response(C + np.einsum("pi,pj->pij", v, v), fibres)
    gradient = np.einsum("pij,pj->pi", response.stress, v)
    for _ in range(steps):
        hessian = _hessian_of_f(response.stress, response.tangent, v)
        usable = np.linalg.eigvalsh(hessian)[:, 0] > 0
        if not usable.any():
            break
        trial = v.copy()
        trial[usable] -= np.linalg.solve(hessian[usable], gradient[usable][..., None])[..., 0]
        moved = material.response(C + np.einsum("pi,pj->pij", trial, trial), fibres)
        moved_gradient = np.einsum("pij,pj->pi", moved.stress, trial)
        better = usable & (
            np.linalg.norm(moved_gradient, axis=-1) < np.linalg.norm(gradient, axis=-1)
        )
        v = np.where(better[:, None], trial, v)
        gradient = np.where(better[:, None], moved_gradient, gradient)
        stress = np.where(better[:, None, None], moved.stress, response.stress)
        tangent = np.where(better[:, None, None, None, None], moved.tangent, response.tangent)
        response = type(response)(response.psi, stress, tangent)
    length = np.linalg.norm(v, axis=-1)
    found = (length > 0) & (np.linalg.norm(gradient, axis=-1) <= limit * length)
    return v, found


def _across(material, C, theta, fibres, limit, beta=None):
    """For directions ``n = (cos θ, sin θ)``: the amplitude ``β ≥ 0`` at which the stress across
    ``n`` of ``C + β n nᵀ`` vanishes (0 where it is not compressive at β = 0), the shear
    ``n⊥·S n`` and ``Ψ`` there (one-dimensional Newton from ``beta``)."""
    n = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    outer = np.einsum("pi,pj->pij", n, n)
    beta = np.zeros(len(n)) if beta is None else np.array(beta, dtype=float)
    for _ in range(_NEWTON_STEPS):
        response = material.response(C + beta[:, None, None] * outer, fibres)
        across = np.einsum("pi,pij,pj->p", n, response.stress, n)
        moving = (across < -limit) | ((beta > 0) & (np.abs(across) > limit))
        if not moving.any():
            break
        slope = 0.5 * np.einsum("pij,pijkl,pkl->p", outer, response.tangent, outer)
        change = np.where(moving & (slope > 0), -across / np.where(slope > 0, slope, 1.0), 0.0)
        beta = np.maximum(beta + change, 0.1 * beta)
    response = material.response(C + beta[:, None, None] * outer, fibres, tangent=False)
    normal = np.stack([-n[:, 1], n[:, 0]], axis=-1)
    shear = np.einsum("pi,pij,pj->p", normal, response.stress, n)
    return beta, shear, np.broadcast_to(response.psi, beta.shape)
