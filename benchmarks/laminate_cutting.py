"""A laminate end to end, with its ply book and cutter files (docs/composites.md, "Laminates").

    python benchmarks/laminate_cutting.py [--job examples/laminate/laminate.toml] [--workers 1]
        [--scheduler tcp://host:port] [--darts auto] [--locking-angle DEG]
        [--nest-times 1,2,5] [--out DIR]

Runs the job as ``vares laminate JOB -o DIR`` does (``--workers`` processes, or the workers of
a Dask scheduler) and prints the time of each stage (reading the mould, draping every ply and
checking the pairs, the blanks, the nest, the ply book, writing), the ply book's size, the files'
sizes and the nest's length and yield; with ``--darts auto`` (and a ``--locking-angle`` for every
ply) each drape's darts: how many, their lengths, the largest shear without and with them, the
solves with darts and the drape's seconds. Then nests the same blanks again for each of
``--nest-times`` seconds of search (``--nest-times ""``: not again).
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
    parser.add_argument("--scheduler", default=None)
    parser.add_argument("--darts", choices=("none", "auto"), default=None)
    parser.add_argument("--locking-angle", type=float, default=None)
    parser.add_argument("--nest-times", default="1,2,5")
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="laminate-cutting-")) / "out"
    command = f"python benchmarks/laminate_cutting.py --job {args.job}"
    command += f" --scheduler {args.scheduler}" if args.scheduler else f" --workers {args.workers}"
    if args.darts is not None:
        command += f" --darts {args.darts}"
    if args.locking_angle is not None:
        command += f" --locking-angle {args.locking_angle:g}"
    print(command)
    print(f"{platform.node()}, {os.cpu_count()} cores, load average {os.getloadavg()}")
    started = time.perf_counter()
    job = load_laminate_job(args.job).with_output(out)
    loaded = load_input(job.job)
    changes = {"scheduler": args.scheduler} if args.scheduler else {"workers": args.workers}
    changes |= {k: v for k, v in (("darts", args.darts), ("locking_angle", args.locking_angle))
                if v is not None}  # fmt: skip
    read = time.perf_counter()
    result = drape_laminate(
        loaded.panels[0].mesh,
        job.build_plies(),
        job.laminate.replace(**changes),
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
    for drape in result.drapes:
        darted = drape.darted
        if darted is None:
            continue
        lengths = ", ".join(f"{length:.4g}" for length in darted.summary()["dart_lengths"])
        after = "–" if darted.max_shear_after is None else f"{darted.max_shear_after:.2f}°"
        print(f"  drape {drape.label}: locking {darted.locking_angle:g}°, "
              f"{len(darted.dart_lines)} dart(s) [{lengths}], largest shear "
              f"{darted.max_shear_before:.2f}° -> {after}, {len(darted.rounds)} solve(s) with "
              f"darts, {'cut with them' if drape.is_darted else 'cut whole'}, "
              f"converged {drape.converged}, {drape.seconds:.2f} s")  # fmt: skip
    for path in laminate_files(job, result.labels, nested=run.nest is not None):
        print(f"  {path.relative_to(out)}: {path.stat().st_size / 1024:.0f} KiB")
    if nest is None:
        print(f"not nested: {run.nest_error}")
        return
    units = run.units
    print(f"nest ({job.laminate.nest_time:g} s): roll {nest.roll_width:g} {units}, length "
          f"{nest.length:.5g} {units}, yield {100 * nest.yield_:.1f} %")  # fmt: skip
    for seconds in (float(s) for s in args.nest_times.split(",") if s):
        again = nest_plies(run.blanks, nest.roll_width, time_limit=seconds)
        print(f"  nest for {seconds:g} s: took {again.elapsed:.2f} s, length "
              f"{again.length:.5g} {units}, yield {100 * again.yield_:.1f} %")  # fmt: skip


if __name__ == "__main__":
    main()
