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
    for name, make in examples.robustness_suite(fine=True).items():
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
