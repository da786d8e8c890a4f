"""Forward drape of a square blank onto the hemisphere against the VaReS pattern (issue 22 §5).

Hemisphere R = 100 mm to the equator (``irregular_cap(100, 90, rings, 0.3, 1)``), a woven ply
(orthotropic St. Venant–Kirchhoff, E1 = E2 = ratio × G12, G12 = 10, ν12 = 0), seed at the pole,
warp along x. The forward drape of a square blank (``rectangle_blank(side, side, spacing)``,
yarn-aligned right triangles) beside ``vares.solve`` on the mould's mesh with the same law and
``warp_direction=(1, 0, 0)``: per mould node the distance between the node and where the
pattern's material point lies in the forward drape, per mould cell the shear difference, both
for all nodes the blank covers and by polar angle; and the four 45° meridians' shear of both.

    python benchmarks/blank_drape.py --side 200 --spacing 4 --rings 40
    python benchmarks/blank_drape.py --side 320 --spacing 4 --rings 40 \\
        --plot docs/images/blank_drape_hemisphere.png                 # the whole mould
    python benchmarks/blank_drape.py --side 120 --spacing 4 --rings 20 --half-angle 45
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import vares
from vares.analysis.blank_compare import against_pattern
from vares.analysis.blank_drape import drape_blank
from vares.analysis.locking import meridian_shear
from vares.geometry.blank import rectangle_blank
from vares.geometry.examples import irregular_cap
from vares.materials import OrthotropicStVenantKirchhoff

POLAR = (30.0, 45.0, 60.0, 75.0)
BANDS = ((0.0, 30.0), (30.0, 60.0), (60.0, 75.0), (75.0, 90.0))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=float, default=200.0)
    parser.add_argument("--spacing", type=float, default=4.0)
    parser.add_argument("--rings", type=int, default=40)
    parser.add_argument("--half-angle", type=float, default=90.0, help="the cap's polar extent")
    parser.add_argument("--ratio", type=float, default=100.0, help="E / G12")
    parser.add_argument("--plot", default=None, help="write a figure (PNG) to this path")
    args = parser.parse_args()
    mould = irregular_cap(100.0, args.half_angle, args.rings, 0.3, 1)
    fabric = OrthotropicStVenantKirchhoff(
        E1=10.0 * args.ratio, E2=10.0 * args.ratio, G12=10.0, nu12=0.0
    )
    blank = rectangle_blank(args.side, args.side, args.spacing)
    print(
        f"mould {mould.num_cells} triangles; blank {len(blank.coordinates)} nodes, "
        f"{len(blank.triangles)} cells; E/G {args.ratio:g}"
    )
    started = time.perf_counter()
    drape = drape_blank(mould, blank, fabric, seed=(0, 0, 100), warp_direction=(1, 0, 0))
    forward = time.perf_counter() - started
    s = drape.summary()
    print(
        f"forward drape: {forward:.1f} s, {s['iterations']} iterations, converged "
        f"{s['converged']} (relative residual {s['relative_residual']:.2e}); net area "
        f"{s['net_area']:.0f} mm², excess {s['excess_area']:.0f} mm²; largest shear on the "
        f"mould {s['max_shear_on_part']:.2f}°"
    )
    print("residuals", " ".join(f"{h['relative_residual']:.1e}" for h in drape.history))
    print(f"unbalanced tangential force {s['unbalanced_force']:.2e} of the cells' forces")
    started = time.perf_counter()
    pattern = vares.solve(mould, fabric, 1.0, warp_direction=(1.0, 0.0, 0.0))
    inverse = time.perf_counter() - started
    print(f"VaReS: {inverse:.1f} s, {pattern.iterations} iterations, converged {pattern.converged}")
    shear = pattern.fields["shear_angle"]
    polar = np.degrees(np.arccos(np.clip(mould.points[:, 2] / 100.0, -1, 1)))
    cells = mould.cells["triangle"]
    cell_polar = polar[cells].mean(axis=1)
    c = against_pattern(drape, mould, pattern.material_coordinates, shear)
    print(f"compared {c['nodes']} nodes, {c['cells']} cells; turn {c['turn']:.4f}°")
    print(
        f"all: position max {c['max_position_difference']:.3f} mm, rms "
        f"{c['rms_position_difference']:.3f} mm; shear max {c['max_shear_difference']:.3f}°, "
        f"rms {c['rms_shear_difference']:.3f}°, mean {c['mean_shear_difference']:+.3f}°"
    )
    for low, high in BANDS:
        nodes = (polar >= low) & (polar < high)
        band = (cell_polar >= low) & (cell_polar < high)
        if not nodes.any() or not np.isfinite(c["position_difference"][nodes]).any():
            continue
        d, g = c["position_difference"][nodes], c["shear_difference"][band]
        print(
            f"polar {low:.0f}–{high:.0f}°: position max {np.nanmax(d):.3f} rms "
            f"{np.sqrt(np.nanmean(d**2)):.3f} mm; shear max {np.nanmax(np.abs(g)):.3f} rms "
            f"{np.sqrt(np.nanmean(g**2)):.3f}°; |shear| VaReS max "
            f"{np.nanmax(np.abs(shear[band])):.2f}°"
        )
    for name, field in (("forward", c["drape_shear"]), ("VaReS", shear)):
        rows = meridian_shear(mould, field, polar_angles=POLAR)
        print(
            f"{name} meridians 30/45/60/75°:",
            "; ".join(", ".join(f"{v:.2f}" for v in rows[:, k]) for k in range(len(POLAR))),
        )
    if args.plot:
        plot(drape, mould, c, args.plot)


def plot(drape, mould, comparison, path: str) -> None:
    """The flat blank's shear with its trim line, the blank on the mould seen from above, and
    the shear difference forward − VaReS on the mould."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    blank = drape.blank
    figure, axes = plt.subplots(1, 3, figsize=(15, 4.8))
    art = axes[0].tripcolor(
        *blank.coordinates.T, blank.triangles, drape.shear_angle, cmap="RdBu_r", vmin=-60, vmax=60
    )
    for line in drape.trim_lines:
        axes[0].plot(*line.T, "k-", lw=1.2)
    axes[0].set_title("flat blank: shear [°], trim line (black)")
    figure.colorbar(art, ax=axes[0])
    p = drape.positions
    art = axes[1].tripcolor(
        p[:, 0], p[:, 1], blank.triangles, drape.shear_angle, cmap="RdBu_r", vmin=-60, vmax=60
    )
    axes[1].set_title("draped, seen from above: shear [°]")
    figure.colorbar(art, ax=axes[1])
    q = mould.points
    art = axes[2].tripcolor(
        q[:, 0],
        q[:, 1],
        mould.cells["triangle"],
        comparison["shear_difference"],
        cmap="RdBu_r",
        vmin=-3,
        vmax=3,
    )
    axes[2].set_title("on the mould: shear forward − VaReS [°]")
    figure.colorbar(art, ax=axes[2])
    for axis in axes:
        axis.set_aspect("equal")
        axis.set_xlabel("mm")
    figure.tight_layout()
    figure.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
