"""Isotropic laws for the plane-stress state of a membrane (DESIGN.md §2).

Each law is ``Ψ(I1, I3)``: ``I1 = tr C``, ``I3 = det C`` of the 2×2 in-plane ``C``. ``E`` and ``nu``
are the small-strain Young's modulus and Poisson's ratio; the plane-stress Lamé constant is
``λ* = E ν / (1 − ν²)`` and the shear modulus ``μ = E / (2 (1 + ν))``.
"""

from __future__ import annotations

import numpy as np

from .base import Hyperelastic, MaterialError, check_positive

__all__ = ["IncompressibleNeoHooke", "NeoHooke", "StVenantKirchhoff"]


def _check_poisson(nu: float) -> None:
    if not (isinstance(nu, int | float | np.floating | np.integer) and np.isfinite(nu)):
        raise MaterialError(f"nu must be a finite number; got {nu!r}")
    if not -1.0 < nu <= 0.5:
        raise MaterialError(f"an isotropic Poisson's ratio must satisfy -1 < nu <= 0.5; got {nu}")


class _ENuLaw(Hyperelastic):
    """Shared parameter handling of the laws given by ``E`` and ``nu``."""

    invariants = ("I1", "I3")

    def __init__(self, E: float, nu: float) -> None:
        check_positive(E=E)
        _check_poisson(nu)
        self.E = float(E)
        self.nu = float(nu)

    @property
    def lame_plane_stress(self) -> float:
        """``λ* = E ν / (1 − ν²)``."""
        return self.E * self.nu / (1.0 - self.nu**2)

    @property
    def shear_modulus(self) -> float:
        """``μ = E / (2 (1 + ν))``."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def stiffness_scale(self) -> float:
        return self.E


class StVenantKirchhoff(_ENuLaw):
    """St. Venant–Kirchhoff, plane stress: ``Ψ = λ*/2 (tr E)² + μ E:E``, ``E = (C − I)/2``.

    With ``tr E = (I1 − 2)/2`` and ``E:E = (I1² − 2 I3 − 2 I1 + 2)/4``.
    """

    def psi_invariants(self, inv):
        i1, i3 = inv[..., 0], inv[..., 1]
        lam, mu = self.lame_plane_stress, self.shear_modulus
        return lam / 8.0 * (i1 - 2.0) ** 2 + mu / 4.0 * (i1**2 - 2.0 * i3 - 2.0 * i1 + 2.0)

    def dpsi_invariants(self, inv):
        i1 = inv[..., 0]
        lam, mu = self.lame_plane_stress, self.shear_modulus
        return np.stack(
            [lam / 4.0 * (i1 - 2.0) + mu / 2.0 * (i1 - 1.0), np.full_like(i1, -mu / 2.0)], axis=-1
        )

    def d2psi_invariants(self, inv):
        out = np.zeros((*inv.shape, 2), dtype=inv.dtype)
        out[..., 0, 0] = self.lame_plane_stress / 4.0 + self.shear_modulus / 2.0
        return out


class NeoHooke(_ENuLaw):
    """Compressible Neo-Hooke: ``Ψ = μ/2 (I1 − 2 − ln I3) + λ*/8 (ln I3)²``.

    Its small-strain limit is plane-stress Hooke's law with ``E`` and ``nu``.
    """

    def psi_invariants(self, inv):
        i1, i3 = inv[..., 0], inv[..., 1]
        log3 = np.log(i3)
        return self.shear_modulus / 2.0 * (i1 - 2.0 - log3) + self.lame_plane_stress / 8.0 * log3**2

    def dpsi_invariants(self, inv):
        i1, i3 = inv[..., 0], inv[..., 1]
        mu, lam = self.shear_modulus, self.lame_plane_stress
        return np.stack(
            [np.full_like(i1, mu / 2.0), (-mu / 2.0 + lam / 4.0 * np.log(i3)) / i3], axis=-1
        )

    def d2psi_invariants(self, inv):
        i3 = inv[..., 1]
        mu, lam = self.shear_modulus, self.lame_plane_stress
        out = np.zeros((*inv.shape, 2), dtype=inv.dtype)
        out[..., 1, 1] = (mu / 2.0 + lam / 4.0 * (1.0 - np.log(i3))) / i3**2
        return out


class IncompressibleNeoHooke(Hyperelastic):
    """Incompressible Neo-Hooke in plane stress (rubber): ``Ψ = μ/2 (I1 + 1/I3 − 3)``.

    The thickness stretch ``λ₃² = 1/I3`` is eliminated by incompressibility; the small-strain
    Young's modulus is ``3μ``.
    """

    invariants = ("I1", "I3")

    def __init__(self, mu: float) -> None:
        check_positive(mu=mu)
        self.mu = float(mu)

    @property
    def stiffness_scale(self) -> float:
        return 3.0 * self.mu

    def psi_invariants(self, inv):
        i1, i3 = inv[..., 0], inv[..., 1]
        return self.mu / 2.0 * (i1 + 1.0 / i3 - 3.0)

    def dpsi_invariants(self, inv):
        i1, i3 = inv[..., 0], inv[..., 1]
        return np.stack([np.full_like(i1, self.mu / 2.0), -self.mu / (2.0 * i3**2)], axis=-1)

    def d2psi_invariants(self, inv):
        out = np.zeros((*inv.shape, 2), dtype=inv.dtype)
        out[..., 1, 1] = self.mu / inv[..., 1] ** 3
        return out
