"""The plane-stress orthotropic constants of one specimen, fitted to a biaxial test record
(MSAJ/M-02).

With forces per width ``σ`` (kN/m) and strains ``ε`` (mm/mm),

    ε_w =  σ_w/E_w − ν_fw σ_f/E_f
    ε_f = −ν_wf σ_w/E_w + σ_f/E_f,          reciprocity: ν_wf/E_w = ν_fw/E_f,

:func:`fit_elastic` fits the law by least squares of the strain residual over the loading
branches of one chosen cycle of every load ratio at once. Each load ratio has its own strain
offset (the permanent set the earlier cycles left), so only the slopes are shared. Unknowns are
the compliances ``1/E_w, ν_wf/E_w, ν_fw/E_f, 1/E_f`` (three with reciprocity); warp and fill
residuals are weighted by the inverse of their own variance. Standard errors follow from the
covariance of the least-squares estimate (independent Gaussian strain errors) through the
derivatives of ``E = 1/a`` and ``ν = c/a``. Beside the linear law a nonlinear response
``ε = C σ + (k_w σ_w², k_f σ_f²)`` is fitted the same way and reported, so a poor linear fit
shows. The residual of both is given per load ratio. A batch of specimens is summarised in
:mod:`vares.materials.fitting`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .anisotropic import OrthotropicStVenantKirchhoff
from .biaxial import BiaxialRecord, Cycle, NotInRecord, RecordError, find_cycles

__all__ = ["CONSTANTS", "ElasticFit", "RatioResidual", "fit_elastic"]


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
                f"cycle(s); cycle {cycle} asked (cycles count from 1; -1 is the last)"
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
