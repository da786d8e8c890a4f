"""Hyperelastic laws in terms of the invariants of the 2×2 right Cauchy–Green tensor.

A material is a strain energy density ``Ψ`` (per unit reference volume) written as a function of
the invariants of DESIGN.md §2,

    I1 = tr C,  I3 = det C,  I4 = Φ₁·CΦ₁,  I5 = Φ₁·C²Φ₁,  I6 = Φ₂·CΦ₂,  I7 = Φ₂·C²Φ₂,  I8 = Φ₁·CΦ₂,

together with its first and second derivatives with respect to the invariants it uses. Everything
else — the second Piola–Kirchhoff stress ``S = 2 ∂Ψ/∂C`` and the tangent ``ℂ = 4 ∂²Ψ/∂C∂C`` — is
derived here, once, for every law. A new law therefore only writes ``Ψ`` and its invariant
derivatives; the fibre directions ``Φ₁`` (warp) and ``Φ₂`` (fill) are supplied by the caller.

All functions are vectorised over leading axes and accept complex input (for complex-step checks).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .._jit import compiled, njit, prange

__all__ = ["INVARIANTS", "Fibres", "Hyperelastic", "MaterialError", "MaterialResponse"]

#: Names of the invariants a law may use, in the order of DESIGN.md §2.
INVARIANTS = ("I1", "I3", "I4", "I5", "I6", "I7", "I8")

_EYE = np.eye(2)
#: Symmetric fourth-order identity 𝕀_abcd = ½(δ_ac δ_bd + δ_ad δ_bc).
_SYM_IDENTITY = 0.5 * (np.einsum("ac,bd->abcd", _EYE, _EYE) + np.einsum("ad,bc->abcd", _EYE, _EYE))


class MaterialError(ValueError):
    """Inadmissible material parameters or fibre directions."""


class InadmissibleState(RuntimeError):
    """A deformation at which the response cannot be evaluated (e.g. no wrinkled state is
    found): a Newton step treats such a point like a fold, as infinite energy."""


@dataclass(frozen=True)
class Fibres:
    """Unit fibre directions in the pattern plane, ``(2,)`` each: ``warp`` Φ₁ and ``fill`` Φ₂."""

    warp: np.ndarray
    fill: np.ndarray

    @classmethod
    def from_angles(cls, warp_angle: float = 0.0, fill_angle: float | None = None) -> Fibres:
        """Fibres at ``warp_angle`` and ``fill_angle`` degrees from the pattern x-axis.

        The fill defaults to 90° from the warp.
        """
        if fill_angle is None:
            fill_angle = warp_angle + 90.0
        a, b = np.radians(warp_angle), np.radians(fill_angle)
        warp = np.array([np.cos(a), np.sin(a)])
        fill = np.array([np.cos(b), np.sin(b)])
        if abs(warp[0] * fill[1] - warp[1] * fill[0]) < 1e-8:
            raise MaterialError("warp and fill directions must not be parallel")
        return cls(warp, fill)


@dataclass(frozen=True)
class MaterialResponse:
    """A law's response at a set of states.

    ``psi`` ``(...)``: energy density; ``stress`` ``(..., 2, 2)``: ``S``; ``tangent``
    ``(..., 2, 2, 2, 2)``: ``ℂ``, or None when it was not asked for.
    """

    psi: np.ndarray
    stress: np.ndarray
    tangent: np.ndarray | None


def _outer(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return 0.5 * (np.multiply.outer(a, b) + np.multiply.outer(b, a))


def _c_squared_hessian(phi: np.ndarray) -> np.ndarray:
    """``∂²(Φ·C²Φ)/∂C∂C``, symmetrised over both index pairs (a constant)."""
    # d²I[dA, dB] = Φ·(dA dB + dB dA)Φ  →  T_abcd = Φ_a δ_bc Φ_d + Φ_c δ_da Φ_b
    t = np.einsum("a,bc,d->abcd", phi, _EYE, phi) + np.einsum("c,da,b->abcd", phi, _EYE, phi)
    t = 0.5 * (t + t.transpose(1, 0, 2, 3))
    return 0.5 * (t + t.transpose(0, 1, 3, 2))


def invariants(C: np.ndarray, names: tuple[str, ...], fibres: Fibres | None):
    """Values ``(..., k)``, first derivatives (list of ``(..., 2, 2)`` or ``(2, 2)``) and second
    derivatives (list of ``(2, 2, 2, 2)`` constants or ``None`` where zero) of the named invariants.
    """
    values, first, second = [], [], []
    tr = C[..., 0, 0] + C[..., 1, 1]
    for name in names:
        if name in ("I4", "I5", "I6", "I7", "I8") and fibres is None:
            raise MaterialError(f"invariant {name} needs fibre directions (warp/fill)")
        if name == "I1":
            values.append(tr)
            first.append(_EYE)
            second.append(None)
        elif name == "I3":
            values.append(C[..., 0, 0] * C[..., 1, 1] - C[..., 0, 1] * C[..., 1, 0])
            first.append(tr[..., None, None] * _EYE - C)  # cofactor of a 2×2 tensor
            second.append(np.einsum("ab,cd->abcd", _EYE, _EYE) - _SYM_IDENTITY)
        elif name in ("I4", "I6"):
            phi = fibres.warp if name == "I4" else fibres.fill
            values.append(np.einsum("a,...ab,b->...", phi, C, phi))
            first.append(np.multiply.outer(phi, phi))
            second.append(None)
        elif name in ("I5", "I7"):
            phi = fibres.warp if name == "I5" else fibres.fill
            c_phi = np.einsum("...ab,b->...a", C, phi)
            values.append(np.einsum("...a,...a->...", c_phi, c_phi))
            first.append(
                np.einsum("a,...b->...ab", phi, c_phi) + np.einsum("...a,b->...ab", c_phi, phi)
            )
            second.append(_c_squared_hessian(phi))
        elif name == "I8":
            values.append(np.einsum("a,...ab,b->...", fibres.warp, C, fibres.fill))
            first.append(_outer(fibres.warp, fibres.fill))
            second.append(None)
        else:
            raise MaterialError(f"unknown invariant {name!r}; known: {', '.join(INVARIANTS)}")
    return np.stack(values, axis=-1), first, second


class Hyperelastic(ABC):
    """Base class of all laws: subclasses name their ``invariants`` and implement
    :meth:`psi_invariants`, :meth:`dpsi_invariants` and :meth:`d2psi_invariants`.
    """

    #: The invariants ``Ψ`` depends on, a subset of :data:`INVARIANTS`.
    invariants: ClassVar[tuple[str, ...]]
    #: True for laws written for yarns at 90° in the pattern (fibre-frame laws).
    requires_orthogonal_fibres: ClassVar[bool] = False

    @abstractmethod
    def psi_invariants(self, inv: np.ndarray) -> np.ndarray:
        """``Ψ`` for invariant values ``(..., k)`` in the order of :attr:`invariants`."""

    @abstractmethod
    def dpsi_invariants(self, inv: np.ndarray) -> np.ndarray:
        """``∂Ψ/∂I_k``, shape ``(..., k)``."""

    @abstractmethod
    def d2psi_invariants(self, inv: np.ndarray) -> np.ndarray:
        """``∂²Ψ/∂I_k∂I_l``, shape ``(..., k, k)`` (symmetric)."""

    @property
    @abstractmethod
    def stiffness_scale(self) -> float:
        """A representative small-strain stiffness (stress units), used to scale tolerances."""

    def softness(self, fibres: Fibres | None = None) -> float:
        """The smallest eigenvalue of the small-strain stiffness ``ℂ`` at ``C = I`` (in Mandel
        form, so that a shear and a stretch of the same size count alike) over
        :attr:`stiffness_scale`: about 0.5–0.8 for an isotropic law, the shear over the yarn
        modulus for a fabric (2e-4 for yarns 10,000 times stiffer than the shear). ``nan`` where
        ``ℂ`` cannot be evaluated there."""
        try:
            c = self.response(np.eye(2)[None], fibres, tangent=True).tangent[0]
        except (ValueError, ArithmeticError):  # MaterialError is a ValueError
            return float("nan")
        root = np.sqrt(2.0)
        mandel = np.array(
            [
                [c[0, 0, 0, 0], c[0, 0, 1, 1], root * c[0, 0, 0, 1]],
                [c[1, 1, 0, 0], c[1, 1, 1, 1], root * c[1, 1, 0, 1]],
                [root * c[0, 1, 0, 0], root * c[0, 1, 1, 1], 2.0 * c[0, 1, 0, 1]],
            ]
        )
        if not np.all(np.isfinite(mandel)):
            return float("nan")
        return float(np.linalg.eigvalsh(0.5 * (mandel + mandel.T))[0]) / self.stiffness_scale

    @property
    def parameters(self) -> dict[str, object]:
        """The law's parameters by name (for reports and job files)."""
        return dict(vars(self))

    @property
    def needs_fibres(self) -> bool:
        """True when ``Ψ`` depends on the fibre directions (an anisotropic law)."""
        return any(name not in ("I1", "I3") for name in self.invariants)

    # --------------------------------------------------------------------- derived
    def response(
        self, C: np.ndarray, fibres: Fibres | None = None, *, tangent: bool = True
    ) -> MaterialResponse:
        """Energy density, ``S = 2∂Ψ/∂C`` and optionally ``ℂ = 4∂²Ψ/∂C∂C``.

        ``C`` has shape ``(..., 2, 2)``.
        """
        inv, first, second = invariants(C, self.invariants, fibres)
        psi = self.psi_invariants(inv)
        dpsi = self.dpsi_invariants(inv)
        d2psi = self.d2psi_invariants(inv) if tangent else None
        # compiled from as many cells (the leading axis) as the element kernels
        if C.ndim > 2 and compiled(len(C)) and np.isrealobj(C) and np.isrealobj(dpsi):
            stress, cc = _derived_compiled(C.shape, first, second, dpsi, d2psi)
            return MaterialResponse(psi, stress, cc)
        stress = sum(2.0 * dpsi[..., k, None, None] * first[k] for k in range(len(first)))
        stress = np.broadcast_to(stress, C.shape)
        if not tangent:
            return MaterialResponse(psi, stress, None)
        cc = np.zeros((*C.shape, 2, 2), dtype=np.result_type(C, psi))
        for k, dk in enumerate(first):
            for ell, dl in enumerate(first):
                coefficient = d2psi[..., k, ell]
                if not np.any(coefficient):
                    continue
                cc += (
                    4.0
                    * coefficient[..., None, None, None, None]
                    * np.einsum(
                        "...ab,...cd->...abcd",
                        np.broadcast_to(dk, C.shape),
                        np.broadcast_to(dl, C.shape),
                    )
                )
            if second[k] is not None:
                cc += 4.0 * dpsi[..., k, None, None, None, None] * second[k]
        return MaterialResponse(psi, stress, cc)

    def energy_density(self, C: np.ndarray, fibres: Fibres | None = None) -> np.ndarray:
        """``Ψ(C)`` for ``C`` ``(..., 2, 2)``."""
        inv, _, _ = invariants(C, self.invariants, fibres)
        return self.psi_invariants(inv)

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.parameters.items())
        return f"{type(self).__name__}({args})"


def _derived_compiled(shape, first, second, dpsi, d2psi):
    """``S`` and ``ℂ`` (None without ``d2psi``) of :meth:`Hyperelastic.response` by the compiled
    :func:`_derived`: the same sums in the same order, so the same numbers as the numpy form."""
    points, count = int(np.prod(shape[:-2])), len(first)
    gradients = np.empty((points, count, 2, 2))
    for k, dk in enumerate(first):
        gradients[:, k] = np.reshape(np.broadcast_to(dk, shape), (points, 2, 2))
    constants = np.zeros((count, 2, 2, 2, 2))
    has_second = np.zeros(count, dtype=np.bool_)
    for k, sk in enumerate(second):
        if sk is not None:
            constants[k], has_second[k] = sk, True
    first_derivatives = np.reshape(np.broadcast_to(dpsi, (*shape[:-2], count)), (points, count))
    stress = np.empty((points, 2, 2))
    if d2psi is None:  # nothing of these is read
        second_derivatives, pairs = np.zeros((1, count, count)), np.zeros((count, count), bool)
        tangent = np.empty((0, 2, 2, 2, 2))
    else:
        second_derivatives = np.reshape(
            np.broadcast_to(d2psi, (*shape[:-2], count, count)), (points, count, count)
        )
        pairs = np.any(second_derivatives, axis=0)  # the numpy form skips a pair zero everywhere
        tangent = np.empty((points, 2, 2, 2, 2))
    _derived(  # copies: one signature whatever the laws' arrays are (views, read-only)
        np.array(first_derivatives, dtype=float, order="C"),
        np.array(second_derivatives, dtype=float, order="C"),
        gradients,
        constants,
        has_second,
        pairs,
        d2psi is not None,
        stress,
        tangent,
    )
    stress = stress.reshape(shape)
    return stress, (None if d2psi is None else tangent.reshape((*shape, 2, 2)))


@njit(cache=True, parallel=True)
def _derived(
    dpsi, d2psi, gradients, constants, has_second, pairs, with_tangent, stress, tangent
):  # pragma: no cover
    """``S = Σ_k 2 ∂Ψ/∂I_k ∂I_k/∂C`` and ``ℂ = Σ_kl 4 ∂²Ψ/∂I_k∂I_l ∂I_k/∂C ⊗ ∂I_l/∂C + Σ_k 4
    ∂Ψ/∂I_k ∂²I_k/∂C∂C`` point by point (``gradients`` ``(n, k, 2, 2)``: ``∂I_k/∂C``;
    ``constants`` ``(k, 2, 2, 2, 2)``: ``∂²I_k/∂C∂C`` where ``has_second``; ``pairs``: the
    ``(k, l)`` whose ``∂²Ψ/∂I_k∂I_l`` is not zero everywhere)."""
    count = dpsi.shape[1]
    for p in prange(dpsi.shape[0]):
        for a in range(2):
            for b in range(2):
                value = 0.0
                for k in range(count):
                    value += 2.0 * dpsi[p, k] * gradients[p, k, a, b]
                stress[p, a, b] = value
        if not with_tangent:
            continue
        for a in range(2):
            for b in range(2):
                for c in range(2):
                    for d in range(2):
                        value = 0.0
                        for k in range(count):
                            for ell in range(count):
                                if pairs[k, ell]:
                                    value += (4.0 * d2psi[p, k, ell]) * (
                                        gradients[p, k, a, b] * gradients[p, ell, c, d]
                                    )
                            if has_second[k]:
                                value += (4.0 * dpsi[p, k]) * constants[k, a, b, c, d]
                        tangent[p, a, b, c, d] = value
    return 0


def check_positive(**values: float) -> None:
    """Raise :class:`MaterialError` unless every value is a finite positive number."""
    for name, value in values.items():
        if not (isinstance(value, int | float | np.floating | np.integer) and np.isfinite(value)):
            raise MaterialError(f"{name} must be a finite number; got {value!r}")
        if value <= 0:
            raise MaterialError(f"{name} must be positive; got {value!r}")
