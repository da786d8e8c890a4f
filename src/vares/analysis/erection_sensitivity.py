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
from .erection_sensitivity_kernels import chained_points, mixed_derivative

__all__ = [
    "BlockDerivatives",
    "block_derivatives",
    "block_forces",
    "block_least_forces",
    "least_force",
    "least_force_gradients",
    "yarn_force",
    "yarn_force_gradients",
]


@dataclass(frozen=True)
class BlockDerivatives:
    """Per membrane block at an erected state: ``mixed`` ``∂r/∂X`` ``(m, nen, 3, nen, 2)``, the
    membrane forces along warp and fill ``forces`` ``(m, 2)`` and their derivatives by the
    nodes' positions ``force_by_x`` ``(m, 2, nen, 3)`` and by the pattern ``force_by_X``
    ``(m, 2, nen, 2)``; where asked for, the plain law's smaller principal force ``least``
    ``(m,)`` (:func:`block_least_forces`) and its derivatives ``(m, nen, 3)``, ``(m, nen, 2)``."""

    mixed: np.ndarray
    forces: np.ndarray
    force_by_x: np.ndarray
    force_by_X: np.ndarray
    least: np.ndarray | None = None
    least_by_x: np.ndarray | None = None
    least_by_X: np.ndarray | None = None


def yarn_force(C: np.ndarray, S: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """``(Φ·CSCΦ)/(Φ·CΦ)/√det C``: the Cauchy stress along the erected yarn of reference
    direction ``Φ`` ``(2,)`` at states ``C``, ``S`` ``(..., 2, 2)`` (real or complex)."""
    CSC = C @ S @ C
    along = np.einsum("a,...ab,b->...", direction, CSC, direction)
    length = np.einsum("a,...ab,b->...", direction, C, direction)
    det = C[..., 0, 0] * C[..., 1, 1] - C[..., 0, 1] * C[..., 1, 0]
    return along / length / np.sqrt(det)


def yarn_force_gradients(
    C: np.ndarray, S: np.ndarray, direction: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`yarn_force` ``n`` and its derivatives ``∂n/∂C`` and ``∂n/∂S`` ``(..., 2, 2)``,
    entry by entry, in closed form: with ``a = Φ·CSCΦ``, ``l = Φ·CΦ``, ``n = a / (l √det C)``,
    ``∂a/∂C = Φ ⊗ SCΦ + SᵀCᵀΦ ⊗ Φ``, ``∂a/∂S = CΦ ⊗ CᵀΦ``, ``∂l/∂C = Φ ⊗ Φ`` and
    ``∂det C/∂C`` the cofactors (``tests/test_erection_optimum.py`` checks them by complex
    step)."""
    phi = np.asarray(direction, dtype=float)
    C_phi = C @ phi  # CΦ (..., 2)
    Ct_phi = phi @ C  # CᵀΦ
    SC_phi = np.einsum("...ab,...b->...a", S, C_phi)
    StCt_phi = np.einsum("...ba,...b->...a", S, Ct_phi)
    a = np.einsum("...a,...a->...", Ct_phi, SC_phi)
    length = np.einsum("a,...a->...", phi, C_phi)
    det = C[..., 0, 0] * C[..., 1, 1] - C[..., 0, 1] * C[..., 1, 0]
    scale = 1.0 / (length * np.sqrt(det))
    n = a * scale
    cofactors = np.stack(
        [np.stack([C[..., 1, 1], -C[..., 1, 0]], -1), np.stack([-C[..., 0, 1], C[..., 0, 0]], -1)],
        -2,
    )
    by_a = phi[:, None] * SC_phi[..., None, :] + StCt_phi[..., :, None] * phi[None, :]
    by_C = (
        scale[..., None, None] * by_a
        - (n / length)[..., None, None] * np.outer(phi, phi)
        - (0.5 * n / det)[..., None, None] * cofactors
    )
    by_S = scale[..., None, None] * Ct_phi[..., :, None] * C_phi[..., None, :]
    return n, by_C, by_S


def least_force(C: np.ndarray, S: np.ndarray) -> np.ndarray:
    """The smaller principal Cauchy stress ``λ_min(S C)/√det C`` at states ``C``, ``S``
    ``(..., 2, 2)`` (``S C`` has the eigenvalues of ``F S Fᵀ`` in the surface; real or
    complex)."""
    return _least(C, S)[0]


def _least(C, S):
    det_c = C[..., 0, 0] * C[..., 1, 1] - C[..., 0, 1] * C[..., 1, 0]
    det_s = S[..., 0, 0] * S[..., 1, 1] - S[..., 0, 1] * S[..., 1, 0]
    half = 0.5 * np.einsum("...ab,...ab->...", S, C)  # tr(S C) / 2
    q = np.sqrt(half**2 - det_s * det_c)
    root = np.sqrt(det_c)
    return (half - q) / root, det_c, det_s, half, q, root


def _cofactors(A: np.ndarray) -> np.ndarray:
    return np.stack(
        [np.stack([A[..., 1, 1], -A[..., 1, 0]], -1), np.stack([-A[..., 0, 1], A[..., 0, 0]], -1)],
        -2,
    )


def least_force_gradients(C: np.ndarray, S: np.ndarray) -> tuple[np.ndarray, ...]:
    """:func:`least_force` ``m`` and its derivatives ``∂m/∂C``, ``∂m/∂S`` ``(..., 2, 2)``,
    entry by entry: with ``h = tr(SC)/2``, ``q = √(h² − det S det C)``, ``λ = h − q``,
    ``∂λ/∂C = (1 − h/q) S/2 + det S cof C/(2q)``, ``∂λ/∂S = (1 − h/q) C/2 + det C cof S/(2q)``
    and ``m = λ/√det C`` (``q`` is kept above round-off where the two principal forces are
    equal; ``tests/test_erection_optimum.py`` checks them by complex step)."""
    m, det_c, det_s, half, q, root = _least(C, S)
    q = np.maximum(q, 1e-12 * (np.abs(half) + 1e-300))
    along = (1.0 - half / q)[..., None, None]
    by_C = (0.5 * along * S + (det_s / (2.0 * q))[..., None, None] * _cofactors(C)) / root[
        ..., None, None
    ] - (0.5 * m / det_c)[..., None, None] * _cofactors(C)
    by_S = (0.5 * along * C + (det_c / (2.0 * q))[..., None, None] * _cofactors(S)) / root[
        ..., None, None
    ]
    return m, by_C, by_S


def _points(problem: ErectionProblem, index: int, x: np.ndarray, tangent: bool):
    block: MembraneBlock = problem.blocks[index]
    G, w = block.reference.gradients, block.reference.weights  # (m,q,nen,2), (m,q)
    F = deformation_gradients(np.ascontiguousarray(x[block.cells]), G)  # (m,q,3,2)
    C = np.swapaxes(F, -1, -2) @ F
    _, S, cc = problem.response(block.fibres, block=index)(C, tangent)
    return block, G, w, F, C, np.broadcast_to(S, C.shape), cc


def _directions(block: MembraneBlock) -> list[np.ndarray]:
    warp = (1.0, 0.0) if block.fibres is None else block.fibres.warp
    fill = (0.0, 1.0) if block.fibres is None else block.fibres.fill
    return [np.asarray(warp, float), np.asarray(fill, float)]


def block_forces(problem: ErectionProblem, index: int, x: np.ndarray) -> np.ndarray:
    """The membrane forces along warp and fill ``(m, 2)`` of membrane block ``index`` at the
    erected positions ``x`` ``(n, 3)`` (the cell means of :func:`block_derivatives`)."""
    block, _, w, _, C, S, _ = _points(problem, index, x, False)
    total = w.sum(axis=1)
    forces = [np.sum(w * yarn_force(C, S, d), axis=1) / total for d in _directions(block)]
    return problem.thickness * np.stack(forces, axis=1)


def block_least_forces(problem: ErectionProblem, index: int, x: np.ndarray) -> np.ndarray:
    """The plain law's smaller principal membrane force, cell means ``(m,)``, of membrane block
    ``index`` at ``x``: negative where the erected membrane is wrinkled or slack (the relaxed
    law's is zero there), the compression the plain law would carry across the wrinkles."""
    block = problem.blocks[index]
    G, w = block.reference.gradients, block.reference.weights
    F = deformation_gradients(np.ascontiguousarray(x[block.cells]), G)
    C = np.swapaxes(F, -1, -2) @ F
    _, S, _ = problem.response(block.fibres, relaxed=False)(C, False)
    m = least_force(C, np.broadcast_to(S, C.shape))
    return problem.thickness * np.sum(w * m, axis=1) / w.sum(axis=1)


def block_derivatives(
    problem: ErectionProblem, index: int, x: np.ndarray, with_least: bool = False
) -> BlockDerivatives:
    """The derivatives (:class:`BlockDerivatives`) of membrane block ``index`` of ``problem``
    at the erected positions ``x`` ``(n, 3)``, with the problem's law (relaxed or plain);
    ``with_least``: also the plain law's smaller principal force (:func:`block_least_forces`)
    and its derivatives."""
    block, G, w, F, C, S, cc = _points(problem, index, x, True)
    cc = np.broadcast_to(cc, (*C.shape, 2, 2))
    mixed = mixed_derivative(G, w, F, C, S, cc)
    t = problem.thickness
    forces, by_x, by_X = [], [], []
    for direction in _directions(block):
        n, by_C, by_S = yarn_force_gradients(C, S, direction)  # (m, q), (m, q, 2, 2) ×2
        mean, dn_x, dn_X = _chained(n, by_C, by_S, cc, G, w, F, C, t)
        forces.append(mean)
        by_x.append(dn_x)
        by_X.append(dn_X)
    least = least_by_x = least_by_X = None
    if with_least:  # the plain law's smaller principal force and its derivatives
        _, S0, cc0 = problem.response(block.fibres, relaxed=False)(C, True)
        S0 = np.broadcast_to(S0, C.shape)
        cc0 = np.broadcast_to(cc0, (*C.shape, 2, 2))
        m, by_C, by_S = least_force_gradients(C, S0)
        least, least_by_x, least_by_X = _chained(m, by_C, by_S, cc0, G, w, F, C, t)
    return BlockDerivatives(
        mixed,
        np.stack(forces, axis=1),
        np.stack(by_x, axis=1),
        np.stack(by_X, axis=1),
        least,
        least_by_x,
        least_by_X,
    )


def _chained(n, by_C, by_S, cc, G, w, F, C, t):
    """The cell mean ``t Σ_q w n / Σ_q w`` of a point function ``n`` ``(m, q)`` of ``C`` and
    ``S`` (partial derivatives ``by_C``, ``by_S``; ``S`` of ``C`` by the tangent ``cc``), and
    its derivatives by the nodes' positions ``(m, nen, 3)`` and by the pattern ``(m, nen, 2)``
    (:func:`~vares.analysis.erection_sensitivity_kernels.chained_points`)."""
    total = w.sum(axis=1)
    mean = np.sum(w * n, axis=1) / total
    by_x, by_X = chained_points(n, by_C, by_S, cc, G, w, F, C)
    # the mean's weights change with the pattern too: − mean Σ_q δw
    by_X -= mean[:, None, None] * (w[..., None, None] * G).sum(axis=1)
    scale = t / total[:, None, None]
    return t * mean, scale * by_x, scale * by_X
