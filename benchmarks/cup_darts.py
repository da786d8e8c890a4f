"""Darts on a mould nobody here made: the square cup of Kratos Multiphysics' inverse-forming tests.

The file is not shipped (Kratos is BSD-4 licensed): take it from the Kratos repository,
``applications/StructuralMechanicsApplication/tests/inverseforming_test/cup.mdpa`` (commit
4d92078), and pass its path. It is a 62 mm square punch face at z = 25 mm with rounded corners,
its walls, and a flange out to ±75 mm at z = 0, in mm (689 nodes, 1,226 membrane triangles).
Printed: the kinematic drape from the punch face's centre (warp along x, spacing 2 mm); the
README's non-crimp fabric's pattern and the share of its area beyond the locking angle that is
negatively curved; the automatic darts (every solve with darts: the rule that placed them, its
largest shear; the darts kept); and four given darts along the diagonals, from the flange's
corners towards the centre to ``|x| = |y| = t`` for every ``--tips t`` (the sections of the
surface by the diagonal planes), each set opened on the pattern. ``--square-cup CELLS:SEED``
drapes ``vares.geometry.hard_surfaces.square_cup(CELLS, seed=SEED)`` instead (a box of the same
size, made here, irregular triangles), one after the other, for every value given.

    python benchmarks/cup_darts.py cup.mdpa --tips 40 34 28 22 15 8
    python benchmarks/cup_darts.py --square-cup 40:1 50:1 60:1 60:2 60:3 80:1 --tips 28
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from vares.analysis.darts import over_locking_curvature, solve_with_darts
from vares.analysis.drape import drape_ply
from vares.geometry.hard_surfaces import square_cup
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
    parser.add_argument(
        "mould", type=Path, nargs="?", help="the cup's .mdpa (or any format vares reads)"
    )
    parser.add_argument("--tips", type=float, nargs="+", default=[40.0, 34.0, 28.0, 22.0])
    parser.add_argument("--square-cup", nargs="+", metavar="CELLS:SEED", help="made boxes")
    args = parser.parse_args()
    if args.mould is None and not args.square_cup:
        parser.error("give the cup's file or --square-cup")
    moulds = [] if args.mould is None else [(args.mould.name, lambda: read_mesh(args.mould))]
    for value in args.square_cup or []:
        cells, seed = (int(v) for v in value.split(":"))
        moulds.append(
            (f"square_cup({cells}, seed={seed})", lambda c=cells, s=seed: square_cup(c, seed=s))
        )
    for name, make in moulds:
        drape_mould(name, make(), args.tips)


def drape_mould(name: str, mesh, tips: list[float]) -> None:
    """Everything printed for one mould (module docs)."""
    print(f"{name}: {mesh.num_points} nodes, {mesh.num_cells} cells, area {mesh.area:.1f} mm²")
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
    for r in summary["rounds"]:
        print(
            f"  darts by the {r['rule']}, tip {r['tip_angle']:.1f}°: "
            f"{len(r['lengths'])} of {min(r['lengths']):.1f}–{max(r['lengths']):.1f} mm, "
            f"largest shear {r['max_shear']:.2f}° ({r['iterations']} it, converged "
            f"{r['converged']})"
        )
    after = summary["max_shear_after"]
    mouths = ", ".join(f"{v:.1f}" for v in summary["mouth_openings"])
    print(
        f"automatic darts: {summary['darts']} kept {summary['kept']}, by the "
        f"{summary['chosen_rule']}, largest shear after "
        f"{'-' if after is None else f'{after:.2f}°'}; mouths {mouths}; "
        f"{time.perf_counter() - clock:.1f} s"
    )
    for tip in tips:
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
