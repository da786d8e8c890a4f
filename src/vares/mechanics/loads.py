"""Edge cables and pressure of the erection problem, each with its exact gradient and Hessian.

**Edge cables** are tension-only line elements between consecutive boundary nodes: a segment of
unstressed length ``L₀`` and axial stiffness ``EA`` stretched to length ``ℓ`` stores

    E = EA (ℓ − L₀)² / (2 L₀)  for ℓ > L₀,   0 otherwise (a slack cable carries nothing),

with the tension ``T = EA (ℓ − L₀)/L₀`` along the segment and the tangent
``EA/L₀ e⊗e + T/ℓ (I − e⊗e)`` (``e`` the unit vector along it).

**Pressure** ``p`` acts along the surface normal of the cells' orientation (right-hand rule on the
node order) and follows the surface as it moves. With every boundary node held, it is the
gradient of the potential ``−p V``, ``V = Σ_triangles x₁·(x₂ × x₃)/6`` the volume of the cones
from the origin over the cells (a quad: the mean of its two triangulations); its Hessian is the
load stiffness of the follower load.
"""

from __future__ import annotations

import numpy as np

__all__ = ["cable_terms", "pressure_terms"]

#: The two triangulations of a quad (node order 0-1-2-3), each counted with weight ½.
_QUAD_TRIANGLES = ((0, 1, 2), (0, 2, 3), (0, 1, 3), (1, 2, 3))


def cable_terms(
    positions: np.ndarray, rest_length: np.ndarray, stiffness: float, order: int = 2
) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None, np.ndarray]:
    """Energy ``(k,)``, gradient ``(k, 2, 3)``, Hessian ``(k, 2, 3, 2, 3)`` and tension ``(k,)``
    of cable segments whose end positions are ``positions`` ``(k, 2, 3)``."""
    delta = positions[:, 1] - positions[:, 0]
    length = np.linalg.norm(delta, axis=1)
    stretch = np.maximum(length - rest_length, 0.0)
    tension = stiffness * stretch / rest_length
    energy = 0.5 * stiffness * stretch**2 / rest_length
    if order == 0:
        return energy, None, None, tension
    unit = delta / length[:, None]
    force = tension[:, None] * unit
    gradient = np.stack([-force, force], axis=1)
    if order == 1:
        return energy, gradient, None, tension
    taut = (stretch > 0)[:, None, None]
    outer = np.einsum("ki,kj->kij", unit, unit)
    block = np.where(
        taut,
        (stiffness / rest_length)[:, None, None] * outer
        + (tension / length)[:, None, None] * (np.eye(3) - outer),
        0.0,
    )
    hessian = np.zeros((len(delta), 2, 3, 2, 3))
    hessian[:, 0, :, 0, :] = hessian[:, 1, :, 1, :] = block
    hessian[:, 0, :, 1, :] = hessian[:, 1, :, 0, :] = -block
    return energy, gradient, hessian, tension


def _skew(a: np.ndarray) -> np.ndarray:
    """``[a]×`` ``(..., 3, 3)``: ``[a]× b = a × b``."""
    out = np.zeros((*a.shape[:-1], 3, 3), dtype=a.dtype)
    out[..., 0, 1], out[..., 0, 2] = -a[..., 2], a[..., 1]
    out[..., 1, 0], out[..., 1, 2] = a[..., 2], -a[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -a[..., 1], a[..., 0]
    return out


def _cone_volume(x: np.ndarray, order: int):
    """Volume ``x₁·(x₂ × x₃)/6`` of triangles ``(m, 3, 3)``, its gradient and Hessian."""
    volume = np.einsum("mi,mi->m", x[:, 0], np.cross(x[:, 1], x[:, 2])) / 6.0
    if order == 0:
        return volume, None, None
    gradient = np.stack([np.cross(x[:, (a + 1) % 3], x[:, (a + 2) % 3]) for a in range(3)], 1) / 6
    if order == 1:
        return volume, gradient, None
    hessian = np.zeros((len(x), 3, 3, 3, 3), dtype=x.dtype)
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        hessian[:, a, :, b, :] = -_skew(x[:, c]) / 6.0
        hessian[:, a, :, c, :] = _skew(x[:, b]) / 6.0
    return volume, gradient, hessian


def pressure_terms(nodes: np.ndarray, pressure: float, order: int = 2):
    """Potential ``−p V`` ``(m,)`` of cells whose node positions are ``nodes`` ``(m, nen, 3)``
    (triangles or quads), its gradient ``(m, nen, 3)`` and Hessian ``(m, nen, 3, nen, 3)``."""
    m, nen = nodes.shape[:2]
    triangles = ((0, 1, 2),) if nen == 3 else _QUAD_TRIANGLES
    weight = -pressure * (1.0 if nen == 3 else 0.5)
    energy = np.zeros(m, dtype=nodes.dtype)
    gradient = None if order == 0 else np.zeros((m, nen, 3), dtype=nodes.dtype)
    hessian = None if order < 2 else np.zeros((m, nen, 3, nen, 3), dtype=nodes.dtype)
    for triangle in triangles:
        index = list(triangle)
        volume, g, h = _cone_volume(nodes[:, index], order)
        energy += weight * volume
        if gradient is not None:
            gradient[:, index] += weight * g
        if hessian is not None:
            for ia, a in enumerate(index):
                for ib, b in enumerate(index):
                    hessian[:, a, :, b, :] += weight * h[:, ia, :, ib, :]
    return energy, gradient, hessian
