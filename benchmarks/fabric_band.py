"""What the band of a fabric's scatter costs against one solve, and what it gives, on the
shipped fabric file (examples/biaxial/pes-batch-42.toml).

    python benchmarks/fabric_band.py [--samples 8 16] [--workers 2] [--cases sail strips]

For each case (the four-point sail, warp (1, 1, 0); the six strips of the hyperbolic
paraboloid, warp (1, 0, 0), seams matched) it times, in one process and one after the other:
one nominal case (the patterns, and their erection), then ``fabric_band`` with each number of
samples in this process and, with ``--workers``, on that many local processes. The first
nominal case is run once before, so the kernels are compiled; one case is the median of three.
Prints wall and CPU times (the CPU time of this process: on a loaded machine it is the steadier
measure; it leaves out worker processes), their ratio to one case and the band (± 2 std) of
every figure of the largest run in this process.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from vares.analysis.erection import erect
from vares.analysis.erection_model import patterns_of
from vares.analysis.scatter import ScatterOptions, sample_law
from vares.app.fabric_band import fabric_band
from vares.geometry.examples import EXAMPLES, STRUCTURE_EXAMPLES
from vares.materials.presets import file_fabric
from vares.structures.matching import solve_structure
from vares.structures.panels import Panel, split_panels

FABRIC = Path(__file__).parent.parent / "examples" / "biaxial" / "pes-batch-42.toml"


def strips() -> list[Panel]:
    mesh, ids = STRUCTURE_EXAMPLES["hypar-strips"]()
    return split_panels(mesh, ids, {int(i): f"strip-{int(i) + 1}" for i in set(ids)})


CASES = {
    "sail": ("four-point sail", lambda: [Panel("sail", EXAMPLES["sail"]())], (1.0, 1.0, 0.0)),
    "strips": ("hypar, six strips", strips, (1.0, 0.0, 0.0)),
}


def one_case(panels: list[Panel], fabric, warp) -> None:
    """The nominal case alone: the patterns compensated by the mean values, and erected."""
    c = fabric.compensation
    law = sample_law(fabric, c.warp, c.fill)
    structure = solve_structure(panels, law, prestress=c.prestress, warp_direction=warp)
    erected = erect(patterns_of(structure), law, 1.0, solver=structure.options)
    assert structure.converged and erected.converged


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, nargs="+", default=[8, 16])
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    args = parser.parse_args()
    fabric = file_fabric(FABRIC)
    for key in args.cases:
        title, make, warp = CASES[key]
        panels = make()
        cells = sum(p.mesh.num_cells for p in panels)
        print(f"\n{title}: {len(panels)} panel(s), {cells} cells")
        warm = ScatterOptions(samples=1)
        fabric_band(panels, fabric, scatter=warm, warp_direction=warp)  # compile the kernels
        walls, cpus = [], []
        for _ in range(3):
            wall, cpu = time.perf_counter(), time.process_time()
            one_case(panels, fabric, warp)
            walls.append(time.perf_counter() - wall)
            cpus.append(time.process_time() - cpu)
        wall1, cpu1 = statistics.median(walls), statistics.median(cpus)
        print(f"  one case (patterns + erection): {wall1:.2f} s wall, {cpu1:.2f} s CPU")
        largest = None
        for n in args.samples:
            runs = [(None, "this process")]
            if args.workers:
                runs.append((args.workers, f"{args.workers} processes"))
            for workers, where in runs:
                wall, cpu = time.perf_counter(), time.process_time()
                band = fabric_band(
                    panels,
                    fabric,
                    scatter=ScatterOptions(samples=n),
                    workers=workers,
                    warp_direction=warp,
                )
                wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
                print(
                    f"  {n:3d} samples + nominal, {where}: {wall:6.2f} s wall = "
                    f"{wall / wall1:5.1f} cases, {cpu:6.2f} s CPU = {cpu / cpu1:5.1f} cases"
                )
                if workers is None:
                    largest = band
        print(f"  band of {largest.options.samples} samples (nominal, ± 2 std, min … max):")
        for name, d in largest.band.to_dict().items():
            print(
                f"    {name:32s} {d['nominal']:12.6g} ± {d['spread']:9.3g}   "
                f"{d['min']:.6g} … {d['max']:.6g}"
            )


if __name__ == "__main__":
    main()
