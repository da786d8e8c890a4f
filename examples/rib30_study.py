"""The rib study of the seed paper (§5.2): how material and ply orientation shape the pattern.

    python examples/rib30_study.py [--output docs/images]

Surface: ``vares.examples.rib30()`` (hat section, 30° arc, rounded corners), triangles.
Materials: Neo-Hooke (E = 1000, nu = 0.3) and a non-crimp fabric made with
``NonCrimpFabric.from_moduli(1000, 1000, 1)`` — illustrative values chosen here (yarn tension
1000 : in-plane shear 1, the order of magnitude of dry fabrics), not measured coefficients; no
prestress, so only these ratios matter. Plies: 0°/90° (warp along the rib, 3D direction +y at
its middle) and ±45° (warp along (−1, 1, 0)).

Writes PNG figures and prints the figures quoted in docs/rib30.md.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import vares
from vares.geometry.examples import rib30
from vares.io.plot import plot_pattern, save_pattern_figure

RIB_AXIS = (0.0, 1.0, 0.0)
BIAS = (-1.0, 1.0, 0.0)
VISIBLE_COMPRESSION = 1.0  # stress of 0.1 % yarn compression with the yarn modulus 1000


def kabsch(reference: np.ndarray, moving: np.ndarray) -> np.ndarray:
    """``moving`` after the proper rigid motion that best fits it onto ``reference``."""
    ca, cb = reference.mean(axis=0), moving.mean(axis=0)
    u, _, vt = np.linalg.svd((moving - cb).T @ (reference - ca))
    r = u @ np.diag([1.0, np.sign(np.linalg.det(u @ vt))]) @ vt
    return (moving - cb) @ r + ca


def solve(mesh, material, label, **options):
    start = time.perf_counter()
    result = vares.solve(mesh, material, **options)
    elapsed = time.perf_counter() - start
    assert result.converged, result.reason
    steps = ", ".join(f"{s.strategy} τ={s.tau:.3g}: {s.iterations}" for s in result.steps)
    deviation = (
        ""
        if result.warp_deviation is None
        else (f", mean warp deviation {result.warp_deviation:.1e}°")
    )
    print(
        f"{label}: {result.iterations} iterations ({steps}), {elapsed:.2f} s, "
        f"energy {result.energy:.4e}{deviation}"
    )
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=Path("docs/images"))
    args = parser.parse_args()
    out = args.output
    out.mkdir(parents=True, exist_ok=True)

    mesh = rib30()
    print(f"rib30: {mesh}, area {mesh.area:.5f} m²")
    neo_hooke = vares.materials.NeoHooke(E=1000.0, nu=0.3)
    ncf = vares.materials.NonCrimpFabric.from_moduli(1000.0, 1000.0, 1.0)

    nh = solve(mesh, neo_hooke, "Neo-Hooke")
    save_pattern_figure(
        out / "rib30_neohooke_detF.png",
        mesh,
        nh.material_coordinates,
        nh.fields["det_F"],
        field="det_F",
        title="rib30, Neo-Hooke: det F",
        dpi=110,
    )

    # det F at the start of each pseudo-time step: the previous pattern on the raised surface
    stepped = solve(
        mesh, neo_hooke, "Neo-Hooke, 4 pseudo-time steps", strategy="pseudo-time", steps=4
    )
    done = [s for s in stepped.steps if s.converged]
    previous = [stepped.plane.project(mesh.points)] + [s.coordinates for s in done[:-1]]
    fig, axes = plt.subplots(1, len(done), figsize=(4 * len(done), 5), layout="constrained")
    starts = []
    for step, pattern in zip(done, previous, strict=True):
        surface = mesh.transformed(stepped.plane.lift(mesh.points, step.tau))
        starts.append(vares.evaluate(surface, pattern, neo_hooke).fields["det_F"])
    low, high = min(f.min() for f in starts), max(f.max() for f in starts)
    for ax, step, pattern, det_f in zip(axes, done, previous, starts, strict=True):
        plot_pattern(
            mesh,
            pattern,
            det_f,
            field="det_F",
            ax=ax,
            value_range=(low, high),
            title=f"start of step τ = {step.tau:.2f}",
        )
        print(f"  start of step τ = {step.tau:.2f}: det F {det_f.min():.4f} … {det_f.max():.4f}")
    fig.savefig(out / "rib30_pseudo_time_detF.png", dpi=120)
    plt.close(fig)

    plies = {
        "0/90": solve(mesh, ncf, "NCF 0°/90°", warp_direction=RIB_AXIS),
        "±45": solve(mesh, ncf, "NCF ±45°", warp_direction=BIAS),
    }
    for name, result in plies.items():
        tag = "0_90" if name == "0/90" else "pm45"
        for field in ("det_F", "shear_angle", "warp_stress", "fill_stress"):
            values = result.fields[field]
            save_pattern_figure(
                out / f"rib30_ncf_{tag}_{field}.png",
                mesh,
                result.material_coordinates,
                values,
                field=field,
                fibres=result.fibres,
                title=f"rib30, NCF {name}: {field}",
                dpi=110,
            )
            print(f"  NCF {name} {field}: {values.min():.4g} … {values.max():.4g}")

    # outline difference after the best rigid alignment of the boundary nodes
    boundary = np.unique(mesh.boundary_edges())
    a = plies["0/90"].material_coordinates[boundary]
    b = kabsch(a, plies["±45"].material_coordinates[boundary])
    distance = np.linalg.norm(a - b, axis=1)
    print(
        f"outline 0/90 vs ±45 after rigid alignment: max {1e3 * distance.max():.3f} mm, "
        f"RMS {1e3 * np.sqrt(np.mean(distance**2)):.3f} mm "
        f"(pattern length {1e3 * np.ptp(a, axis=0).max():.1f} mm)"
    )
    nh_boundary = kabsch(a, nh.material_coordinates[boundary])
    print(
        f"outline 0/90 vs Neo-Hooke: max "
        f"{1e3 * np.linalg.norm(a - nh_boundary, axis=1).max():.3f} mm"
    )

    # ply-stack check: a 0/90 ply cut from the ±45 pattern (yarns at −45°/+45° in its frame)
    bias = plies["±45"]
    for threshold in (0.0, VISIBLE_COMPRESSION):
        own = vares.evaluate(
            mesh, bias.material_coordinates, ncf, warp_angle=0.0, compression_threshold=threshold
        )
        check = vares.evaluate(
            mesh,
            bias.material_coordinates,
            ncf,
            warp_angle=-45.0,
            fill_angle=45.0,
            compression_threshold=threshold,
        )
        print(
            f"ply check, compression beyond {threshold:g}: ±45 ply on its own pattern "
            f"{100 * own.compressed_area_fraction:.1f} % of the area, 0/90 ply on the ±45 "
            f"pattern {100 * check.compressed_area_fraction:.1f} %; 0/90 ply yarn stress "
            f"{min(check.fields['warp_stress'].min(), check.fields['fill_stress'].min()):.4g} "
            f"… {max(check.fields['warp_stress'].max(), check.fields['fill_stress'].max()):.4g}"
            f", energy {check.energy:.4e} vs {own.energy:.4e}"
        )
    fig, axes = plt.subplots(1, 2, figsize=(10, 6), layout="constrained")
    for ax, field in zip(axes, ("warp_stress", "fill_stress"), strict=True):
        plot_pattern(
            mesh,
            bias.material_coordinates,
            check.fields[field],
            field=field,
            ax=ax,
            fibres=check.fibres,
            title=f"0/90 ply cut from the ±45 pattern: {field}",
        )
        compressed = check.fields[field] < -VISIBLE_COMPRESSION
        ax.set_xlabel(
            f"{100 * np.sum(mesh.cell_areas()[compressed]) / mesh.area:.1f} % of the "
            f"area below −{VISIBLE_COMPRESSION:g}"
        )
    fig.savefig(out / "rib30_ply_check.png", dpi=120)
    plt.close(fig)
    print(f"figures in {out}/; reproduce: python examples/rib30_study.py --output {out}")


if __name__ == "__main__":
    main()
