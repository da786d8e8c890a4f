"""Compensation values from biaxial test records, and the orthotropic law through them.

**Compensation values (EN 17117-2).** The warp and fill strains at the prestress after the
prescribed cycles and holds: the mean strain over the last ``window`` seconds of the record's
last hold at the prestress (:func:`compensation_values`), relative to the length the machine
zeroed its extensometers at.

**In the pattern.** :func:`law_compensation` is the compensation VaReS gives a flat panel of an
orthotropic law under the prestress. To compensate by the measured values instead,
:func:`compensating_law` gives the orthotropic law (the fit's ``nu12``, a ``G12`` from
elsewhere) whose VaReS pattern of a flat panel under the prestress is shorter by exactly the
measured strains: erected length = pattern length × (1 + ε). The constants themselves are
fitted in :mod:`vares.materials.fitting`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .anisotropic import OrthotropicStVenantKirchhoff
from .base import MaterialError
from .biaxial import BiaxialRecord, NotInRecord, RecordError, find_cycles

__all__ = [
    "CompensationValues",
    "MeasuredCompensationLaw",
    "compensating_law",
    "compensation_values",
    "law_compensation",
    "strains_per_cycle",
]


@dataclass(frozen=True)
class CompensationValues:
    """The compensation values of one specimen: warp and fill strain (mm/mm) at the
    ``prestress`` (warp, fill; kN/m), read at ``time`` s over ``samples`` samples."""

    name: str
    prestress: tuple[float, float]
    warp: float
    fill: float
    time: float
    samples: int
    source: str = ""


def compensation_values(
    record: BiaxialRecord,
    prestress: tuple[float, float],
    *,
    tolerance: float | None = None,
    window: float = 10.0,
) -> CompensationValues:
    """The strains at the prestress after the record's load cycles and holds.

    The record's last hold at the prestress (every sample within ``tolerance`` kN/m of it in
    both directions; default 5 % of the larger prestress, at least 0.05 kN/m) that comes after
    its last load cycle; the strains are averaged over its last ``window`` seconds. Raises
    :class:`RecordError` naming the record when it has no such hold.
    """
    target = np.asarray(prestress, dtype=float)
    if target.shape != (2,) or not np.all(target > 0):
        raise RecordError(f"the prestress must be two positive forces; got {prestress!r}")
    if tolerance is None:
        tolerance = max(0.05 * float(target.max()), 0.05)
    near = np.all(np.abs(record.force - target) <= tolerance, axis=1)
    try:
        cycles = find_cycles(record)
        after = cycles[-1].peak
    except RecordError:
        after = 0
    near[: after + 1] = False
    if not near.any():
        raise NotInRecord(
            f"{record.name}: no hold at the prestress {target[0]:g}/{target[1]:g} kN/m after "
            "the last load cycle: compensation values need a record of the compensation "
            "protocol (EN 17117-2)"
        )
    last = int(np.flatnonzero(near)[-1])
    first = last
    while first > 0 and near[first - 1]:
        first -= 1
    start_time = max(record.time[first], record.time[last] - window)
    chosen = np.flatnonzero(near & (record.time >= start_time))
    chosen = chosen[chosen <= last]
    warp, fill = record.strain[chosen].mean(axis=0)
    return CompensationValues(
        record.name,
        (float(target[0]), float(target[1])),
        float(warp),
        float(fill),
        float(record.time[last]),
        len(chosen),
        record.source,
    )


def strains_per_cycle(
    record: BiaxialRecord, prestress: tuple[float, float], *, tolerance: float | None = None
) -> list[tuple[int, float, float]]:
    """The warp and fill strains (mm/mm) at the prestress before each load cycle and after the
    last: ``(k, warp, fill)`` with ``k`` the number of cycles done (0 before the first), at the
    cycles' troughs where the force is within ``tolerance`` of the prestress (as in
    :func:`compensation_values`). How the compensation grows over the cycles; empty when the
    record has no cycles."""
    target = np.asarray(prestress, dtype=float)
    if tolerance is None:
        tolerance = max(0.05 * float(target.max()), 0.05)
    try:
        cycles = find_cycles(record)
    except RecordError:
        return []
    near = np.all(np.abs(record.force - target) <= tolerance, axis=1)
    # each cycle starts where the force leaves its trough: the trough is the last sample at the
    # prestress before that (after the previous cycle's peak)
    bounds = [(0, cycles[0].start)] + [
        (c.peak, cycles[k + 1].start if k + 1 < len(cycles) else c.end)
        for k, c in enumerate(cycles)
    ]
    out = []
    for k, (low, i) in enumerate(bounds):
        at = np.flatnonzero(near[low : i + 1])
        if at.size:
            j = low + int(at[-1])
            out.append((k, float(record.strain[j, 0]), float(record.strain[j, 1])))
    return out


def _flat_stationarity(
    Q11: float, Q12: float, Q22: float, E11: float, E22: float, p1: float, p2: float
) -> np.ndarray:
    """Residuals of the flat uniform VaReS optimum: ``λ_i² S̃_ii − Ψ̃`` for i = 1, 2."""
    S1 = Q11 * E11 + Q12 * E22 - p1
    S2 = Q12 * E11 + Q22 * E22 - p2
    psi = 0.5 * (Q11 * E11**2 + 2 * Q12 * E11 * E22 + Q22 * E22**2) - p1 * E11 - p2 * E22
    return np.array([(1 + 2 * E11) * S1 - psi, (1 + 2 * E22) * S2 - psi])


def law_compensation(
    material: OrthotropicStVenantKirchhoff, prestress: tuple[float, float]
) -> tuple[float, float]:
    """The warp and fill strains (mm/mm; erected length = pattern length × (1 + ε)) by which
    VaReS compensates a flat panel of ``material`` (thickness 1) under ``prestress`` (kN/m):
    the stationary point of ``Π(λ_w, λ_f) = (Ψ − S_pre:E)/(λ_w λ_f)`` (the Eshelby stress
    ``Ψ̃ I − C S̃`` vanishes)."""
    p1, p2 = (float(p) for p in prestress)
    Q11, Q12, Q22 = material.Q11, material.Q12, material.Q22
    strain = np.linalg.solve(np.array([[Q11, Q12], [Q12, Q22]]), np.array([p1, p2]))
    for _ in range(50):
        E11, E22 = strain
        residual = _flat_stationarity(Q11, Q12, Q22, E11, E22, p1, p2)
        S1 = Q11 * E11 + Q12 * E22 - p1
        S2 = Q12 * E11 + Q22 * E22 - p2
        jacobian = np.array(
            [
                [S1 + (1 + 2 * E11) * Q11, (1 + 2 * E11) * Q12 - S2],
                [(1 + 2 * E22) * Q12 - S1, S2 + (1 + 2 * E22) * Q22],
            ]
        )
        step = np.linalg.solve(jacobian, -residual)
        strain = strain + step
        if np.max(np.abs(step)) < 1e-15 + 1e-13 * np.max(np.abs(strain)):
            break
    else:
        raise MaterialError("no compensation of a flat panel found (Newton did not converge)")
    solution = strain
    stretch = np.sqrt(1.0 + 2.0 * solution)
    return float(stretch[0] - 1.0), float(stretch[1] - 1.0)


class MeasuredCompensationLaw(OrthotropicStVenantKirchhoff):
    """The orthotropic law through measured compensation values (:func:`compensating_law`):
    an :class:`~vares.materials.OrthotropicStVenantKirchhoff` that also knows the prestress
    ``measured_at`` (warp, fill; kN/m) it was calibrated at, so that a pattern under another
    prestress can be warned about (:func:`vares.analysis.checks.pattern_warnings`)."""

    def __init__(
        self, E1: float, E2: float, G12: float, nu12: float, measured_at: tuple[float, float]
    ) -> None:
        super().__init__(E1, E2, G12, nu12)
        self.measured_at = (float(measured_at[0]), float(measured_at[1]))

    @property
    def parameters(self) -> dict[str, object]:
        return super().parameters | {"measured_at": list(self.measured_at)}


def compensating_law(
    warp: float,
    fill: float,
    prestress: tuple[float, float],
    nu12: float,
    G12: float,
) -> MeasuredCompensationLaw:
    """The orthotropic law whose VaReS pattern of a flat panel under ``prestress`` (kN/m) is
    compensated by exactly the measured strains ``warp`` and ``fill`` (mm/mm).

    ``nu12`` and ``G12`` are kept (the fit's, and the shear stiffness from elsewhere); ``E1``
    and ``E2`` are the secant stiffnesses that make the stationarity conditions of
    :func:`law_compensation` hold at the stretches ``1 + warp`` and ``1 + fill``. They are
    linear in ``Q11`` and ``Q22`` (``Q12 = nu12 Q22``), so this is a 2×2 solve. Raises
    :class:`MaterialError` when no positive-definite law gives these values (e.g. a strain
    that is not positive).
    """
    if not (warp > 0 and fill > 0):
        raise MaterialError(
            f"compensation values must be positive strains; got warp {warp:g}, fill {fill:g}"
        )
    p1, p2 = (float(p) for p in prestress)
    l1, l2 = 1.0 + warp, 1.0 + fill
    E11, E22 = 0.5 * (l1**2 - 1.0), 0.5 * (l2**2 - 1.0)
    nu = float(nu12)
    # λ1² (Q11 E11 + ν Q22 E22 − p1) = Ψ̃ and λ2² (ν Q22 E11 + Q22 E22 − p2) = Ψ̃,
    # Ψ̃ = ½ (Q11 E11² + 2 ν Q22 E11 E22 + Q22 E22²) − p1 E11 − p2 E22.
    half = 0.5 * (E11**2), nu * E11 * E22 + 0.5 * E22**2
    matrix = np.array(
        [
            [l1**2 * E11 - half[0], l1**2 * nu * E22 - half[1]],
            [-half[0], l2**2 * (nu * E11 + E22) - half[1]],
        ]
    )
    work = -p1 * E11 - p2 * E22
    rhs = np.array([l1**2 * p1 + work, l2**2 * p2 + work])
    Q11, Q22 = np.linalg.solve(matrix, rhs)
    E1 = Q11 - nu**2 * Q22
    E2 = Q22 * E1 / Q11 if Q11 != 0 else -1.0
    if not (Q11 > 0 and Q22 > 0 and E1 > 0 and E2 > 0):
        raise MaterialError(
            f"no positive-definite orthotropic law with nu12 = {nu:g} is compensated by warp "
            f"{warp:.4%} and fill {fill:.4%} at the prestress {p1:g}/{p2:g}"
        )
    return MeasuredCompensationLaw(float(E1), float(E2), float(G12), nu, (p1, p2))
