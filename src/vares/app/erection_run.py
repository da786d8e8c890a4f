"""``vares erect DIR``: erect the patterns an earlier run wrote into its folder and write the
folder's ``erect/`` as one set, added to the run's manifest (:mod:`vares.app.staging`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ..analysis.options import ErectionOptions
from ..solver import IterationRecord
from .erection_outputs import erection_files, write_erection
from .inputs import saved_patterns, saved_units
from .job import Job, load_job
from .outputs import JOB_FILE
from .staging import OutputFolder, add_to_manifest, listed

if TYPE_CHECKING:
    from ..analysis.erection import ErectionResult

__all__ = ["ErectionRun", "run_erection"]


@dataclass
class ErectionRun:
    """What ``vares erect DIR`` did: the job it read, the erection and the files written."""

    job: Job
    result: ErectionResult
    files: list[Path] = field(default_factory=list)
    units: str = "m"


def run_erection(
    directory: str | Path,
    options: ErectionOptions | None = None,
    *,
    force: bool = False,
    report: bool = False,
    callback: Callable[[IterationRecord], None] | None = None,
) -> ErectionRun:
    """Erect the patterns that a run wrote into ``directory`` (from its ``job.toml``, the panels'
    ``surface.vtu``, ``pattern.vtu`` and ``summary.json``) and write ``directory/erect/`` (as one
    set, added to the run's manifest).

    ``options`` default to the job's ``[erection]`` table (or the defaults); the tolerance,
    iteration limit and linear solver are the job's.
    """
    directory = Path(directory)
    job_file = directory / JOB_FILE
    if not job_file.is_file():
        raise FileNotFoundError(
            f"no {JOB_FILE} in {directory}: erect an output directory written by "
            "'vares pattern', 'example', 'run' or 'panels'"
        )
    job = load_job(job_file).with_output(directory)
    options = options or job.erection or ErectionOptions()
    material = job.material.build(job.base)
    patterns = saved_patterns(job)
    target = directory / "erect"
    folder = OutputFolder(
        target,
        erection_files(target, report),
        force=force,
        inputs=[],
        manifest=False,
        known=[p for p in listed(directory) if target.resolve() in p.resolve().parents],
    )
    folder.check()
    from ..analysis.erection import erect  # imported when erecting

    result = erect(
        patterns,
        material,
        job.material.thickness,
        solver=job.solve,
        options=options,
        callback=callback,
    )
    units = saved_units(job)
    root = folder.start()
    try:
        staged = write_erection(result, root, units)
        if report:
            from .erection_report import write_erection_report

            staged.append(write_erection_report(result, root, units))
        files = [folder.directory / Path(p).relative_to(root) for p in staged]
        # listed beside the old ones first: killed before the commit, the run's folder still
        # knows every file of erect/ as its own; trimmed to the new ones once they are in place
        add_to_manifest(directory, files, replacing=None)
        folder.commit()
        add_to_manifest(directory, files, replacing=folder.directory)
    finally:
        folder.discard()
    return ErectionRun(job, result, files, units)
