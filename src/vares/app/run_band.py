"""The band of a run's own patterns under the scatter of its fabric file: the ``[scatter]`` table
of a job, ``--scatter`` on ``vares pattern``, ``example``, ``panels`` and ``cut``.

:func:`check_run_band` refuses, before the solve, a job whose band could not be the band of its
own patterns: no fabric file, a file without the scatter of what is sampled (or with that of
one specimen: unknown, or of 0: :func:`vares.analysis.scatter.check_scatter`, as ``vares fabric
band`` refuses it), a run compensated otherwise than the samples are, a prestress that is not
one uniform value, patterns optimised for the erected state. :func:`run_band` then patterns the
run's panels (one surface, a structure's panels, or a cut job's strips, each with the warp it
was solved with) by :func:`vares.app.fabric_band.fabric_band` with the job's solver, structure
and erection options: the nominal case again, and every sample. The samples are solved in this
process (a job holds no worker settings; ``vares batch`` runs whole jobs in parallel). The
nominal case is the run's own pattern solved again with the same law, prestress and options;
``nominal_difference`` records how far its figures are from the run's (0 to round-off).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..analysis.scatter import check_scatter, pattern_dimensions
from ..materials.base import MaterialError
from ..materials.presets import FabricPreset, fabric, file_fabric
from ..solver.options import SolveOptions
from ..structures.panels import Panel
from .band_result import RunBand
from .job import Job, JobError
from .outcome import JobOutcome

__all__ = ["BandInputs", "RunBand", "check_run_band", "run_band"]

#: How a refusal starts: the flag and the job-file table that asked for the band.
ASKED = "--scatter ([scatter])"


@dataclass(frozen=True)
class BandInputs:
    """What a run's band is computed from: the fabric file, its fabric (with the scatter of what
    is sampled) and the run's uniform prestress (warp, fill[, shear])."""

    path: Path
    fabric: FabricPreset
    prestress: tuple[float, ...]


def check_run_band(job: Job) -> BandInputs | None:
    """The inputs of the job's band (None without ``[scatter]``); a :class:`JobError` names the
    fabric file when the band cannot be the band of the run's own patterns."""
    options = job.scatter
    if options is None:
        return None
    material = job.material
    if material.presets is None:
        given = material.fabric or material.law or "the default law"
        raise JobError(
            f"{ASKED} needs a fabric file with scatter (--fabric FILE.toml, from 'vares fabric "
            f"fit'); the material is {given}"
        )
    path = job.path(material.presets)
    try:
        preset = file_fabric(path) if material.fabric is None else fabric(material.fabric, path)
    except MaterialError as exc:
        raise JobError(f"{ASKED}: {exc}") from None
    by = material.compensate_by or preset.compensate_by
    if options.sampled == "compensation" and by != "measured":
        raise JobError(
            f"{ASKED}: {path}: the run compensates by the fitted law: sample its "
            "constants, add --scatter-sampled constants ([scatter] sampled = 'constants')"
        )
    if options.sampled == "constants" and by != "law":
        raise JobError(
            f"{ASKED}: {path}: sampling the constants is the band of a pattern compensated "
            "by the fitted law; the run compensates by the measured values: add "
            "--compensate-by law, or sample the compensation values"
        )
    try:
        check_scatter(preset, options.sampled)
    except MaterialError as exc:
        raise JobError(f"{ASKED} needs a fabric file with scatter: {path}: {exc}") from None
    prestress = job.prestress
    if prestress.field is not None or prestress.warp is None:
        measured = preset.compensation
        at = (
            ""
            if measured is None
            else "; the fabric was measured at {:g}/{:g}".format(*measured.prestress)
        )
        raise JobError(
            f"{ASKED} needs one uniform prestress (--prestress WARP,FILL){at}; got "
            + ("a per-cell field" if prestress.field is not None else "none")
        )
    if job.erection is not None and job.erection.optimise:
        raise JobError(
            f"{ASKED} gives the band of the VaReS patterns; with --optimise the run cuts "
            "patterns optimised for the erected state: leave one of them out"
        )
    load = tuple(float(v) for v in prestress.value({}))
    return BandInputs(path, preset, load)


def run_band(outcome: JobOutcome, inputs: BandInputs, options: SolveOptions) -> RunBand:
    """The band of a run's patterns (module docs); a case that does not converge gives a band
    with its ``reason`` instead (and a warning in the outcome)."""
    from .fabric_band import fabric_band, structure_figures  # imported by a run with a band

    job = outcome.job
    settings: dict[str, Any] = {"options": options}
    structure = outcome.structure
    if structure is None:
        panels = [Panel(p.name, p.mesh) for p in outcome.panels]
    else:
        panels = list(structure.panels)
        settings["structure"] = structure.structure_options
        if outcome.cut is not None and options.warp_direction is None:  # each strip's own warp
            settings["panel_settings"] = [
                {"warp_direction": tuple(r.options.warp_direction)} for r in structure.results
            ]
    try:
        with warnings.catch_warnings():  # the run has said it of its own patterns
            warnings.simplefilter("ignore")
            band = fabric_band(
                panels,
                inputs.fabric,
                job.material.thickness,
                inputs.prestress,
                scatter=job.scatter,
                erection=job.erection,
                **settings,
            )
    except MaterialError as exc:
        outcome.warnings.append(f"no scatter band: {exc}")
        return RunBand(inputs.path, None, str(exc))
    own = (
        pattern_dimensions(outcome.panels[0].result)
        if structure is None
        else structure_figures(structure)
    )
    difference = max(abs(band.band.nominal[name] - value) for name, value in own.items())
    return RunBand(inputs.path, band, None, float(difference))
