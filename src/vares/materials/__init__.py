"""Hyperelastic laws on the invariants of the in-plane right Cauchy–Green tensor."""

from .anisotropic import NonCrimpFabric, OrthotropicStVenantKirchhoff
from .base import INVARIANTS, Fibres, Hyperelastic, MaterialError, MaterialResponse
from .isotropic import IncompressibleNeoHooke, NeoHooke, StVenantKirchhoff

__all__ = [
    "INVARIANTS",
    "Fibres",
    "Hyperelastic",
    "IncompressibleNeoHooke",
    "MaterialError",
    "MaterialResponse",
    "NeoHooke",
    "NonCrimpFabric",
    "OrthotropicStVenantKirchhoff",
    "StVenantKirchhoff",
]
