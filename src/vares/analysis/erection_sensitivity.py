"""Derivatives of an erected state with respect to its patterns: what the adjoint of the
erection's equilibrium needs.

An erected state ``x*(X)`` solves ``R(x, X) = ∂Π/∂x = 0`` (:mod:`vares.mechanics.erection`; the
patterns ``X`` fixed). A function ``f(x*, X)`` of it changes with the patterns as

    df/dX = ∂f/∂X − λᵀ ∂R/∂X,    K λ = ∂f/∂x,   K = ∂R/∂x

(one solve with the erection's tangent per function, or per product with a Jacobian). This module
gives the element blocks of the mixed derivative ``∂R/∂X`` and of the derivatives of the membrane
forces along the yarns, in closed form from the law's stress ``S`` and tangent ``ℂ`` (the relaxed
ones where a cell wrinkles). At a quadrature point, with ``G_a = ∇_X N_a`` and ``w = t ω det J``,
a change ``δX_b = e_α`` of pattern node ``b`` gives

    δw = w G_bα,   δG_a = −G_aα G_b,   δF = −F e_α ⊗ G_b,
    δC = −(G_b ⊗ C e_α + C e_α ⊗ G_b),   δS = ½ ℂ : δC,

and the nodal residual ``r_a = w F S G_a`` changes by the sum of the four products. A membrane
force along a yarn ``Φ`` is ``n = t (Φ·CSCΦ)/(Φ·CΦ)/√det C`` per point (averaged over the cell by
the points' weights): its derivative is ``(∂n/∂C + ½ ∂n/∂S : ℂ) : dC`` with ``dC`` from the node
positions or the pattern (``tests/test_erection_optimum.py`` checks both against finite
differences).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..mechanics.erection import ErectionProblem, MembraneBlock
from ..mechanics.forward import deformation_gradients

__all__ = ["BlockDerivatives", "block_derivatives", "yarn_force"]

_H = 1e-30


@dataclass(frozen=True)
class BlockDerivatives:
    """Per membrane block at an erected state: ``mixed`` ``∂r/∂X`` ``(m, nen, 3, nen, 2)``, the
    membrane forces along warp and fill ``forces`` ``(m, 2)`` and their derivatives by the
    nodes' positions ``force_by_x`` ``(m, 2, nen, 3)`` and by the pattern ``force_by_X``
    ``(m, 2, nen, 2)``."""

    mixed: np.ndarray
    forces: np.ndarray
    force_by_x: np.ndarray
    force_by_X: np.ndarray


def yarn_force(C: np.ndarray, S: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """``(Φ·CSCΦ)/(Φ·CΦ)/√det C``: the Cauchy stress along the erected yarn of reference
    direction ``Φ`` ``(2,)`` at states ``C``, ``S`` ``(..., 2, 2)`` (real or complex)."""
    CSC = C @ S @ C
    along = np.einsum("a,...ab,b->...", direction, CSC, direction)
    length = np.einsum("a,...ab,b->...", direction, C, direction)
    det = C[..., 0, 0] * C[..., 1, 1] - C[..., 0, 1] * C[..., 1, 0]
    return along / length / np.sqrt(det)


def _force_gradients(C, S, direction):
    """``∂n/∂C`` and ``∂n/∂S`` ``(..., 2, 2)`` of :func:`yarn_force`, entry by entry (complex
    step: exact to round-off)."""
    by_C, by_S = np.zeros(C.shape), np.zeros(S.shape)
    for i in range(2):
        for j in range(2):
            step = np.zeros((2, 2), complex)
            step[i, j] = 1j * _H
            by_C[..., i, j] = yarn_force(C + step, S.astype(complex), direction).imag / _H
            by_S[..., i, j] = yarn_force(C.astype(complex), S + step, direction).imag / _H
    return by_C, by_S


def block_derivatives(problem: ErectionProblem, index: int, x: np.ndarray) -> BlockDerivatives:
    """The derivatives (:class:`BlockDerivatives`) of membrane block ``index`` of ``problem``
    at the erected positions ``x`` ``(n, 3)``, with the problem's law (relaxed or plain)."""
    block: MembraneBlock = problem.blocks[index]
    G, w = block.reference.gradients, block.reference.weights  # (m,q,nen,2), (m,q)
    F = deformation_gradients(np.ascontiguousarray(x[block.cells]), G)  # (m,q,3,2)
    C = np.swapaxes(F, -1, -2) @ F
    _, S, cc = problem.response(block.fibres, block=index)(C, True)
    S = np.broadcast_to(S, C.shape)
    cc = np.broadcast_to(cc, (*C.shape, 2, 2))
    eye = np.eye(2)
    # δC per pattern dof (b, α): −(G_bβ C_αγ + C_βα G_bγ)
    dC_X = -(
        np.einsum("mqbx,ay,mqyz->mqbaxz", G, eye, C) + np.einsum("mqxy,ya,mqbz->mqbaxz", C, eye, G)
    )
    dS_X = 0.5 * np.einsum("mqxyuv,mqbauv->mqbaxy", cc, dC_X)
    FS = F @ S
    FSG = np.einsum("mqiy,mqay->mqai", FS, G)  # F S G_a
    dw = w[..., None, None] * G  # δw per (b, α)
    mixed = (
        np.einsum("mqba,mqci->mciba", dw, FSG)
        - np.einsum("mq,mqia,mqby,mqyz,mqcz->mciba", w, F, G, S, G)
        + np.einsum("mq,mqiy,mqbayz,mqcz->mciba", w, F, dS_X, G)
        - np.einsum("mq,mqca,mqbi->mciba", w, G, FSG)
    )
    warp = (1.0, 0.0) if block.fibres is None else block.fibres.warp
    fill = (0.0, 1.0) if block.fibres is None else block.fibres.fill
    t = problem.thickness
    total = w.sum(axis=1)
    forces, by_x, by_X = [], [], []
    for direction in (np.asarray(warp, float), np.asarray(fill, float)):
        n = yarn_force(C, S, direction)  # (m, q)
        by_C, by_S = _force_gradients(C, S, direction)
        D = by_C + 0.5 * np.einsum("mqxy,mqxyuv->mquv", by_S, cc)
        mean = np.sum(w * n, axis=1) / total
        # dC by node positions (a, i): G_aβ F_iγ + F_iβ G_aγ
        dn_x = np.einsum("mquv,mqau,mqiv->mqai", D, G, F) + np.einsum(
            "mquv,mqiu,mqav->mqai", D, F, G
        )
        forces.append(t * mean)
        by_x.append(t * np.einsum("mq,mqai->mai", w, dn_x) / total[:, None, None])
        dn_X = np.einsum("mquv,mqbauv->mqba", D, dC_X)
        by_X.append(
            t
            * (
                np.einsum("mqba,mq->mba", dw, n)
                + np.einsum("mq,mqba->mba", w, dn_X)
                - mean[:, None, None] * dw.sum(axis=1)
            )
            / total[:, None, None]
        )
    return BlockDerivatives(
        mixed, np.stack(forces, axis=1), np.stack(by_x, axis=1), np.stack(by_X, axis=1)
    )
