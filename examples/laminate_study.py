"""The laminate example of docs/composites.md: a [0/45/-45/90]s stack of a biaxial non-crimp
fabric on a spherical cap over a square, every ply draped, every pair checked, the fibre
directions written for FE and read back.

    python examples/laminate_study.py --output docs/images

runs ``examples/laminate/laminate.toml`` (into a temporary folder), prints the pair matrices,
the times with one and with two worker processes and the read-back error of the orientation
table, and draws the figures of the docs into ``--output``.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection

from vares.app.laminate_job import load_laminate_job
from vares.app.laminate_outputs import run_laminate
from vares.io.orientations import read_abaqus_orientations, read_orientation_csv
from vares.structures.laminate import PAIR_VALUES, blank_used_for

JOB = Path(__file__).parent / "laminate" / "laminate.toml"


def top_view(ax, mesh, values, cmap, limits, title):
    """The mould seen from above, cells coloured by ``values`` ``(m,)``."""
    cells = mesh.cells["triangle"]
    polygons = mesh.points[cells][:, :, :2]
    collection = PolyCollection(polygons, array=values, cmap=cmap, edgecolors="none")
    collection.set_clim(*limits)
    ax.add_collection(collection)
    ax.set_xlim(polygons[..., 0].min(), polygons[..., 0].max())
    ax.set_ylim(polygons[..., 1].min(), polygons[..., 1].max())
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    ax.set_xticks([])
    ax.set_yticks([])
    return collection


def yarns(ax, mesh, warp, count=9, length=9.0):
    """Short warp lines at the cells nearest a ``count`` × ``count`` grid (top view)."""
    centroids = mesh.points[mesh.cells["triangle"]].mean(axis=1)
    low, high = centroids[:, :2].min(axis=0), centroids[:, :2].max(axis=0)
    u, v = np.meshgrid(
        *(np.linspace(a, b, count + 2)[1:-1] for a, b in zip(low, high, strict=True))
    )
    grid = np.column_stack([u.ravel(), v.ravel()])
    picked = np.argmin(np.linalg.norm(centroids[None, :, :2] - grid[:, None], axis=2), axis=1)
    for c, w in zip(centroids[picked], warp[picked], strict=True):
        d = w[:2] * length / 2
        ax.plot([c[0] - d[0], c[0] + d[0]], [c[1] - d[1], c[1] + d[1]], "k-", lw=0.6)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=Path("laminate-figures"))
    args = parser.parse_args()
    args.output.mkdir(parents=True, exist_ok=True)
    job = load_laminate_job(JOB)
    with tempfile.TemporaryDirectory() as folder:
        timings = {}
        for workers in (1, 2):
            out = Path(folder) / f"out-{workers}"
            started = time.perf_counter()
            result = run_laminate(job.with_output(out), workers=workers)
            timings[workers] = (time.perf_counter() - started, result.seconds)
            if workers == 1:
                sequential = result
                abaqus = read_abaqus_orientations(out / "orientations.inp")
                table = read_orientation_csv(out / "orientations.csv")
    result = sequential
    print(f"converged: {result.converged}; labels {result.labels}")
    for drape in result.drapes:
        data = drape.summary()
        against = data["kinematic_drape"]["against_pattern"]
        print(
            f"  {drape.label} ({', '.join(drape.plies)}): {data['iterations']} iterations, "
            f"energy {data['energy']:.6g}, largest shear {data['max_shear']:.2f}° "
            f"(kinematic {against['max_kinematic_shear']:.2f}°, mean difference "
            f"{against['mean_abs_difference']:.2f}°, correlation {against['correlation']:.4f}), "
            f"{drape.seconds:.2f} s"
        )
    np.set_printoptions(precision=4, suppress=True)
    for value in PAIR_VALUES:
        print(value)
        print(result.pair_matrix(value))
    for workers, (wall, inside) in timings.items():
        print(f"workers {workers}: {wall:.2f} s in all, {inside:.2f} s draping and checking")
    error = 0.0
    for name, ply in abaqus.items():
        drape = result.drape(name)
        rows = ply.elements - 1
        error = max(
            error,
            np.abs(ply.warp - drape.warp[rows]).max(),
            np.abs(ply.fill - drape.fill[rows]).max(),
            np.abs(table[name].warp - drape.warp[rows]).max(),
        )
    print(f"orientation table read back: largest difference {error:.3g}")

    labels = result.labels
    fig, axes = plt.subplots(1, 2, figsize=(8.4, 3.6), constrained_layout=True)
    for ax, value, title in (
        (axes[0], "warp_compressed_fraction", "area with compressed warp [%]"),
        (axes[1], "largest_compression", "largest yarn compression [%]"),
    ):
        matrix = 100 * result.pair_matrix(value)
        image = ax.imshow(matrix, cmap="Reds", vmin=0)
        for i in range(len(labels)):
            for j in range(len(labels)):
                colour = "white" if matrix[i, j] > 0.5 * matrix.max() else "black"
                text = f"{matrix[i, j]:.1f}"
                ax.text(j, i, text, ha="center", va="center", fontsize=8, color=colour)
        ax.set_xticks(range(len(labels)), labels)
        ax.set_yticks(range(len(labels)), labels)
        ax.set_xlabel("used for the ply")
        ax.set_ylabel("the blank of")
        ax.set_title(title, fontsize=9)
        fig.colorbar(image, ax=ax, shrink=0.8)
    fig.savefig(args.output / "laminate_pairs.png", dpi=150)
    plt.close(fig)

    mesh = result.mesh
    zero, plus = result.drape("P1"), result.drape("P2")
    own = blank_used_for(zero, zero).fields
    wrong = blank_used_for(plus, zero).fields
    fig, axes = plt.subplots(1, 2, figsize=(8.4, 3.9), constrained_layout=True)
    limits = (-5.0, 5.0)
    for ax, fields, title in (
        (axes[0], own, "0° ply on its own blank"),
        (axes[1], wrong, "0° ply on the 45° blank"),
    ):
        strain = 100 * (fields["warp_stretch"] - 1.0)
        collection = top_view(ax, mesh, strain, "coolwarm", limits, title)
    fig.colorbar(collection, ax=axes, shrink=0.8, label="warp strain [%] (blue: compressed)")
    fig.savefig(args.output / "laminate_ply_check.png", dpi=150)
    plt.close(fig)

    fig, axes = plt.subplots(1, 4, figsize=(12.0, 3.4), constrained_layout=True)
    shear_limits = (-10.0, 10.0)
    for ax, drape, kinematic in (
        (axes[0], zero, False),
        (axes[1], zero, True),
        (axes[2], plus, False),
        (axes[3], plus, True),
    ):
        shear = drape.kinematic_shear_angle if kinematic else drape.shear_angle
        warp = drape.kinematic_warp if kinematic else drape.warp
        kind = "kinematic net" if kinematic else "mechanical drape"
        collection = top_view(ax, mesh, shear, "PiYG", shear_limits, f"{drape.label}: {kind}")
        yarns(ax, mesh, warp)
    fig.colorbar(collection, ax=axes, shrink=0.8, label="shear angle [°]")
    fig.savefig(args.output / "laminate_shear.png", dpi=150)
    plt.close(fig)


if __name__ == "__main__":
    main()
