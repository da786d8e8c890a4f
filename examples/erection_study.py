"""Erected stresses of a catenoid band: vares' compensated patterns, the same optimised for the
erected structure, and a uniformly shrunk geometric flattening (LSCM + ARAP), on an isotropic and
an orthotropic low-shear fabric; and the VaReS and optimised patterns of single panels.

    python examples/erection_study.py [--output docs/images]     (needs: pip install libigl)

Structure: ``vares.examples.catenoid_band()`` (12 gores, waist radius 3 m, 3 m high, 1,536
triangles), both rings held, intended prestress 2.0/2.0 kN/m, warp along the meridians
(direction (0, 0, 1)). Fabrics: an isotropic Neo-Hooke membrane, E·t = 600 kN/m, ν = 0.3, and
the PES/PVC type II preset (E1 = 840, E2 = 640, G12 = 32 kN/m, ν12 = 0.3: low shear stiffness).

(a) vares: ``solve_structure`` (matched seams) with the prestress, then ``erect``.
(a') optimised: ``vares.optimise_for_erection`` of (a) with the default options (shape weight
    0.1, shape deviation bounded by 1.5 × (a)'s), seams kept matched, erected.
(b) geometric: each gore flattened by LSCM (two boundary nodes pinned) and 50 ARAP iterations
    (libigl), turned so that the mean meridian runs along +x, then shrunk uniformly by the
    compensation at which a flat membrane carries the intended prestress in both yarns (the
    stretches solved from the law), and erected the same way (the seams welded as they are).

Single panels (``--panels``), both boundaries held: a 120° section of a catenoid (waist radius
5 m, 1 m high), a hypar z = 0.06 x y over 10 m × 10 m (isotropic St. Venant–Kirchhoff
E·t = 600 kN/m, ν = 0.3, 2 kN/m; and PES/PVC, 2/1.5 kN/m, warp along x), the shipped sail with
the warp along its diagonal (1, 1, 0) (PES/PVC, 2/1.5 kN/m), and the same options over shape
weights and bounds (the trade-off); ``--trade-off``: only the trade-off of the panels that miss
the aim with the default options (the catenoid sections and the sail).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from scipy.optimize import fsolve

import vares
from vares.analysis import Pattern
from vares.geometry.elements import ELEMENTS
from vares.geometry.flatten import signed_area

PRESTRESS = (2.0, 2.0)
DIRECTION = np.array([0.0, 0.0, 1.0])


def flat_compensation(material, prestress) -> tuple[float, float]:
    """Stretches (warp, fill) at which a flat membrane (t = 1, yarns at 90°) carries the
    prestress as membrane forces along the yarns."""
    fibres = vares.Fibres.from_angles(0.0)

    def forces(stretch):
        l1, l2 = stretch
        S = material.response(np.diag([l1**2, l2**2])[None], fibres, tangent=False).stress[0]
        return [l1 / l2 * S[0, 0] - prestress[0], l2 / l1 * S[1, 1] - prestress[1]]

    l1, l2 = fsolve(forces, [1.0, 1.0], xtol=1e-13)
    return float(l1), float(l2)


def geometric_pattern(mesh, stretches) -> np.ndarray:
    """LSCM + ARAP flattening of a gore, meridian along +x, shrunk by ``1/stretches``."""
    import igl

    points = np.ascontiguousarray(mesh.points)
    faces = np.ascontiguousarray(mesh.cells["triangle"], dtype=np.int64)
    boundary = igl.boundary_loop(faces)
    first = boundary[0]
    second = boundary[np.argmax(np.linalg.norm(points[boundary] - points[first], axis=1))]
    pinned = np.array([first, second], dtype=np.int64)
    values = np.array([[0.0, 0.0], [np.linalg.norm(points[second] - points[first]), 0.0]])
    uv, _ = igl.lscm(points, faces, pinned, values)
    data = igl.ARAPData()
    data.max_iter = 50
    fixed = np.array([first], dtype=np.int32)
    igl.arap_precomputation(points, faces, 2, fixed, data)
    uv = np.asarray(igl.arap_solve(uv[fixed], data, uv))[:, :2]
    if signed_area(mesh, uv) < 0:
        uv[:, 1] *= -1
    # the meridian's image in the pattern, averaged over the cells (weighted by area)
    element = ELEMENTS["triangle"]
    j = element.jacobians(points, faces)[:, 0]
    J = element.jacobians(uv, faces)[:, 0]
    images = np.einsum(
        "mab,mbc,mc->ma", J, np.linalg.pinv(j), np.broadcast_to(DIRECTION, (len(j), 3))
    )
    mean = (images * mesh.cell_areas()[:, None]).sum(axis=0)
    angle = np.arctan2(mean[1], mean[0])
    c, s = np.cos(angle), np.sin(angle)
    uv = uv @ np.array([[c, -s], [s, c]])
    return uv / np.array(stretches)


def row(label: str, result, design: bool) -> str:
    stats = result.statistics(design=design)
    warp, fill = stats["stress"]["warp"], stats["stress"]["fill"]
    deviation = (
        "—"
        if design
        else f"{result.deviation()['max'] * 1000:.1f} / "
        + (f"{result.deviation()['rms'] * 1000:.1f}")
    )
    return (
        f"| {label} | {warp['mean']:.2f} | {warp['min']:.2f} … {warp['max']:.2f} | "
        f"{warp['rms_deviation']:.2f} | {fill['mean']:.2f} | {fill['min']:.2f} … {fill['max']:.2f}"
        f" | {fill['rms_deviation']:.2f} | {100 * stats['wrinkled_area_fraction']:.1f} | "
        f"{100 * stats['slack_area_fraction']:.1f} | {deviation} |"
    )


def draw(result, output: Path, name: str) -> None:
    import matplotlib.pyplot as plt

    from vares.io.plot import plot_surface

    per_cell = np.concatenate(
        [result.normal_deviation[c].mean(axis=1) * 1000 for c in result.mesh.cells.values()]
    )
    for field, values, title in (
        ("warp_stress", result.fields["warp_stress"], "warp force after erection [kN/m]"),
        ("normal_deviation", per_cell, "normal deviation from the design [mm]"),
    ):
        fig = plot_surface(
            result.erected_mesh, values, field=field, title=title, stress_unit="kN/m"
        )
        fig.savefig(output / f"erection_{name}_{field}.png", dpi=100)
        plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=Path("docs/images"))
    parser.add_argument("--panels", action="store_true", help="the single panels too")
    parser.add_argument(
        "--trade-off", action="store_true", help="only the trade-off of the panels that miss"
    )
    args = parser.parse_args()
    if args.trade_off:
        trade_off()
        return
    args.output.mkdir(parents=True, exist_ok=True)
    mesh, ids = vares.examples.catenoid_band()
    panels = vares.split_panels(mesh, ids, {int(i): f"gore-{int(i) + 1}" for i in set(ids)})
    print(f"catenoid band: {mesh}, {len(panels)} gores, design area {mesh.area:.3f} m²")
    fabrics = {
        "isotropic": vares.materials.NeoHooke(E=600.0, nu=0.3),
        "pes-pvc-2": vares.materials.fabric("pes-pvc-type-2").material(),
    }
    header = (
        "| pattern | warp mean | warp min … max | warp RMS dev. | fill mean | fill min … max | "
        "fill RMS dev. | wrinkled % | slack % | deviation max / RMS (mm) |\n"
        "|---|---|---|---|---|---|---|---|---|---|"
    )
    for label, fabric in fabrics.items():
        start = time.perf_counter()
        structure = vares.solve_structure(
            panels, fabric, warp_direction=DIRECTION, prestress=PRESTRESS
        )
        assert structure.converged, structure.reason
        compensated = vares.erect(structure)
        optimum = vares.optimise_for_erection(structure)
        optimised = optimum.erected
        stretches = flat_compensation(fabric, PRESTRESS)
        geometric = vares.erect(
            [
                Pattern(
                    p.mesh,
                    geometric_pattern(p.mesh, stretches),
                    vares.Fibres.from_angles(0.0),
                    PRESTRESS,
                    p.name,
                )
                for p in panels
            ],
            fabric,
        )
        assert compensated.converged and geometric.converged and optimum.converged
        elapsed = time.perf_counter() - start
        print(
            f"\n{label}: {fabric!r}; flat compensation warp {100 * (1 - 1 / stretches[0]):.3f} %, "
            f"fill {100 * (1 - 1 / stretches[1]):.3f} %; erection iterations "
            f"{compensated.iterations} / {geometric.iterations}; optimiser {optimum.iterations} "
            f"steps, {optimum.elapsed:.1f} s; {elapsed:.1f} s in all"
        )
        print(header)
        print(row("vares, on the design shape", compensated, True))
        print(row("**vares, erected**", compensated, False))
        print(row("vares optimised, on the design shape", optimised, True))
        print(row("**vares optimised, erected**", optimised, False))
        print(row("LSCM + ARAP shrunk, on the design shape", geometric, True))
        print(row("**LSCM + ARAP shrunk, erected**", geometric, False))
        draw(compensated, args.output, f"{label}_vares")
        draw(geometric, args.output, f"{label}_geometric")
        draw(optimised, args.output, f"{label}_optimised")
    if args.panels:
        single_panels()
    print("\nreproduce: python examples/erection_study.py --output docs/images --panels")


def panel_cases() -> dict:
    """The single panels: name → (mesh, law, solve settings)."""
    iso = vares.materials.StVenantKirchhoff(E=600.0, nu=0.3)
    pes = vares.materials.fabric("pes-pvc-type-2").material()
    catenoid = vares.examples.catenoid_section(
        waist=5.0, height=1.0, angle=120.0, n_along=12, n_around=40
    )
    hypar = vares.examples.hypar(size=10.0, rise=0.06, n=28)
    cases = {
        "catenoid 120°, isotropic": (catenoid, iso, {"prestress": 2.0}),
        "catenoid 120°, PES/PVC, warp along the axis": (
            catenoid,
            pes,
            {"prestress": (2.0, 2.0), "warp_direction": (0, 0, 1)},
        ),
        "hypar, isotropic": (hypar, iso, {"prestress": 2.0}),
        "hypar, PES/PVC, warp along x": (
            hypar,
            pes,
            {"prestress": (2.0, 1.5), "warp_direction": (1, 0, 0)},
        ),
        "sail, PES/PVC, warp along (1, 1, 0)": (
            vares.examples.four_point_sail(),
            pes,
            {"prestress": (2.0, 1.5), "warp_direction": (1, 1, 0)},
        ),
    }
    return cases


def trade_off() -> None:
    """The erected forces against the shape over the shape weight and bound, for the panels
    that miss the aim with the default options (the catenoid sections and the sail): RMS and
    largest deviation also relative to the VaReS pattern's erection."""
    cases = panel_cases()
    options = ((0.0, None), (0.0, 2.0), (0.1, 3.0), (0.1, 2.0), (0.1, 1.5), (0.0, 1.5), (0.1, 1.2))
    print(
        "| case | shape weight | shape bound | warp mean | warp RMS dev. | fill mean | "
        "fill RMS dev. | deviation max (mm) | steps |\n|---|---|---|---|---|---|---|---|---|"
    )
    for name in (
        "catenoid 120°, isotropic",
        "catenoid 120°, PES/PVC, warp along the axis",
        "sail, PES/PVC, warp along (1, 1, 0)",
    ):
        mesh, law, settings = cases[name]
        solved = vares.solve(mesh, law, **settings)
        for k, (weight, bound) in enumerate(options):
            optimum = vares.optimise_for_erection(solved, shape_weight=weight, shape_bound=bound)
            start, after = optimum.start, optimum.erected
            s0, s1 = start.statistics()["stress"], after.statistics()["stress"]
            if k == 0:
                print(
                    f"| {name} | VaReS | — | {s0['warp']['mean']:.3f} | "
                    f"{s0['warp']['rms_deviation']:.3f} | {s0['fill']['mean']:.3f} | "
                    f"{s0['fill']['rms_deviation']:.3f} | {start.deviation()['max'] * 1e3:.1f} | |"
                )
            ratio = [s1[y]["rms_deviation"] / s0[y]["rms_deviation"] for y in ("warp", "fill")]
            shape = after.deviation()["max"] / start.deviation()["max"]
            print(
                f"| | {weight:g} | {bound if bound is not None else 'none'} | "
                f"{s1['warp']['mean']:.3f} | {s1['warp']['rms_deviation']:.3f} ({ratio[0]:.2f} ×)"
                f" | {s1['fill']['mean']:.3f} | {s1['fill']['rms_deviation']:.3f} "
                f"({ratio[1]:.2f} ×) | {after.deviation()['max'] * 1e3:.1f} ({shape:.2f} ×) | "
                f"{optimum.iterations} |",
                flush=True,
            )


def single_panels() -> None:
    """VaReS against optimised patterns of single panels, and the trade-off over the options."""
    cases = panel_cases()
    print(
        "\n| panel | triangles | pattern | warp mean | warp RMS dev. | fill mean | "
        "fill RMS dev. | wrinkled % | deviation max / RMS (mm) | solve / optimise s (steps) |\n"
        "|---|---|---|---|---|---|---|---|---|---|"
    )
    for name, (mesh, law, settings) in cases.items():
        start = time.perf_counter()
        solved = vares.solve(mesh, law, **settings)
        solve_time = time.perf_counter() - start
        optimum = vares.optimise_for_erection(solved)
        for label, result in (("VaReS", optimum.start), ("optimised", optimum.erected)):
            stats = result.statistics()
            warp, fill = stats["stress"]["warp"], stats["stress"]["fill"]
            deviation = result.deviation()
            timing = (
                f"{solve_time:.2f} / {optimum.elapsed:.2f} ({optimum.iterations})"
                if label == "optimised"
                else ""
            )
            first = label == "VaReS"
            print(
                f"| {name if first else ''} | {mesh.num_cells if first else ''} | {label} | "
                f"{warp['mean']:.3f} | {warp['rms_deviation']:.3f} | "
                f"{fill['mean']:.3f} | {fill['rms_deviation']:.3f} | "
                f"{100 * stats['wrinkled_area_fraction']:.1f} | {deviation['max'] * 1e3:.1f} / "
                f"{deviation['rms'] * 1e3:.1f} | {timing} |"
            )
    print(
        "\ntrade-off, hypar isotropic: | shape weight | shape bound | warp mean | RMS dev. "
        "(warp) | deviation max (mm) |\n|---|---|---|---|---|"
    )
    mesh, law, settings = cases["hypar, isotropic"]
    solved = vares.solve(mesh, law, **settings)
    for weight, bound in (
        (0.0, None),
        (0.1, 3.0),
        (0.1, 1.5),
        (0.1, 1.2),
        (1.0, 1.0),
        (10.0, None),
    ):
        optimum = vares.optimise_for_erection(solved, shape_weight=weight, shape_bound=bound)
        warp = optimum.erected.statistics()["stress"]["warp"]
        print(
            f"| {weight:g} | {bound if bound is not None else 'none'} | {warp['mean']:.3f} | "
            f"{warp['rms_deviation']:.3f} | {optimum.erected.deviation()['max'] * 1e3:.1f} |"
        )


if __name__ == "__main__":
    main()
