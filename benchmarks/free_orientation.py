"""Free orientation (``orientation="free"``) against the held one, on anisotropic fabrics.

For each case: Newton iterations of the held solve and of the free one, the free solve's
strategy path, energies and wall time. The first case is the orthotropic hypar of
``tests/test_options.py`` (4 m, G12 = 40) with the options of that test: let free, it took
1,065 iterations (globalised Newton, then pseudo-time, then damped pseudo-time) before the
line search's steps turned the pattern rigidly.

    python benchmarks/free_orientation.py            # every case
    python benchmarks/free_orientation.py --quick    # the first two

The 1,065 iterations, from the code before the rigid turns (commit 6c6d443's parent):

    git archive 6c6d443~1 | tar -x -C /tmp/before
    PYTHONPATH=/tmp/before/src python benchmarks/free_orientation.py --quick
"""

from __future__ import annotations

import sys
import time

import vares
from vares.geometry.examples import hypar
from vares.materials import NonCrimpFabric, OrthotropicStVenantKirchhoff

ORTHO = OrthotropicStVenantKirchhoff(E1=800.0, E2=640.0, G12=40.0, nu12=0.4)
NCF = NonCrimpFabric.from_moduli(1000.0, 1000.0, 5.0)
#: the options of tests/test_options.py but the strategy and the damping (defaults)
OPTIONS_TEST = dict(
    warp_angle=15.0,
    fill_angle=105.0,
    steps=4,
    initial_guess="projection",
    plane="xy",
    tolerance=1e-9,
    max_iterations=40,
    linear_solver="scipy-superlu",
)

CASES = [
    (
        "orthotropic hypar 4 m, options test",
        hypar(size=4.0, rise=0.15, n=8),
        ORTHO,
        0.8,
        OPTIONS_TEST,
    ),
    (
        "non-crimp fabric, flat hypar 10 m",
        hypar(size=10.0, rise=0.06, n=24),
        NCF,
        1.0,
        dict(warp_angle=20.0),
    ),
    (
        "orthotropic hypar 4 m, rise 0.5, n 16",
        hypar(size=4.0, rise=0.5, n=16),
        ORTHO,
        1.0,
        dict(warp_angle=0.0),
    ),
    (
        "orthotropic hypar 4 m, rise 0.25, n 32",
        hypar(size=4.0, rise=0.25, n=32),
        ORTHO,
        1.0,
        dict(warp_angle=0.0),
    ),
    (
        "orthotropic hypar 4 m, rise 0.25, n 8",
        hypar(size=4.0, rise=0.25, n=8),
        ORTHO,
        1.0,
        dict(warp_angle=30.0),
    ),
    (
        "orthotropic quads 4 m, rise 0.5, n 16",
        hypar(size=4.0, rise=0.5, n=16, cell_type="quad"),
        ORTHO,
        1.0,
        dict(warp_angle=30.0),
    ),
]


def main(quick: bool = False) -> None:
    print(f"vares {vares.__version__}")
    header = f"{'case':40s} {'held':>5s} {'free':>5s}  {'E held':>12s} {'E free':>16s}"
    print(f"{header} {'s free':>7s}  path")
    for name, mesh, law, thickness, options in CASES[: 2 if quick else None]:
        held = vares.solve(mesh, law, thickness, **options)
        started = time.perf_counter()
        free = vares.solve(mesh, law, thickness, orientation="free", **options)
        elapsed = time.perf_counter() - started
        status = "" if free.converged else f"  NOT CONVERGED: {free.reason}"
        print(
            f"{name:40s} {held.iterations:5d} {free.iterations:5d}  {held.energy:12.8g} "
            f"{free.energy:16.12g} {elapsed:7.2f}  {' → '.join(free.strategy)}{status}",
            flush=True,
        )


if __name__ == "__main__":
    main("--quick" in sys.argv)
