"""The race: a full vares solve against libigl's LSCM + ARAP (10 iterations), same process, warm.

    pip install -e ".[benchmark]"       # libigl
    python benchmarks/race.py --triangles 100000 --repeat 5 [--solver scipy-superlu]
    python benchmarks/race.py --file camelhead.off --file face.obj --repeat 3

Surface: the 10 m × 10 m hyperbolic paraboloid ``z = 0.06 x y``, or each mesh file given with
``--file`` (read as the ``vares`` command reads it, repair included), raced one after the other
in the same process. Both methods first run once on the same mesh (numba and libigl code
compiled and loaded, memory touched); then they run ``--repeat`` times each, alternately, and
the median wall time of each is reported with their ratio. vares solves from scratch every
time: from the point and cell arrays (a new ``SurfaceMesh``, its checks and cached tables
timed), isotropic St. Venant–Kirchhoff (the hypar) or Neo-Hooke (files: on the camel head St.
Venant–Kirchhoff does not converge in 50 + 50 iterations), E = 1000, ν = 0.3, default strategy,
start and tolerance 1e-10 (``--also-initial-guess`` races a named start beside it), its sparse
solver's symbolic analysis forgotten between runs. A solve whose Newton iteration reached the
tolerance counts even where the pattern is then refused (a nearly closed head is no cutting
pattern: its area is far from the surface's): the race is the cost of the optimum, and the
refusal is printed. libigl runs LSCM with two pinned boundary
vertices, then ``arap_precomputation`` with one pinned vertex and 10 ARAP iterations. Peak
memory is the process's (both methods together).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time
import warnings
from pathlib import Path

import numpy as np


def make_mesh(triangles: int):
    import vares

    n = max(2, round(np.sqrt(triangles / 2)))
    return vares.examples.hypar(size=10.0, rise=0.06, n=n)


MATERIALS = ("stvk", "neo-hooke")


def run_vares(
    mesh, solver: str | None, material: str = "stvk", initial_guess: str = "auto"
) -> tuple[float, dict]:
    import vares
    from vares.solver import linear

    linear.forget_pardiso_analysis()  # from scratch: no symbolic analysis kept from a run before
    law = vares.materials.StVenantKirchhoff if material == "stvk" else vares.materials.NeoHooke
    points, cells = mesh.points.copy(), {k: v.copy() for k, v in mesh.cells.items()}
    start = time.perf_counter()
    # from the arrays, as libigl gets them: the mesh's checks and cached tables are timed too
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # which start was passed over is in the result
        result = vares.solve(
            vares.SurfaceMesh(points, cells),
            law(1000.0, 0.3),
            linear_solver=solver,
            initial_guess=initial_guess,
        )
    elapsed = time.perf_counter() - start
    last = result.history[-1]
    reached = last.residual <= result.options.tolerance * last.residual / last.relative_residual
    assert result.converged or reached, result.reason
    return elapsed, {
        "iterations": result.iterations,
        "solver": result.linear_solver,
        "factorisations": result.factorisations,
        "cg": result.cg_iterations,
        "start": result.initial_guess,
        "energy": result.energy,
        "refused": result.reason,
    }


def run_arap(mesh) -> tuple[float, dict]:
    import igl
    from flatteners import pins  # the same LSCM pins as the flatteners benchmark

    points = np.ascontiguousarray(mesh.points)
    faces = np.ascontiguousarray(mesh.cells["triangle"], dtype=np.int64)
    start = time.perf_counter()
    pinned, values = pins(points, faces)
    uv, _ = igl.lscm(points, faces, pinned, values)
    data = igl.ARAPData()
    data.max_iter = 10
    fixed = np.array([pinned[0]], dtype=np.int32)
    igl.arap_precomputation(points, faces, 2, fixed, data)
    igl.arap_solve(uv[fixed], data, uv)
    return time.perf_counter() - start, {}


def peak_mib() -> float:
    status = Path("/proc/self/status").read_text()
    return int(status.split("VmHWM:")[1].split()[0]) / 1024


def race(
    mesh, name: str, repeat: int, solver: str | None, material: str, also: str | None = None
) -> float:
    """Both methods on ``mesh``, warm, alternating; prints the medians; returns their ratio.
    ``also``: vares is raced a second time from that start (``projection``, ``lscm``,
    ``tutte``: a start asked for by name, never taken an ARAP step further), in the same
    alternation, so the two starts compare side by side."""
    variants = {"vares": "auto"} | ({f"vares ({also})": also} if also else {})
    for guess in variants.values():  # warm-up: compiled code, loaded libraries, touched memory
        run_vares(mesh, solver, material, guess)
    run_arap(mesh)
    times: dict[str, list[float]] = {name: [] for name in variants} | {"arap": []}
    info: dict[str, dict] = {}
    for _ in range(repeat):
        for variant, guess in variants.items():
            elapsed, info[variant] = run_vares(mesh, solver, material, guess)
            times[variant].append(elapsed)
        times["arap"].append(run_arap(mesh)[0])
    median = {k: statistics.median(v) for k, v in times.items()}
    print(f"{name}, {mesh.num_cells} triangles:")
    for method, values in times.items():
        shown = ", ".join(f"{v:.3f}" for v in values)
        print(f"  {method:<18} median {median[method]:.3f} s  (runs: {shown})")
    for variant in variants:
        ratio = median[variant] / median["arap"]
        found = info[variant]
        print(
            f"  {variant} / (LSCM + ARAP) = {ratio:.2f}; from {found['start']}, "
            f"{found['iterations']} Newton iterations, {found['solver']} "
            f"({found['factorisations']} factorisations, {found['cg']} CG iterations), "
            f"energy {found['energy']:.12g}"
        )
        if found["refused"]:
            print(f"  (the optimum reached, then refused as a pattern: {found['refused']})")
    return median["vares"] / median["arap"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--triangles", type=int, default=100_000)
    parser.add_argument("--file", type=Path, action="append", default=[], help="mesh file")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--solver", default=None, help="vares linear solver (default: fastest)")
    parser.add_argument(
        "--material", choices=MATERIALS, help="default: stvk (hypar), neo-hooke (files)"
    )
    parser.add_argument(
        "--also-initial-guess",
        choices=("projection", "lscm", "tutte"),
        help="race vares from this start too (never ARAP-refined), side by side",
    )
    args = parser.parse_args()
    import vares

    missing = [str(path) for path in args.file if not path.is_file()]
    if missing:
        parser.error(f"no such mesh file: {', '.join(missing)}")
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, vares {vares.__version__}"
    )
    if args.file:
        for path in args.file:
            race(
                vares.read_mesh(path),
                path.name,
                args.repeat,
                args.solver,
                args.material or "neo-hooke",
                args.also_initial_guess,
            )
    else:
        mesh = make_mesh(args.triangles)
        material = args.material or "stvk"
        race(mesh, "hypar", args.repeat, args.solver, material, args.also_initial_guess)
    print(f"peak {peak_mib():.0f} MiB")
    source = " ".join(f"--file {path}" for path in args.file) or f"--triangles {args.triangles}"
    command = f"python benchmarks/race.py {source} --repeat {args.repeat}"
    command += f" --solver {args.solver}" if args.solver else ""
    command += f" --material {args.material}" if args.material else ""
    also = args.also_initial_guess
    print(f"reproduce: {command}" + (f" --also-initial-guess {also}" if also else ""))


if __name__ == "__main__":
    main()
