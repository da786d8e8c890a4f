"""Element kernels of the forward (erection) problem: the pattern fixed, the 3D positions unknown.

The energy is that of the pattern problem with the roles swapped. At a quadrature point

    W(j) = t det J Ψ(C),   C = Fᵀ F,   F = j J⁻¹ (3×2),

with ``J = ∂X/∂ξ`` the fixed 2×2 Jacobian of the pattern (each cell its own panel's) and
``j = ∂x/∂ξ`` the unknown 3×2 Jacobian of the erected cell. ``F`` is linear in the nodal positions,
``dF = Σ_a dx_a ⊗ ∇_X N_a`` with ``∇_X N_a = J⁻ᵀ ∇_ξ N_a``, and

    ∂W/∂F = t det J F S,     ∂²W/∂F_ib ∂F_kd = t det J (δ_ik S_bd + F_ia ℂ_abcd F_kc),

``S = 2∂Ψ/∂C``, ``ℂ = 4∂²Ψ/∂C∂C`` (the material's, or the relaxed ones of
:mod:`vares.mechanics.wrinkling`). Every loop is compiled with numba and works in complex
arithmetic too (complex-step checks).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._jit import njit, prange
from ..geometry.elements import ReferenceElement, determinant, inverse
from .kernels import BlockResult, project_psd

__all__ = [
    "ReferenceBlock",
    "deformation_gradients",
    "forward_block",
    "forward_projected_hessian",
    "reference_block",
]

#: ``response(C, tangent) -> (psi, S, ℂ or None)`` at the quadrature points ``(m, q, 2, 2)``.
Response = Callable[[np.ndarray, bool], tuple[np.ndarray, np.ndarray, np.ndarray | None]]


@dataclass(frozen=True)
class ReferenceBlock:
    """What the fixed pattern gives a block of cells: ``gradients`` ``∇_X N_a`` ``(m, q, nen, 2)``
    and ``weights`` ``t w_q det J`` ``(m, q)`` (pattern volume per quadrature point)."""

    gradients: np.ndarray
    weights: np.ndarray


def reference_block(
    element: ReferenceElement, pattern_nodes: np.ndarray, thickness: float
) -> ReferenceBlock:
    """The reference block of cells whose pattern coordinates are ``(m, nen, 2)``."""
    J = np.einsum("mai,qaj->mqij", pattern_nodes, element.shape_gradients)
    det_j = determinant(J)
    K = inverse(J, det_j)
    gradients = np.einsum("qaj,mqjk->mqak", element.shape_gradients, K)
    weights = thickness * det_j * element.quadrature_weights
    return ReferenceBlock(np.ascontiguousarray(gradients), np.ascontiguousarray(weights))


def forward_block(
    reference: ReferenceBlock, nodes: np.ndarray, response: Response, order: int = 2
) -> BlockResult:
    """Energy ``(m,)``, gradient ``(m, nen, 3)`` and Hessian ``(m, nen, 3, nen, 3)`` (by
    ``order``) of a block whose erected node positions are ``nodes`` ``(m, nen, 3)``;
    ``jacobian_hessian`` holds ``∂²W/∂F²`` ``(m, q, 6, 6)`` per unit weight (index ``2 i + α``
    for ``F_iα``)."""
    dtype = np.result_type(nodes, reference.gradients)
    gradients = reference.gradients.astype(dtype, copy=False)
    F = deformation_gradients(np.ascontiguousarray(nodes, dtype=dtype), gradients)
    C = np.swapaxes(F, -1, -2) @ F
    psi, S, tangent = response(C, order >= 2)
    weights = reference.weights.astype(dtype, copy=False)
    energy = np.sum(weights * psi, axis=1)
    if order == 0:
        return BlockResult(energy, None, None)
    if tangent is None:
        tangent = np.zeros((1, 1, 2, 2, 2, 2), dtype)
    gradient, jacobian_hessian = _derivatives(
        F,
        np.ascontiguousarray(np.broadcast_to(S, C.shape), dtype=dtype),
        np.ascontiguousarray(tangent, dtype=dtype),
        gradients,
        weights,
        order >= 2,
    )
    if order < 2:
        return BlockResult(energy, gradient, None)
    hessian = _nodal_hessian(jacobian_hessian, gradients, weights)
    return BlockResult(energy, gradient, hessian, jacobian_hessian)


def forward_projected_hessian(reference: ReferenceBlock, jacobian_hessian: np.ndarray):
    """Nodal Hessian ``(m, nen, 3, nen, 3)`` with the negative eigenvalues of every quadrature
    point's ``∂²W/∂F²`` set to zero (positive semi-definite; real arithmetic)."""
    projected = jacobian_hessian.copy()
    project_psd(projected)
    return _nodal_hessian(projected, reference.gradients, reference.weights)


@njit(cache=True, parallel=True)
def deformation_gradients(nodes, gradients):  # pragma: no cover - compiled
    """``F = Σ_a x_a ⊗ ∇_X N_a`` ``(m, q, 3, 2)`` from the erected nodes ``(m, nen, 3)`` and
    the shape functions' pattern gradients ``(m, q, nen, 2)``."""
    m, nq, nen = gradients.shape[0], gradients.shape[1], gradients.shape[2]
    F = np.zeros((m, nq, 3, 2), nodes.dtype)
    for e in prange(m):
        for q in range(nq):
            for a in range(nen):
                g0, g1 = gradients[e, q, a, 0], gradients[e, q, a, 1]
                for i in range(3):
                    x = nodes[e, a, i]
                    F[e, q, i, 0] += x * g0
                    F[e, q, i, 1] += x * g1
    return F


@njit(cache=True, parallel=True)
def _derivatives(F, S, tangent, gradients, weights, with_hessian):  # pragma: no cover
    """Nodal gradient ``Σ_q w F S ∇N_a`` and ``∂²W/∂F²`` per unit weight at each point."""
    m, nq, nen = gradients.shape[0], gradients.shape[1], gradients.shape[2]
    dtype = F.dtype
    gradient = np.zeros((m, nen, 3), dtype)
    hessian = np.zeros((m, nq, 6, 6) if with_hessian else (1, 1, 6, 6), dtype)
    for e in prange(m):
        fs = np.empty((3, 2), dtype)
        for q in range(nq):
            f = F[e, q]
            s = S[e, q]
            w = weights[e, q]
            for i in range(3):
                for b in range(2):
                    fs[i, b] = f[i, 0] * s[0, b] + f[i, 1] * s[1, b]
            for a in range(nen):
                for i in range(3):
                    gradient[e, a, i] += w * (
                        fs[i, 0] * gradients[e, q, a, 0] + fs[i, 1] * gradients[e, q, a, 1]
                    )
            if not with_hessian:
                continue
            cc = tangent[e, q]
            for i in range(3):
                for b in range(2):
                    for k in range(3):
                        for d in range(2):
                            value = s[b, d] if i == k else 0.0 * s[b, d]
                            for a in range(2):
                                for c in range(2):
                                    value += f[i, a] * cc[a, b, c, d] * f[k, c]
                            hessian[e, q, 2 * i + b, 2 * k + d] = value
    return gradient, hessian


@njit(cache=True, parallel=True)
def _nodal_hessian(jacobian_hessian, gradients, weights):  # pragma: no cover
    """``Σ_q w Bᵀ H B``: nodal Hessian ``(m, nen, 3, nen, 3)`` from ``(m, q, 6, 6)``."""
    m, nq, nen = gradients.shape[0], gradients.shape[1], gradients.shape[2]
    out = np.zeros((m, nen, 3, nen, 3), jacobian_hessian.dtype)
    for e in prange(m):
        for q in range(nq):
            h = jacobian_hessian[e, q]
            w = weights[e, q]
            g = gradients[e, q]
            for a in range(nen):
                for i in range(3):
                    for b in range(nen):
                        for k in range(3):
                            value = 0.0 * h[0, 0]
                            for al in range(2):
                                for be in range(2):
                                    value += g[a, al] * h[2 * i + al, 2 * k + be] * g[b, be]
                            out[e, a, i, b, k] += w * value
    return out
