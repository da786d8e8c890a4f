"""Intra-ply shear locking of a stiff-yarn ply on a hemisphere (issue 22, item 1).

A woven ply (orthotropic St. Venant–Kirchhoff, E1 = E2 = ratio × G12, ν12 = 0) on a hemisphere of
radius 100 mm cut at the equator, irregular triangles (``irregular_cap(100, 90, rings, 0.3, 1)``),
warp along x. The yarn shear angle along the four 45° meridians (cells whose centroid lies within
3° of the meridian's azimuth and 2.5° of the polar angle, signed so that all four are positive)
against the kinematic net of the exact sphere, for the cell-wise law (``yarn_strain="element"``,
what ``vares.solve`` does), yarn stretches smoothed over each node's domain
(``yarn_strain="smoothed"``) and over the domains of pairs of nodes (``"paired"``), all
started from the kinematic net's pattern on the same mesh, the warp aligned with x by the
solver's secant iteration.

    python benchmarks/locking.py --stabilisation 10                # 40 rings (9,600 cells)
    python benchmarks/locking.py --rings 20 30 40 60 --stabilisation 10   # mesh convergence

    python benchmarks/locking.py --yarn-strain paired --ratios 1e6 --stabilisation 10 \
        --continuation 1e2 1e3 1e4 1e5 --both      # E/G 1e6 through decades, with and without
                                                    # the extrapolation of the stages' patterns

(``--stabilisation c``: the share ``c G12/E`` of the yarn part kept per cell;
``--continuation``: the ratios solved first, each stage from the last pattern, ``--align-up-to``:
the warp aligned at the stages up to this ratio and the rotation held above it; from the third
stage on each starts from the extrapolation in 1/ratio of the two before, unless
``--no-extrapolation``; docs/locking.md.)
The blank's extent along the warp, the fill and the two diagonals is compared with the net's
pattern on the same mesh.
"""

from __future__ import annotations

import argparse

import numpy as np

from vares.analysis.locking import (
    blank_extent,
    cell_shear_angle,
    meridian_shear,
    solve_yarn_strain,
)
from vares.geometry.drape import kinematic_drape
from vares.geometry.examples import irregular_cap
from vares.materials import Fibres, OrthotropicStVenantKirchhoff

POLAR = (30.0, 45.0, 60.0, 75.0)
#: Kinematic net on the exact sphere, seed at the pole, warp along x (docs/composites.md) [°].
NET = np.array([7.52, 16.11, 26.95, 39.27])


def mesh_net(rings: int) -> tuple[np.ndarray, np.ndarray]:
    """The kinematic net on the same mesh (spacing 1 mm), sampled as the solves are, and the flat
    pattern it implies (the solves' start)."""
    mesh = irregular_cap(100.0, 90.0, rings, 0.3, 1)
    drape = kinematic_drape(mesh, seed=(0, 0, 100), warp_direction=(1, 0, 0), spacing=1.0)
    return meridian_shear(mesh, drape.shear_angle, polar_angles=POLAR), drape.material_coordinates


def run(
    rings: int,
    ratio: float,
    yarn_strain: str,
    stabilisation: float,
    net: np.ndarray,
    start: np.ndarray,
    continuation: tuple[float, ...] = (),
    align_up_to: float | None = None,
    extrapolate: bool = True,
) -> dict:
    """One solve from the net's pattern, through the ratios of ``continuation`` below
    ``ratio``."""
    mesh = irregular_cap(100.0, 90.0, rings, 0.3, 1)
    material = OrthotropicStVenantKirchhoff(E1=ratio, E2=ratio, G12=1.0, nu12=0.0)
    result = solve_yarn_strain(
        mesh,
        material,
        yarn_strain=yarn_strain,
        yarn_stabilisation=stabilisation / ratio if yarn_strain != "element" else 0.0,
        warp_direction=(1, 0, 0),
        initial_guess=start,
        continuation=tuple(r for r in continuation if r < ratio),
        align_up_to=align_up_to,
        extrapolate=extrapolate,
    )
    shear = cell_shear_angle(mesh, result.coordinates, material, result.fibres)
    table = meridian_shear(mesh, shear, polar_angles=POLAR)
    extent = blank_extent(result.coordinates, result.fibres)
    net_extent = blank_extent(start, Fibres.from_angles(0.0))
    return {
        "cells": mesh.num_cells,
        "converged": result.converged,
        "iterations": " + ".join(str(s.iterations) for s in result.stages)
        or str(result.iterations),
        "aligning": " + ".join(str(n) for n in alignment_iterations(result.history)),
        "stage_seconds": " + ".join(f"{s.elapsed:.1f}" for s in result.stages)
        or f"{result.elapsed:.1f}",
        "seconds": result.elapsed,
        "table": table,
        "spread": np.nanmax(table, axis=0) - np.nanmin(table, axis=0),
        "error": np.nanmax(np.abs(table - NET), axis=0),
        "mesh_error": np.nanmax(np.abs(table - net), axis=0),
        "mean": np.nanmean(table, axis=0),
        "extent": extent,
        "extent_error": extent - net_extent,
    }


def alignment_iterations(history) -> list[int]:
    """The Newton iterations of the warp alignment's secant steps, per stage (the stages'
    records are led by ``E/G …:``, the law's own are not)."""
    counts: dict[str, int] = {}
    for record in history:
        stage, _, strategy = record.strategy.rpartition(": ")
        counts.setdefault(stage, 0)
        if record.iteration > 0 and strategy.startswith("warp alignment"):
            counts[stage] += 1
    return list(counts.values())


def report(rings: int, ratio: float, label: str, r: dict) -> None:
    """Print one solve's meridians, spread, errors and extent."""
    print(
        f"\n{rings} rings ({r['cells']} cells), E/G = {ratio:.0e}, {label}: "
        f"converged {r['converged']}, {r['iterations']} iterations, "
        f"{r['stage_seconds']} = {r['seconds']:.1f} s (of the iterations, the warp "
        f"alignment's: {r['aligning']})"
    )
    print("polar angle         " + "  ".join(f"{p:6.0f}" for p in POLAR))
    for azimuth, line in zip((45, 135, 225, 315), r["table"], strict=True):
        print(f"  meridian {azimuth:3d}°     " + "  ".join(f"{v:6.2f}" for v in line))
    print("  spread of the 4   " + "  ".join(f"{v:6.2f}" for v in r["spread"]))
    print("  mean of the 4     " + "  ".join(f"{v:6.2f}" for v in r["mean"]))
    print("  max |Δ net|       " + "  ".join(f"{v:6.2f}" for v in r["error"]))
    print("  max |Δ mesh net|  " + "  ".join(f"{v:6.2f}" for v in r["mesh_error"]))
    print(
        "  extent warp / fill / +45 / -45 [mm]  "
        + " / ".join(f"{v:.2f}" for v in r["extent"])
        + "  (minus the net's: "
        + " / ".join(f"{v:+.2f}" for v in r["extent_error"])
        + ")"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rings", type=int, nargs="+", default=[40])
    parser.add_argument("--ratios", type=float, nargs="+", default=[1e4, 1e6])
    parser.add_argument("--yarn-strain", nargs="+", default=["element", "smoothed", "paired"])
    parser.add_argument(
        "--stabilisation",
        type=float,
        default=0.0,
        help="share of the yarn part kept per cell, times E/G (smoothed only)",
    )
    parser.add_argument(
        "--continuation",
        type=float,
        nargs="*",
        default=[],
        help="E/G ratios solved first, each from the last pattern (those below the ratio)",
    )
    parser.add_argument(
        "--align-up-to",
        type=float,
        default=None,
        help="align the warp at the stages up to this E/G, hold the rotation above it",
    )
    parser.add_argument(
        "--no-extrapolation",
        action="store_true",
        help="start every stage from the last pattern (not the extrapolation of the two before)",
    )
    parser.add_argument(
        "--both",
        action="store_true",
        help="with --continuation: solve with and without the extrapolation, side by side",
    )
    args = parser.parse_args()
    print("net (exact sphere)  " + "  ".join(f"{v:6.2f}" for v in NET))
    rows = []
    for rings in args.rings:
        net, start = mesh_net(rings)
        print(f"\nnet on the {rings}-ring mesh")
        for azimuth, line in zip((45, 135, 225, 315), net, strict=True):
            print(f"  meridian {azimuth:3d}°     " + "  ".join(f"{v:6.2f}" for v in line))
        spread = np.nanmax(net, axis=0) - np.nanmin(net, axis=0)
        print("  spread of the 4   " + "  ".join(f"{v:6.2f}" for v in spread))
        extent = blank_extent(start, Fibres.from_angles(0.0))
        print("  extent warp / fill / +45 / -45 [mm]  " + " / ".join(f"{v:.2f}" for v in extent))
        for ratio in args.ratios:
            variants = [True, False] if args.both else [not args.no_extrapolation]
            for yarn_strain in args.yarn_strain:
                for extrapolate in variants if args.continuation else [True]:
                    label = yarn_strain
                    if args.continuation:
                        label += ", extrapolated" if extrapolate else ", from the last"
                    r = run(
                        rings,
                        ratio,
                        yarn_strain,
                        args.stabilisation,
                        net,
                        start,
                        tuple(args.continuation),
                        args.align_up_to,
                        extrapolate,
                    )
                    rows.append((rings, ratio, label, r))
                    report(rings, ratio, label, r)
    print(
        "\n| rings | cells | E/G | yarn strain | iterations | s | spread (30/45/60/75°) | "
        "max abs. error vs net | vs the mesh's net | extent − net's [mm] |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for rings, ratio, yarn_strain, r in rows:
        spread = " / ".join(f"{v:.2f}" for v in r["spread"])
        error = " / ".join(f"{v:.2f}" for v in r["error"])
        mesh_error = " / ".join(f"{v:.2f}" for v in r["mesh_error"])
        extent = " / ".join(f"{v:+.2f}" for v in r["extent_error"])
        print(
            f"| {rings} | {r['cells']} | {ratio:.0e} | {yarn_strain} | {r['iterations']} | "
            f"{r['seconds']:.1f} | {spread} | {error} | {mesh_error} | {extent} |"
        )


if __name__ == "__main__":
    main()
