"""Element kernels: energy, gradient and Hessian of the VaReS functional for a block of cells.

For one quadrature point the energy is ``W(J) = det J · Ψ̃(C)``, ``C = J⁻ᵀ G J⁻¹``, with ``J`` the
2×2 Jacobian of the pattern (unknown), ``G = jᵀj`` the fixed metric of the 3D surface and
``Ψ̃ = Ψ − S_pre:E``. Its exact gradient with respect to ``J`` is the Eshelby form of DESIGN.md
eq. (2),

    ∂W/∂J = det J · Σ J⁻ᵀ,     Σ = Ψ̃ I − C S̃,   S̃ = S − S_pre,

and its Hessian is the derivative of that expression in the four directions ``dJ = e_i ⊗ e_α``,
written with ``L = dJ J⁻¹``:

    d(det J) = det J tr L,   dC = −(LᵀC + C L),   d(J⁻ᵀ) = −Lᵀ J⁻ᵀ,
    dΣ = (½ S̃:dC) I − dC S̃ − C (½ ℂ:dC).

``J`` is linear in the nodal pattern coordinates (``J = Σ_a X_a ⊗ ∇_ξ N_a``), so the nodal
gradient and Hessian follow by contraction with the shape function gradients. Every array
operation is vectorised over cells and quadrature points and works in complex arithmetic too.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._jit import compiled, lanes, njit, prange
from ..geometry.elements import ReferenceElement, determinant, inverse
from ..materials import Fibres, Hyperelastic

__all__ = [
    "BlockResult",
    "block_energy",
    "determinant",
    "inverse",
    "nodal_hessian",
    "project_psd",
    "projected_hessian",
]

_EYE = np.eye(2)


@dataclass(frozen=True)
class BlockResult:
    """Per-cell contributions of one cell block.

    ``energy`` ``(m,)``; ``gradient`` ``(m, nen, 2)``; ``hessian`` ``(m, nen, 2, nen, 2)`` or None;
    ``jacobian_hessian`` ``(m, q, 4, 4)``: ``∂²W/∂J²`` at each quadrature point, from which
    :func:`projected_hessian` makes a positive semi-definite tangent without recomputing.
    """

    energy: np.ndarray
    gradient: np.ndarray | None
    hessian: np.ndarray | None
    jacobian_hessian: np.ndarray | None = None


def block_energy(
    element: ReferenceElement,
    pattern_nodes: np.ndarray,
    metric: np.ndarray,
    material: Hyperelastic,
    thickness: float,
    *,
    fibres: Fibres | None = None,
    prestress: np.ndarray | None = None,
    order: int = 2,
) -> BlockResult:
    """Energy (and gradient for ``order ≥ 1``, Hessian for ``order = 2``) of a block of cells.

    Parameters
    ----------
    element
        Reference element of the block's cell type.
    pattern_nodes
        Pattern coordinates of each cell's nodes, ``(m, nen, 2)``.
    metric
        Surface metric ``jᵀj`` at the quadrature points, ``(m, q, 2, 2)``.
    material, thickness, fibres
        The law, the thickness (energy per area = thickness × Ψ) and the fibre directions.
    prestress
        Second Piola–Kirchhoff prestress in the pattern frame, broadcastable to ``(m, q, 2, 2)``.

    The caller ensures ``det J > 0`` (see :meth:`vares.problem.Problem.inverted_cells`).
    """
    dtype = np.result_type(pattern_nodes, metric)
    m, nq = len(pattern_nodes), len(element.quadrature_weights)
    nodes = np.ascontiguousarray(pattern_nodes, dtype=dtype)
    shape_gradients = np.ascontiguousarray(element.shape_gradients, dtype=dtype)
    metric = np.ascontiguousarray(metric, dtype=dtype)
    det_j, K, C = np.empty((m, nq), dtype), np.empty((m, nq, 2, 2), dtype), np.empty_like(metric)
    if compiled(m):
        _kinematics(nodes, shape_gradients, metric, det_j, K, C)
    else:
        outputs = map(lanes, (det_j, K, C))
        _kinematics.py_func(lanes(nodes), shape_gradients, lanes(metric), *outputs)
    response = material.response(C, fibres, tangent=order >= 2)
    psi, S = response.psi, response.stress
    if prestress is not None:
        strain = 0.5 * (C - _EYE)
        psi = psi - np.einsum("...ab,...ab->...", prestress, strain)
        S = S - prestress
    scale = (thickness * element.quadrature_weights).astype(dtype)
    energy = (det_j * psi) @ scale
    if order == 0:
        return BlockResult(energy, None, None)
    with_hessian = order >= 2
    tangent = response.tangent if with_hessian else np.zeros((1, 1, 2, 2, 2, 2), dtype)
    psi = np.ascontiguousarray(np.broadcast_to(psi, det_j.shape), dtype=dtype)
    S = np.ascontiguousarray(np.broadcast_to(S, C.shape), dtype=dtype)
    tangent = np.ascontiguousarray(tangent, dtype=dtype)
    gradient = np.zeros((m, shape_gradients.shape[1], 2), dtype)
    jacobian_hessian = np.zeros((m, nq, 4, 4) if with_hessian else (1, 1, 4, 4), dtype)
    if compiled(m):
        _derivatives(
            det_j, K, C, psi, S, tangent, shape_gradients, scale, with_hessian, gradient,
            jacobian_hessian,
        )  # fmt: skip
    else:
        blocks = map(lanes, (det_j, K, C, psi, S, tangent))
        _derivatives.py_func(
            *blocks, shape_gradients, scale, with_hessian, lanes(gradient), lanes(jacobian_hessian)
        )
    if order < 2:
        return BlockResult(energy, gradient, None)
    hessian = nodal_hessian(jacobian_hessian, shape_gradients, scale)
    return BlockResult(energy, gradient, hessian, jacobian_hessian)


def projected_hessian(
    element: ReferenceElement, jacobian_hessian: np.ndarray, thickness: float
) -> np.ndarray:
    """Nodal Hessian ``(m, nen, 2, nen, 2)`` with the negative eigenvalues of every quadrature
    point's ``∂²W/∂J²`` set to zero: positive semi-definite, for Newton steps far from the
    solution (real arithmetic only)."""
    projected = jacobian_hessian.copy()
    project_psd(projected)
    scale = thickness * element.quadrature_weights
    return nodal_hessian(projected, np.ascontiguousarray(element.shape_gradients), scale)


def nodal_hessian(
    jacobian_hessian: np.ndarray, shape_gradients: np.ndarray, scale: np.ndarray
) -> np.ndarray:
    """``Σ_q w_q Bᵀ H_q B``: nodal Hessian ``(m, nen, 2, nen, 2)`` from the Hessians of
    ``W(J)`` ``(m, q, 4, 4)``, the shape function gradients ``(q, nen, 2)`` and the
    quadrature weights ``scale`` ``(q,)``."""
    m, nen = jacobian_hessian.shape[0], shape_gradients.shape[1]
    hessian = np.zeros((m, nen, 2, nen, 2), jacobian_hessian.dtype)
    if compiled(m):
        _nodal_hessian(jacobian_hessian, shape_gradients, scale, hessian)
    else:
        _nodal_hessian.py_func(lanes(jacobian_hessian), shape_gradients, scale, lanes(hessian))
    return hessian


def project_psd(jacobian_hessian: np.ndarray) -> None:
    """Set the negative eigenvalues of every n × n block ``(m, q, n, n)`` to zero, in place.

    Blocks with a positive, diagonally dominant diagonal are positive semi-definite already and
    are left alone; the others are replaced by their symmetric part's projection (compiled:
    cyclic Jacobi; below COMPILED_FROM cells: LAPACK's symmetric eigensolver, the same
    projection to round-off).
    """
    if compiled(len(jacobian_hessian)):
        _project_psd(jacobian_hessian)
        return
    h = jacobian_hessian
    symmetric = 0.5 * (h + np.swapaxes(h, -1, -2))
    n = h.shape[-1]
    off = np.where(np.eye(n, dtype=bool), 0.0, np.abs(symmetric)).sum(axis=-1)
    todo = ~np.all(np.diagonal(h, axis1=-2, axis2=-1) >= off, axis=-1)
    if todo.any():
        values, vectors = np.linalg.eigh(symmetric[todo])
        kept = vectors * np.maximum(values, 0.0)[..., None, :]
        h[todo] = kept @ np.swapaxes(vectors, -1, -2)


# The loops below do one cell at a time, compiled; below COMPILED_FROM cells the same functions
# run as Python over arrays with the cells on the last axis (vares._jit.lanes): every scalar of
# a cell is then an array over the cells, so the bodies use elementwise arithmetic only and write
# into arrays their caller made.


@njit(cache=True)
def _kinematics(pattern_nodes, shape_gradients, metric, det_j, K, C):  # pragma: no cover
    """``det J``, ``J⁻¹`` and ``C = J⁻ᵀ G J⁻¹`` at every quadrature point of every cell."""
    m, nen = pattern_nodes.shape[0], pattern_nodes.shape[1]
    nq = shape_gradients.shape[0]
    for e in range(m):
        for q in range(nq):
            zero = 0.0 * pattern_nodes[e, 0, 0]  # one array each over the cells (no `a = b = …`)
            j00, j01, j10, j11 = zero, zero + 0.0, zero + 0.0, zero + 0.0
            for a in range(nen):
                x, y = pattern_nodes[e, a, 0], pattern_nodes[e, a, 1]
                d0, d1 = shape_gradients[q, a, 0], shape_gradients[q, a, 1]
                j00 += x * d0
                j01 += x * d1
                j10 += y * d0
                j11 += y * d1
            d = j00 * j11 - j01 * j10
            k00, k01, k10, k11 = j11 / d, -j01 / d, -j10 / d, j00 / d
            g00, g01, g10, g11 = (
                metric[e, q, 0, 0],
                metric[e, q, 0, 1],
                metric[e, q, 1, 0],
                metric[e, q, 1, 1],
            )
            # C = Kᵀ G K
            gk00 = g00 * k00 + g01 * k10
            gk01 = g00 * k01 + g01 * k11
            gk10 = g10 * k00 + g11 * k10
            gk11 = g10 * k01 + g11 * k11
            det_j[e, q] = d
            K[e, q, 0, 0], K[e, q, 0, 1], K[e, q, 1, 0], K[e, q, 1, 1] = k00, k01, k10, k11
            C[e, q, 0, 0] = k00 * gk00 + k10 * gk10
            C[e, q, 0, 1] = k00 * gk01 + k10 * gk11
            C[e, q, 1, 0] = k01 * gk00 + k11 * gk10
            C[e, q, 1, 1] = k01 * gk01 + k11 * gk11


@njit(cache=True, parallel=True)
def _derivatives(
    det_j, K, C, psi, S, tangent, shape_gradients, scale, with_hessian, gradient, jacobian_hessian
):  # pragma: no cover
    """Add the nodal gradient into ``gradient`` ``(m, nen, 2)`` and write the Hessian of
    ``W(J)`` at each quadrature point into ``jacobian_hessian`` ``(m, q, 4, 4)``, index
    ``2 i + α`` for ``J_iα``, from the Eshelby form and its directional derivatives."""
    m, nq = det_j.shape[0], det_j.shape[1]
    nen = shape_gradients.shape[1]
    for e in prange(m):
        sigma = np.empty_like(C[0, 0])  # (2, 2) of a cell, or of every cell
        sigma_kt = np.empty_like(sigma)
        dC = np.empty_like(sigma)
        dS = np.empty_like(sigma)
        d_sigma = np.empty_like(sigma)
        for q in range(nq):
            d = det_j[e, q]
            w = scale[q]
            k = K[e, q]
            c = C[e, q]
            s = S[e, q]
            # Σ = Ψ̃ I − C S̃ and g = det J Σ Kᵀ
            for a in range(2):
                for b in range(2):
                    sigma[a, b] = -(c[a, 0] * s[0, b] + c[a, 1] * s[1, b])
                sigma[a, a] += psi[e, q]
            for a in range(2):
                for b in range(2):
                    sigma_kt[a, b] = sigma[a, 0] * k[b, 0] + sigma[a, 1] * k[b, 1]
            for a in range(nen):
                for kk in range(2):
                    gradient[e, a, kk] += (
                        w
                        * d
                        * (
                            shape_gradients[q, a, 0] * sigma_kt[kk, 0]
                            + shape_gradients[q, a, 1] * sigma_kt[kk, 1]
                        )
                    )
            if not with_hessian:
                continue
            cc = tangent[e, q]
            for i in range(2):
                for al in range(2):
                    # direction dJ = e_i ⊗ e_α, L = dJ J⁻¹: L_kl = δ_ki K_αl, tr L = K_αi
                    trace_l = k[al, i]
                    for a in range(2):
                        for b in range(2):
                            dC[a, b] = -(k[al, a] * c[i, b] + c[a, i] * k[al, b])
                    d_psi = 0.5 * (
                        s[0, 0] * dC[0, 0]
                        + s[0, 1] * dC[0, 1]
                        + s[1, 0] * dC[1, 0]
                        + s[1, 1] * dC[1, 1]
                    )
                    for a in range(2):
                        for b in range(2):
                            dS[a, b] = 0.5 * (
                                cc[a, b, 0, 0] * dC[0, 0]
                                + cc[a, b, 0, 1] * dC[0, 1]
                                + cc[a, b, 1, 0] * dC[1, 0]
                                + cc[a, b, 1, 1] * dC[1, 1]
                            )
                    for a in range(2):
                        for b in range(2):
                            d_sigma[a, b] = -(
                                dC[a, 0] * s[0, b]
                                + dC[a, 1] * s[1, b]
                                + c[a, 0] * dS[0, b]
                                + c[a, 1] * dS[1, b]
                            )
                        d_sigma[a, a] += d_psi
                    # dg = det J [tr L Σ Kᵀ + dΣ Kᵀ − Σ Lᵀ Kᵀ]
                    for a in range(2):
                        for b in range(2):
                            value = trace_l * sigma_kt[a, b]
                            value += d_sigma[a, 0] * k[b, 0] + d_sigma[a, 1] * k[b, 1]
                            # (Lᵀ Kᵀ)_{pb} = L_{rp} K_{br} = K_{αp} K_{bi}
                            value -= (sigma[a, 0] * k[al, 0] + sigma[a, 1] * k[al, 1]) * k[b, i]
                            # ∂g_ab / ∂J_i,al
                            jacobian_hessian[e, q, 2 * i + al, 2 * a + b] = d * value


@njit(cache=True, parallel=True)
def _nodal_hessian(jacobian_hessian, shape_gradients, scale, hessian):  # pragma: no cover
    """Add ``Σ_q w_q Bᵀ H_q B`` into ``hessian`` ``(m, nen, 2, nen, 2)``."""
    m, nq = jacobian_hessian.shape[0], jacobian_hessian.shape[1]
    nen = shape_gradients.shape[1]
    for e in prange(m):
        for q in range(nq):
            h = jacobian_hessian[e, q]
            w = scale[q]
            for a in range(nen):
                for kk in range(2):
                    for b in range(nen):
                        for ll in range(2):
                            value = 0.0 * h[0, 0]
                            for al in range(2):
                                for be in range(2):
                                    value += (
                                        shape_gradients[q, a, al]
                                        * h[2 * ll + be, 2 * kk + al]
                                        * shape_gradients[q, b, be]
                                    )
                            hessian[e, a, kk, b, ll] += w * value


@njit(cache=True, parallel=True)
def _project_psd(jacobian_hessian):  # pragma: no cover
    """:func:`project_psd` by cyclic Jacobi, block by block."""
    n = jacobian_hessian.shape[2]
    for e in prange(jacobian_hessian.shape[0]):
        a = np.empty((n, n))
        v = np.empty((n, n))
        for q in range(jacobian_hessian.shape[1]):
            h = jacobian_hessian[e, q]
            dominant = True
            for r in range(n):
                off = 0.0
                for c in range(n):
                    if c != r:
                        off += abs(0.5 * (h[r, c] + h[c, r]))
                if h[r, r] < off:
                    dominant = False
            if dominant:
                continue
            scale = 0.0
            for r in range(n):
                for c in range(n):
                    a[r, c] = 0.5 * (h[r, c] + h[c, r])
                    v[r, c] = 1.0 if r == c else 0.0
                    scale += a[r, c] * a[r, c]
            for _sweep in range(30):
                off = 0.0
                for r in range(n - 1):
                    for c in range(r + 1, n):
                        off += a[r, c] * a[r, c]
                if off <= 1e-30 * scale:
                    break
                for p in range(n - 1):
                    for r in range(p + 1, n):
                        if a[p, r] == 0.0:
                            continue
                        theta = (a[r, r] - a[p, p]) / (2.0 * a[p, r])
                        t = (1.0 if theta >= 0 else -1.0) / (
                            abs(theta) + np.sqrt(theta * theta + 1.0)
                        )
                        cos = 1.0 / np.sqrt(t * t + 1.0)
                        sin = t * cos
                        for k in range(n):  # A ← A G (columns p, r)
                            akp, akr = a[k, p], a[k, r]
                            a[k, p] = cos * akp - sin * akr
                            a[k, r] = sin * akp + cos * akr
                        for k in range(n):  # A ← Gᵀ A (rows p, r)
                            apk, ark = a[p, k], a[r, k]
                            a[p, k] = cos * apk - sin * ark
                            a[r, k] = sin * apk + cos * ark
                        for k in range(n):
                            vkp, vkr = v[k, p], v[k, r]
                            v[k, p] = cos * vkp - sin * vkr
                            v[k, r] = sin * vkp + cos * vkr
            for r in range(n):
                for c in range(n):
                    value = 0.0
                    for k in range(n):
                        if a[k, k] > 0.0:
                            value += v[r, k] * a[k, k] * v[c, k]
                    h[r, c] = value
