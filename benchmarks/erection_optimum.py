"""Patterns optimised for the erected structure against plain patterning: wall time and
iterations on 1.5k, 10k and 50k triangles.

    python benchmarks/erection_optimum.py [--sizes 28,71,158] [--solver NAME] [--solves 3]

Surface: ``vares.examples.hypar(size=10, rise=0.06, n=N)`` (2 N² triangles) with the PES/PVC
type II preset, 2.0/1.5 kN/m, warp along x; default erection (boundary held, tension field) and
optimiser options (``shape_weight`` 0.1, ``shape_bound`` 1.5, at most 8 steps). For each size,
in one process after a warm-up on a small mesh: ``vares.solve``, ``vares.erect`` of its pattern,
and ``vares.optimise_for_erection`` of it (which erects the VaReS pattern again, then per step
one LSQR solve and the erection of the trial patterns); the ratio optimise / solve is the figure
asked for (the solve timed as the fastest of ``--solves`` runs). Also printed: the steps,
LSQR's iterations (two solves with the erection tangent each), the Newton iterations of all
erections in the optimisation (the start's and the trials') and the objective ``J`` at the
start and at the end.
"""

from __future__ import annotations

import argparse
import platform
import time
import warnings

import numpy as np

import vares
from vares.solver.linear import available_solvers


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="28,71,158", help="cells per side of the hypars")
    parser.add_argument("--solver", default=None, choices=available_solvers())
    parser.add_argument("--solves", type=int, default=3, help="solves timed, the fastest counts")
    args = parser.parse_args()
    solver = args.solver or available_solvers()[0]
    warnings.simplefilter("ignore")
    fabric = vares.materials.fabric("pes-pvc-type-2").material()
    settings = {"prestress": (2.0, 1.5), "warp_direction": (1.0, 0.0, 0.0)}
    small = vares.solve(vares.examples.hypar(n=6), fabric, linear_solver=solver, **settings)
    vares.optimise_for_erection(small)  # warm-up: compiled code loaded
    print(f"linear solver {solver}; {platform.processor() or platform.machine()}")
    print(
        f"{'triangles':>9} {'solve s':>8} {'erect s':>8} {'optimise s':>10} {'ratio':>6} "
        f"{'steps':>5} {'LSQR':>5} {'Newton':>6} {'J':>13} {'warp mean':>13} {'RMS warp':>13} "
        f"{'RMS fill':>13} {'max dev mm':>11}"
    )
    for n in (int(s) for s in args.sizes.split(",")):
        mesh = vares.examples.hypar(size=10.0, rise=0.06, n=n)
        solve_time = np.inf
        for _ in range(args.solves):  # the best of a few: one short solve is the noisiest figure
            start = time.perf_counter()
            pattern = vares.solve(mesh, fabric, linear_solver=solver, **settings)
            solve_time = min(solve_time, time.perf_counter() - start)
        start = time.perf_counter()
        vares.erect(pattern)
        erect_time = time.perf_counter() - start
        start = time.perf_counter()
        optimum = vares.optimise_for_erection(pattern)
        optimise_time = time.perf_counter() - start
        before = optimum.start.statistics()["stress"]
        after = optimum.erected.statistics()["stress"]
        lsqr = sum(r.lsqr_iterations for r in optimum.history)
        newton = optimum.start.iterations + sum(
            getattr(r, "erection_iterations", 0) for r in optimum.history
        )
        objective = f"{optimum.history[0].objective:.3f}→{optimum.history[-1].objective:.4f}"

        def pair(key, yarn, a=before, b=after):
            return f"{a[yarn][key]:.3f}→{b[yarn][key]:.3f}"

        deviation = (optimum.start.deviation()["max"], optimum.erected.deviation()["max"])
        print(
            f"{mesh.num_cells:>9} {solve_time:>8.2f} {erect_time:>8.2f} {optimise_time:>10.2f} "
            f"{optimise_time / solve_time:>6.1f} {optimum.iterations:>5} {lsqr:>5} {newton:>6} "
            f"{objective:>13} {pair('mean', 'warp'):>13} {pair('rms_deviation', 'warp'):>13} "
            f"{pair('rms_deviation', 'fill'):>13} "
            f"{np.round(1e3 * deviation[0], 1)}→{np.round(1e3 * deviation[1], 1)}"
        )
    print(
        f"reproduce: python benchmarks/erection_optimum.py --sizes {args.sizes} --solver {solver} "
        f"--solves {args.solves}"
    )


if __name__ == "__main__":
    main()
