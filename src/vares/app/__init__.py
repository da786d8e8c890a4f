"""Jobs and what runs them: the job model, the runner, batches, reports and the command line."""

from .batch import JobStatus, run_batch
from .job import Job, JobError, load_job
from .outcome import JobOutcome, PanelOutcome
from .runner import run_job

__all__ = [
    "Job",
    "JobError",
    "JobOutcome",
    "JobStatus",
    "PanelOutcome",
    "load_job",
    "run_batch",
    "run_job",
]
