"""Hyperelastic laws on the invariants of the in-plane right Cauchy–Green tensor."""

from .anisotropic import NonCrimpFabric, OrthotropicStVenantKirchhoff
from .base import (
    INVARIANTS,
    Fibres,
    Hyperelastic,
    InadmissibleState,
    MaterialError,
    MaterialResponse,
)
from .forming import FABRIC_KINDS, FabricKind, locking_angle
from .isotropic import IncompressibleNeoHooke, NeoHooke, StVenantKirchhoff
from .presets import FabricPreset, fabric, load_presets, presets

#: Laws by the names used on the command line and in job files.
LAWS: dict[str, type[Hyperelastic]] = {
    "neo-hooke": NeoHooke,
    "st-venant-kirchhoff": StVenantKirchhoff,
    "incompressible-neo-hooke": IncompressibleNeoHooke,
    "orthotropic": OrthotropicStVenantKirchhoff,
    "ncf": NonCrimpFabric,
}


def make_material(law: str, parameters: dict[str, object]) -> Hyperelastic:
    """A law by name (:data:`LAWS`) with its parameters; unknown names or parameters, and
    missing ones, raise :class:`MaterialError` naming them."""
    import inspect

    if law not in LAWS:
        raise MaterialError(f"unknown material {law!r}; choose from {', '.join(LAWS)}")
    cls = LAWS[law]
    accepted = list(inspect.signature(cls.__init__).parameters)[1:]
    unknown = sorted(set(parameters) - set(accepted))
    if unknown:
        raise MaterialError(
            f"{law} takes {', '.join(accepted)}; {', '.join(unknown)} do(es) not apply"
        )
    missing = [name for name in accepted if name not in parameters]
    if missing:
        raise MaterialError(f"{law} needs {', '.join(missing)}")
    return cls(**parameters)


__all__ = [
    "FABRIC_KINDS",
    "INVARIANTS",
    "LAWS",
    "FabricKind",
    "FabricPreset",
    "Fibres",
    "Hyperelastic",
    "InadmissibleState",
    "IncompressibleNeoHooke",
    "MaterialError",
    "MaterialResponse",
    "NeoHooke",
    "NonCrimpFabric",
    "OrthotropicStVenantKirchhoff",
    "StVenantKirchhoff",
    "fabric",
    "load_presets",
    "locking_angle",
    "make_material",
    "presets",
]
