"""Erection against patterning on the 100k-triangle hypar: wall time and Newton iterations.

    python benchmarks/erection.py [--n 224] [--hard-n 56] [--solver NAME] [--repeat 2]

Surface: ``vares.examples.hypar(n=224)`` (10 m × 10 m, z = 0.06 x y, 100,352 triangles) with the
PES/PVC type II preset, 2.0/1.5 kN/m warp/fill prestress, warp along (1, 1, 0). A hard case on a
smaller hypar (``--hard-n``): Neo-Hooke (E = 1000, ν = 0.3) with an isotropic prestress of 2,
whose pattern leaves 40 % of the design shape in compression, so that a quarter of the erected
membrane wrinkles. For each: ``vares.solve`` with the default options, then ``vares.erect`` of
its pattern with the default options (boundary held, tension-field energy). Each is timed
``--repeat`` times in this process after a warm-up on a small mesh (compiled code loaded); the
best time is printed. The linear solver is the fastest installed unless ``--solver`` names one.
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
    parser.add_argument("--hard-n", type=int, default=56, help="… of the hard case's")
    parser.add_argument("--solver", default=None, choices=available_solvers())
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    solver = args.solver or available_solvers()[0]
    fabric = vares.materials.fabric("pes-pvc-type-2").material()
    jobs = {
        "PES/PVC II, 2/1.5, warp (1,1,0)": (
            fabric,
            {"prestress": (2.0, 1.5), "warp_direction": (1.0, 1.0, 0.0)},
            args.n,
        ),
        "Neo-Hooke, prestress 2 (hard)": (
            vares.materials.NeoHooke(1000.0, 0.3),
            {"prestress": 2.0},
            args.hard_n,
        ),
    }
    small = vares.examples.hypar(n=6)
    for material, settings, _ in jobs.values():  # warm-up: load compiled code
        vares.erect(vares.solve(small, material, linear_solver=solver, **settings))
    print(f"linear solver {solver}; {platform.processor() or platform.machine()}")
    print(
        f"{'job':<32} {'triangles':>9} {'pattern s':>9} {'its':>4} {'erect s':>8} {'its':>4} "
        f"{'ratio':>6} {'wrinkled':>8} {'deviation max':>13} {'warp mean':>9}"
    )
    for label, (material, settings, n) in jobs.items():
        mesh = vares.examples.hypar(n=n)
        pattern_time, pattern = best(
            args.repeat,
            lambda g=mesh, m=material, s=settings: vares.solve(g, m, linear_solver=solver, **s),
        )
        erect_time, erected = best(args.repeat, lambda p=pattern: vares.erect(p))
        assert pattern.converged and erected.converged
        statistics = erected.statistics()
        print(
            f"{label:<32} {mesh.num_cells:>9} {pattern_time:>9.2f} {pattern.iterations:>4} "
            f"{erect_time:>8.2f} {erected.iterations:>4} {erect_time / pattern_time:>6.2f} "
            f"{statistics['wrinkled_area_fraction']:>8.3f} {erected.deviation()['max']:>13.4g} "
            f"{statistics['stress']['warp']['mean']:>9.4g}"
        )
    print(
        f"reproduce: python benchmarks/erection.py --n {args.n} --hard-n {args.hard_n} "
        f"--solver {solver}"
    )


if __name__ == "__main__":
    main()
