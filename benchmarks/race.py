"""The race: a full vares solve against libigl's LSCM + ARAP (10 iterations), same process, warm.

    pip install -e ".[benchmark]"       # libigl
    python benchmarks/race.py --triangles 100000 --repeat 5 [--solver scipy-superlu]

Surface: the 10 m × 10 m hyperbolic paraboloid ``z = 0.06 x y``. Both methods first run once on
the same mesh (numba and libigl code compiled and loaded, memory touched); then they run
``--repeat`` times each, alternately, and the median wall time of each is reported with their
ratio. vares solves from scratch every time: from the point and cell arrays (a new
``SurfaceMesh``, its checks and cached tables timed), isotropic St. Venant–Kirchhoff, E = 1000,
ν = 0.3, default strategy and tolerance 1e-10, its sparse solver's symbolic analysis forgotten
between runs; libigl runs LSCM with two pinned boundary vertices, then
``arap_precomputation`` with one pinned vertex and 10 ARAP iterations. Peak memory is the
process's (both methods together).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np


def make_mesh(triangles: int):
    import vares

    n = max(2, round(np.sqrt(triangles / 2)))
    return vares.examples.hypar(size=10.0, rise=0.06, n=n)


def run_vares(mesh, solver: str | None) -> tuple[float, dict]:
    import vares
    from vares.solver import linear

    linear._PARDISO_ANALYSED = None  # from scratch: no symbolic analysis kept from a run before
    material = vares.materials.StVenantKirchhoff(1000.0, 0.3)
    points, cells = mesh.points.copy(), {k: v.copy() for k, v in mesh.cells.items()}
    start = time.perf_counter()
    # from the arrays, as libigl gets them: the mesh's checks and cached tables are timed too
    result = vares.solve(vares.SurfaceMesh(points, cells), material, linear_solver=solver)
    elapsed = time.perf_counter() - start
    assert result.converged, result.reason
    return elapsed, {
        "iterations": result.iterations,
        "solver": result.linear_solver,
        "factorisations": result.factorisations,
        "cg": result.cg_iterations,
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--triangles", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--solver", default=None, help="vares linear solver (default: fastest)")
    args = parser.parse_args()
    import vares

    mesh = make_mesh(args.triangles)
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, vares {vares.__version__}; hypar with "
        f"{mesh.num_cells} triangles"
    )
    run_vares(mesh, args.solver)  # warm-up: compiled code, loaded libraries, touched memory
    run_arap(mesh)
    times: dict[str, list[float]] = {"vares": [], "arap": []}
    info = {}
    for _ in range(args.repeat):
        elapsed, info = run_vares(mesh, args.solver)
        times["vares"].append(elapsed)
        times["arap"].append(run_arap(mesh)[0])
    median = {k: statistics.median(v) for k, v in times.items()}
    for name, values in times.items():
        shown = ", ".join(f"{v:.3f}" for v in values)
        print(f"{name:<6} median {median[name]:.3f} s  (runs: {shown})")
    print(
        f"vares / (LSCM + ARAP) = {median['vares'] / median['arap']:.2f}; vares: "
        f"{info['iterations']} Newton iterations, {info['solver']} ({info['factorisations']} "
        f"factorisations, {info['cg']} CG iterations); peak {peak_mib():.0f} MiB"
    )
    command = f"python benchmarks/race.py --triangles {args.triangles} --repeat {args.repeat}"
    print(f"reproduce: {command}" + (f" --solver {args.solver}" if args.solver else ""))


if __name__ == "__main__":
    main()
