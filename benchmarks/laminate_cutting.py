"""A laminate end to end, with its ply book and cutter files (docs/composites.md, "Laminates").

    python benchmarks/laminate_cutting.py [--job examples/laminate/laminate.toml] [--workers 1]
        [--nest-times 1,2,5] [--out DIR]

Runs the job as ``vares laminate JOB -o DIR`` does (one process, ``--workers``) and prints the
time of each stage (reading the mould, draping every ply and checking the pairs, the blanks,
the nest, the ply book, writing), the ply book's size, the files' sizes and the nest's length
and yield; then nests the same blanks again for each of ``--nest-times`` seconds of search.
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from pathlib import Path

from vares.app.inputs import load_input
from vares.app.laminate_job import load_laminate_job
from vares.app.laminate_outputs import laminate_cutting, laminate_files, write_laminate
from vares.app.ply_book import ply_book
from vares.app.staging import OutputFolder
from vares.structures.laminate import drape_laminate
from vares.structures.laminate_blanks import nest_plies

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--job", type=Path, default=ROOT / "examples/laminate/laminate.toml")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--nest-times", default="1,2,5")
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="laminate-cutting-")) / "out"
    print(f"python benchmarks/laminate_cutting.py --job {args.job} --workers {args.workers}")
    print(f"{platform.node()}, {os.cpu_count()} cores, load average {os.getloadavg()}")
    started = time.perf_counter()
    job = load_laminate_job(args.job).with_output(out)
    loaded = load_input(job.job)
    read = time.perf_counter()
    result = drape_laminate(
        loaded.panels[0].mesh,
        job.build_plies(),
        job.laminate.replace(workers=args.workers),
        cell_data=loaded.cell_data,
        solve_settings=job.job.solve.to_dict(),
    )
    draped = time.perf_counter()
    run = laminate_cutting(result, loaded.units)
    cut = time.perf_counter()
    book = ply_book(result, run.blanks, run.nest, units=run.units)
    booked = time.perf_counter()
    folder = OutputFolder(job.directory, laminate_files(job), force=True, inputs=[],
                          command="laminate")  # fmt: skip
    folder.check()
    folder.start()
    try:
        write_laminate(folder, job, run)
        folder.commit()
    finally:
        folder.discard()
    written = time.perf_counter()
    mesh = result.mesh
    print(f"mould: {mesh.num_cells} cells; {len(result.laminate.plies)} plies, "
          f"{len(result.drapes)} drapes, converged {result.converged}")  # fmt: skip
    nest = run.nest
    print(f"read {read - started:.2f} s, drape and pairs {draped - read:.2f} s, "
          f"blanks and nest {cut - draped:.2f} s (nest {nest.elapsed if nest else 0:.2f} s), "
          f"ply book {booked - cut:.2f} s ({len(book.encode()) / 2**20:.2f} MiB), "
          f"writing (the book again) {written - booked:.2f} s; "
          f"total {written - started:.2f} s")  # fmt: skip
    for path in laminate_files(job, result.labels):
        print(f"  {path.relative_to(out)}: {path.stat().st_size / 1024:.0f} KiB")
    if nest is None:
        print(f"not nested: {run.nest_error}")
        return
    units = run.units
    print(f"nest ({job.laminate.nest_time:g} s): roll {nest.roll_width:g} {units}, length "
          f"{nest.length:.5g} {units}, yield {100 * nest.yield_:.1f} %")  # fmt: skip
    for seconds in (float(s) for s in args.nest_times.split(",")):
        again = nest_plies(run.blanks, nest.roll_width, time_limit=seconds)
        print(f"  nest for {seconds:g} s: took {again.elapsed:.2f} s, length "
              f"{again.length:.5g} {units}, yield {100 * again.yield_:.1f} %")  # fmt: skip


if __name__ == "__main__":
    main()
