"""The robustness suite and the real-world-like set: every surface patterned with the default
strategy, two materials.

    python benchmarks/robustness.py [--large]

Prints, per surface and material, whether it converged, the initial guess and strategy used,
the Newton iterations and the wall time (the first solve of the process also loads compiled
code, so a warm-up solve comes first). The real-world-like set (a scan with rough triangles and
measurement noise, a CAD roof in millimetres, with ``--large`` a 300k-triangle scan) is given in
metres here; ``benchmarks/backends.py`` reads it from files as the command does.
"""

from __future__ import annotations

import argparse
import time
import warnings

import vares
from vares import examples


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--large", action="store_true", help="add the 300k-triangle scan")
    args = parser.parse_args()
    materials = {
        "Neo-Hooke": vares.materials.NeoHooke(1000.0, 0.3),
        "orthotropic": vares.materials.OrthotropicStVenantKirchhoff(800.0, 640.0, 40.0, 0.4),
    }
    vares.solve(examples.hypar(n=4), materials["Neo-Hooke"])  # warm-up
    print(
        f"{'surface':<30} {'cells':>6} {'material':<12} {'ok':<3} {'start':<10} "
        f"{'iterations':>10} {'time s':>7}  strategy"
    )
    surfaces = dict(examples.robustness_suite(fine=True))
    for name, (make, units) in examples.real_world_suite(large=args.large).items():
        scale = vares.units.unit_factor(units, "m")
        surfaces[name] = lambda make=make, scale=scale: vares.SurfaceMesh(
            make().points * scale, make().cells
        )
    for name, make in surfaces.items():
        mesh = make()
        for label, material in materials.items():
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # the start's warnings: the table says it
                result = vares.solve(mesh, material)
            elapsed = time.perf_counter() - start
            print(
                f"{name:<30} {mesh.num_cells:>6} {label:<12} "
                f"{'yes' if result.converged else 'NO':<3} {result.initial_guess:<10} "
                f"{result.iterations:>10} {elapsed:>7.2f}  {' → '.join(result.strategy)}"
            )
    print("reproduce: python benchmarks/robustness.py" + (" --large" if args.large else ""))


if __name__ == "__main__":
    main()
