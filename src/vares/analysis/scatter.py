"""The scatter of a fabric's compensation values carried into a panel's pattern.

The compensation values of a batch scatter from specimen to specimen (docs/fabrics.md). A
pattern compensated by their mean is one of the patterns the batch allows.

- :func:`pattern_band` solves the panel again with the warp and fill values at their mean ±
  ``sigmas`` standard deviations (the four corners) and reports, for the pattern's length along
  the warp, its width along the fill, its boundary length and its area, the value of the mean
  pattern and the smallest and largest over the corners, and how far any node moves (after the
  best rigid fit).
- :func:`compensation_samples` draws random compensation values from their scatter (independent
  normal warp and fill values: a batch of a few specimens says nothing of their correlation),
  :func:`constant_samples` the fitted constants ``E1, E2, nu12`` from theirs, and
  :class:`Band` gathers any named figures of the samples (:class:`ScatterOptions`: what is
  sampled, how many samples, which seed, how many standard deviations the band spans). The
  solves themselves are :func:`vares.app.fabric_band.fabric_band`'s, which also erects the
  patterns.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product

import numpy as np

from ..geometry.mesh import SurfaceMesh
from ..geometry.rigid_fit import rigid_fit
from ..materials.anisotropic import OrthotropicStVenantKirchhoff
from ..materials.base import MaterialError
from ..materials.compensation_law import compensating_law
from ..materials.fabric_file import ConstantScatter
from ..materials.presets import FabricPreset
from ..solver.api import solve
from ..solver.result import PatternResult
from .scatter_options import SAMPLED, ScatterOptions

__all__ = [
    "SAMPLED",
    "Band",
    "PatternBand",
    "ScatterOptions",
    "check_scatter",
    "compensation_samples",
    "constant_samples",
    "constants_law",
    "pattern_band",
    "pattern_dimensions",
    "sample_law",
]

#: The dimensions a band gives (pattern units; area in units²).
DIMENSIONS = ("warp_length", "fill_length", "boundary_length", "area")


@dataclass(frozen=True)
class PatternBand:
    """A panel's pattern under the scatter of its compensation values.

    ``mean``: the dimensions of the pattern from the mean values; ``low``, ``high``: the
    smallest and largest over the corner cases ``cases`` (warp, fill strains);
    ``node_deviation``: the largest distance of a node from its place in the mean pattern,
    each corner pattern moved rigidly onto it (pattern units); ``sigmas``: the half-width of
    the band in standard deviations.
    """

    mean: dict[str, float]
    low: dict[str, float]
    high: dict[str, float]
    node_deviation: float
    sigmas: float
    cases: tuple[tuple[float, float], ...]
    results: tuple[PatternResult, ...]

    def rows(self) -> list[tuple[str, str, str]]:
        """Text rows ``(dimension, mean, low … high)``."""
        return [
            (n.replace("_", " "), f"{self.mean[n]:.6g}", f"{self.low[n]:.6g} … {self.high[n]:.6g}")
            for n in DIMENSIONS
        ]


def pattern_dimensions(result: PatternResult) -> dict[str, float]:
    """Length along the warp, width along the fill (extents of the nodes projected on the
    pattern's fibre directions), boundary length and area of a solved pattern."""
    pattern = result.material_coordinates
    fibres = result.fibres
    warp = np.array([1.0, 0.0]) if fibres is None else fibres.warp
    fill = np.array([0.0, 1.0]) if fibres is None else fibres.fill
    edges = result.mesh.boundary_edges()
    boundary = float(np.linalg.norm(pattern[edges[:, 1]] - pattern[edges[:, 0]], axis=1).sum())
    return {
        "warp_length": float(np.ptp(pattern @ warp)),
        "fill_length": float(np.ptp(pattern @ fill)),
        "boundary_length": boundary,
        "area": float(result.fields["pattern_area"].sum()),
    }


def compensation_samples(
    fabric: FabricPreset, samples: int, seed: int = 0
) -> list[tuple[float, float]]:
    """``samples`` (warp, fill) compensation values (mm/mm) drawn from independent normal
    distributions with the fabric's means and standard deviations. Raises
    :class:`MaterialError` for a fabric without measured compensation values, or when a draw is
    not a positive strain (a scatter too wide for a normal distribution)."""
    c = fabric.compensation
    if c is None:
        raise MaterialError(f"fabric {fabric.name!r} has no measured compensation values")
    z = np.random.default_rng(seed).standard_normal((int(samples), 2))
    drawn = [(c.warp + a * c.warp_std, c.fill + b * c.fill_std) for a, b in z]
    if any(w <= 0 or f <= 0 for w, f in drawn):
        raise MaterialError(
            f"fabric {fabric.name!r}: a sample of its compensation values is not a positive "
            f"strain (warp {c.warp:.3g} ± {c.warp_std:.3g}, fill {c.fill:.3g} ± {c.fill_std:.3g})"
        )
    return [(float(w), float(f)) for w, f in drawn]


def constant_samples(
    fabric: FabricPreset, scatter: ConstantScatter, samples: int, seed: int = 0
) -> list[tuple[float, float, float]]:
    """``samples`` (E1, E2, nu12) drawn from independent normal distributions with the fabric's
    constants as means and ``scatter``'s standard deviations. Raises :class:`MaterialError`
    when a draw is not an admissible orthotropic law."""
    z = np.random.default_rng(seed).standard_normal((int(samples), 3))
    mean = np.array([fabric.E1, fabric.E2, fabric.nu12])
    drawn = mean + z * [scatter.E1, scatter.E2, scatter.nu12]
    out = [(float(a), float(b), float(c)) for a, b, c in drawn]
    for values in out:
        constants_law(fabric, *values)
    return out


def constants_law(
    fabric: FabricPreset, E1: float, E2: float, nu12: float
) -> OrthotropicStVenantKirchhoff:
    """The fabric's orthotropic law with the constants ``E1``, ``E2`` (kN/m), ``nu12`` and its
    own ``G12``; :class:`MaterialError` names the fabric when they are not admissible."""
    try:
        return OrthotropicStVenantKirchhoff(E1, E2, fabric.G12, nu12)
    except (MaterialError, ValueError) as exc:
        raise MaterialError(
            f"fabric {fabric.name!r}: a sample of its constants (E1 {E1:.4g}, E2 {E2:.4g}, "
            f"nu12 {nu12:.4g}) is not a law: {exc}"
        ) from None


def sample_law(fabric: FabricPreset, warp: float, fill: float) -> OrthotropicStVenantKirchhoff:
    """The law compensating by the values ``warp``, ``fill`` at the fabric's measured prestress,
    with its ``nu12`` and ``G12`` (:func:`compensating_law`)."""
    c = fabric.compensation
    if c is None:
        raise MaterialError(f"fabric {fabric.name!r} has no measured compensation values")
    return compensating_law(warp, fill, c.prestress, fabric.nu12, fabric.G12)


@dataclass(frozen=True)
class Band:
    """Named figures of a nominal case and of its samples.

    ``nominal``: each figure of the nominal case (the mean values); ``samples``: the figure of
    each sample, in order; ``sigmas``: the band's half-width in sample standard deviations. The
    band of a figure is ``nominal ± sigmas · std``.
    """

    nominal: dict[str, float]
    samples: dict[str, tuple[float, ...]]
    sigmas: float

    @classmethod
    def of(cls, nominal: dict[str, float], samples: list[dict[str, float]], sigmas: float) -> Band:
        """The band of the figures ``nominal`` has, from one mapping per sample."""
        return cls(
            dict(nominal), {n: tuple(float(s[n]) for s in samples) for n in nominal}, float(sigmas)
        )

    @property
    def names(self) -> list[str]:
        return list(self.nominal)

    def std(self, name: str) -> float:
        """Sample standard deviation of a figure (0 for one sample)."""
        values = np.asarray(self.samples[name])
        # about the first sample: equal samples have a standard deviation of exactly 0
        return float(np.std(values - values[0], ddof=1)) if len(values) > 1 else 0.0

    def spread(self, name: str) -> float:
        """Half-width of the band: ``sigmas`` standard deviations."""
        return self.sigmas * self.std(name)

    def to_dict(self) -> dict[str, dict[str, float]]:
        """Per figure: nominal, mean, std, spread (± ``sigmas`` std), min and max of the samples."""
        return {
            name: {
                "nominal": value,
                "mean": float(np.mean(self.samples[name])),
                "std": self.std(name),
                "spread": self.spread(name),
                "min": float(np.min(self.samples[name])),
                "max": float(np.max(self.samples[name])),
            }
            for name, value in self.nominal.items()
        }


def check_scatter(fabric: FabricPreset, sampled: str = "compensation") -> None:
    """Raise :class:`MaterialError` for a fabric whose band of what is ``sampled`` (one of
    :data:`SAMPLED`) would be the nominal pattern alone: without measured compensation values
    or without the scatter of its constants (a ``[scatter]`` table), or with a scatter that is
    unknown (the values of one specimen) or 0 (every standard deviation 0 or not given). One
    message for every command that samples them."""
    if sampled not in SAMPLED:
        raise ValueError(f"sampled must be one of {', '.join(SAMPLED)}; got {sampled!r}")
    if sampled == "constants":
        s = fabric.scatter
        if s is None:
            raise MaterialError(
                f"fabric {fabric.name!r} has no scatter of its constants (no [scatter] table): "
                "fit two or more stiffness records"
            )
        what, records, specimens = "constants", "stiffness", s.specimens
        deviations, zero = (s.E1, s.E2, s.nu12), "E1, E2 and nu12 are 0 or not given"
    else:
        c = fabric.compensation
        if c is None:
            raise MaterialError(f"fabric {fabric.name!r} has no measured compensation values")
        what, records, specimens = "compensation values", "compensation", c.specimens
        deviations, zero = (c.warp_std, c.fill_std), "warp_std and fill_std are 0 or not given"
    if specimens == 1 or not any(deviations):
        origin = "the values of one specimen: unknown" if specimens == 1 else zero
        raise MaterialError(
            f"fabric {fabric.name!r} has no scatter of its {what} ({origin}): its band would be "
            f"the nominal pattern alone; fit two or more {records} records"
        )


def pattern_band(
    mesh: SurfaceMesh,
    fabric: FabricPreset,
    prestress: tuple[float, float] | None = None,
    *,
    sigmas: float = 1.0,
    thickness: float = 1.0,
    **settings,
) -> PatternBand:
    """Solve ``mesh`` with ``fabric`` compensated by its measured values at the mean and at
    the four corners mean ± ``sigmas`` standard deviations of warp and fill.

    ``prestress`` defaults to the one the values were measured at; ``settings`` go to
    :func:`vares.solve` (``warp_direction``, ``orientation``, …). Raises
    :class:`MaterialError` for a fabric without measured compensation values or without their
    scatter (both standard deviations 0, as from a single specimen).
    """
    check_scatter(fabric)
    c = fabric.compensation
    if not (np.isfinite(sigmas) and sigmas >= 0):
        raise ValueError(f"sigmas must be a number ≥ 0; got {sigmas!r}")
    load = c.prestress if prestress is None else prestress
    mean_law = compensating_law(c.warp, c.fill, c.prestress, fabric.nu12, fabric.G12)
    centre = solve(mesh, mean_law, thickness, prestress=load, **settings)
    if not centre.converged:
        raise MaterialError(f"the pattern from the mean values did not converge: {centre.reason}")
    cases, results = [], []
    for sw, sf in product((-1.0, 1.0), repeat=2):
        warp, fill = c.warp + sw * sigmas * c.warp_std, c.fill + sf * sigmas * c.fill_std
        law = compensating_law(warp, fill, c.prestress, fabric.nu12, fabric.G12)
        results.append(solve(mesh, law, thickness, prestress=load, **settings))
        cases.append((warp, fill))
    failed = [case for case, r in zip(cases, results, strict=True) if not r.converged]
    if failed:
        raise MaterialError(f"the pattern did not converge for the compensation values {failed}")
    dims = [pattern_dimensions(r) for r in results]
    reference = centre.material_coordinates
    deviation = max(
        float(np.linalg.norm(moved - reference, axis=1).max())
        for moved in (rigid_fit(r.material_coordinates, reference) for r in results)
    )
    return PatternBand(
        mean=pattern_dimensions(centre),
        low={n: min(d[n] for d in dims) for n in DIMENSIONS},
        high={n: max(d[n] for d in dims) for n in DIMENSIONS},
        node_deviation=deviation,
        sigmas=float(sigmas),
        cases=tuple(cases),
        results=(centre, *results),
    )
