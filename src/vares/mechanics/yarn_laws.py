"""The parts of a fibre law that stiff-yarn treatments need: the law without the share of its
yarn part that is evaluated elsewhere (:class:`ShearPart`), the law with its yarn part scaled
(:class:`ScaledYarns`, the stages of a continuation in the yarn-to-shear ratio), and that ratio
(:func:`yarn_to_shear_ratio`). Laws of ``(I4, I6, I8)`` only; the yarn part is
``Ψ(I4, I6, 0)``, the rest ``Ψ(I4, I6, I8) − Ψ(I4, I6, 0)`` the shear part.
"""

from __future__ import annotations

import numpy as np

from ..materials import Hyperelastic, MaterialError

__all__ = ["FIBRE_INVARIANTS", "ScaledYarns", "ShearPart", "yarn_to_shear_ratio"]

#: The invariants of the laws these parts are made from.
FIBRE_INVARIANTS = ("I4", "I6", "I8")


def _unsheared(inv: np.ndarray) -> np.ndarray:
    out = inv.copy()
    out[..., 2] = 0.0
    return out


class ShearPart(Hyperelastic):
    """``Ψ(I4, I6, I8) − (1 − kept) Ψ(I4, I6, 0)`` of a fibre law: what is left per cell when
    the share ``1 − kept`` of the yarn part ``Ψ(I4, I6, 0)`` is evaluated with smoothed
    stretches."""

    invariants = FIBRE_INVARIANTS
    requires_orthogonal_fibres = True

    def __init__(self, law: Hyperelastic, kept: float = 0.0) -> None:
        if tuple(law.invariants) != FIBRE_INVARIANTS:
            raise MaterialError(
                "smoothed yarn strains need a law of the invariants (I4, I6, I8); "
                f"{type(law).__name__} uses {', '.join(law.invariants)}"
            )
        self.law = law
        self.kept = float(kept)
        self._removed = 1.0 - self.kept

    def psi_invariants(self, inv):
        unsheared = self.law.psi_invariants(_unsheared(inv))
        return self.law.psi_invariants(inv) - self._removed * unsheared

    def dpsi_invariants(self, inv):
        d0 = self.law.dpsi_invariants(_unsheared(inv))
        d0[..., 2] = 0.0
        return self.law.dpsi_invariants(inv) - self._removed * d0

    def d2psi_invariants(self, inv):
        d0 = self.law.d2psi_invariants(_unsheared(inv))
        d0[..., 2, :] = 0.0
        d0[..., :, 2] = 0.0
        return self.law.d2psi_invariants(inv) - self._removed * d0

    @property
    def stiffness_scale(self) -> float:
        return self.law.stiffness_scale

    @property
    def parameters(self) -> dict[str, object]:
        return {"law": type(self.law).__name__, **self.law.parameters}


def yarn_to_shear_ratio(material: Hyperelastic) -> float:
    """The small-strain yarn-to-shear stiffness ratio ``E/G`` of a law of ``(I4, I6, I8)``:
    ``4 ∂²Ψ/∂I4²`` (or ``∂²Ψ/∂I6²``, the larger) over ``∂²Ψ/∂I8²`` at ``C = I`` (for the
    orthotropic St. Venant–Kirchhoff law ``Q11/G12``)."""
    if tuple(material.invariants) != FIBRE_INVARIANTS:
        raise MaterialError(
            "a yarn-to-shear ratio needs a law of the invariants (I4, I6, I8); "
            f"{type(material).__name__} uses {', '.join(material.invariants)}"
        )
    d2 = material.d2psi_invariants(np.array([1.0, 1.0, 0.0]))
    return float(4.0 * max(d2[0, 0], d2[1, 1]) / d2[2, 2])


class ScaledYarns(Hyperelastic):
    """A law of ``(I4, I6, I8)`` with its yarn part scaled:
    ``Ψ_s = s Ψ(I4, I6, 0) + [Ψ(I4, I6, I8) − Ψ(I4, I6, 0)]``, so the yarn-to-shear ratio is
    ``s`` times the law's and the shear response is the law's (for the orthotropic
    St. Venant–Kirchhoff law: ``E1``, ``E2`` times ``s``, ``G12`` and ``ν12`` kept)."""

    invariants = FIBRE_INVARIANTS
    requires_orthogonal_fibres = True

    def __init__(self, law: Hyperelastic, factor: float) -> None:
        yarn_to_shear_ratio(law)  # refuses laws of other invariants
        if not (np.isfinite(factor) and factor > 0.0):
            raise MaterialError(f"the yarn scale factor must be positive; got {factor!r}")
        self.law = law
        self.factor = float(factor)

    def psi_invariants(self, inv):
        return self.law.psi_invariants(inv) + (self.factor - 1.0) * self.law.psi_invariants(
            _unsheared(inv)
        )

    def dpsi_invariants(self, inv):
        d0 = self.law.dpsi_invariants(_unsheared(inv))
        d0[..., 2] = 0.0
        return self.law.dpsi_invariants(inv) + (self.factor - 1.0) * d0

    def d2psi_invariants(self, inv):
        d0 = self.law.d2psi_invariants(_unsheared(inv))
        d0[..., 2, :] = 0.0
        d0[..., :, 2] = 0.0
        return self.law.d2psi_invariants(inv) + (self.factor - 1.0) * d0

    @property
    def stiffness_scale(self) -> float:
        return self.factor * self.law.stiffness_scale

    @property
    def parameters(self) -> dict[str, object]:
        return {"law": type(self.law).__name__, "yarn_factor": self.factor, **self.law.parameters}
