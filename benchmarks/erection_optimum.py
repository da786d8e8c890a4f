"""Patterns optimised for the erected structure against plain patterning: wall time and
iterations on 1.5k, 10k and 50k triangles.

    python benchmarks/erection_optimum.py [--sizes 28,71,158] [--solver NAME] [--solves 3]
                                          [--compare] [--repeats 1] [--tolerances 0.01,0.1]

Surface: ``vares.examples.hypar(size=10, rise=0.06, n=N)`` (2 N² triangles) with the PES/PVC
type II preset, 2.0/1.5 kN/m, warp along x; default erection (boundary held, tension field) and
optimiser options (``shape_weight`` 0.1, ``shape_bound`` 1.5, at most 8 steps). For each size,
in one process after a warm-up on a small mesh (the compiled kernels loaded as well as their
numpy forms): ``vares.solve``, ``vares.erect`` of its pattern, and
``vares.optimise_for_erection`` of it (which erects the VaReS pattern again, then per step one
LSQR solve and the erection of the trial patterns); the ratio optimise / solve is the figure
asked for (the solve timed as the fastest of ``--solves`` runs). Also printed: the steps, LSQR's
iterations (two solves with the erection tangent each), the Newton iterations of all erections
in the optimisation (the start's and the trials') and the objective ``J`` at the start and at
the end, and the process's CPU time of the solve and of the optimisation (on a machine shared
with other work the CPU time is the steadier figure; it counts PARDISO's threads).

``--tolerances`` runs the optimisation once for each of the optimiser's ``tolerance`` values
(default: its default, 0.01): what a looser stopping rule saves in time and costs in ``J``.

``--compare`` runs, for each size and repeat, the optimiser as it was before the trial erections
were made cheaper and before the compression penalty (:data:`BEFORE`: trials erected to the
full tolerance, their Newton steps not preconditioned by the accepted state's factorisation, the
dof map made for every erection, no penalty on compressed cells, a step promising less than a
tenth of the tolerance ending it) and as it is, one after the other in the same process.
"""

from __future__ import annotations

import argparse
import itertools
import platform
import time
import warnings

import numpy as np

import vares
from vares._jit import sized_for
from vares.analysis import erection_model, erection_optimum, erection_residuals, erection_trials
from vares.solver.linear import available_solvers

#: The settings of the optimiser before (module, name, value): what ``--compare`` runs as
#: "before" beside the current settings.
BEFORE = (
    (erection_trials, "PRIMED_ITERATIONS", 0),
    (erection_optimum, "TRIAL_TOLERANCE", 0.0),
    (erection_residuals, "WRINKLE_WEIGHT", 0.0),
    (erection_model, "REUSE_DOF_MAP", False),
    (erection_optimum, "PROMISED_GAIN", 0.1),
)
CURRENT = tuple((module, name, getattr(module, name)) for module, name, _ in BEFORE)


def settings_of(variant: str) -> None:
    """Set the optimiser's module settings of ``variant`` ("before" or "after")."""
    for module, name, value in BEFORE if variant == "before" else CURRENT:
        setattr(module, name, value)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="28,71,158", help="cells per side of the hypars")
    parser.add_argument("--solver", default=None, choices=available_solvers())
    parser.add_argument("--solves", type=int, default=3, help="solves timed, the fastest counts")
    parser.add_argument("--compare", action="store_true", help="the optimiser before, too")
    parser.add_argument("--repeats", type=int, default=1, help="optimisations per size")
    parser.add_argument(
        "--tolerances", default="0.01", help="the optimiser's tolerance (comma-separated values)"
    )
    args = parser.parse_args()
    solver = args.solver or available_solvers()[0]
    warnings.simplefilter("ignore")
    fabric = vares.materials.fabric("pes-pvc-type-2").material()
    settings = {"prestress": (2.0, 1.5), "warp_direction": (1.0, 0.0, 0.0)}
    for compiled in (True, False):  # warm-up: the compiled kernels loaded, and their numpy forms
        with sized_for(compiled):
            small = vares.solve(vares.examples.hypar(n=6), fabric, linear_solver=solver, **settings)
            vares.optimise_for_erection(small)
    print(f"linear solver {solver}; {platform.processor() or platform.machine()}")
    print(
        f"{'triangles':>9} {'variant':>7} {'tol':>5} {'solve s':>7} {'cpu':>6} {'erect s':>7} "
        f"{'optimise s':>10} {'cpu':>6} {'ratio':>5} {'cpu':>5} {'steps':>5} {'LSQR':>4} "
        f"{'Newton':>6} {'J':>13} {'warp mean':>11} {'RMS warp':>11} {'RMS fill':>11} "
        f"{'wrinkled %':>10} {'max dev mm':>11}"
    )
    variants = ("before", "after") if args.compare else ("after",)
    tolerances = [float(t) for t in args.tolerances.split(",")]
    for n in (int(s) for s in args.sizes.split(",")):
        mesh = vares.examples.hypar(size=10.0, rise=0.06, n=n)
        solve_time = solve_cpu = np.inf
        for _ in range(args.solves):  # the best of a few: one short solve is the noisiest figure
            start, cpu = time.perf_counter(), time.process_time()
            pattern = vares.solve(mesh, fabric, linear_solver=solver, **settings)
            solve_time = min(solve_time, time.perf_counter() - start)
            solve_cpu = min(solve_cpu, time.process_time() - cpu)
        start = time.perf_counter()
        vares.erect(pattern)
        erect_time = time.perf_counter() - start
        for _ in range(args.repeats):
            for tolerance, variant in itertools.product(tolerances, variants):
                settings_of(variant)
                start, cpu = time.perf_counter(), time.process_time()
                optimum = vares.optimise_for_erection(pattern, tolerance=tolerance)
                wall, cpu = time.perf_counter() - start, time.process_time() - cpu
                times = (solve_time, solve_cpu, erect_time, wall, cpu)
                row(mesh, f"{variant:>7} {tolerance:>5g}", optimum, times)
        settings_of("after")
    print(
        f"reproduce: python benchmarks/erection_optimum.py --sizes {args.sizes} --solver {solver} "
        f"--solves {args.solves} --tolerances {args.tolerances}"
        + (f" --compare --repeats {args.repeats}" if args.compare else "")
    )


def row(mesh, variant: str, optimum, times) -> None:
    """One line of the table: times, counts and the erected figures before → after."""
    solve_time, solve_cpu, erect_time, wall, cpu = times
    before = optimum.start.statistics()["stress"]
    after = optimum.erected.statistics()["stress"]
    lsqr = sum(r.lsqr_iterations for r in optimum.history)
    # every erection's Newton iterations: the start's, the trials' and the optimum's tightening
    newton = optimum.start.iterations + optimum.newton_iterations
    objective = f"{optimum.history[0].objective:.3f}→{optimum.history[-1].objective:.4f}"

    def pair(key, yarn, a=before, b=after):
        return f"{a[yarn][key]:.3f}→{b[yarn][key]:.3f}"

    wrinkled = [
        100 * r.statistics()["wrinkled_area_fraction"] for r in (optimum.start, optimum.erected)
    ]
    deviation = [1e3 * r.deviation()["max"] for r in (optimum.start, optimum.erected)]
    print(
        f"{mesh.num_cells:>9} {variant} {solve_time:>7.2f} {solve_cpu:>6.2f} {erect_time:>7.2f} "
        f"{wall:>10.2f} {cpu:>6.2f} {wall / solve_time:>5.1f} {cpu / solve_cpu:>5.1f} "
        f"{optimum.iterations:>5} {lsqr:>4} {newton:>6} {objective:>13} "
        f"{pair('mean', 'warp'):>11} {pair('rms_deviation', 'warp'):>11} "
        f"{pair('rms_deviation', 'fill'):>11} {wrinkled[0]:>4.1f}→{wrinkled[1]:<4.1f} "
        f"{deviation[0]:.1f}→{deviation[1]:.1f}",
        flush=True,
    )


if __name__ == "__main__":
    main()
