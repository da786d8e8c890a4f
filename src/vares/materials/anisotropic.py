"""Anisotropic laws for fabrics: coated architectural fabrics and non-crimp composite fabrics.

Both are written in the fibre invariants ``I4 = Φ₁·CΦ₁`` (warp), ``I6 = Φ₂·CΦ₂`` (fill) and
``I8 = Φ₁·CΦ₂`` for yarns that are orthogonal in the pattern (fill at 90° to the warp: 0°/90° or
±45° plies). For orthogonal yarns ``C`` in the fibre frame is ``[[I4, I8], [I8, I6]]``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .base import Hyperelastic, MaterialError, check_positive

__all__ = ["NonCrimpFabric", "OrthotropicStVenantKirchhoff"]


class OrthotropicStVenantKirchhoff(Hyperelastic):
    """Orthotropic St. Venant–Kirchhoff law in the fibre frame (coated fabrics, 1 = warp).

    ``Ψ = ½ (Q11 E11² + 2 Q12 E11 E22 + Q22 E22² + Q66 γ²)`` with ``E11 = (I4 − 1)/2``,
    ``E22 = (I6 − 1)/2``, the engineering shear strain ``γ = 2 E12 = I8`` and the plane-stress
    stiffnesses ``Q11 = E1/(1 − ν12 ν21)``, ``Q22 = E2/(1 − ν12 ν21)``,
    ``Q12 = ν12 E2/(1 − ν12 ν21)``, ``Q66 = G12``, ``ν21 = ν12 E2/E1``. For fabrics given as
    force per length (``E·t``) use thickness 1. With ``E1 = E2 = E`` and
    ``G12 = E/(2(1 + ν))`` it is the isotropic law.
    """

    invariants = ("I4", "I6", "I8")
    requires_orthogonal_fibres = True

    def __init__(self, E1: float, E2: float, G12: float, nu12: float) -> None:
        check_positive(E1=E1, E2=E2, G12=G12)
        if not (isinstance(nu12, int | float | np.floating | np.integer) and np.isfinite(nu12)):
            raise MaterialError(f"nu12 must be a finite number; got {nu12!r}")
        self.E1, self.E2, self.G12, self.nu12 = float(E1), float(E2), float(G12), float(nu12)
        nu21 = self.nu12 * self.E2 / self.E1
        if self.nu12 * nu21 >= 1.0:
            raise MaterialError(
                "the orthotropic stiffness matrix is not positive definite: it needs "
                f"nu12² < E1/E2 = {self.E1 / self.E2:.6g}; got nu12 = {self.nu12}"
            )
        denominator = 1.0 - self.nu12 * nu21
        self.Q11 = self.E1 / denominator
        self.Q22 = self.E2 / denominator
        self.Q12 = self.nu12 * self.E2 / denominator
        self.Q66 = self.G12

    @property
    def parameters(self) -> dict[str, object]:
        return {"E1": self.E1, "E2": self.E2, "G12": self.G12, "nu12": self.nu12}

    @property
    def stiffness_scale(self) -> float:
        return max(self.E1, self.E2)

    def psi_invariants(self, inv):
        e1, e2, gamma = 0.5 * (inv[..., 0] - 1.0), 0.5 * (inv[..., 1] - 1.0), inv[..., 2]
        return 0.5 * (
            self.Q11 * e1**2 + 2.0 * self.Q12 * e1 * e2 + self.Q22 * e2**2 + self.Q66 * gamma**2
        )

    def dpsi_invariants(self, inv):
        e1, e2 = 0.5 * (inv[..., 0] - 1.0), 0.5 * (inv[..., 1] - 1.0)
        return np.stack(
            [
                0.5 * (self.Q11 * e1 + self.Q12 * e2),
                0.5 * (self.Q12 * e1 + self.Q22 * e2),
                self.Q66 * inv[..., 2],
            ],
            axis=-1,
        )

    def d2psi_invariants(self, inv):
        out = np.zeros((*inv.shape, 3), dtype=inv.dtype)
        out[..., 0, 0] = 0.25 * self.Q11
        out[..., 0, 1] = out[..., 1, 0] = 0.25 * self.Q12
        out[..., 1, 1] = 0.25 * self.Q22
        out[..., 2, 2] = self.Q66
        return out


def _coefficients(name: str, values: Sequence[float], first: int) -> np.ndarray:
    array = np.asarray(values, dtype=float).ravel()
    if array.size == 0:
        raise MaterialError(f"{name} needs at least one coefficient")
    if not np.all(np.isfinite(array)):
        raise MaterialError(f"{name} coefficients must be finite; got {list(values)}")
    if first and array.size and array[0] <= 0:
        raise MaterialError(f"{name}[0] must be positive (the small-strain stiffness)")
    return array


class NonCrimpFabric(Hyperelastic):
    """Non-crimp fabric law of the seed paper (eq. 6, after Aimène et al. 2010).

    ``Ψ = Σ_i A_i/(i+1) (I4^{i+1} − 1) + Σ_j B_j/(j+1) (I6^{j+1} − 1)
    + Σ_k C_k/k (I8²/(I4 I6))^k``

    with ``A = [A_0, A_1, …]``, ``B = [B_0, B_1, …]`` (``i, j`` from 0) and ``C = [C_1, C_2, …]``
    (``k`` from 1). The yarn stresses are ``S_warp = 2 Σ_i A_i I4^i`` and alike for the fill;
    ``I8²/(I4 I6) = cos²θ`` with ``θ`` the angle between the yarns after erection, so the
    ``C`` terms resist yarn shear. The reference state is stress free only when
    ``Σ A_i = Σ B_j = 0``; this is required. Small-strain stiffnesses: warp modulus
    ``4 Σ_i i A_i``, fill modulus ``4 Σ_j j B_j``, shear modulus ``2 C_1``.

    No measured coefficient set is built in; :meth:`from_moduli` makes a simple one from the
    small-strain moduli a user knows.
    """

    invariants = ("I4", "I6", "I8")
    requires_orthogonal_fibres = True

    def __init__(self, A: Sequence[float], B: Sequence[float], C: Sequence[float]) -> None:
        self.A = _coefficients("A", A, first=0)
        self.B = _coefficients("B", B, first=0)
        self.C = _coefficients("C", C, first=1)
        for name, coefficients in (("A", self.A), ("B", self.B)):
            if abs(coefficients.sum()) > 1e-12 * np.abs(coefficients).max():
                raise MaterialError(
                    f"sum({name}) must be 0 for a stress-free reference state; got "
                    f"{coefficients.sum():.6g}"
                )
        if self.warp_modulus <= 0 or self.fill_modulus <= 0:
            raise MaterialError(
                "the small-strain yarn moduli 4 Σ i A_i and 4 Σ j B_j must be positive; got "
                f"{self.warp_modulus:.6g} and {self.fill_modulus:.6g}"
            )

    @classmethod
    def from_moduli(
        cls, warp_modulus: float, fill_modulus: float, shear_modulus: float
    ) -> NonCrimpFabric:
        """The simplest law with the given small-strain moduli (stress units, or force/length
        with thickness 1): ``A = [−a, a]``, ``a = warp_modulus/4``, likewise ``B``, and
        ``C = [shear_modulus/2]``. The yarn stress is then ``S = 2a I4 (I4 − 1)``.
        """
        check_positive(
            warp_modulus=warp_modulus, fill_modulus=fill_modulus, shear_modulus=shear_modulus
        )
        a, b = warp_modulus / 4.0, fill_modulus / 4.0
        return cls([-a, a], [-b, b], [shear_modulus / 2.0])

    @property
    def warp_modulus(self) -> float:
        return float(4.0 * np.arange(self.A.size) @ self.A)

    @property
    def fill_modulus(self) -> float:
        return float(4.0 * np.arange(self.B.size) @ self.B)

    @property
    def parameters(self) -> dict[str, object]:
        return {"A": self.A.tolist(), "B": self.B.tolist(), "C": self.C.tolist()}

    @property
    def stiffness_scale(self) -> float:
        return max(self.warp_modulus, self.fill_modulus)

    @staticmethod
    def _yarn(coefficients, stretch_sq, derivative):
        powers = np.arange(coefficients.size)
        if derivative == 0:
            return sum(
                c / (i + 1) * (stretch_sq ** (i + 1) - 1.0)
                for i, c in zip(powers, coefficients, strict=True)
            )
        if derivative == 1:
            return sum(c * stretch_sq**i for i, c in zip(powers, coefficients, strict=True))
        return (
            sum(
                c * i * stretch_sq ** (i - 1)
                for i, c in zip(powers[1:], coefficients[1:], strict=True)
            )
            + 0.0 * stretch_sq
        )

    def _shear(self, inv):
        """Shear energy ``f(s) = Σ C_k/k s^k`` of ``s = I8²/(I4 I6)`` and its derivatives."""
        s = inv[..., 2] ** 2 / (inv[..., 0] * inv[..., 1])
        ks = np.arange(1, self.C.size + 1)
        f = sum(c / k * s**k for k, c in zip(ks, self.C, strict=True))
        df = sum(c * s ** (k - 1) for k, c in zip(ks, self.C, strict=True))
        d2f = sum(c * (k - 1) * s ** (k - 2) for k, c in zip(ks[1:], self.C[1:], strict=True))
        return s, f, df, d2f + 0.0 * s

    def psi_invariants(self, inv):
        _, f, _, _ = self._shear(inv)
        return self._yarn(self.A, inv[..., 0], 0) + self._yarn(self.B, inv[..., 1], 0) + f

    def dpsi_invariants(self, inv):
        i4, i6, i8 = inv[..., 0], inv[..., 1], inv[..., 2]
        s, _, df, _ = self._shear(inv)
        return np.stack(
            [
                self._yarn(self.A, i4, 1) - df * s / i4,
                self._yarn(self.B, i6, 1) - df * s / i6,
                df * 2.0 * i8 / (i4 * i6),
            ],
            axis=-1,
        )

    def d2psi_invariants(self, inv):
        i4, i6, i8 = inv[..., 0], inv[..., 1], inv[..., 2]
        s, _, df, d2f = self._shear(inv)
        # s = I8²/(I4 I6): first and second derivatives with respect to (I4, I6, I8)
        ds = np.stack([-s / i4, -s / i6, 2.0 * i8 / (i4 * i6)], axis=-1)
        d2s = np.empty((*inv.shape, 3), dtype=inv.dtype)
        d2s[..., 0, 0] = 2.0 * s / i4**2
        d2s[..., 1, 1] = 2.0 * s / i6**2
        d2s[..., 2, 2] = 2.0 / (i4 * i6)
        d2s[..., 0, 1] = d2s[..., 1, 0] = s / (i4 * i6)
        d2s[..., 0, 2] = d2s[..., 2, 0] = -2.0 * i8 / (i4**2 * i6)
        d2s[..., 1, 2] = d2s[..., 2, 1] = -2.0 * i8 / (i4 * i6**2)
        out = d2f[..., None, None] * ds[..., :, None] * ds[..., None, :]
        out = out + df[..., None, None] * d2s
        out[..., 0, 0] += self._yarn(self.A, i4, 2)
        out[..., 1, 1] += self._yarn(self.B, i6, 2)
        return out
