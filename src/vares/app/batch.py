"""Batches: many independent jobs, on local worker processes or on a Dask cluster.

Each job file runs as :func:`vares.app.runner.run_job` would run it alone, so the results do not
depend on where it ran. A failing job is reported and does not stop the others. A job whose
``summary.json`` (``structure.json`` for a structure) is complete — converged, and written for the
same job (the job's digest is stored in it) — is skipped, so an interrupted batch resumes where it
stopped.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Sequence
from concurrent.futures import as_completed
from dataclasses import asdict, dataclass
from pathlib import Path

from ..parallel import process_pool
from .job import Job, JobError, load_job
from .runner import run_job

__all__ = ["JobStatus", "is_complete", "run_batch", "run_job_file"]


@dataclass(frozen=True)
class JobStatus:
    """How one job of a batch ended: ``done``, ``skipped``, ``failed`` or ``not converged``."""

    job: str
    status: str
    message: str
    seconds: float
    output: str

    def to_dict(self) -> dict:
        return asdict(self)


def _summary_path(job: Job) -> Path:
    return job.directory / ("summary.json" if job.structure is None else "structure.json")


def _previous(job: Job) -> dict:
    try:
        return json.loads(_summary_path(job).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}


def is_complete(job: Job) -> bool:
    """True when the job's outputs exist, converged, and were written for this very job (a cut
    with its nest; with an erection, its ``erect.json`` says it converged)."""
    data = _previous(job)
    if not (data.get("converged") and data.get("job_digest") == job.digest()):
        return False
    if job.cut is not None and not (data.get("cutting") or {}).get("nest"):
        return False  # a cut with no nest: its patterns did not fit the roll
    if job.erection is None:
        return True
    try:
        erected = json.loads((job.directory / "erect" / "erect.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return bool(erected.get("converged"))


def _refuse_shared_outputs(paths: list[str]) -> None:
    """Two jobs writing into one folder would lose one result: refuse before any work."""
    seen: dict[Path, str] = {}
    for path in paths:
        try:
            directory = load_job(path).directory.resolve()
        except (OSError, ValueError):
            continue  # reported when the job runs
        for other, owner in seen.items():
            if directory == other or other in directory.parents or directory in other.parents:
                raise JobError(
                    f"{owner} and {path} write into the same folder or one into the other's "
                    f"({other}, {directory}): give each job a folder of its own"
                )
        seen[directory] = path


def run_job_file(path: str, force: bool = False) -> JobStatus:
    """Run one job file (in whatever process calls this); never raises."""
    started = time.perf_counter()
    output = ""
    try:
        job = load_job(path)
        output = str(_summary_path(job).parent)
        if not force and is_complete(job):
            return JobStatus(str(path), "skipped", "complete", 0.0, output)
        # an unfinished run of this very job is replaced; anything else only with force
        own = _previous(job).get("job_digest") == job.digest()
        outcome = run_job(job, force=force or own)
        status = "done" if outcome.converged else "not converged"
        iterations = sum(p.result.iterations for p in outcome.panels)
        energy = sum(p.result.energy for p in outcome.panels)
        message = (
            f"{iterations} iterations, energy {energy:.6e}"
            if outcome.converged
            else str(outcome.reason)
        )
        if outcome.converged and outcome.unfit:  # patterned, but no nest on this roll
            status, message = "failed", outcome.unfit
        return JobStatus(str(path), status, message, time.perf_counter() - started, output)
    except Exception as exc:  # a failing job is reported, the batch goes on
        return JobStatus(
            str(path),
            "failed",
            f"{type(exc).__name__}: {exc}",
            time.perf_counter() - started,
            output,
        )


def run_batch(
    paths: Sequence[str | Path],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    force: bool = False,
    callback: Callable[[JobStatus], None] | None = None,
) -> list[JobStatus]:
    """Run job files in parallel: ``workers`` local processes (default: one per core), or the
    workers of the Dask distributed scheduler at ``scheduler`` (``tcp://host:port``).

    Returns one :class:`JobStatus` per job, in the order given; ``callback`` sees each as it ends.
    """
    paths = [str(Path(p).resolve()) for p in paths]
    if not paths:
        return []
    _refuse_shared_outputs(paths)
    statuses: dict[str, JobStatus] = {}

    def finished(status: JobStatus) -> None:
        statuses[status.job] = status
        if callback is not None:
            callback(status)

    if scheduler is not None:
        from dask.distributed import Client
        from dask.distributed import as_completed as dask_completed

        with Client(scheduler, timeout="20s") as client:
            futures = client.map(run_job_file, paths, force=force, pure=False)
            for future in dask_completed(futures):
                finished(future.result())
    else:
        workers = max(1, workers or os.cpu_count() or 1)
        with process_pool(workers) as pool:
            futures = [pool.submit(run_job_file, path, force) for path in paths]
            for future in as_completed(futures):
                finished(future.result())
    return [statuses[path] for path in paths]
