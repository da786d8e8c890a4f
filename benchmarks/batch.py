"""Wall time of a batch of 64 jobs with 1 and 2 local workers and on a local Dask cluster.

    pip install -e ".[dask]"
    python benchmarks/batch.py [--jobs 64]

Each job patterns the ``hypar`` example (20 × 20 cells, 800 triangles) with St. Venant–Kirchhoff
and its own Poisson's ratio and warp angle, so no two jobs are alike. Every configuration starts
from empty output folders (nothing skipped); the Dask cluster (2 worker processes, one thread
each, on 127.0.0.1) is started before the clock starts.
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from pathlib import Path

from vares.app.batch import run_batch


def write_jobs(folder: Path, count: int) -> list[Path]:
    paths = []
    for k in range(count):
        path = folder / f"job{k:03d}.toml"
        path.write_text(
            f'[input]\nexample = "hypar"\n\n[material]\nlaw = "st-venant-kirchhoff"\n'
            f"E = 1000.0\nnu = {0.05 + 0.4 * k / count:.4f}\n\n[fibres]\n"
            f'warp_angle = {360.0 * k / count:.3f}\n\n[output]\ndirectory = "out{k:03d}"\n'
        )
        paths.append(path)
    return paths


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=64)
    args = parser.parse_args()
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}; {args.jobs} jobs"
    )
    for label, options in (
        ("1 local worker", {"workers": 1}),
        ("2 local workers", {"workers": 2}),
        ("local Dask cluster, 2 workers", None),
    ):
        with tempfile.TemporaryDirectory() as tmp:
            paths = write_jobs(Path(tmp), args.jobs)
            if options is None:
                from distributed import LocalCluster

                with LocalCluster(
                    n_workers=2,
                    threads_per_worker=1,
                    processes=True,
                    host="127.0.0.1",
                    dashboard_address=None,
                ) as cluster:
                    start = time.perf_counter()
                    statuses = run_batch(paths, scheduler=cluster.scheduler_address)
                    elapsed = time.perf_counter() - start
            else:
                start = time.perf_counter()
                statuses = run_batch(paths, **options)
                elapsed = time.perf_counter() - start
        done = sum(s.status == "done" for s in statuses)
        print(
            f"{label:<32} {elapsed:8.2f} s   ({done}/{len(statuses)} done, "
            f"{elapsed / len(statuses):.3f} s per job)"
        )
    print(f"reproduce: python benchmarks/batch.py --jobs {args.jobs}")


if __name__ == "__main__":
    main()
