"""The seed's 160° cylinder benchmark: iterations per pseudo-time step, and damping for comparison.

    python benchmarks/cylinder160.py

Neo-Hooke (E = 1000, nu = 0.3), projection on the x-y plane as initial guess, relative residual
tolerance 1e-10, on the triangle and the quad mesh of ``vares example cylinder160``.
"""

from __future__ import annotations

import time

import numpy as np

import vares
from vares.geometry.examples import cylinder160, cylinder_arc_length


def main() -> None:
    material = vares.materials.NeoHooke(E=1000.0, nu=0.3)
    print(
        f"{'mesh':<9} {'strategy':<12} {'steps (τ: iterations, x = failed and cut back)':<62}"
        f"{'total':>6} {'width err':>10} {'area err':>10} {'energy':>10} {'time':>7}"
    )
    for cell_type in ("triangle", "quad"):
        mesh = cylinder160(cell_type=cell_type)
        for strategy, steps in (
            ("pseudo-time", 3),
            ("pseudo-time", 6),
            ("damping", 1),
            ("auto", 1),
        ):
            start = time.perf_counter()
            result = vares.solve(mesh, material, strategy=strategy, steps=steps, plane="xy")
            elapsed = time.perf_counter() - start
            x = result.material_coordinates
            width = np.linalg.norm(x[32] - x[0])
            path = " ".join(
                f"{s.tau:.3g}:{s.iterations}{'' if s.converged else 'x'}" for s in result.steps
            )
            label = strategy if strategy != "pseudo-time" else f"{strategy} {steps}"
            print(
                f"{cell_type:<9} {label:<12} {path:<62}{result.iterations:>6} "
                f"{width / cylinder_arc_length() - 1:>10.1e} "
                f"{result.pattern_area / mesh.area - 1:>10.1e} {result.energy:>10.1e} "
                f"{elapsed:>6.2f}s"
            )
    print("reproduce: python benchmarks/cylinder160.py")


if __name__ == "__main__":
    main()
