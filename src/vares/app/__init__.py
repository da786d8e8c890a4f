"""Jobs and what runs them: the job model, the runner, batches, reports and the command line."""

from typing import TYPE_CHECKING

from .._lazy import lazy_exports

if TYPE_CHECKING:
    from .batch import JobStatus, run_batch
    from .job import Job, JobError, load_job
    from .outcome import JobOutcome, PanelOutcome
    from .runner import run_job

__getattr__, __dir__, __all__ = lazy_exports(__name__, __file__)
