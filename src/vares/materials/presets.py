"""Fabric presets: named orthotropic laws from TOML files.

The shipped catalogue (``vares/data/fabrics.toml``) holds typical coated-fabric values, each with
the source of its numbers; they are for trying designs, not for cutting: use your own biaxial
test values. Your own presets go in a TOML file of the same form::

    [my-fabric]
    description = "PES/PVC type II, roll 4711, biaxial test 2026-03"
    E1 = 780.0      # warp stiffness E·t, force per length
    E2 = 590.0      # fill stiffness
    G12 = 25.0      # in-plane shear stiffness
    nu12 = 0.38     # Poisson's ratio warp → fill
    source = "our biaxial test report 2026-031"

and are loaded with :func:`load_presets` (``vares pattern --presets FILE``).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from .anisotropic import OrthotropicStVenantKirchhoff
from .base import MaterialError

__all__ = ["FabricPreset", "fabric", "load_presets", "presets"]

_FIELDS = {"E1", "E2", "G12", "nu12"}


@dataclass(frozen=True)
class FabricPreset:
    """A named orthotropic fabric (stiffnesses as force per length, use thickness 1)."""

    name: str
    description: str
    E1: float
    E2: float
    G12: float
    nu12: float
    source: str

    def material(self) -> OrthotropicStVenantKirchhoff:
        return OrthotropicStVenantKirchhoff(self.E1, self.E2, self.G12, self.nu12)


def _parse(text: str, origin: str) -> dict[str, FabricPreset]:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise MaterialError(f"{origin}: not valid TOML: {exc}") from exc
    out = {}
    for name, entry in data.items():
        if not isinstance(entry, dict):
            raise MaterialError(f"{origin}: [{name}] must be a table of E1, E2, G12, nu12")
        missing = sorted(_FIELDS - set(entry))
        if missing:
            raise MaterialError(f"{origin}: [{name}] lacks {', '.join(missing)}")
        unknown = sorted(set(entry) - _FIELDS - {"description", "source"})
        if unknown:
            raise MaterialError(f"{origin}: [{name}] has unknown keys {', '.join(unknown)}")
        if not str(entry.get("source", "")).strip():
            raise MaterialError(
                f'{origin}: [{name}] must say where its numbers come from (source = "…")'
            )
        try:
            values = {key: float(entry[key]) for key in _FIELDS}
        except (TypeError, ValueError) as exc:
            raise MaterialError(
                f"{origin}: [{name}]: E1, E2, G12 and nu12 must be numbers"
            ) from exc
        preset = FabricPreset(
            name, str(entry.get("description", name)), source=str(entry["source"]), **values
        )
        try:
            preset.material()
        except MaterialError as exc:
            raise MaterialError(f"{origin}: [{name}]: {exc}") from exc
        out[name] = preset
    return out


def presets() -> dict[str, FabricPreset]:
    """The shipped catalogue."""
    text = resources.files("vares").joinpath("data/fabrics.toml").read_text(encoding="utf-8")
    return _parse(text, "vares/data/fabrics.toml")


def load_presets(path: str | Path) -> dict[str, FabricPreset]:
    """Presets from a user TOML file (see the module docs for the form)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    return _parse(path.read_text(encoding="utf-8"), str(path))


def fabric(name: str, extra: str | Path | None = None) -> FabricPreset:
    """A preset by name, from the shipped catalogue or (first) from the file ``extra``."""
    catalogue = presets() | (load_presets(extra) if extra is not None else {})
    if name not in catalogue:
        raise MaterialError(f"unknown fabric preset {name!r}; known: {', '.join(catalogue)}")
    return catalogue[name]
