"""``vares batch``: many jobs in parallel, on local workers or a Dask cluster."""

import time
from pathlib import Path
from typing import Annotated

import typer

from .common import check_parallel, console, fail, guarded, scheduler_option, workers_option

__all__ = ["batch"]


def batch(
    jobs: Annotated[list[Path], typer.Argument(metavar="JOB...", help="Job files (TOML).")],
    workers: Annotated[int | None, workers_option("the jobs", "one per core")] = None,
    scheduler: Annotated[str | None, scheduler_option("the jobs")] = None,
    force: Annotated[
        bool,
        typer.Option("--force", "-f", help="Rerun complete jobs too, replacing their runs."),
    ] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Only the final table.")] = False,
) -> None:
    """Run many jobs in parallel; complete jobs are skipped, failing ones reported."""
    from ..batch import run_batch

    def body() -> None:
        check_parallel(workers, scheduler)
        missing = [str(j) for j in jobs if not j.is_file()]
        if missing:
            raise FileNotFoundError(f"no such file: {', '.join(missing)}")
        count = {"n": 0}

        def progress(status) -> None:
            count["n"] += 1
            if not quiet:
                colour = {"done": "green", "skipped": "cyan"}.get(status.status, "red")
                console.print(
                    f"[{count['n']}/{len(jobs)}] [{colour}]{status.status}[/] "
                    f"{status.job} ({status.seconds:.2f} s) {status.message}"
                )

        started = time.perf_counter()
        statuses = run_batch(
            jobs, workers=workers, scheduler=scheduler, force=force, callback=progress
        )
        elapsed = time.perf_counter() - started
        tally = {
            s: sum(x.status == s for x in statuses)
            for s in ("done", "skipped", "not converged", "failed")
        }
        console.print(", ".join(f"{n} {s}" for s, n in tally.items() if n) + f" in {elapsed:.2f} s")
        bad = [s for s in statuses if s.status in ("failed", "not converged")]
        if bad:
            raise typer.Exit(
                fail(
                    f"{len(bad)} of {len(statuses)} jobs did not finish: "
                    f"{bad[0].job}: {bad[0].message}",
                    1,
                )
            )

    guarded(body)
