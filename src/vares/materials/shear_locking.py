"""A non-crimp fabric that locks: its shear stiffness rises steeply towards a locking angle.

A dry fabric shears almost freely until the yarns of one family press against each other; near
that **locking angle** its shear stiffness rises by orders of magnitude (docs/composites.md,
"Darts"). The plain non-crimp fabric law (:class:`~vares.materials.NonCrimpFabric` with one
``C`` term) has no locking in it: with inextensible yarns its shear energy is ``C₁ sin²γ``
(``γ`` the shear angle, ``I8²/(I4 I6) = sin²γ``), whose stiffness ``d²Ψ/dγ² = 2 C₁ cos 2γ``
falls to zero at 45° and is negative beyond.

:func:`locking_fabric` adds one term ``Cₙ/n (I8²/(I4 I6))ⁿ = Cₙ/n sin²ⁿγ`` of a high power
``n`` (default 12) to such a law, with ``Cₙ`` chosen so that the term's stiffness at the locking
angle ``θ_L`` is the one asked for:

    d²/dγ² (Cₙ/n sin²ⁿγ) = 2 Cₙ [(2n − 1) sin²ⁿ⁻²γ cos²γ − sin²ⁿγ]   at γ = θ_L

It is small well below ``θ_L`` (with ``n = 12`` and ``θ_L = 50°``: 3.1 % of its value at 40°,
0.02 % at 30°, 21 % at 45°) and grows steeply beyond (3.4 times at 55°). This is a shape of
stiffening, not a fitted fabric: measure the shear curve (picture-frame or bias-extension
test) of the fabric you lay.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .anisotropic import NonCrimpFabric
from .base import check_positive

__all__ = ["locking_coefficient", "locking_fabric", "shear_stiffness"]


def locking_coefficient(locking_angle: float, stiffness: float, power: int = 12) -> float:
    """The coefficient ``Cₙ`` (``n = power``) whose term ``Cₙ/n sin²ⁿγ`` has the shear
    stiffness ``stiffness`` (energy per area per rad², as ``G12``) at ``locking_angle``
    (degrees, in (0, 90))."""
    check_positive(stiffness=stiffness)
    if not 0.0 < locking_angle < 90.0:
        raise ValueError(f"the locking angle must lie in (0, 90) degrees; got {locking_angle}")
    if power < 2:
        raise ValueError(f"the power must be at least 2; got {power}")
    s, c = np.sin(np.radians(locking_angle)), np.cos(np.radians(locking_angle))
    slope = 2.0 * ((2 * power - 1) * s ** (2 * power - 2) * c**2 - s ** (2 * power))
    if slope <= 0.0:
        raise ValueError(
            f"a term of power {power} does not stiffen at {locking_angle}°: take a higher power"
        )
    return float(stiffness / slope)


def locking_fabric(
    A: Sequence[float],
    B: Sequence[float],
    C: Sequence[float],
    locking_angle: float,
    stiffness: float,
    power: int = 12,
) -> NonCrimpFabric:
    """The non-crimp fabric law ``NonCrimpFabric(A, B, C)`` with the term ``Cₙ/n sin²ⁿγ``
    (``n = power``) added whose shear stiffness at ``locking_angle`` (degrees) is ``stiffness``
    (module docs). E.g. ``locking_fabric([-250, 250], [-250, 250], [0.5], 50.0, 100.0)``: the
    README's fabric (shear modulus 1, yarn modulus 1,000) stiffening to 100 times its shear
    modulus at 50°."""
    coefficients = list(np.asarray(C, dtype=float).ravel()) + [0.0] * power
    coefficients = coefficients[: max(power, len(np.ravel(C)))]
    coefficients[power - 1] += locking_coefficient(locking_angle, stiffness, power)
    return NonCrimpFabric(A, B, coefficients)


def shear_stiffness(law: NonCrimpFabric, shear_angle: float) -> float:
    """``d²Ψ/dγ²`` of a non-crimp fabric law with inextensible yarns at ``shear_angle``
    (degrees): ``Σ_k C_k/k sin²ᵏγ`` differentiated twice (energy per area per rad²)."""
    s, c = np.sin(np.radians(shear_angle)), np.cos(np.radians(shear_angle))
    k = np.arange(1, law.C.size + 1)
    terms = 2.0 * ((2 * k - 1) * s ** (2 * k - 2) * c**2 - s ** (2 * k))
    return float(law.C @ terms)
