"""Darts on a mould nobody here made: the square cup of Kratos Multiphysics' inverse-forming tests.

The file is not shipped (Kratos is BSD-4 licensed): take it from the Kratos repository,
``applications/StructuralMechanicsApplication/tests/inverseforming_test/cup.mdpa`` (commit
4d92078), and pass its path. It is a 62 mm square punch face at z = 25 mm with rounded corners,
its walls, and a flange out to ±75 mm at z = 0, in mm (689 nodes, 1,226 membrane triangles).
Printed: the kinematic drape from the punch face's centre (warp along x, spacing 2 mm); the
README's non-crimp fabric's pattern and the share of its area beyond the locking angle that is
negatively curved; the automatic darts; and four given darts along the diagonals, from the
flange's corners towards the centre to ``|x| = |y| = t`` for every ``--tips t`` (the sections
of the surface by the diagonal planes), each set opened on the pattern.

    python benchmarks/cup_darts.py cup.mdpa --tips 40 34 28 22 15 8
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from vares.analysis.darts import over_locking_curvature, solve_with_darts
from vares.analysis.drape import drape_ply
from vares.geometry.surface_lines import plane_sections
from vares.io.meshes import read_mesh
from vares.materials import NonCrimpFabric

LOCKING = 50.0
WARP = (1.0, 0.0, 0.0)


def diagonal(mesh, sx: float, sy: float, tip: float) -> np.ndarray:
    """The dart along the diagonal of the quadrant (sx, sy): the section of the surface by the
    vertical plane through the axis and the corner, from the flange's corner to where
    ``|x| = |y| = tip`` (its points on the mesh's edges)."""
    normal = np.array([sy, -sx, 0.0]) / np.sqrt(2.0)
    (section,) = plane_sections(mesh, normal, 0.0)
    points = section.points
    along = points[:, 0] * sx  # = |x| on this quadrant's half, negative on the other
    half = points[along >= tip]
    return half[np.argsort(-(half[:, 0] * sx))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("mould", type=Path, help="the cup's .mdpa (or any format vares reads)")
    parser.add_argument("--tips", type=float, nargs="+", default=[40.0, 34.0, 28.0, 22.0])
    args = parser.parse_args()
    mesh = read_mesh(args.mould)
    print(
        f"{args.mould.name}: {mesh.num_points} nodes, {mesh.num_cells} cells, "
        f"area {mesh.area:.1f} mm²"
    )
    clock = time.perf_counter()
    net = drape_ply(mesh, seed=(0.0, 0.0, 25.0), warp=WARP, spacing=2.0, locking_angle=LOCKING)
    check = net.producibility
    print(
        f"kinematic net: largest shear {check.max_shear:.2f}°, "
        f"{100 * check.fractions['limit']:.2f} % of the area at or beyond {LOCKING:g}°; "
        f"{time.perf_counter() - clock:.1f} s"
    )
    ncf = NonCrimpFabric([-250.0, 250.0], [-250.0, 250.0], [0.5])
    clock = time.perf_counter()
    auto = solve_with_darts(mesh, ncf, locking_angle=LOCKING, darts="auto", warp_direction=WARP)
    shares = over_locking_curvature(auto.before, LOCKING)
    summary = auto.summary()
    print(
        f"pattern: largest shear {auto.max_shear_before:.2f}° ({auto.before.iterations} it, "
        f"converged {auto.before.converged}); beyond {LOCKING:g}°: "
        f"{100 * shares['negative']:.0f} % negatively, {100 * shares['positive']:.0f} % "
        f"positively curved"
    )
    print(
        f"automatic darts: {summary['darts']} placed, largest shear after "
        f"{summary['max_shear_after']}, kept {summary['kept']}; "
        f"{time.perf_counter() - clock:.1f} s"
    )
    for tip in args.tips:
        lines = [diagonal(mesh, sx, sy, tip) for sx in (1.0, -1.0) for sy in (1.0, -1.0)]
        clock = time.perf_counter()
        darted = solve_with_darts(
            mesh, ncf, locking_angle=LOCKING, polylines=lines, warp_direction=WARP
        )
        s = darted.summary()
        lengths = ", ".join(f"{v:.1f}" for v in s["dart_lengths"])
        mouths = ", ".join(f"{v:.1f}" for v in s["mouth_openings"])
        print(
            f"four diagonal darts to |x| = |y| = {tip:g}: largest shear "
            f"{s['max_shear_after']:.2f}° ({darted.after.iterations} it, converged "
            f"{darted.after.converged}, kept {s['kept']}); lengths {lengths}; mouths "
            f"{mouths}; {time.perf_counter() - clock:.1f} s"
        )


if __name__ == "__main__":
    main()
