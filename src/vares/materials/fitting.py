"""Elastic constants and compensation values from biaxial test records.

**Elastic constants (MSAJ/M-02).** The plane-stress orthotropic law of a fabric, with forces per
width ``σ`` (kN/m) and strains ``ε`` (mm/mm),

    ε_w =  σ_w/E_w − ν_fw σ_f/E_f
    ε_f = −ν_wf σ_w/E_w + σ_f/E_f,          reciprocity: ν_wf/E_w = ν_fw/E_f,

is fitted by least squares of the strain residual over the loading branches of one chosen cycle
of every load ratio at once (:func:`fit_elastic`). Each load ratio has its own strain offset
(the permanent set the earlier cycles left), so only the slopes are shared. Unknowns are the
compliances ``1/E_w, ν_wf/E_w, ν_fw/E_f, 1/E_f`` (three with reciprocity); warp and fill
residuals are weighted by the inverse of their own variance. Standard errors follow from the
covariance of the least-squares estimate (independent Gaussian strain errors) through the
derivatives of ``E = 1/a`` and ``ν = c/a``. Beside the linear law a nonlinear response
``ε = C σ + (k_w σ_w², k_f σ_f²)`` is fitted the same way and reported, so a poor linear fit
shows. The residual of both is given per load ratio.

**Compensation values (EN 17117-2).** The warp and fill strains at the prestress after the
prescribed cycles and holds: the mean strain over the last ``window`` seconds of the record's
last hold at the prestress (:func:`compensation_values`), relative to the length the machine
zeroed its extensometers at.

**Several specimens** (:func:`summarise`): the mean and the sample standard deviation of every
constant and compensation value over the specimens.

**In the pattern.** The fitted law is an :class:`~vares.materials.OrthotropicStVenantKirchhoff`
(``E1 = E_w``, ``E2 = E_f``, ``nu12 = ν_wf``); the shear stiffness ``G12`` is not measured by
biaxial tests and is taken from elsewhere. To compensate by the measured values instead,
:func:`compensating_law` gives the orthotropic law (same ``nu12`` and ``G12``) whose VaReS
pattern of a flat panel under the prestress is shorter by exactly the measured strains: erected
length = pattern length × (1 + ε).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .anisotropic import OrthotropicStVenantKirchhoff
from .base import MaterialError
from .biaxial import BiaxialRecord, Cycle, RecordError, find_cycles

__all__ = [
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


class NotInRecord(RecordError):
    """A record lacks what was asked of it (two load ratios for a fit, a hold at the
    prestress for compensation values); other records may have it."""


#: The constants a fit reports.
CONSTANTS = ("E_w", "E_f", "nu_wf", "nu_fw")


@dataclass(frozen=True)
class RatioResidual:
    """The strain residual of a fit on one load ratio (mm/mm): RMS of warp and fill, largest
    absolute value, and the number of samples of its loading branch."""

    label: str
    stage: int
    cycle: int
    samples: int
    rms_warp: float
    rms_fill: float
    max_abs: float


@dataclass(frozen=True)
class ElasticFit:
    """The plane-stress orthotropic constants of one specimen.

    ``E_w``, ``E_f`` in kN/m (E·t), ``nu_wf`` (warp → fill: fill contraction under warp force)
    and ``nu_fw``; ``standard_errors`` of each (same units); ``residuals`` per load ratio;
    ``rms`` the overall strain residual (mm/mm). ``nonlinear``: the coefficients of the fitted
    nonlinear response (``E_w``, ``E_f``, ``nu_wf`` of its linear part, ``k_w``, ``k_f`` in
    (kN/m)⁻²), its ``rms`` and its residuals per ratio.
    """

    name: str
    E_w: float
    E_f: float
    nu_wf: float
    nu_fw: float
    reciprocal: bool
    cycle: int
    standard_errors: dict[str, float]
    residuals: tuple[RatioResidual, ...]
    rms: float
    nonlinear: dict[str, float] = field(default_factory=dict)
    nonlinear_residuals: tuple[RatioResidual, ...] = ()
    source: str = ""

    @property
    def constants(self) -> dict[str, float]:
        return {name: getattr(self, name) for name in CONSTANTS}

    @property
    def linear_is_poor(self) -> bool:
        """The nonlinear response leaves less than two thirds of the linear law's residual."""
        return bool(self.nonlinear) and self.nonlinear["rms"] < 2.0 / 3.0 * self.rms

    def material(self, G12: float) -> OrthotropicStVenantKirchhoff:
        """The fitted law (``G12``: the shear stiffness, kN/m, which biaxial tests do not give)."""
        return OrthotropicStVenantKirchhoff(self.E_w, self.E_f, G12, self.nu_wf)


def _branches(record: BiaxialRecord, cycle: int) -> list[tuple[Cycle, np.ndarray]]:
    """The chosen cycle of each stage and the sample indices of its loading branch."""
    cycles = find_cycles(record)
    stages: dict[int, list[Cycle]] = {}
    for c in cycles:
        stages.setdefault(c.stage, []).append(c)
    chosen = []
    for stage, members in stages.items():
        if cycle == -1:
            pick = members[-1]
        elif 1 <= cycle <= len(members):
            pick = members[cycle - 1]
        else:
            raise RecordError(
                f"{record.name}: stage {stage} ({members[0].label}) has {len(members)} "
                f"cycle(s); cycle {cycle} asked"
            )
        chosen.append((pick, np.arange(pick.start, pick.loaded + 1)))
    return chosen


def _design(
    record: BiaxialRecord,
    branches: list[tuple[Cycle, np.ndarray]],
    reciprocal: bool,
    nonlinear: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """The least-squares problem: its matrix (per load ratio a block of warp rows, then one of
    fill rows, one row per sample of the branch), the measured strains, each row's direction
    (0 warp, 1 fill) and the number of shared (non-offset) unknowns.

    Unknowns: ``a = 1/E_w``, ``c = ν_wf/E_w``, [``b = ν_fw/E_f``], ``d = 1/E_f``,
    [``k_w``, ``k_f``], then one warp and one fill offset per stage."""
    rows, rhs, direction = [], [], []
    shared = (3 if reciprocal else 4) + (2 if nonlinear else 0)
    n_unknowns = shared + 2 * len(branches)
    for s, (_, index) in enumerate(branches):
        sw, sf = record.force[index, 0], record.force[index, 1]
        for yarn in (0, 1):
            block = np.zeros((len(index), n_unknowns))
            if reciprocal:
                # ε_w = a σ_w − c σ_f ; ε_f = −c σ_w + d σ_f
                if yarn == 0:
                    block[:, 0], block[:, 1] = sw, -sf
                else:
                    block[:, 1], block[:, 2] = -sw, sf
            else:
                # ε_w = a σ_w − b σ_f ; ε_f = −c σ_w + d σ_f  (columns a, c, b, d)
                if yarn == 0:
                    block[:, 0], block[:, 2] = sw, -sf
                else:
                    block[:, 1], block[:, 3] = -sw, sf
            if nonlinear:
                linear = 3 if reciprocal else 4
                block[:, linear + yarn] = (sw if yarn == 0 else sf) ** 2
            block[:, shared + 2 * s + yarn] = 1.0
            rows.append(block)
            rhs.append(record.strain[index, yarn])
            direction.append(np.full(len(index), yarn))
    return np.vstack(rows), np.concatenate(rhs), np.concatenate(direction), shared


def _weighted_lstsq(
    A: np.ndarray, y: np.ndarray, direction: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least squares with each direction's rows weighted by its residual variance; the
    solution, its covariance and the residuals."""
    unknowns = A.shape[1]

    def row_weights(residual: np.ndarray) -> np.ndarray:
        """1/σ² per row, σ² each direction's residual variance (half the unknowns each)."""
        variance = np.empty(2)
        for yarn in (0, 1):
            mask = direction == yarn
            dof = max(mask.sum() - unknowns / 2.0, 1.0)
            variance[yarn] = max(float(residual[mask] @ residual[mask]) / dof, 1e-30)
        return 1.0 / variance[direction]

    x, *_ = np.linalg.lstsq(A, y, rcond=None)
    root = np.sqrt(row_weights(y - A @ x))
    x, *_ = np.linalg.lstsq(A * root[:, None], y * root, rcond=None)
    residual = y - A @ x
    scaled = A * np.sqrt(row_weights(residual))[:, None]
    covariance = np.linalg.inv(scaled.T @ scaled)
    return x, covariance, residual


def _constants(
    x: np.ndarray, covariance: np.ndarray, reciprocal: bool
) -> tuple[dict[str, float], dict[str, float]]:
    """``E_w, E_f, ν_wf, ν_fw`` and their standard errors from the compliances."""
    if reciprocal:
        a, c, d = x[:3]
        b = c
        index = {"a": 0, "c": 1, "b": 1, "d": 2}
    else:
        a, c, b, d = x[:4]
        index = {"a": 0, "c": 1, "b": 2, "d": 3}
    if a <= 0 or d <= 0:
        raise RecordError(
            "the fitted compliance is not positive (the strains do not grow with the force): "
            "check the columns' units and the warp/fill assignment"
        )
    values = {
        "E_w": float(1.0 / a),
        "E_f": float(1.0 / d),
        "nu_wf": float(c / a),
        "nu_fw": float(b / d),
    }
    gradients = {
        "E_w": {"a": -1.0 / a**2},
        "E_f": {"d": -1.0 / d**2},
        "nu_wf": {"c": 1.0 / a, "a": -c / a**2},
        "nu_fw": {"b": 1.0 / d, "d": -b / d**2},
    }
    errors = {}
    for name, parts in gradients.items():
        g = np.zeros(len(covariance))
        for symbol, derivative in parts.items():
            g[index[symbol]] += derivative
        errors[name] = float(np.sqrt(max(g @ covariance @ g, 0.0)))
    return values, errors


def _residuals(
    branches: list[tuple[Cycle, np.ndarray]], residual: np.ndarray
) -> tuple[RatioResidual, ...]:
    """RMS residual per load ratio; ``residual``: all warp rows, then all fill rows."""
    out, offset = [], 0
    lengths = [len(index) for _, index in branches]
    total = sum(lengths)
    for (cycle, _index), n in zip(branches, lengths, strict=True):
        warp = residual[offset : offset + n]
        fill = residual[total + offset : total + offset + n]
        offset += n
        out.append(
            RatioResidual(
                cycle.label,
                cycle.stage,
                cycle.number,
                n,
                float(np.sqrt(np.mean(warp**2))),
                float(np.sqrt(np.mean(fill**2))),
                float(max(np.abs(warp).max(), np.abs(fill).max())),
            )
        )
    return tuple(out)


def _reorder(residual: np.ndarray, branches: list[tuple[Cycle, np.ndarray]]) -> np.ndarray:
    """Residuals stacked per stage (warp block, fill block) → all warp rows, then all fill."""
    warp, fill, offset = [], [], 0
    for _, index in branches:
        n = len(index)
        warp.append(residual[offset : offset + n])
        fill.append(residual[offset + n : offset + 2 * n])
        offset += 2 * n
    return np.concatenate(warp + fill)


def fit_elastic(record: BiaxialRecord, *, cycle: int = -1, reciprocal: bool = True) -> ElasticFit:
    """The plane-stress orthotropic constants of one specimen, by least squares over the loading
    branch of cycle ``cycle`` (1-based; -1: the last) of every load ratio of the record.

    With ``reciprocal`` the fit has the three unknowns ``E_w, E_f, ν_wf`` (``ν_fw = ν_wf E_f/E_w``);
    without it four. Raises :class:`RecordError` if the record's cycles cannot give them (fewer
    than two load ratios, a stage without the chosen cycle, a compliance that is not positive).
    """
    branches = _branches(record, cycle)
    if len(branches) < 2:
        raise NotInRecord(
            f"{record.name}: the fit needs at least two load ratios; found "
            f"{', '.join(c.label for c, _ in branches)}"
        )
    fits = {}
    for nonlinear in (False, True):
        A, y, direction, _ = _design(record, branches, reciprocal, nonlinear)
        if np.linalg.matrix_rank(A) < A.shape[1]:
            raise RecordError(
                f"{record.name}: the load ratios {', '.join(c.label for c, _ in branches)} do "
                "not determine the constants (the warp and fill forces move together)"
            )
        x, covariance, residual = _weighted_lstsq(A, y, direction)
        fits[nonlinear] = (x, covariance, _reorder(residual, branches))
    x, covariance, residual = fits[False]
    try:
        values, errors = _constants(x, covariance, reciprocal)
    except RecordError as exc:
        raise RecordError(f"{record.name}: {exc}") from None
    x_nl, cov_nl, residual_nl = fits[True]
    nonlinear: dict[str, float] = {}
    try:
        nl_values, _ = _constants(x_nl, cov_nl, reciprocal)
        linear = 3 if reciprocal else 4
        nonlinear = {
            "E_w": nl_values["E_w"],
            "E_f": nl_values["E_f"],
            "nu_wf": nl_values["nu_wf"],
            "nu_fw": nl_values["nu_fw"],
            "k_w": float(x_nl[linear]),
            "k_f": float(x_nl[linear + 1]),
            "k_w_error": float(np.sqrt(cov_nl[linear, linear])),
            "k_f_error": float(np.sqrt(cov_nl[linear + 1, linear + 1])),
            "rms": float(np.sqrt(np.mean(residual_nl**2))),
        }
    except RecordError:
        nonlinear = {}
    return ElasticFit(
        name=record.name,
        reciprocal=reciprocal,
        cycle=cycle,
        standard_errors=errors,
        residuals=_residuals(branches, residual),
        rms=float(np.sqrt(np.mean(residual**2))),
        nonlinear=nonlinear,
        nonlinear_residuals=_residuals(branches, residual_nl) if nonlinear else (),
        source=record.source,
        **values,
    )


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

    def to_toml(self, compensate_by: str | None = None, description: str | None = None) -> str:
        """The fabric file (:mod:`vares.materials.fabric_file`) of this fit.

        ``compensate_by``: the pattern's default compensation (``"measured"`` when there are
        compensation values, else ``"law"``); ``description`` defaults to one naming the
        specimens and the evaluation."""
        from .._version import __version__
        from .fabric_file import fabric_toml

        choice = compensate_by or ("measured" if self.compensation is not None else "law")
        if choice == "measured" and self.compensation is None:
            raise MaterialError("no compensation records: a pattern can only use the law")
        mean, std = self.constants.mean, self.constants.std
        n = self.constants.specimens
        fit0 = self.fits[0]
        cycle = "last cycle" if fit0.cycle == -1 else f"cycle {fit0.cycle}"
        ratios = [r.label for r in fit0.residuals]
        text = description or (
            f"biaxial fit of {n} specimen(s), load ratios {' '.join(ratios)} ({cycle} of each)"
        )
        sources = sorted({r.source for r in (*self.fits, *self.compensations) if r.source})
        source = (
            f"vares {__version__} fabric fit of {', '.join(sources) or 'records'} "
            f"(MSAJ/M-02 least squares of the strain residual, "
            f"{'with' if fit0.reciprocal else 'without'} reciprocity"
            + (", EN 17117-2 compensation values" if self.compensation else "")
            + f"); G12 {self.G12:g} kN/m {self.G12_source} (not measured by biaxial tests)"
        )
        head = {
            "description": text,
            "E1": mean["E_w"],
            "E2": mean["E_f"],
            "G12": self.G12,
            "nu12": mean["nu_wf"],
            "source": source,
            "compensate_by": choice,
        }
        tables: dict[str, dict[str, object]] = {
            "scatter": {
                "specimens": n,
                "E1": std["E_w"],
                "E2": std["E_f"],
                "nu12": std["nu_wf"],
                "nu21": std["nu_fw"],
            }
        }
        if self.compensation is not None and self.prestress is not None:
            c = self.compensation
            law = self.law_compensation() or (math.nan, math.nan)
            tables["compensation"] = {
                "prestress": list(self.prestress),
                "warp": c.mean["warp"],
                "fill": c.mean["fill"],
                "warp_std": c.std["warp"],
                "fill_std": c.std["fill"],
                "specimens": c.specimens,
                "law_warp": law[0],
                "law_fill": law[1],
                "note": "strains (mm/mm) at the prestress after the cycles and holds, from the "
                "extensometers' zero; erected length = pattern length × (1 + strain)",
            }
        tables["fit"] = {
            "method": "MSAJ/M-02: least squares of the strain residual over the loading "
            "branches of all load ratios, one strain offset per ratio",
            "cycle": fit0.cycle,
            "reciprocal": fit0.reciprocal,
            "ratios": ratios,
            "nu21": mean["nu_fw"],
            "rms_residual": float(np.mean([f.rms for f in self.fits])),
            "nonlinear_rms_residual": float(
                np.mean([f.nonlinear.get("rms", math.nan) for f in self.fits])
            ),
            "linear_is_poor": any(f.linear_is_poor for f in self.fits),
            "G12_source": self.G12_source,
        }
        specimens: list[dict[str, object]] = []
        for f in self.fits:
            row: dict[str, object] = {
                "name": f.name,
                "file": f.source,
                "E1": f.E_w,
                "E2": f.E_f,
                "nu12": f.nu_wf,
                "nu21": f.nu_fw,
                "E1_error": f.standard_errors["E_w"],
                "E2_error": f.standard_errors["E_f"],
                "nu12_error": f.standard_errors["nu_wf"],
                "nu21_error": f.standard_errors["nu_fw"],
                "rms_residual": f.rms,
                "ratios": [r.label for r in f.residuals],
                "rms_warp": [r.rms_warp for r in f.residuals],
                "rms_fill": [r.rms_fill for r in f.residuals],
            }
            if f.nonlinear:
                row |= {
                    "nonlinear_E1": f.nonlinear["E_w"],
                    "nonlinear_E2": f.nonlinear["E_f"],
                    "nonlinear_nu12": f.nonlinear["nu_wf"],
                    "k_w": f.nonlinear["k_w"],
                    "k_f": f.nonlinear["k_f"],
                    "nonlinear_rms_residual": f.nonlinear["rms"],
                }
            specimens.append(row)
        for c in self.compensations:
            specimens.append(
                {
                    "name": c.name,
                    "file": c.source,
                    "compensation_warp": c.warp,
                    "compensation_fill": c.fill,
                    "read_at": c.time,
                }
            )
        comment = (
            f"Fabric {self.name}: written by vares {__version__} (vares fabric fit).\n"
            "E1, E2 (E·t, kN/m) and nu12 are the means over the specimens; [scatter] their sample\n"
            "standard deviations. G12 is not measured by biaxial tests (see source)."
        )
        return fabric_toml(self.name, head, tables, specimens, comment)


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
