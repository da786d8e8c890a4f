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

and are loaded with :func:`load_presets` (``vares pattern --presets FILE``). A fabric file
written by ``vares fabric fit`` (:mod:`vares.materials.fabric_file`) is such a file whose entry
also holds the measured compensation values and how the numbers were found; its path stands
for its one fabric (``fabric("pes-batch-42.toml")``, ``--fabric pes-batch-42.toml``).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from .anisotropic import OrthotropicStVenantKirchhoff
from .base import MaterialError
from .fabric_file import (
    COMPENSATE_BY,
    EXTRA_KEYS,
    ConstantScatter,
    MeasuredCompensation,
    read_scatter,
    read_test_tables,
)

__all__ = ["FabricPreset", "fabric", "file_fabric", "load_presets", "presets"]

_FIELDS = {"E1", "E2", "G12", "nu12"}


@dataclass(frozen=True)
class FabricPreset:
    """A named orthotropic fabric (stiffnesses as force per length, use thickness 1).

    A fabric from biaxial tests also has its measured ``compensation`` values, the way a
    pattern is compensated by default (``compensate_by``: ``"measured"`` or ``"law"``) and the
    ``scatter`` of its fitted constants over the specimens (its ``[NAME.scatter]`` table).
    """

    name: str
    description: str
    E1: float
    E2: float
    G12: float
    nu12: float
    source: str
    compensation: MeasuredCompensation | None = None
    compensate_by: str = "law"
    scatter: ConstantScatter | None = None

    def material(self, compensate_by: str | None = None) -> OrthotropicStVenantKirchhoff:
        """The fabric's law; with ``compensate_by="measured"`` (default: the preset's choice)
        the law through the measured compensation values instead
        (:func:`vares.materials.compensation_law.compensating_law`: a flat panel under the tested
        prestress is compensated by exactly those strains)."""
        choice = compensate_by or self.compensate_by
        if choice not in COMPENSATE_BY:
            raise MaterialError(f"compensate_by must be one of {', '.join(COMPENSATE_BY)}")
        if choice == "law":
            return OrthotropicStVenantKirchhoff(self.E1, self.E2, self.G12, self.nu12)
        if self.compensation is None:
            raise MaterialError(
                f"fabric {self.name!r} has no measured compensation values: compensate by its "
                "law, or fit it with compensation records ('vares fabric fit --compensation')"
            )
        from .compensation_law import compensating_law

        c = self.compensation
        return compensating_law(c.warp, c.fill, c.prestress, self.nu12, self.G12)


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
        unknown = sorted(set(entry) - _FIELDS - {"description", "source"} - EXTRA_KEYS)
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
        compensation, choice = read_test_tables(entry, f"{origin}: [{name}]")
        preset = FabricPreset(
            name,
            str(entry.get("description", name)),
            source=str(entry["source"]),
            compensation=compensation,
            compensate_by=choice or ("measured" if compensation else "law"),
            scatter=read_scatter(entry, f"{origin}: [{name}]"),
            **values,
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
    """A preset by name, from the shipped catalogue or (first) from the file ``extra``; or the
    one fabric of a fabric file, named by its path (ending in ``.toml``)."""
    if extra is None and str(name).endswith(".toml"):
        return file_fabric(name)
    catalogue = presets() | (load_presets(extra) if extra is not None else {})
    if name not in catalogue:
        raise MaterialError(f"unknown fabric preset {name!r}; known: {', '.join(catalogue)}")
    return catalogue[name]


def file_fabric(path: str | Path) -> FabricPreset:
    """The one fabric of a fabric file (a preset file of one entry, as ``vares fabric fit``
    writes); a file of several names them."""
    catalogue = load_presets(path)
    if len(catalogue) != 1:
        raise MaterialError(
            f"{path} holds {len(catalogue)} fabrics ({', '.join(catalogue) or 'none'}): name "
            "one (--fabric NAME --presets FILE)"
        )
    return next(iter(catalogue.values()))
