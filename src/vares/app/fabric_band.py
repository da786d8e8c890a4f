"""The band of a structure's patterns under the scatter of its fabric.

:func:`fabric_band` patterns the panels (seams matched, as ``vares panels`` does) compensated by
the fabric's mean measured values — the nominal case — and again for each of
``ScatterOptions.samples`` random draws of the values (:func:`vares.analysis.scatter.
compensation_samples`); or, with ``ScatterOptions.sampled = "constants"``, with the fitted law
of the mean constants and of random draws of ``E1, E2, nu12`` (:func:`vares.analysis.scatter.
constant_samples`). Each case gives the length along the warp, the width along the fill, the
boundary length and the area of every panel's pattern, the length of every seam, and the
**erected prestress**: the nominal patterns — the ones that are cut — erected
(:func:`vares.erect`) with the fabric of the sample. That is the structure the client gets when
the delivered fabric behaves like the sample; erecting each sample's own patterns with its own
fabric would give back the intended prestress by construction and say nothing.

The samples are independent solves: in this process, on ``workers`` local processes (as a batch
runs its jobs), or on the workers of a Dask scheduler (:func:`vares.parallel.parallel_map`).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..analysis.erection import ErectionResult, erect
from ..analysis.erection_model import Pattern, patterns_of
from ..analysis.options import ErectionOptions
from ..analysis.scatter import (
    Band,
    ScatterOptions,
    compensation_samples,
    constant_samples,
    constants_law,
    pattern_dimensions,
    sample_law,
)
from ..materials.base import MaterialError
from ..materials.fabric_file import ConstantScatter
from ..materials.presets import FabricPreset
from ..parallel import parallel_map
from ..structures.matching import StructureResult, solve_structure
from ..structures.panels import Panel

__all__ = [
    "FabricBand",
    "SampleTask",
    "fabric_band",
    "prestress_figures",
    "solve_sample",
    "structure_figures",
]

#: The erected prestress figures of a case (force per length).
PRESTRESS_FIGURES = ("warp_mean", "warp_min", "warp_max", "fill_mean", "fill_min", "fill_max")


def structure_figures(structure: StructureResult) -> dict[str, float]:
    """Per panel its pattern's dimensions (:func:`pattern_dimensions`, named ``PANEL
    dimension``, or the dimension alone for a single panel), and per seam its length in the
    first panel's pattern (``seam FIRST|SECOND``; after matching both sides are equally long)."""
    single = len(structure.panels) == 1
    out: dict[str, float] = {}
    for panel, result in zip(structure.panels, structure.results, strict=True):
        for name, value in pattern_dimensions(result).items():
            out[name if single else f"{panel.name} {name}"] = value
    for report in structure.seam_reports:
        out[f"seam {report.first}|{report.second}"] = float(report.length_first_after)
    return out


def prestress_figures(erection: ErectionResult) -> dict[str, float]:
    """Area-weighted mean, smallest and largest erected membrane force of warp and fill."""
    stress = erection.statistics()["stress"]
    return {
        f"prestress {yarn}_{kind}": float(stress[yarn][kind])
        for yarn in ("warp", "fill")
        for kind in ("mean", "min", "max")
    }


@dataclass(frozen=True)
class SampleTask:
    """One case: the panels solved with ``law`` (and ``settings``: solve and structure options
    of :func:`vares.solve_structure`); with ``patterns``, those erected with ``law`` too."""

    panels: tuple[Panel, ...]
    law: Any
    thickness: float
    prestress: tuple[float, float]
    settings: Mapping[str, Any]
    patterns: tuple[Pattern, ...] | None = None
    erection: ErectionOptions | None = None


@dataclass(frozen=True)
class SampleOutcome:
    """What one case gave: its figures, whether its solve and erection converged (and why not),
    and its time (s)."""

    figures: dict[str, float]
    converged: bool
    reason: str | None
    seconds: float


def solve_sample(task: SampleTask) -> SampleOutcome:
    """Solve one case (any process may run it)."""
    started = time.perf_counter()
    structure = solve_structure(
        list(task.panels), task.law, task.thickness, prestress=task.prestress, **task.settings
    )
    figures = structure_figures(structure)
    converged, reason = structure.converged, structure.reason
    if task.patterns is not None and converged:
        erected = erect(
            list(task.patterns),
            task.law,
            task.thickness,
            solver=structure.options,
            options=task.erection,
        )
        figures.update(prestress_figures(erected))
        converged, reason = erected.converged, erected.reason
    return SampleOutcome(figures, converged, reason, time.perf_counter() - started)


@dataclass
class FabricBand:
    """A structure's patterns under the scatter of its fabric (module docs).

    ``band``: every figure's nominal value and samples (:class:`Band`); ``cases``: the sampled
    values (``warp``, ``fill`` compensation strains, or ``E1``, ``E2``, ``nu12``); ``constants``:
    the constants' scatter they were drawn with (None for compensation values); ``nominal``: the
    nominal structure and ``erection`` its plain erection (None when not erected); ``seconds``:
    the nominal case's time and the samples' total wall time.
    """

    fabric: FabricPreset
    prestress: tuple[float, float]
    options: ScatterOptions
    band: Band
    cases: list[dict[str, float]]
    nominal: StructureResult
    erection: ErectionResult | None
    seconds: dict[str, float] = field(default_factory=dict)
    constants: ConstantScatter | None = None

    @property
    def sampled(self) -> str:
        """What was sampled, in words."""
        if self.options.sampled == "constants":
            return "the fitted constants E1, E2, nu12 (independent normal), compensated by the law"
        return "the compensation values (independent normal warp and fill)"

    def to_dict(self) -> dict[str, object]:
        """The band as ``summary.json`` keeps it."""
        f, c, s = self.fabric, self.fabric.compensation, self.constants
        out: dict[str, object] = {
            "fabric": f.name,
            "source": f.source,
            "constants": {"E1": f.E1, "E2": f.E2, "G12": f.G12, "nu12": f.nu12},
        }
        if s is not None:
            out["constants_std"] = {"E1": s.E1, "E2": s.E2, "nu12": s.nu12}
        if c is not None:
            out["compensation"] = {
                "prestress": list(c.prestress),
                "warp": c.warp,
                "fill": c.fill,
                "warp_std": c.warp_std,
                "fill_std": c.fill_std,
                "specimens": c.specimens,
            }
        return {
            **out,
            "prestress": list(self.prestress),
            "scatter": self.options.to_dict(),
            "sampled": self.sampled,
            "erected": "the nominal patterns erected with the fabric of each sample",
            "panels": [p.name for p in self.nominal.panels],
            "figures": self.band.to_dict(),
            "samples": self.cases,
            "seconds": self.seconds,
            "converged": True,
        }


def fabric_band(
    panels: Sequence[Panel],
    fabric: FabricPreset,
    thickness: float = 1.0,
    prestress: tuple[float, float] | None = None,
    *,
    scatter: ScatterOptions | None = None,
    constants: ConstantScatter | None = None,
    erection: ErectionOptions | None = None,
    erected: bool = True,
    workers: int | None = None,
    scheduler: str | None = None,
    **settings: Any,
) -> FabricBand:
    """The nominal case and ``scatter.samples`` sampled cases of ``panels`` (module docs).

    ``prestress`` defaults to the one the values were measured at; ``constants``: the scatter
    of the constants when they are sampled (default: the fabric's, its file's ``[scatter]``);
    ``settings`` are options of :func:`vares.solve_structure` (``warp_direction``,
    ``match_seams``, …); ``erected`` False leaves out the erections. Raises
    :class:`MaterialError` for a fabric without what is to be sampled and when a case does not
    converge. A scatter of 0 gives a band of zero width (the commands refuse it:
    :func:`vares.analysis.scatter.check_scatter`).
    """
    scatter = scatter or ScatterOptions()
    c = fabric.compensation
    if prestress is None and c is None:
        raise MaterialError(f"fabric {fabric.name!r} has no measured prestress: give one")
    load = tuple(float(v) for v in (c.prestress if prestress is None else prestress))
    if scatter.sampled == "constants":
        constants = fabric.scatter if constants is None else constants
        if constants is None:
            raise MaterialError(f"fabric {fabric.name!r} has no scatter of its constants")
        law = constants_law(fabric, fabric.E1, fabric.E2, fabric.nu12)
        drawn = constant_samples(fabric, constants, scatter.samples, scatter.seed)
        cases = [{"E1": a, "E2": b, "nu12": n} for a, b, n in drawn]
        laws = [constants_law(fabric, *values) for values in drawn]
    else:
        if c is None:
            raise MaterialError(f"fabric {fabric.name!r} has no measured compensation values")
        law = sample_law(fabric, c.warp, c.fill)
        drawn = compensation_samples(fabric, scatter.samples, scatter.seed)
        cases = [{"warp": w, "fill": f} for w, f in drawn]
        laws = [sample_law(fabric, w, f) for w, f in drawn]
    panels = tuple(panels)
    started = time.perf_counter()
    nominal = solve_structure(list(panels), law, thickness, prestress=load, **settings)
    if not nominal.converged:
        raise MaterialError(f"the nominal patterns did not converge: {nominal.reason}")
    figures = structure_figures(nominal)
    patterns, plain = None, None
    if erected:
        patterns = tuple(patterns_of(nominal))
        plain = erect(list(patterns), law, thickness, solver=nominal.options, options=erection)
        if not plain.converged:
            raise MaterialError(f"the nominal patterns did not erect: {plain.reason}")
        figures.update(prestress_figures(plain))
    nominal_seconds = time.perf_counter() - started
    tasks = [
        SampleTask(panels, sample, thickness, load, settings, patterns, erection) for sample in laws
    ]
    started = time.perf_counter()
    outcomes, _ = parallel_map(solve_sample, tasks, workers=workers, scheduler=scheduler)
    failed = [(k, o.reason) for k, o in enumerate(outcomes) if not o.converged]
    if failed:
        k, reason = failed[0]
        values = ", ".join(f"{name} {value:.4g}" for name, value in cases[k].items())
        raise MaterialError(
            f"{len(failed)} of {len(cases)} samples did not converge; the first ({values}): "
            f"{reason}"
        )
    return FabricBand(
        fabric,
        (load[0], load[1]),
        scatter,
        Band.of(figures, [o.figures for o in outcomes], scatter.sigmas),
        cases,
        nominal,
        plain,
        {
            "nominal": nominal_seconds,
            "samples": time.perf_counter() - started,
            "per_sample_mean": float(np.mean([o.seconds for o in outcomes])),
        },
        constants,
    )
