"""Time one Newton iteration on a large surface, split into element kernels, assembly and solve.

    python benchmarks/newton_iteration.py [--cells 100000] [--cell-type triangle] [--repeat 3]

The surface is the 10 m × 10 m hyperbolic paraboloid z = 0.06 x y; the pattern is its projection
on the x-y plane (the first iteration of a solve). Material: Neo-Hooke, E = 1000, nu = 0.3.
Times are the best of ``--repeat`` runs; for a solver that keeps its symbolic analysis (PARDISO,
CHOLMOD) the repeated factorisations are numeric only, as in the Newton iterations of a solve.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

import vares
from vares.mechanics import Assembler, Problem, rigid_modes
from vares.solver.linear import available_solvers, get_solver


def best_of(repeat: int, func):
    times, value = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        value = func()
        times.append(time.perf_counter() - start)
    return min(times), value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=100_000, help="approximate number of cells")
    parser.add_argument("--cell-type", default="triangle", choices=["triangle", "quad"])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--solver", default=None, choices=available_solvers())
    args = parser.parse_args()

    per_side = args.cells / (2 if args.cell_type == "triangle" else 1)
    n = max(2, round(np.sqrt(per_side)))
    mesh = vares.examples.hypar(size=10.0, rise=0.06, n=n, cell_type=args.cell_type)
    material = vares.materials.NeoHooke(E=1000.0, nu=0.3)
    problem = Problem(mesh, material)
    x = vares.projection_plane(mesh, "xy").project(mesh.points)

    small = vares.examples.hypar(n=3, cell_type=args.cell_type)  # load compiled code first
    Problem(small, material).evaluate(small.points[:, :2])
    Assembler(small, rigid_modes(small.points[:, :2], "fixed")[0])
    setup, assembler = best_of(1, lambda: Assembler(mesh, rigid_modes(x, "fixed")[0]))
    kernel, evaluation = best_of(args.repeat, lambda: problem.evaluate(x, order=2))
    vector, residual = best_of(args.repeat, lambda: assembler.vector(evaluation.gradients))
    matrix_time, matrix = best_of(args.repeat, lambda: assembler.matrix(evaluation.hessians))
    rhs = -residual.ravel()[assembler.free]
    solver = get_solver(args.solver)

    def linear_solve():
        solver.factorize(matrix)
        return solver.solve(rhs)

    solve_time, _ = best_of(args.repeat, linear_solve)
    print(
        f"machine: {platform.processor() or platform.machine()}, "
        f"{platform.python_implementation()} {platform.python_version()}, numpy {np.__version__}"
    )
    print(
        f"mesh: {mesh.num_cells} {args.cell_type} cells, {mesh.num_points} nodes, "
        f"{assembler.num_free} unknowns, {assembler.nnz} matrix non-zeros"
    )
    print(f"sparsity pattern and scatter map (once per mesh): {setup:8.3f} s")
    print(f"element kernels (energy, gradient, Hessian):      {kernel:8.3f} s")
    print(f"assembly (vector + matrix):                       {vector + matrix_time:8.3f} s")
    print(f"linear solve ({solver.name}, factorise + solve): {solve_time:8.3f} s")
    print(f"kernels + assembly / linear solve: {(kernel + vector + matrix_time) / solve_time:.2f}")
    print(
        "reproduce: python benchmarks/newton_iteration.py "
        f"--cells {args.cells} --cell-type {args.cell_type} --repeat {args.repeat}"
    )


if __name__ == "__main__":
    main()
