"""Every linear solver on the robustness suite, the real-world-like set and any mesh files given.

    python benchmarks/backends.py [--large] [--files DIR_OR_FILE ...] [--solvers NAME ...]

For every surface and every installed linear solver (or those named): a full ``vares.solve``
with the default strategy (Neo-Hooke, E = 1000, ν = 0.3), timed, with every factorisation and
solve of the tangent timed on its own. Printed per row: cells, unknowns, the start, Newton
iterations, factorisations and conjugate-gradient iterations (solvers whose factorisation is dear
reuse it, vares.solver.reuse), the solve's wall time, the slowest linear solve of a Newton step
and that figure per 100k unknowns (a direct solver's cost grows faster than the unknowns, so
this is the figure that must stay at a few seconds). Files are read as the ``vares`` command
reads them (repair included); the real-world-like set is written to files first (the scan as
a binary STL, a soup of unwelded triangles; the CAD roof as an OBJ in millimetres) and read
back the same way. A warm-up solve comes first, so compiled code is loaded.
"""

from __future__ import annotations

import argparse
import importlib
import os
import platform
import tempfile
import time
import warnings
from pathlib import Path
from typing import ClassVar

import meshio
import numpy as np

import vares
from vares import examples
from vares.io.meshes import read_mesh_file
from vares.solver import linear
from vares.solver.reuse import ReusingSolver
from vares.units import unit_factor

MESH_SUFFIXES = {".obj", ".off", ".stl", ".ply", ".vtu", ".vtk", ".msh", ".3dm"}


class Timed(ReusingSolver):
    """The Newton systems' solver, timing every linear solve of a Newton step (a factorisation
    and its solve, or conjugate gradients preconditioned by an earlier factorisation)."""

    times: ClassVar[list[float]] = []

    def __init__(self, solver) -> None:
        super().__init__(solver)
        self._depth = 0

    def solve(self, *args, **kwargs):
        return self._timed(super().solve, *args, **kwargs)

    def exact(self, *args, **kwargs):
        return self._timed(super().exact, *args, **kwargs)

    def _timed(self, call, *args, **kwargs):
        self._depth += 1
        started = time.perf_counter()
        try:
            return call(*args, **kwargs)
        finally:
            self._depth -= 1
            if self._depth == 0:
                Timed.times.append(time.perf_counter() - started)


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
        f"{'it':>3} {'fac':>4} {'cg':>4} {'time s':>7} {'max lin s':>9} {'per 100k':>8}"
    )
    worst = 0.0
    importlib.import_module("vares.solver.newton").ReusingSolver = Timed
    with tempfile.TemporaryDirectory() as tmp:
        for name, mesh in surfaces(args.large, args.files, Path(tmp)):
            for solver in solvers:
                Timed.times = []
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    start = time.perf_counter()
                    result = vares.solve(mesh, material, linear_solver=solver)
                    elapsed = time.perf_counter() - start
                unknowns = 2 * mesh.num_points
                slowest = max(Timed.times, default=0.0)
                per = slowest * 1e5 / unknowns
                worst = max(worst, per)
                print(
                    f"{name[:40]:<40} {mesh.num_cells:>7} {unknowns:>8} {solver:<13} "
                    f"{'yes' if result.converged else 'NO':<3} {result.initial_guess:<10} "
                    f"{result.iterations:>3} {result.factorisations:>4} {result.cg_iterations:>4} "
                    f"{elapsed:>7.2f} {slowest:>9.3f} {per:>8.3f}",
                    flush=True,
                )
    print(f"slowest linear solve per 100k unknowns, over every row: {worst:.3f} s")
    command = "python benchmarks/backends.py" + (" --large" if args.large else "")
    if args.files:
        command += " --files " + " ".join(str(f) for f in args.files)
    print(f"reproduce: {command}")


if __name__ == "__main__":
    main()
