"""The robustness suite: every surface patterned with the default strategy, two materials.

    python benchmarks/robustness.py

Prints, per surface and material, whether it converged, the initial guess and strategy used,
the Newton iterations and the wall time (the first solve of the process also loads compiled
code, so a warm-up solve comes first).
"""

from __future__ import annotations

import time

import vares
from vares import examples

SUITE = {
    "hypar z = 0.06 xy, 10 m": lambda: examples.hypar(n=40),
    "spherical cap 60°": lambda: examples.spherical_cap(half_angle=60.0, n_rings=20),
    "hemisphere": lambda: examples.spherical_cap(half_angle=90.0, n_rings=20),
    "deep cap 120°": lambda: examples.spherical_cap(half_angle=120.0, n_rings=20),
    "cap R 12 m over 10 m square": lambda: examples.cap_over_square(n=40),
    "cone segment 120°": lambda: examples.cone_segment(),
    "catenoid section": lambda: examples.catenoid_section(),
    "bumpy random surface": lambda: examples.bumpy(n=40),
    "graded mesh, sizes 1:100": lambda: examples.graded_hypar(n=40),
    "slivers, aspect 1:100": lambda: examples.graded_hypar(n=40, grading=1.0, sliver=0.01),
    "cylinder 220°": lambda: examples.cylinder160(angle=220.0, n_around=44),
    "rib30 (quads)": lambda: examples.rib30(cell_type="quad"),
}


def main() -> None:
    materials = {
        "Neo-Hooke": vares.materials.NeoHooke(1000.0, 0.3),
        "orthotropic": vares.materials.OrthotropicStVenantKirchhoff(800.0, 640.0, 40.0, 0.4),
    }
    vares.solve(examples.hypar(n=4), materials["Neo-Hooke"])  # warm-up
    print(
        f"{'surface':<30} {'cells':>6} {'material':<12} {'ok':<3} {'start':<10} "
        f"{'iterations':>10} {'time s':>7}  strategy"
    )
    for name, make in SUITE.items():
        mesh = make()
        for label, material in materials.items():
            start = time.perf_counter()
            result = vares.solve(mesh, material)
            elapsed = time.perf_counter() - start
            print(
                f"{name:<30} {mesh.num_cells:>6} {label:<12} "
                f"{'yes' if result.converged else 'NO':<3} {result.initial_guess:<10} "
                f"{result.iterations:>10} {elapsed:>7.2f}  {' → '.join(result.strategy)}"
            )
    print("reproduce: python benchmarks/robustness.py")


if __name__ == "__main__":
    main()
