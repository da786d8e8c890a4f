"""Splices placed through a ply's seed (``vares.analysis.splice_lines.place_splices``, ``vares
drape --splices auto``): per mould, the whole ply's largest shear, every set of lines tried (its
angles from the warp and the pieces' largest shear), the set taken and the seconds it all took.

Moulds (the README's non-crimp fabric, ``NonCrimpFabric([-250, 250], [-250, 250], [0.5])``,
locking angle ``--locking``, default 50°): ``double-dome`` (the shipped double dome from the
saddle's centre, warp along x), ``double-dome-45`` (the same, warp along (1, 1, 0)),
``hemisphere`` (``irregular_cap(100, 90, 30, 0.3, 1)`` from the pole, warp along x),
``square-cup-40`` and ``square-cup-60`` (``square_cup(40 or 60, seed=1)`` from the middle of the
punch face, warp along x).

    python benchmarks/placed_splices.py
    python benchmarks/placed_splices.py --moulds double-dome hemisphere --locking 45
"""

from __future__ import annotations

import argparse
import platform
import time
import warnings

import numpy as np

from vares.analysis.splice_lines import place_splices, placed_text
from vares.geometry.double_dome import double_dome, double_dome_height
from vares.geometry.examples import irregular_cap
from vares.geometry.hard_surfaces import square_cup
from vares.materials import NonCrimpFabric

SADDLE = (0.0, 0.0, float(double_dome_height(np.zeros(1), np.zeros(1))[0]))
MOULDS = {
    "double-dome": (double_dome, SADDLE, (1.0, 0.0, 0.0)),
    "double-dome-45": (double_dome, SADDLE, (1.0, 1.0, 0.0)),
    "hemisphere": (lambda: irregular_cap(100.0, 90.0, 30, 0.3, 1), (0.0, 0.0, 100.0), (1, 0, 0)),
    "square-cup-40": (lambda: square_cup(40, seed=1), (0.0, 0.0, 25.0), (1.0, 0.0, 0.0)),
    "square-cup-60": (lambda: square_cup(60, seed=1), (0.0, 0.0, 25.0), (1.0, 0.0, 0.0)),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--moulds", nargs="+", choices=list(MOULDS), default=list(MOULDS))
    parser.add_argument("--locking", type=float, default=50.0, help="locking angle, degrees")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    fabric = NonCrimpFabric([-250.0, 250.0], [-250.0, 250.0], [0.5])
    print(f"{platform.processor() or platform.machine()}; locking angle {args.locking:g}°")
    for name in args.moulds:
        make, seed, warp = MOULDS[name]
        mesh = make()
        start = time.perf_counter()
        placed = place_splices(
            mesh, fabric, locking_angle=args.locking, seed=seed, warp_direction=warp
        )
        seconds = time.perf_counter() - start
        whole = float(np.nanmax(np.abs(placed.before.fields["shear_angle"])))
        how = placed_text(placed.summary())
        print(
            f"{name} ({mesh.num_cells} cells): whole ply {whole:.2f}°; {how}; {seconds:.1f} s",
            flush=True,
        )
    print(
        f"reproduce: python benchmarks/placed_splices.py --moulds {' '.join(args.moulds)} "
        f"--locking {args.locking:g}"
    )


if __name__ == "__main__":
    main()
