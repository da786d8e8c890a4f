"""Every linear solver on the robustness suite, the real-world-like set and any mesh files given.

    python benchmarks/backends.py [--large] [--files DIR_OR_FILE ...] [--solvers NAME ...]

For every surface and every installed linear solver (or those named): a full ``vares.solve``
with the default strategy (Neo-Hooke, E = 1000, ν = 0.3), timed, with every factorisation and
solve of the tangent timed on its own. Printed per row: cells, unknowns, the start, Newton
iterations, the solve's wall time, the slowest linear solve (factorisation + back-substitution)
and that figure per 100k unknowns (a direct solver's cost grows faster than the unknowns, so
this is the figure that must stay at a few seconds). Files are read as the ``vares`` command
reads them (repair included); the real-world-like set is written to files first (the scan as
a binary STL, a soup of unwelded triangles; the CAD roof as an OBJ in millimetres) and read
back the same way. A warm-up solve comes first, so compiled code is loaded.
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
import warnings
from pathlib import Path

import meshio
import numpy as np

import vares
from vares import examples
from vares.io.meshes import read_mesh_file
from vares.solver import linear
from vares.units import unit_factor

MESH_SUFFIXES = {".obj", ".off", ".stl", ".ply", ".vtu", ".vtk", ".msh", ".3dm"}


class Timed:
    """Wraps a linear solver: the wall time of every factorisation + solve pair."""

    def __init__(self, inner) -> None:
        self.inner, self.name, self.times = inner, inner.name, []
        self._started = 0.0

    def factorize(self, matrix) -> None:
        self._started = time.perf_counter()
        self.inner.factorize(matrix)

    def solve(self, rhs):
        out = self.inner.solve(rhs)
        self.times.append(time.perf_counter() - self._started)
        return out


def surfaces(large: bool, files: list[Path], folder: Path):
    """``(name, mesh)`` for the robustness suite, the real-world-like set and the files."""
    for name, make in examples.robustness_suite(fine=True).items():
        yield name, make()
    for name, (make, units) in examples.real_world_suite(large=large).items():
        mesh = make()
        if name.startswith("scan"):
            path = folder / "scan.stl"  # binary STL: every triangle its own three points
            soup = mesh.points[mesh.cells["triangle"]].reshape(-1, 3)
            triangles = np.arange(len(soup)).reshape(-1, 3)
            meshio.write(path, meshio.Mesh(soup, [("triangle", triangles)]), binary=True)
        else:
            path = folder / "roof_mm.obj"
            meshio.write(path, meshio.Mesh(mesh.points, [("triangle", mesh.cells["triangle"])]))
        yield name, read(path, units)
    for entry in files:
        paths = sorted(p for p in entry.iterdir() if p.suffix.lower() in MESH_SUFFIXES)
        for path in paths if entry.is_dir() else [entry]:
            try:
                yield path.name, read(path, None)
            except Exception as exc:  # a file that is no single surface is reported, not fatal
                print(f"{path.name}: not read ({exc})")


def read(path: Path, units: str | None) -> vares.SurfaceMesh:
    source = read_mesh_file(path)
    mesh = source.surface()
    factor = unit_factor(units or source.units or "m", "m")
    return vares.SurfaceMesh(mesh.points * factor, mesh.cells) if factor != 1.0 else mesh


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--large", action="store_true", help="add the 300k-triangle scan")
    parser.add_argument("--files", type=Path, nargs="*", default=[], help="mesh files or folders")
    parser.add_argument("--solvers", nargs="*", default=None, help="default: every installed one")
    args = parser.parse_args()
    solvers = args.solvers or linear.available_solvers()
    material = vares.materials.NeoHooke(1000.0, 0.3)
    for name in solvers:
        vares.solve(examples.hypar(n=4), material, linear_solver=name)  # warm-up
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, vares {vares.__version__}; solvers: {', '.join(solvers)}"
    )
    print(
        f"{'surface':<40} {'cells':>7} {'unknowns':>8} {'solver':<13} {'ok':<3} {'start':<10} "
        f"{'it':>3} {'time s':>7} {'max lin s':>9} {'per 100k':>8}"
    )
    original = linear.get_solver
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for name, mesh in surfaces(args.large, args.files, Path(tmp)):
            for solver in solvers:
                timed: list[Timed] = []

                def wrapped(requested=None, _timed=timed):
                    _timed.append(Timed(original(requested)))
                    return _timed[-1]

                linear.get_solver = wrapped
                vares.solver.api.get_solver = wrapped
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        start = time.perf_counter()
                        result = vares.solve(mesh, material, linear_solver=solver)
                        elapsed = time.perf_counter() - start
                finally:
                    linear.get_solver = original
                    vares.solver.api.get_solver = original
                times = [t for solver_ in timed for t in solver_.times]
                unknowns = 2 * mesh.num_points
                slowest = max(times, default=0.0)
                per = slowest * 1e5 / unknowns
                worst = max(worst, per)
                print(
                    f"{name[:40]:<40} {mesh.num_cells:>7} {unknowns:>8} {solver:<13} "
                    f"{'yes' if result.converged else 'NO':<3} {result.initial_guess:<10} "
                    f"{result.iterations:>3} {elapsed:>7.2f} {slowest:>9.3f} {per:>8.3f}",
                    flush=True,
                )
    print(f"slowest linear solve per 100k unknowns, over every row: {worst:.3f} s")
    command = "python benchmarks/backends.py" + (" --large" if args.large else "")
    if args.files:
        command += " --files " + " ".join(str(f) for f in args.files)
    print(f"reproduce: {command}")


if __name__ == "__main__":
    main()
