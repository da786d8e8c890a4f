"""What the band of a fabric's scatter costs against one solve, and what it gives, on the
shipped fabric file (examples/biaxial/pes-batch-42.toml).

    python benchmarks/fabric_band.py [--samples 8 16] [--workers 2] [--cases sail strips]

For each case (the four-point sail, warp (1, 1, 0); the six strips of the hyperbolic
paraboloid, warp (1, 0, 0), seams matched) it times, in one process and one after the other:
one nominal case (the patterns, and their erection), then ``fabric_band`` with each number of
samples in this process and, with ``--workers``, on that many local processes. The first
nominal case is run once before, so the kernels are compiled. Prints the times, their ratio to
one nominal case and the band (± 2 std) of every figure of the largest run in this process.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from vares.analysis.scatter import ScatterOptions
from vares.app.fabric_band import fabric_band
from vares.geometry.examples import EXAMPLES, STRUCTURE_EXAMPLES
from vares.materials.presets import file_fabric
from vares.structures.panels import Panel, split_panels

FABRIC = Path(__file__).parent.parent / "examples" / "biaxial" / "pes-batch-42.toml"


def strips() -> list[Panel]:
    mesh, ids = STRUCTURE_EXAMPLES["hypar-strips"]()
    return split_panels(mesh, ids, {int(i): f"strip-{int(i) + 1}" for i in set(ids)})


CASES = {
    "sail": ("four-point sail", lambda: [Panel("sail", EXAMPLES["sail"]())], (1.0, 1.0, 0.0)),
    "strips": ("hypar, six strips", strips, (1.0, 0.0, 0.0)),
}


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
        started = time.perf_counter()
        one = fabric_band(panels, fabric, scatter=warm, warp_direction=warp)
        nominal = one.seconds["nominal"]
        print(f"  one case (patterns + erection): {nominal:.2f} s")
        largest = None
        for n in args.samples:
            runs = [(None, "this process")]
            if args.workers:
                runs.append((args.workers, f"{args.workers} processes"))
            for workers, where in runs:
                started = time.perf_counter()
                band = fabric_band(
                    panels,
                    fabric,
                    scatter=ScatterOptions(samples=n),
                    workers=workers,
                    warp_direction=warp,
                )
                total = time.perf_counter() - started
                print(
                    f"  {n:3d} samples, {where}: {total:6.2f} s in all, samples "
                    f"{band.seconds['samples']:6.2f} s = {band.seconds['samples'] / nominal:5.1f}"
                    " nominal cases"
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
