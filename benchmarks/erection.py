"""Erection against patterning on the 100k-triangle hypar: wall time and Newton iterations.

    python benchmarks/erection.py [--n 224] [--solver NAME] [--repeat 2]

Surface: ``vares.examples.hypar(n=224)`` (10 m × 10 m, z = 0.06 x y, 100,352 triangles). Two
jobs: Neo-Hooke (E = 1000, ν = 0.3) with an isotropic prestress of 2, and the PES/PVC type II
preset with 2.0/1.5 kN/m warp/fill and the warp along (1, 1, 0). For each: ``vares.solve`` with
the default options, then ``vares.erect`` of its pattern with the default options (boundary
held, tension-field energy). Each is timed ``--repeat`` times in this process after a warm-up on
a small mesh (compiled code loaded); the best time is printed. The linear solver is the fastest
installed unless ``--solver`` names one.
"""

from __future__ import annotations

import argparse
import platform
import time

import vares
from vares.solver.linear import available_solvers


def best(repeat: int, run):
    times, value = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        value = run()
        times.append(time.perf_counter() - start)
    return min(times), value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=224, help="cells per side of the hypar")
    parser.add_argument("--solver", default=None, choices=available_solvers())
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    solver = args.solver or available_solvers()[0]
    mesh = vares.examples.hypar(n=args.n)
    fabric = vares.materials.fabric("pes-pvc-type-2").material()
    jobs = {
        "Neo-Hooke, prestress 2": (vares.materials.NeoHooke(1000.0, 0.3), {"prestress": 2.0}),
        "PES/PVC II, 2/1.5, warp (1,1,0)": (
            fabric,
            {"prestress": (2.0, 1.5), "warp_direction": (1.0, 1.0, 0.0)},
        ),
    }
    small = vares.examples.hypar(n=6)
    for material, settings in jobs.values():  # warm-up: load compiled code
        vares.erect(vares.solve(small, material, linear_solver=solver, **settings))
    print(f"{mesh}; linear solver {solver}; {platform.processor() or platform.machine()}")
    print(
        f"{'job':<32} {'pattern s':>9} {'its':>4} {'erect s':>8} {'its':>4} {'ratio':>6} "
        f"{'deviation max':>14} {'warp mean':>9}"
    )
    for label, (material, settings) in jobs.items():
        pattern_time, pattern = best(
            args.repeat,
            lambda m=material, s=settings: vares.solve(mesh, m, linear_solver=solver, **s),
        )
        erect_time, erected = best(args.repeat, lambda p=pattern: vares.erect(p))
        assert pattern.converged and erected.converged
        warp = erected.statistics()["stress"]["warp"]["mean"]
        print(
            f"{label:<32} {pattern_time:>9.2f} {pattern.iterations:>4} {erect_time:>8.2f} "
            f"{erected.iterations:>4} {erect_time / pattern_time:>6.2f} "
            f"{erected.deviation()['max']:>14.4g} {warp:>9.4g}"
        )
    print(f"reproduce: python benchmarks/erection.py --n {args.n} --solver {solver}")


if __name__ == "__main__":
    main()
