"""Elastic constants and compensation values of a fabric from its biaxial test records.

**Per specimen.** The plane-stress orthotropic constants of a stiffness record (MSAJ/M-02) are
:func:`fit_elastic`'s (:mod:`vares.materials.elastic_fit`); the compensation values of a
compensation record (EN 17117-2) and the law through them are
:mod:`vares.materials.compensation_law`'s. Both are re-exported here.

**Several specimens** (:func:`fit_fabric`, :func:`summarise`): the records sorted into
stiffness and compensation records, and the mean and sample standard deviation of every constant
and compensation value over the specimens.

**In the pattern.** The fitted law is an :class:`~vares.materials.OrthotropicStVenantKirchhoff`
(``E1 = E_w``, ``E2 = E_f``, ``nu12 = ν_wf``); the shear stiffness ``G12`` is not measured by
biaxial tests and is taken from elsewhere. A fit's fabric file is written by
:func:`vares.materials.fabric_file.fit_toml`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .anisotropic import OrthotropicStVenantKirchhoff
from .base import MaterialError
from .biaxial import BiaxialRecord, NotInRecord, RecordError
from .compensation_law import (
    CompensationValues,
    MeasuredCompensationLaw,
    compensating_law,
    compensation_values,
    law_compensation,
)
from .elastic_fit import CONSTANTS, ElasticFit, RatioResidual, fit_elastic

__all__ = [
    "CONSTANTS",
    "CompensationValues",
    "ElasticFit",
    "FabricFit",
    "MeasuredCompensationLaw",
    "NotInRecord",
    "RatioResidual",
    "Summary",
    "compensating_law",
    "compensation_values",
    "fit_elastic",
    "fit_fabric",
    "law_compensation",
    "summarise",
]


@dataclass(frozen=True)
class Summary:
    """Mean and sample standard deviation (0 for one specimen) of named values over specimens;
    ``values`` each specimen's, in order."""

    mean: dict[str, float]
    std: dict[str, float]
    values: dict[str, tuple[float, ...]]
    specimens: int

    def standard_error(self, name: str) -> float:
        """Standard error of the mean of ``name`` (std/√n)."""
        return self.std[name] / np.sqrt(self.specimens)


def summarise(rows: list[dict[str, float]]) -> Summary:
    """Mean and scatter of every key of ``rows`` (one dict per specimen, same keys)."""
    if not rows:
        raise RecordError("no specimens to summarise")
    names = list(rows[0])
    values = {n: tuple(float(r[n]) for r in rows) for n in names}
    mean = {n: float(np.mean(v)) for n, v in values.items()}
    std = {n: float(np.std(v, ddof=1)) if len(v) > 1 else 0.0 for n, v in values.items()}
    return Summary(mean, std, values, len(rows))


@dataclass(frozen=True)
class FabricFit:
    """A fabric from biaxial tests: the fits of its stiffness records, the compensation values
    of its compensation records, and their summaries over the specimens.

    ``constants``: mean and scatter of ``E_w, E_f, nu_wf, nu_fw`` over ``fits``;
    ``compensation``: of ``warp`` and ``fill`` over ``compensations`` (None without
    compensation records); ``G12`` (kN/m) and ``G12_source``: the shear stiffness, which
    biaxial tests do not measure.
    """

    name: str
    fits: tuple[ElasticFit, ...]
    constants: Summary
    compensations: tuple[CompensationValues, ...]
    compensation: Summary | None
    prestress: tuple[float, float] | None
    G12: float
    G12_source: str

    def material(self, compensate_by: str = "law") -> OrthotropicStVenantKirchhoff:
        """The fitted law (mean constants) or, with ``"measured"``, the law through the mean
        measured compensation values (:func:`compensating_law`)."""
        m = self.constants.mean
        if compensate_by == "law":
            return OrthotropicStVenantKirchhoff(m["E_w"], m["E_f"], self.G12, m["nu_wf"])
        if self.compensation is None or self.prestress is None:
            raise MaterialError("no compensation records: compensate by the law")
        c = self.compensation.mean
        return compensating_law(c["warp"], c["fill"], self.prestress, m["nu_wf"], self.G12)

    def law_compensation(self) -> tuple[float, float] | None:
        """The compensation (warp, fill strains) the fitted law gives a flat panel at the
        prestress, to compare with the measured values (None without a prestress)."""
        if self.prestress is None:
            return None
        return law_compensation(self.material("law"), self.prestress)


def fit_fabric(
    records: list[BiaxialRecord],
    *,
    name: str,
    G12: float,
    G12_source: str,
    prestress: tuple[float, float] | None = None,
    cycle: int = -1,
    reciprocal: bool = True,
) -> FabricFit:
    """Fit a fabric from its records: each record with at least two load ratios gives
    constants (:func:`fit_elastic`), each with a hold at the ``prestress`` after its cycles
    gives compensation values (:func:`compensation_values`); a record may give both.

    Raises :class:`RecordError` naming a record that gives neither, and when no record gives
    constants (or, with a prestress, compensation values).
    """
    fits, compensations = [], []
    for record in records:
        reasons = []
        try:
            fits.append(fit_elastic(record, cycle=cycle, reciprocal=reciprocal))
        except NotInRecord as exc:
            reasons.append(str(exc))
        if prestress is not None:
            try:
                compensations.append(compensation_values(record, prestress))
            except NotInRecord as exc:
                reasons.append(str(exc))
        if len(reasons) == (2 if prestress is not None else 1):
            where = record.source or record.name
            raise RecordError(
                f"{where} gives neither constants nor compensation values ({'; '.join(reasons)})"
            )
    if not fits:
        raise RecordError(
            "no record has two or more load ratios (MSAJ/M-02: 1:1, 2:1, 1:2, 1:0, 0:1) to fit "
            "the constants from"
        )
    if prestress is not None and not compensations:
        raise RecordError(
            f"no record holds the prestress {prestress[0]:g}/{prestress[1]:g} kN/m after its "
            "cycles (EN 17117-2): no compensation values"
        )
    if not (G12 > 0 and np.isfinite(G12)):
        raise MaterialError(f"G12 must be a positive number; got {G12!r}")
    constants = summarise([f.constants for f in fits])
    compensation = (
        summarise([{"warp": c.warp, "fill": c.fill} for c in compensations])
        if compensations
        else None
    )
    return FabricFit(
        name=name,
        fits=tuple(fits),
        constants=constants,
        compensations=tuple(compensations),
        compensation=compensation,
        prestress=None if prestress is None else (float(prestress[0]), float(prestress[1])),
        G12=float(G12),
        G12_source=G12_source,
    )
