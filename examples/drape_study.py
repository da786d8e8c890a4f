"""The kinematic drape of a hemisphere: the figures and numbers of docs/composites.md.

    python examples/drape_study.py [--output docs/images]

Mould: the hemisphere R = 100 mm to the equator, irregular triangles
(``vares.geometry.examples.irregular_cap(100, 90, n_rings, 0.3, 1)``: 40 rings, edges about
3.9 mm, and 80 rings, about 2 mm). Seed at the pole, warp along x, spacings 2 mm and 1 mm. The
reference is the same net on the exact sphere (three spheres intersected in closed form) and the
Chebyshev-net relation γ = f(K u v), z f'' + f' = cos f.

Writes PNG figures and prints the tables quoted in docs/composites.md.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

from vares.analysis.producibility import producibility
from vares.geometry.drape import kinematic_drape
from vares.geometry.drape_net import kinematic_net
from vares.geometry.examples import irregular_cap
from vares.materials.forming import locking_angle

R = 100.0
K = 1.0 / R**2
POLAR = (30.0, 45.0, 60.0, 75.0)
QUADRANTS = ((1, 1), (-1, 1), (-1, -1), (1, -1))  # the meridians at 45°, 135°, 225°, 315°


def chebyshev_shear(z: np.ndarray) -> np.ndarray:
    """``f(z)`` in radians: ``z f'' + f' = cos f``, ``f(0) = 0`` (series ``z − z³/18`` near 0)."""
    z = np.atleast_1d(np.asarray(z, dtype=float))
    z0 = 1e-4
    solution = solve_ivp(
        lambda x, y: [y[1], (np.cos(y[0]) - y[1]) / x],
        [z0, max(float(z.max()), 2 * z0)],
        [z0 - z0**3 / 18, 1 - z0**2 / 6],
        rtol=1e-12,
        atol=1e-14,
        dense_output=True,
    )
    return np.where(z < z0, z - z**3 / 18, solution.sol(np.maximum(z, z0))[0])


def exact_sphere_net(radius: float, spacing: float, n: int) -> np.ndarray:
    """The first quadrant ``(n + 1, n + 1, 3)`` of the net on the exact sphere (pole seed, warp
    along x), every node from its two neighbours by intersecting three spheres."""
    net = np.full((n + 1, n + 1, 3), np.nan)
    angle = 2 * np.arcsin(spacing / (2 * radius)) * np.arange(n + 1)
    zero = np.zeros(n + 1)
    net[:, 0] = radius * np.column_stack([np.sin(angle), zero, np.cos(angle)])
    net[0, :] = radius * np.column_stack([zero, np.sin(angle), np.cos(angle)])
    level = radius**2 - spacing**2 / 2
    for k in range(2, 2 * n + 1):
        i = np.arange(max(1, k - n), min(n, k - 1) + 1)
        j = k - i
        p1, p2, p0 = net[i - 1, j], net[i, j - 1], net[i - 1, j - 1]
        g11, g12, g22 = (p1 * p1).sum(1), (p1 * p2).sum(1), (p2 * p2).sum(1)
        det = g11 * g22 - g12**2
        base = (level * (g22 - g12) / det)[:, None] * p1 + (level * (g11 - g12) / det)[:, None] * p2
        normal = np.cross(p1, p2)
        height2 = (radius**2 - (base * base).sum(1)) / (normal * normal).sum(1)
        height = np.sqrt(np.where(height2 >= 0, height2, np.nan))
        first, second = base + height[:, None] * normal, base - height[:, None] * normal
        far = np.linalg.norm(first - p0, axis=1) > np.linalg.norm(second - p0, axis=1)
        net[i, j] = np.where(far[:, None], first, second)
    return net


def diagonal(positions: np.ndarray, shear: np.ndarray, seed, quadrant) -> tuple:
    """Polar angles (degrees) and shear magnitudes along one diagonal of a net, up to its end."""
    su, sv = quadrant
    out_polar, out_shear = [], []
    for k in range(1, min(positions.shape[:2])):
        a, b = seed[0] + su * k, seed[1] + sv * k
        if not (0 <= a < shear.shape[0] and 0 <= b < shear.shape[1]):
            break
        if not np.isfinite(shear[a, b]):
            break
        out_polar.append(np.degrees(np.arccos(positions[a, b, 2] / R)))
        out_shear.append(su * sv * shear[a, b])
    return np.array(out_polar), np.array(out_shear)


def at_polar(polar: np.ndarray, shear: np.ndarray) -> np.ndarray:
    return CubicSpline(polar, shear)(POLAR)


def exact_diagonal(spacing: float) -> tuple[np.ndarray, np.ndarray]:
    net = exact_sphere_net(R, spacing, int(1.1 * np.pi / 2 * R / spacing))
    warp = net[2:, 1:-1] - net[:-2, 1:-1]
    fill = net[1:-1, 2:] - net[1:-1, :-2]
    cosine = (warp * fill).sum(-1) / np.linalg.norm(warp, axis=-1) / np.linalg.norm(fill, axis=-1)
    shear = 90.0 - np.degrees(np.arccos(cosine))
    k = np.arange(1, len(shear) + 1)
    polar = np.degrees(np.arccos(net[k, k, 2] / R))
    keep = np.isfinite(shear[k - 1, k - 1]) & (polar <= 90.0)
    return polar[keep], shear[k - 1, k - 1][keep]


def hemisphere_table() -> dict:
    print("\nshear (degrees) along the 45° meridians at polar angles", POLAR)
    curves = {}
    for spacing in (2.0, 1.0, 0.5):
        polar, shear = exact_diagonal(spacing)
        curves[("exact", spacing)] = (polar, shear)
        print(f"  exact sphere, spacing {spacing}: {np.round(at_polar(polar, shear), 2)}")
    for rings in (40, 80):
        mesh = irregular_cap(R, 90.0, rings, 0.3, 1)
        for spacing in (2.0, 1.0):
            start = time.perf_counter()
            net = kinematic_net(mesh, [0, 0, R], [1, 0, 0], spacing)
            seconds = time.perf_counter() - start
            shear = net.node_shear
            rows = []
            for quadrant in QUADRANTS:
                polar, values = diagonal(net.positions, shear, net.seed, quadrant)
                rows.append(at_polar(polar, values))
                curves[(rings, spacing, quadrant)] = (polar, values)
            rows = np.array(rows)
            print(
                f"  {rings} rings ({mesh.num_cells} triangles), spacing {spacing} "
                f"({seconds:.2f} s, {net.valid.sum()} nodes): mean {np.round(rows.mean(0), 2)}, "
                f"spread of the 4 meridians {np.round(np.ptp(rows, 0), 2)}"
            )
            for quadrant, row in zip(QUADRANTS, rows, strict=True):
                print(f"      quadrant {quadrant}: {np.round(row, 2)}")
    return curves


def near_seed() -> None:
    print("\nnear the seed: γ / (K u v) − 1 on the diagonal, cap 30°, spacing = edge / 2")
    for rings in (40, 80, 160):
        mesh = irregular_cap(R, 30.0, rings, 0.3, 2)
        edge = R * np.radians(30.0) / rings
        spacing = edge / 2
        net = kinematic_net(mesh, [0, 0, R], [1, 0, 0], spacing, max_length=25.0)
        row = []
        for t in (2.5, 5.0, 10.0, 20.0):
            k = round(t / spacing)
            values = [
                su * sv * net.node_shear[net.seed[0] + su * k, net.seed[1] + sv * k]
                for su, sv in QUADRANTS
            ]
            row.append(np.radians(np.mean(values)) / (K * (k * spacing) ** 2) - 1.0)
        print(f"  edges {edge:.2f} mm: t = 2.5, 5, 10, 20 mm → {np.round(row, 4)}")


def refinement() -> None:
    print("\nmesh and spacing halved together (cap 45°): shear at (u, v) and its change")
    points = [(20, 20), (40, 40), (40, -20), (-30, 20), (-40, -40)]
    net = exact_sphere_net(R, 0.3125, 140)
    warp = net[2:, 1:-1] - net[:-2, 1:-1]
    fill = net[1:-1, 2:] - net[1:-1, :-2]
    cosine = (warp * fill).sum(-1) / np.linalg.norm(warp, axis=-1) / np.linalg.norm(fill, axis=-1)
    exact = 90.0 - np.degrees(np.arccos(cosine))
    reference = np.array(
        [
            np.sign(u * v) * exact[round(abs(u) / 0.3125) - 1, round(abs(v) / 0.3125) - 1]
            for u, v in points
        ]
    )
    print(f"  exact sphere (spacing 0.3125): {np.round(reference, 4)}")
    previous = None
    for rings, spacing in ((15, 2.5), (30, 1.25), (60, 0.625), (120, 0.3125)):
        mesh = irregular_cap(R, 45.0, rings, 0.3, 4)
        net = kinematic_net(mesh, [0, 0, R], [1, 0, 0], spacing, max_length=45.0)
        values = np.array(
            [
                net.node_shear[net.seed[0] + round(u / spacing), net.seed[1] + round(v / spacing)]
                for u, v in points
            ]
        )
        change = "" if previous is None else f", max change {np.abs(values - previous).max():.4f}"
        error = np.abs(values - reference).max()
        print(f"  {rings} rings, spacing {spacing}: max |error| {error:.4f}{change}")
        previous = values


def exact_against_chebyshev() -> None:
    print("\nexact-sphere net against f(K u v): max error at (u, v) = (20..60, 20..60) mm")
    points = [(20, 20), (40, 40), (60, 60), (40, 60)]
    for spacing in (4.0, 2.0, 1.0):
        net = exact_sphere_net(R, spacing, int(64 / spacing) + 2)
        warp = net[2:, 1:-1] - net[:-2, 1:-1]
        fill = net[1:-1, 2:] - net[1:-1, :-2]
        cosine = (warp * fill).sum(-1) / np.linalg.norm(warp, axis=-1)
        cosine /= np.linalg.norm(fill, axis=-1)
        shear = 90.0 - np.degrees(np.arccos(cosine))
        values = np.array([shear[int(u / spacing) - 1, int(v / spacing) - 1] for u, v in points])
        z = np.array([K * u * v for u, v in points])
        print(f"  spacing {spacing}: {np.abs(values - np.degrees(chebyshev_shear(z))).max():.2e}°")


def figures(curves: dict, output: Path) -> None:
    output.mkdir(parents=True, exist_ok=True)
    mesh = irregular_cap(R, 90.0, 40, 0.3, 1)
    drape = kinematic_drape(mesh, [0, 0, R], [1, 0, 0], 2.0)
    triangles = mesh.cells["triangle"]
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.6))
    ax = axes[0]
    art = ax.tripcolor(
        mesh.points[:, 0], mesh.points[:, 1], triangles, facecolors=drape.shear_angle,
        cmap="RdBu_r", vmin=-55, vmax=55,
    )  # fmt: skip
    net = drape.net
    for k in range(0, net.faces.shape[0], 10):
        ax.plot(net.positions[k, :, 0], net.positions[k, :, 1], color="k", lw=0.4)
        ax.plot(net.positions[:, k, 0], net.positions[:, k, 1], color="k", lw=0.4)
    ax.set_aspect("equal")
    ax.set_title(
        "hemisphere R = 100 mm, seen from above: shear angle [°]\n(every 10th yarn, spacing 2 mm)"
    )
    fig.colorbar(art, ax=ax, shrink=0.8)
    ax = axes[1]
    result = producibility(drape.shear_angle, mesh.cell_areas(), locking_angle("woven-twill"))
    codes = np.searchsorted(["limit", "none", "ok", "warn"], result.classes)
    colours = np.array([[0.85, 0.2, 0.15], [0.8, 0.8, 0.8], [0.3, 0.7, 0.4], [0.95, 0.75, 0.2]])
    flat = drape.material_coordinates
    keep = np.isfinite(flat[triangles]).all(axis=(1, 2))
    from matplotlib.collections import PolyCollection

    ax.add_collection(PolyCollection(flat[triangles[keep]], facecolors=colours[codes[keep]], lw=0))
    ax.autoscale()
    ax.set_aspect("equal")
    fractions = ", ".join(f"{k} {100 * v:.1f} %" for k, v in result.fractions.items())
    print(f"\nproducibility, 40 rings, spacing 2, 2/2 twill: {fractions}; {result.summary()}")
    for kind in ("woven-plain", "woven-satin"):
        other = producibility(drape.shear_angle, mesh.cell_areas(), locking_angle(kind))
        print(f"  {kind}: " + ", ".join(f"{k} {100 * v:.1f} %" for k, v in other.fractions.items()))
    print(
        f"  mesh nodes interpolated {drape.node_in_net.mean():.3f}, "
        f"NaN {np.isnan(drape.material_coordinates[:, 0]).mean():.3f}; "
        f"cells NaN {np.isnan(drape.shear_angle).mean():.4f}"
    )
    ax.set_title(f"flat pattern [mm], 2/2 twill (locking 50°, warn 40°):\n{fractions}")
    fig.tight_layout()
    fig.savefig(output / "drape_hemisphere_shear.png", dpi=90)
    plt.close(fig)

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    ax = axes[0]
    polar, shear = curves[("exact", 1.0)]
    exact = CubicSpline(polar, shear)
    for rings, colour in ((40, "tab:orange"), (80, "tab:blue")):
        for quadrant in QUADRANTS:
            p, s = curves[(rings, 1.0, quadrant)]
            keep = p <= polar.max()
            label = f"mesh, {rings} rings" if quadrant == (1, 1) else None
            ax.plot(p[keep], s[keep] - exact(p[keep]), color=colour, lw=0.8, label=label)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("polar angle on the 45° meridian [°]")
    ax.set_ylabel("shear − shear of the exact-sphere net [°]")
    ax.set_title("the four 45° meridians, spacing 1 mm: mesh against exact sphere")
    ax.legend()
    ax = axes[1]
    t = np.linspace(1, 105, 300)
    z = K * t**2
    ax.plot(t, np.degrees(z), "k:", label="K u v")
    ax.plot(t, np.degrees(chebyshev_shear(z)), "k-", label="f(K u v), Chebyshev net")
    net = kinematic_net(mesh, [0, 0, R], [1, 0, 0], 1.0)
    k = np.arange(1, 110)
    values = np.mean(
        [
            su * sv * net.node_shear[net.seed[0] + su * k, net.seed[1] + sv * k]
            for su, sv in QUADRANTS
        ],
        axis=0,
    )
    ax.plot(k * 1.0, values, "r.", ms=3, label="mesh net (40 rings), mean of the 4 diagonals")
    ax.set_xlabel("u = v [mm]")
    ax.set_ylabel("shear angle [°]")
    ax.set_title("shear on the diagonal against the yarn length")
    ax.legend()
    fig.tight_layout()
    fig.savefig(output / "drape_hemisphere_diagonal.png", dpi=90)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=Path("docs/images"))
    args = parser.parse_args()
    exact_against_chebyshev()
    curves = hemisphere_table()
    near_seed()
    refinement()
    figures(curves, args.output)
    print("\nreproduce: python examples/drape_study.py --output docs/images")


if __name__ == "__main__":
    main()
