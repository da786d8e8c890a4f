"""Darts where a ply's shear reaches its locking angle (issue 22, item 4).

A woven or stitched ply draped over a mould from the pole with the warp along x
(``vares.analysis.darts.solve_with_darts``, ``darts="auto"``): the pattern solved without darts,
darts placed where its shear reaches the locking angle and lengthened round by round until the
largest shear is below it. Printed per mould: the largest shear before and after, the darts'
number, lengths and mouth openings (the gap between the lips at the boundary in the flat
pattern), every round's tip angle, largest shear, Newton iterations and seconds; and the control
(``--control``): the last round's dart lines made edges of the mesh but not opened.

Moulds: ``hemisphere`` (``irregular_cap(100, 90, rings, 0.3, 1)``, R = 100 mm to the equator),
``rib30`` (the shipped rib, warp along the rib), ``double-dome`` (the shipped double dome,
``double_dome(cell_size=c)`` for every ``--cell-size c``, warp along x; its kinematic drape at
spacing 2 mm from the saddle's centre, the node nearest it and points beside it is printed
first, ``--kinematic``: only that); laws: ``ncf`` (the README's non-crimp fabric,
``NonCrimpFabric([-250, 250], [-250, 250], [0.5])``), ``ncf-stiffening`` (the same with a shear
term ``C₆/6 (I8²/(I4 I6))⁶ = C₆/6 sin¹²γ``, ``C₆ = 200``, that stiffens towards 50°: 28 times
the plain law's shear stiffness there, 0.4 times at 30°; an illustrative choice, not a fitted
fabric) and ``woven`` (orthotropic, E/G = 1e4). On the double dome every solve also prints the
largest shear per quadrant and the yarn strains (the area share beyond 1, 2 and 5 %, and the
largest).

    python benchmarks/darts.py --rings 20 30 40 --control --picture docs/images
    python benchmarks/darts.py --mould rib30 --locking 50 4
    python benchmarks/darts.py --mould double-dome --cell-size 5 4 --law ncf woven
    python benchmarks/darts.py --mould double-dome --radial 35 --law ncf woven
    python benchmarks/darts.py --rings 30 --turned 0 15 30 45 --length 35
    python benchmarks/darts.py --mould double-dome --mirrored 40 30 --law ncf ncf-stiffening
    python benchmarks/darts.py --mould double-dome --splice x y --cell-size 5 4 --law ncf woven
    python benchmarks/darts.py --mould double-dome --splice x --law ncf --picture docs/images

(``--radial``: on the double dome, four given darts along the rays from the domes' centres
``(±55, 0)`` at ``±--ray-angle`` (default 36.9°, towards the most sheared cells) to the x-axis,
from the flange's edge to these plan distances (mm) from the centre. ``--turned``: on the
hemisphere, four given darts of ``--length`` mm from the equator at the 45° meridians, each a
great circle turned by these angles from the meridian, the same way round at every dart,
instead of the automatic ones. ``--mirrored``: on the double dome, the first automatic dart of
the pattern without darts of the plain ``ncf`` law at these tip angles, mirrored across both
planes of symmetry: a symmetric set of four, opened on every ``--law``.)
"""

from __future__ import annotations

import argparse
import itertools
import time
from pathlib import Path

import numpy as np

from vares.analysis.darts import solve_with_darts
from vares.analysis.drape import drape_ply
from vares.analysis.splices import yarn_strain
from vares.geometry.cutting import cut_mesh
from vares.geometry.double_dome import side_darts
from vares.geometry.examples import double_dome, double_dome_height, irregular_cap, rib30
from vares.geometry.surface_lines import EdgeLocator
from vares.materials import NonCrimpFabric, OrthotropicStVenantKirchhoff
from vares.materials.shear_locking import locking_fabric


def locking_laws(stiffness: float) -> dict:
    """The laws that lock at 50° with ``stiffness`` (× the shear modulus 1) there
    (``--locking-stiffness``): the non-crimp fabric's yarns, and yarns ten times stiffer."""
    return {
        "ncf-locking": lambda: locking_fabric(
            [-250.0, 250.0], [-250.0, 250.0], [0.5], 50.0, stiffness
        ),
        "ncf-stiff-locking": lambda: locking_fabric(
            [-2500.0, 2500.0], [-2500.0, 2500.0], [0.5], 50.0, stiffness
        ),
    }


LAWS = {
    "ncf": lambda: NonCrimpFabric([-250.0, 250.0], [-250.0, 250.0], [0.5]),
    "ncf-stiffening": lambda: NonCrimpFabric(
        [-250.0, 250.0], [-250.0, 250.0], [0.5, 0.0, 0.0, 0.0, 0.0, 200.0]
    ),
    "woven": lambda: OrthotropicStVenantKirchhoff(E1=1e4, E2=1e4, G12=1.0, nu12=0.0),
} | locking_laws(100.0)


def mould(name: str, rings: int, cell_size: float = 5.0):
    """The mesh and the warp direction."""
    if name == "hemisphere":
        return irregular_cap(100.0, 90.0, rings, 0.3, 1), (1.0, 0.0, 0.0)
    if name == "double-dome":
        return double_dome(cell_size=cell_size), (1.0, 0.0, 0.0)
    return rib30(), (0.0, 1.0, 0.0)


def kinematic(mesh, warp, locking: float) -> None:
    """The kinematic drape from the saddle's centre (on both planes of symmetry): its largest
    shear, the area at or beyond the locking angle and the share of the area the net reaches;
    then from the node nearest it, and from points 0.01 and 0.1 mm beside it (0.1 mm: across
    the sides of the face the centre lies in)."""
    centre = np.array([0.0, 0.0, float(double_dome_height(np.zeros(1), np.zeros(1))[0])])
    points = mesh.points
    node = points[np.argmin(np.hypot(points[:, 0], points[:, 1]))]
    for seed in (
        centre,
        node,
        centre + np.array([0.01, 0.0, 0.0]),
        centre + np.array([0.0, 0.01, 0.0]),
        centre + np.array([0.1, 0.1, 0.0]),
        centre + np.array([0.1, 0.0, 0.0]),
        centre + np.array([-0.1, 0.0, 0.0]),
        centre + np.array([0.0, 0.1, 0.0]),
        centre + np.array([0.0, -0.1, 0.0]),
    ):
        kinematic_from(mesh, seed, warp, locking)


def kinematic_from(mesh, seed: np.ndarray, warp, locking: float) -> None:
    """The kinematic drape from ``seed`` (see :func:`kinematic`)."""
    clock = time.perf_counter()
    ply = drape_ply(mesh, seed=tuple(seed), warp=warp, spacing=2.0, locking_angle=locking)
    check = ply.producibility
    print(
        f"\nkinematic drape ({mesh.num_cells} cells, seed {np.round(seed, 4).tolist()}, "
        f"spacing 2): "
        f"largest shear {check.max_shear:.2f}°, at or beyond {locking:g}°: "
        f"{100 * check.fractions['limit']:.2f} % of the {100 * check.covered:.1f} % reached; "
        f"{time.perf_counter() - clock:.1f} s"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--mould", choices=("hemisphere", "rib30", "double-dome"), default="hemisphere"
    )
    parser.add_argument("--cell-size", type=float, nargs="+", default=[5.0], help="double dome")
    parser.add_argument("--kinematic", action="store_true", help="double dome: the net only")
    parser.add_argument("--rings", type=int, nargs="+", default=[30])
    parser.add_argument("--law", choices=tuple(LAWS), nargs="+", default=["ncf"])
    parser.add_argument("--locking", type=float, nargs="+", default=[50.0])
    parser.add_argument("--control", action="store_true", help="solve the darts cut but closed")
    parser.add_argument("--picture", type=Path, help="folder for darts_<mould>.png")
    parser.add_argument("--turned", type=float, nargs="+", help="given darts turned (degrees)")
    parser.add_argument("--length", type=float, default=35.0, help="their length (mm)")
    parser.add_argument("--radial", type=float, nargs="+", help="given darts' ends (mm)")
    parser.add_argument("--ray-angle", type=float, default=36.9, help="their rays (degrees)")
    parser.add_argument("--mirrored", type=float, nargs="+", help="tip angles (degrees)")
    parser.add_argument("--side", type=float, nargs="+", help="side darts' plan depths (mm)")
    parser.add_argument("--side-x", type=float, nargs="+", default=[55.0], help="their x (mm)")
    parser.add_argument(
        "--splice", choices=("x", "y"), nargs="+", help="double dome: splice along these axes"
    )
    parser.add_argument(
        "--locking-stiffness", type=float, default=100.0, help="locking laws' stiffness at 50°"
    )
    args = parser.parse_args()
    LAWS.update(locking_laws(args.locking_stiffness))
    if args.splice:
        runs = itertools.product(args.cell_size, args.law, args.splice)
        for index, (size, law, along) in enumerate(runs):
            splice(size, law, args.locking[0], along, args.picture if index == 0 else None)
        return
    if args.side:
        for size, law, depth in itertools.product(args.cell_size, args.law, args.side):
            side(size, law, args.locking[0], depth, args.side_x)
        return
    if args.mirrored:
        for size in args.cell_size:
            mirrored(size, args.law, args.locking[0], args.mirrored)
        return
    if args.radial:
        for size, law, end in itertools.product(args.cell_size, args.law, args.radial):
            radial(size, law, args.locking[0], end, args.ray_angle)
        return
    if args.turned:
        for rings in args.rings:
            turned(rings, args.law[0], args.locking[0], args.turned, args.length)
        return
    sizes = args.cell_size if args.mould == "double-dome" else [0.0]
    rings_list = args.rings if args.mould == "hemisphere" else [0]
    for rings, size in ((r, c) for r in rings_list for c in sizes):
        mesh, warp = mould(args.mould, rings, size)
        if args.mould == "double-dome":
            kinematic(mesh, warp, args.locking[0])
            if args.kinematic:
                continue
        for law in args.law:
            for locking in args.locking:
                clock = time.perf_counter()
                darted = solve_with_darts(
                    mesh, LAWS[law](), locking_angle=locking, darts="auto", warp_direction=warp
                )
                total = time.perf_counter() - clock
                s = darted.summary()
                print(
                    f"\n{args.mould} {rings or size or ''} ({mesh.num_cells} cells), {law}, "
                    f"locking {locking:g}°: before {s['max_shear_before']:.2f}° "
                    f"({s['iterations_before']} it, {s['seconds_before']:.1f} s); "
                    f"total {total:.1f} s"
                )
                for r in s["rounds"]:
                    lengths = ", ".join(f"{v:.4g}" for v in r["lengths"])
                    print(
                        f"  tip {r['tip_angle']:.1f}°: darts {lengths}; largest shear "
                        f"{r['max_shear']:.2f}°, {r['iterations']} it, {r['seconds']:.1f} s, "
                        f"converged {r['converged']}"
                    )
                if darted.after is not None:
                    openings = ", ".join(f"{v:.4g}" for v in s["mouth_openings"])
                    print(
                        f"  after: {s['darts']} darts, largest shear {s['max_shear_after']:.2f}°, "
                        f"relieved {s['relieved']}, mouth openings {openings}"
                    )
                    for line in darted.dart_lines:
                        mouth, tip = line[0], line[-1]
                        print(
                            f"    dart from {np.round(mouth, 2).tolist()} to "
                            f"{np.round(tip, 2).tolist()}, azimuth "
                            f"{np.degrees(np.arctan2(mouth[1], mouth[0])):.1f}°"
                        )
                if args.mould == "double-dome":
                    quadrants(darted)
                if args.control and darted.after is not None:
                    locate = EdgeLocator(mesh, tolerance=1e-6 * float(np.ptp(mesh.points)))
                    lines = [locate.line(line) for line in darted.dart_lines]
                    closed = cut_mesh(mesh, lines, panels=False).mesh
                    from vares import solve

                    result = solve(closed, LAWS[law](), warp_direction=warp)
                    largest = float(np.abs(result.fields["shear_angle"]).max())
                    print(
                        f"  control, the darts cut but not opened: largest shear {largest:.2f}°, "
                        f"converged {result.converged}, {result.iterations} it"
                    )
                if args.picture is not None and darted.after is not None:
                    import matplotlib.pyplot as plt

                    from vares.io.dart_plots import plot_darts

                    figure = plot_darts(darted)
                    path = args.picture / f"darts_{args.mould.replace('-', '_')}.png"
                    figure.savefig(path)
                    plt.close(figure)
                    print(f"  wrote {path}")


def turned(rings: int, law: str, locking: float, angles: list[float], length: float) -> None:
    """Given darts on the hemisphere, turned from the meridians (module docs)."""
    mesh, warp = mould("hemisphere", rings)
    for angle in angles:
        lines = []
        for azimuth in np.radians([45.0, 135.0, 225.0, 315.0]):
            mouth = np.array([np.cos(azimuth), np.sin(azimuth), 0.0])
            along = np.array([-np.sin(azimuth), np.cos(azimuth), 0.0])
            a = np.radians(angle)
            heading = np.cos(a) * np.array([0.0, 0.0, 1.0]) + np.sin(a) * along
            s = np.linspace(0.0, length / 100.0, 12)[:, None]
            lines.append(100.0 * (np.cos(s) * mouth + np.sin(s) * heading))
        _, text = given(mesh, law, locking, lines, warp)
        print(
            f"hemisphere {rings} ({mesh.num_cells} cells), {law}, darts turned {angle:g}° from "
            f"the meridian: {text}"
        )


def radial(cell_size: float, law: str, locking: float, end: float, angle: float) -> None:
    """Given darts on the double dome, along rays from the domes' centres (module docs)."""
    mesh, warp = mould("double-dome", 0, cell_size)
    lines = []
    for sx in (1.0, -1.0):
        for sy in (1.0, -1.0):
            ray = np.array([sx * np.cos(np.radians(angle)), sy * np.sin(np.radians(angle))])
            xy = np.array([55.0 * sx, 0.0]) + np.linspace(end, 120.0, 200)[:, None] * ray
            xy = xy[(xy[:, 0] / 155.0) ** 2 + (xy[:, 1] / 100.0) ** 2 < 0.999]
            lines.append(np.column_stack([xy, double_dome_height(xy[:, 0], xy[:, 1])])[::-1])
    darted, text = given(mesh, law, locking, lines, warp)
    print(
        f"double dome {cell_size:g} ({mesh.num_cells} cells), {law}, darts along rays at "
        f"{angle:g}° to {end:g} mm of the domes' centres: {text}"
    )
    quadrants(darted)


def side(cell_size: float, law: str, locking: float, depth: float, xs: list[float]) -> None:
    """Given darts on the double dome from its long sides: at every ``x`` of ``xs`` and its
    mirror image, from the outline along ∓y (across the warp), ``depth`` mm in the plan
    (module docs)."""
    mesh, warp = mould("double-dome", 0, cell_size)
    lines = side_darts(xs, depth)
    darted, text = given(mesh, law, locking, lines, warp)
    print(
        f"double dome {cell_size:g} ({mesh.num_cells} cells), {law}, {len(lines)} darts from the "
        f"sides at x = ±{', ±'.join(f'{v:g}' for v in xs)}, {depth:g} mm deep: {text}"
    )
    quadrants(darted)


def splice(cell_size: float, law: str, locking: float, along: str, picture: Path | None) -> None:
    """The double dome spliced along a plane of symmetry (``along`` x: y = 0, through both domes;
    y: x = 0, across the saddle; ``vares.geometry.double_dome.axis_splice``): the largest shear
    of the whole ply and the share of its area beyond the locking angle that is negatively
    curved; per piece the largest shear, its yarn strains (cells and nodal means), iterations,
    and the kinematic net's largest shear on the piece (``drape_pieces``: from the piece's node
    nearest its nodes' centroid, warp along x, spacing 2 mm). With ``picture``:
    ``splices_double_dome.png`` there (the run passes it to the first mesh, law and axis
    only)."""
    from vares.analysis.darts import over_locking_curvature
    from vares.analysis.drape_options import DrapeOptions
    from vares.analysis.splices import drape_pieces, solve_with_splices
    from vares.geometry.double_dome import axis_splice

    mesh, warp = mould("double-dome", 0, cell_size)
    clock = time.perf_counter()
    ply = solve_with_splices(
        mesh,
        LAWS[law](),
        locking_angle=locking,
        polylines=[axis_splice(along)],
        warp_direction=warp,
    )
    seconds = time.perf_counter() - clock
    if picture is not None:
        import matplotlib.pyplot as plt

        from vares.io.dart_plots import plot_splices

        figure = plot_splices(ply)
        figure.savefig(picture / "splices_double_dome.png")
        plt.close(figure)
    shares = over_locking_curvature(ply.before, locking)
    whole, whole_mean = yarn_strain(ply.before), yarn_strain(ply.before, nodal_mean=True)
    print(
        f"double dome {cell_size:g} ({mesh.num_cells} cells), {law}, spliced along {along}: "
        f"whole ply {ply.max_shear_before:.2f}° ({ply.before.iterations} it, converged "
        f"{ply.before.converged}; yarn strain largest {100 * whole.max():.2f} %, nodal mean "
        f"{100 * whole_mean.max():.2f} %); beyond {locking:g}°: "
        f"{100 * shares['negative']:.0f} % negatively, {100 * shares['positive']:.0f} % "
        f"positively curved; pieces {ply.max_shear_after:.2f}°, relieved {ply.relieved}; "
        f"{seconds:.1f} s in all, {ply.seconds:.1f} s for the pieces"
    )
    ply = drape_pieces(ply, DrapeOptions(spacing=2.0, locking_angle=locking), warp)
    for piece, result, net in zip(ply.pieces, ply.results, ply.nets, strict=True):
        strain, mean = yarn_strain(result), yarn_strain(result, nodal_mean=True)
        print(
            f"  {piece.name}: {result.mesh.num_cells} cells, largest shear "
            f"{np.abs(result.fields['shear_angle']).max():.2f}° ({result.iterations} it, "
            f"converged {result.converged}); yarn strain beyond 2 %: "
            f"{100 * np.mean(strain > 0.02):.2f} % of the cells, largest {100 * strain.max():.2f} "
            f"%, nodal mean {100 * mean.max():.2f} %; kinematic net from "
            f"{np.round(net.seed, 2).tolist()}: {net.producibility.max_shear:.2f}°"
        )


def mirrored(cell_size: float, laws: list[str], locking: float, tips: list[float]) -> None:
    """Symmetric darts on the double dome: the first automatic dart of the plain ``ncf``
    pattern at each tip angle, mirrored across x = 0 and y = 0 (module docs)."""
    from vares import solve
    from vares.analysis.dart_lines import erected_yarns, place_darts

    mesh, warp = mould("double-dome", 0, cell_size)
    plain = solve(mesh, LAWS["ncf"](), warp_direction=warp)
    fibres = plain.fibres
    yarns = erected_yarns(mesh, plain.material_coordinates, fibres.warp, fibres.fill)
    for tip in tips:
        first = place_darts(mesh, plain.fields["shear_angle"], *yarns, locking, tip)[0].points
        lines = [first * np.array([sx, sy, 1.0]) for sx in (1.0, -1.0) for sy in (1.0, -1.0)]
        for law in laws:
            darted, text = given(mesh, law, locking, lines, warp)
            print(
                f"double dome {cell_size:g} ({mesh.num_cells} cells), {law}, the ncf pattern's "
                f"first dart at tip {tip:g}° mirrored into four: {text}"
            )
            quadrants(darted)


def given(mesh, law: str, locking: float, lines: list[np.ndarray], warp):
    """The pattern with the given dart ``lines`` open, and the line printed of it: the largest
    shear before and after, the solve's iterations, the darts' lengths and mouth openings."""
    clock = time.perf_counter()
    darted = solve_with_darts(
        mesh, LAWS[law](), locking_angle=locking, polylines=lines, warp_direction=warp
    )
    s = darted.summary()
    if not s["rounds"]:
        return darted, f"before {s['max_shear_before']:.2f}°, no solve with the darts"
    r = s["rounds"][0]
    openings = ", ".join(f"{v:.4g}" for v in s["mouth_openings"])
    lengths = ", ".join(f"{v:.4g}" for v in s["dart_lengths"])
    return darted, (
        f"before {s['max_shear_before']:.2f}°, after {r['max_shear']:.2f}° "
        f"({r['iterations']} it, converged {r['converged']}); lengths {lengths}; mouths "
        f"{openings}; {time.perf_counter() - clock:.1f} s"
    )


def quadrants(darted) -> None:
    """The largest shear of every quadrant (signs of x and y) before and after the darts, and
    the yarn strains: the area share beyond 1, 2 and 5 % and the largest."""
    for name, result in (("before", darted.before), ("after", darted.after)):
        if result is None:
            continue
        centres = result.mesh.points[result.mesh.cells["triangle"]].mean(axis=1)
        shear = np.abs(result.fields["shear_angle"])
        largest = [
            shear[(np.sign(centres[:, 0]) == sx) & (np.sign(centres[:, 1]) == sy)].max()
            for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1))
        ]
        strain, mean = yarn_strain(result), yarn_strain(result, nodal_mean=True)
        areas = result.mesh.cell_areas()
        beyond = areas[shear >= darted.locking_angle].sum() / areas.sum()
        shares = [100 * areas[strain > limit].sum() / areas.sum() for limit in (0.01, 0.02, 0.05)]
        means = [100 * areas[mean > limit].sum() / areas.sum() for limit in (0.005, 0.01, 0.02)]
        print(
            f"  {name}: largest shear per quadrant (+,+) (-,+) (-,-) (+,-): "
            + ", ".join(f"{v:.2f}°" for v in largest)
            + f", {100 * beyond:.2f} % of the area at or beyond {darted.locking_angle:g}°"
            + "; yarn strain beyond 1, 2, 5 %: "
            + ", ".join(f"{v:.2f} %" for v in shares)
            + f" of the area, largest {100 * strain.max():.2f} %; nodal mean beyond 0.5, 1, 2 %: "
            + ", ".join(f"{v:.2f} %" for v in means)
            + f", largest {100 * mean.max():.2f} %"
        )


if __name__ == "__main__":
    main()
