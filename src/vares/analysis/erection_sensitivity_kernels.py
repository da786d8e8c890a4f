"""The loops of :mod:`vares.analysis.erection_sensitivity`: the mixed derivative ``∂r/∂X`` of
a membrane block's nodal residuals and the chain rule of a point function of ``C`` to the nodes'
positions and the pattern, one cell at a time.

Compiled with numba from :data:`vares._jit.COMPILED_FROM` cells; below, the same functions run
as Python over arrays with the cells on the last axis (:func:`vares._jit.lanes`), so their
bodies use elementwise arithmetic only and write into arrays their caller made. The formulas are
those of :mod:`vares.analysis.erection_sensitivity` (its module docs), written out entry by
entry: at a quadrature point, for the pattern dof ``(b, α)``,

    δC = −(G_b ⊗ C e_α + C e_α ⊗ G_b),   δS = ½ ℂ : δC,
    δr_c = w G_bα F S G_c − w F e_α (G_b·S G_c) + w F δS G_c − w G_cα F S G_b.
"""

from __future__ import annotations

import numpy as np

from .._jit import compiled, lanes, njit

__all__ = ["chained_points", "mixed_derivative"]


def mixed_derivative(
    G: np.ndarray, w: np.ndarray, F: np.ndarray, C: np.ndarray, S: np.ndarray, cc: np.ndarray
) -> np.ndarray:
    """``∂r/∂X`` ``(m, nen, 3, nen, 2)`` (``[c, i, b, α]``: residual of node ``c``, direction
    ``i``, by pattern coordinate ``α`` of node ``b``) from the points' shape gradients ``G``
    ``(m, q, nen, 2)``, weights ``w`` ``(m, q)``, ``F`` ``(m, q, 3, 2)``, ``C`` and ``S``
    ``(m, q, 2, 2)`` and tangent ``ℂ`` ``(m, q, 2, 2, 2, 2)``."""
    m, nen = G.shape[0], G.shape[2]
    dtype = np.result_type(G, w, F, C, S, cc)
    out = np.zeros((m, nen, 3, nen, 2), dtype)
    arrays = [np.ascontiguousarray(a, dtype=dtype) for a in (G, w, F, C, S, cc)]
    if compiled(m):
        _mixed(*arrays, out)
    else:
        _mixed.py_func(*map(lanes, arrays), lanes(out))
    return out


def chained_points(
    n: np.ndarray,
    by_C: np.ndarray,
    by_S: np.ndarray,
    cc: np.ndarray,
    G: np.ndarray,
    w: np.ndarray,
    F: np.ndarray,
    C: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """For a point function ``n`` ``(m, q)`` of ``C`` and ``S`` with partial derivatives
    ``by_C``, ``by_S`` ``(m, q, 2, 2)`` (its total ``D = ∂n/∂C + ½ ∂n/∂S : ℂ``): the sums
    over the points ``Σ_q w dn/dx_a`` ``(m, nen, 3)`` and ``Σ_q (δw n + w dn/dX_b)``
    ``(m, nen, 2)``."""
    m, nen = G.shape[0], G.shape[2]
    dtype = np.result_type(n, by_C, by_S, cc, G, w, F, C)
    by_x, by_X = np.zeros((m, nen, 3), dtype), np.zeros((m, nen, 2), dtype)
    arrays = [np.ascontiguousarray(a, dtype=dtype) for a in (n, by_C, by_S, cc, G, w, F, C)]
    if compiled(m):
        _chained(*arrays, by_x, by_X)
    else:
        _chained.py_func(*map(lanes, arrays), lanes(by_x), lanes(by_X))
    return by_x, by_X


@njit(cache=True)
def _mixed(G, w, F, C, S, cc, out):  # pragma: no cover - compiled
    m, nq, nen = G.shape[0], G.shape[1], G.shape[2]
    fs = np.empty_like(F[0, 0])  # (3, 2) of a cell, or of every cell
    fds = np.empty_like(fs)
    dC = np.empty_like(C[0, 0])
    dS = np.empty_like(dC)
    for e in range(m):
        for q in range(nq):
            g, f, c, s, k, wq = G[e, q], F[e, q], C[e, q], S[e, q], cc[e, q], w[e, q]
            for i in range(3):
                for y in range(2):
                    fs[i, y] = f[i, 0] * s[0, y] + f[i, 1] * s[1, y]
            for b in range(nen):
                gs0 = g[b, 0] * s[0, 0] + g[b, 1] * s[1, 0]  # (G_b S)
                gs1 = g[b, 0] * s[0, 1] + g[b, 1] * s[1, 1]
                for al in range(2):
                    for x in range(2):
                        for z in range(2):
                            dC[x, z] = -(g[b, x] * c[al, z] + g[b, z] * c[al, x])
                    for x in range(2):
                        for y in range(2):
                            dS[x, y] = 0.5 * (
                                k[x, y, 0, 0] * dC[0, 0]
                                + k[x, y, 0, 1] * dC[0, 1]
                                + k[x, y, 1, 0] * dC[1, 0]
                                + k[x, y, 1, 1] * dC[1, 1]
                            )
                    for i in range(3):
                        for z in range(2):
                            fds[i, z] = f[i, 0] * dS[0, z] + f[i, 1] * dS[1, z]
                    dw = wq * g[b, al]
                    for cn in range(nen):
                        gsg = gs0 * g[cn, 0] + gs1 * g[cn, 1]
                        for i in range(3):
                            fsg_c = fs[i, 0] * g[cn, 0] + fs[i, 1] * g[cn, 1]
                            fsg_b = fs[i, 0] * g[b, 0] + fs[i, 1] * g[b, 1]
                            fdsg = fds[i, 0] * g[cn, 0] + fds[i, 1] * g[cn, 1]
                            out[e, cn, i, b, al] += (
                                dw * fsg_c
                                - wq * f[i, al] * gsg
                                + wq * fdsg
                                - wq * g[cn, al] * fsg_b
                            )


@njit(cache=True)
def _chained(n, by_C, by_S, cc, G, w, F, C, by_x, by_X):  # pragma: no cover - compiled
    m, nq, nen = G.shape[0], G.shape[1], G.shape[2]
    d = np.empty_like(C[0, 0])  # (2, 2) of a cell, or of every cell
    for e in range(m):
        for q in range(nq):
            g, f, c, k, wq = G[e, q], F[e, q], C[e, q], cc[e, q], w[e, q]
            bs = by_S[e, q]
            for u in range(2):
                for v in range(2):
                    d[u, v] = by_C[e, q, u, v] + 0.5 * (
                        bs[0, 0] * k[0, 0, u, v]
                        + bs[0, 1] * k[0, 1, u, v]
                        + bs[1, 0] * k[1, 0, u, v]
                        + bs[1, 1] * k[1, 1, u, v]
                    )
            s00, s01, s11 = d[0, 0] + d[0, 0], d[0, 1] + d[1, 0], d[1, 1] + d[1, 1]
            for a in range(nen):
                for i in range(3):
                    # Σ_u G_au Σ_v (D_uv + D_vu) F_iv
                    by_x[e, a, i] += wq * (
                        g[a, 0] * (s00 * f[i, 0] + s01 * f[i, 1])
                        + g[a, 1] * (s01 * f[i, 0] + s11 * f[i, 1])
                    )
                for al in range(2):
                    # D : δC = −Σ_uv D_uv (G_bu C_αv + G_bv C_αu)
                    dn = 0.0 * wq
                    for u in range(2):
                        for v in range(2):
                            dn -= d[u, v] * (g[a, u] * c[al, v] + g[a, v] * c[al, u])
                    by_X[e, a, al] += wq * (g[a, al] * n[e, q] + dn)
