"""vares against libigl's geometric flatteners, side by side on the same meshes.

    pip install -e ".[benchmark]"        # libigl (and optionally ".[pardiso]", ".[cholmod]")
    python benchmarks/flatteners.py --sizes 10000 30000 100000 300000 1000000 \
        --methods vares lscm arap --save scaling.json --plot docs/images/scaling.png

Surfaces: the 10 m × 10 m hyperbolic paraboloid ``z = 0.06 x y`` and the spherical cap of radius
12 m over the same square, triangulated with about the given number of triangles. Methods:

- ``vares``: ``vares.solve`` with isotropic St. Venant–Kirchhoff (E = 1000, ν = 0.3), default
  strategy and tolerance, from scratch (initial guess included);
- ``lscm``: ``igl.lscm`` with two boundary vertices pinned at their 3D distance;
- ``arap``: LSCM start, ``igl.arap_precomputation`` with one pinned vertex, 10 iterations;
- ``slim``: LSCM start, ``igl.slim_precompute`` (symmetric Dirichlet), 10 iterations.

Each run is a fresh process (after a warm-up on a tiny mesh, so library loading and compiled
code caches are not timed); wall time is measured around the method's calls only, peak memory is
the process's peak resident set (VmHWM), imports included. Every pattern is then judged the same
way: its energy under the common material (St. Venant–Kirchhoff, E = 1000, ν = 0.3,
thickness 1), RMS and maximum edge strain (pattern length / 3D length − 1) and the number of
inverted triangles.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

SURFACES = ("hypar", "cap")
METHODS = ("vares", "lscm", "arap", "slim")


def make_mesh(surface: str, triangles: int):
    import vares

    n = max(2, round(np.sqrt(triangles / 2)))
    if surface == "hypar":
        return vares.examples.hypar(size=10.0, rise=0.06, n=n)
    return vares.examples.cap_over_square(size=10.0, radius=12.0, n=n)


def pins(points: np.ndarray, faces: np.ndarray):
    """Two boundary vertices to pin for LSCM, far apart, at their 3D distance."""
    import igl

    boundary = igl.boundary_loop(faces)
    first = boundary[0]
    second = boundary[np.argmax(np.linalg.norm(points[boundary] - points[first], axis=1))]
    pinned = np.array([first, second], dtype=np.int64)
    distance = np.linalg.norm(points[second] - points[first])
    return pinned, np.array([[0.0, 0.0], [distance, 0.0]])


def run_method(surface: str, triangles: int, method: str, solver: str | None, out: str) -> dict:
    """Run one method in this process; save the pattern to ``out``; return timings."""
    import vares

    mesh = make_mesh(surface, triangles)
    points = np.ascontiguousarray(mesh.points)
    faces = np.ascontiguousarray(mesh.cells["triangle"], dtype=np.int64)
    info: dict[str, object] = {}
    if method == "vares":
        material = vares.materials.StVenantKirchhoff(1000.0, 0.3)
        vares.solve(make_mesh(surface, 50), material, linear_solver=solver)  # warm-up
        start = time.perf_counter()
        result = vares.solve(mesh, material, linear_solver=solver)
        info["time"] = time.perf_counter() - start
        info["iterations"] = result.iterations
        info["converged"] = result.converged
        info["linear_solver"] = result.linear_solver
        info["initial_guess"] = result.initial_guess
        pattern = result.material_coordinates
    else:
        import igl

        small = make_mesh(surface, 50)
        igl.lscm(
            small.points,
            small.cells["triangle"].astype(np.int64),
            *pins(small.points, small.cells["triangle"].astype(np.int64)),
        )  # warm-up
        start = time.perf_counter()
        pinned, values = pins(points, faces)
        uv, _ = igl.lscm(points, faces, pinned, values)
        info["time_initial_guess"] = time.perf_counter() - start
        if method == "arap":
            data = igl.ARAPData()
            data.max_iter = 10
            fixed = np.array([pinned[0]], dtype=np.int32)
            igl.arap_precomputation(points, faces, 2, fixed, data)
            info["time_setup"] = time.perf_counter() - start
            uv = igl.arap_solve(uv[fixed], data, uv)
        elif method == "slim":
            data = igl.slim_precompute(
                np.asfortranarray(points),
                np.asfortranarray(faces.astype(np.int32)),
                np.asfortranarray(uv),
                igl.MappingEnergyType.SYMMETRIC_DIRICHLET,
                np.array([], dtype=np.int32),
                np.zeros((0, 2), order="F"),
                0.0,
            )
            info["time_setup"] = time.perf_counter() - start
            uv = igl.slim_solve(data, 10)
        info["time"] = time.perf_counter() - start
        pattern = np.asarray(uv)[:, :2]
    np.save(out, pattern)
    # this process's own peak resident set (VmHWM starts afresh at exec, unlike ru_maxrss,
    # which a child inherits from a larger parent)
    status = Path("/proc/self/status").read_text()
    info["peak_mib"] = int(status.split("VmHWM:")[1].split()[0]) / 1024
    return info


def judge(mesh, pattern: np.ndarray) -> dict[str, float]:
    import vares
    from vares.mechanics import Problem

    material = vares.materials.StVenantKirchhoff(1000.0, 0.3)
    problem = Problem(mesh, material)
    inverted = problem.inverted_cells(pattern)
    energy = float(np.sum(np.concatenate(problem.evaluate(pattern, order=0).cell_energy)))
    faces = mesh.cells["triangle"]
    edges = np.unique(
        np.sort(np.vstack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1), axis=0
    )
    length3d = np.linalg.norm(mesh.points[edges[:, 0]] - mesh.points[edges[:, 1]], axis=1)
    length2d = np.linalg.norm(pattern[edges[:, 0]] - pattern[edges[:, 1]], axis=1)
    strain = length2d / length3d - 1.0
    return {
        "energy": energy,
        "rms_edge_strain": float(np.sqrt(np.mean(strain**2))),
        "max_edge_strain": float(np.abs(strain).max()),
        "inverted": int(inverted.size),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--surfaces", nargs="+", default=list(SURFACES), choices=SURFACES)
    parser.add_argument("--methods", nargs="+", default=list(METHODS), choices=METHODS)
    parser.add_argument("--solver", default=None, help="vares linear solver (default: fastest)")
    parser.add_argument(
        "--save", type=Path, help="write every row to this JSON file as it is measured"
    )
    parser.add_argument(
        "--plot", type=Path, help="draw time and peak memory against triangles (log-log) here"
    )
    parser.add_argument(
        "--child", nargs=4, metavar=("SURFACE", "SIZE", "METHOD", "OUT"), help=argparse.SUPPRESS
    )
    args = parser.parse_args()
    if args.child:
        surface, size, method, out = args.child
        print(json.dumps(run_method(surface, int(size), method, args.solver, out)))
        return

    import vares

    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, vares {vares.__version__}, linear solvers available: "
        f"{', '.join(vares.solver.available_solvers())}"
    )
    header = (
        f"{'surface':<7} {'triangles':>9} {'method':<6} {'time s':>8} {'setup s':>8} "
        f"{'peak MiB':>9} {'energy':>11} {'RMS strain':>11} {'max strain':>11} "
        f"{'inverted':>8}  notes"
    )
    print(header)
    rows = []
    for surface in args.surfaces:
        for size in args.sizes:
            mesh = make_mesh(surface, size)
            for method in args.methods:
                with tempfile.TemporaryDirectory() as tmp:
                    out = str(Path(tmp) / "pattern.npy")
                    command = [sys.executable, __file__, "--child", surface, str(size), method, out]
                    if args.solver:
                        command += ["--solver", args.solver]
                    process = subprocess.run(command, stdout=subprocess.PIPE, text=True)
                    status, output = process.returncode, process.stdout
                    if status != 0:
                        print(
                            f"{surface:<7} {mesh.num_cells:>9} {method:<6} failed (status {status})"
                        )
                        continue
                    info = json.loads(output.strip().splitlines()[-1])
                    quality = judge(mesh, np.load(out))
                peak = info.pop("peak_mib")
                notes = ""
                if method == "vares":
                    notes = (
                        f"{info['iterations']} iterations, {info['linear_solver']}, start "
                        f"{info['initial_guess']}, converged {info['converged']}"
                    )
                setup = info.get("time_setup", info.get("time_initial_guess", float("nan")))
                print(
                    f"{surface:<7} {mesh.num_cells:>9} {method:<6} {info['time']:>8.3f} "
                    f"{setup:>8.3f} {peak:>9.0f} {quality['energy']:>11.4e} "
                    f"{quality['rms_edge_strain']:>11.3e} {quality['max_edge_strain']:>11.3e} "
                    f"{quality['inverted']:>8d}  {notes}",
                    flush=True,
                )
                rows.append(
                    {
                        "surface": surface,
                        "triangles": mesh.num_cells,
                        "method": method,
                        "peak_mib": peak,
                        **info,
                        **quality,
                    }
                )
                if args.save:
                    args.save.write_text(json.dumps(rows, indent=1))
    if args.plot:
        plot(rows, args.plot)
    command = " ".join(
        ["python benchmarks/flatteners.py", "--sizes", *map(str, args.sizes)]
        + ["--surfaces", *args.surfaces, "--methods", *args.methods]
        + (["--solver", args.solver] if args.solver else [])
    )
    print(f"reproduce: {command}")


def plot(rows: list[dict], path: Path) -> None:
    """Time and peak memory against the number of triangles, log-log, one line per method and
    surface, with slope-1 guide lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    styles = {"vares": "C0", "lscm": "C2", "arap": "C1", "slim": "C3"}
    for surface, marker in zip(SURFACES, ("o", "s"), strict=True):
        for method, colour in styles.items():
            mine = sorted(
                (r for r in rows if r["surface"] == surface and r["method"] == method),
                key=lambda r: r["triangles"],
            )
            if not mine:
                continue
            n = [r["triangles"] for r in mine]
            label = f"{method}, {surface}"
            dashes = "-" if surface == "hypar" else "--"
            axes[0].loglog(
                n, [r["time"] for r in mine], dashes, marker=marker, color=colour, label=label
            )
            axes[1].loglog(
                n, [r["peak_mib"] for r in mine], dashes, marker=marker, color=colour, label=label
            )
    sizes = np.array(sorted({r["triangles"] for r in rows}), dtype=float)
    if sizes.size:
        for axis, key in zip(axes, ("time", "peak_mib"), strict=True):
            top = max(r[key] for r in rows if r["triangles"] == sizes[-1])
            axis.loglog(sizes, top * sizes / sizes[-1], ":", color="grey", label="∝ n")
    axes[0].set(xlabel="triangles", ylabel="wall time (s)", title="time")
    axes[1].set(xlabel="triangles", ylabel="peak resident memory (MiB)", title="memory")
    for axis in axes:
        axis.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    print(f"plot: {path}")


if __name__ == "__main__":
    main()
