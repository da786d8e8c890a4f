"""What a `vares pattern` command costs around its solve: reading, checking, files, previews
and the report, for a small roof, a 20k-triangle scan and a 100k-triangle hypar.

    python benchmarks/around_the_solve.py [--repeat 5] [--sizes small scan large]

Every run is a fresh `vares pattern FILE -o DIR --force` process (compiled kernels cached on
disk, as after the first run of an install), in three variants: `--no-previews`, the default
(SVG and PNG previews) and `--report`. Prints the median wall time of the whole process, the
solve's own time (``elapsed_seconds`` + ``warm_up_seconds`` of summary.json) and what the
report adds; and, first, what merely loading the libraries a run uses costs: a script that
imports them and calls one compiled (cached) numba function, the floor under any command.
The command is the ``vares`` script installed beside this Python (a version manager's shim on
PATH, such as pyenv's, adds its own start-up: 0.08 s here), else the one on PATH; it imports
the package from PYTHONPATH first: ``PYTHONPATH=src`` measures this tree's code.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import meshio

from vares import examples

SIZES = {
    "small": ("roof, 4,608 triangles (OBJ)", lambda: examples.hypar(n=48)),
    "scan": ("scan, 19,573 triangles (OBJ)", lambda: examples.scan_like(triangles=20000)),
    "large": ("hypar, 100,352 triangles (OBJ)", lambda: examples.hypar(n=224)),
}
VARIANTS = {"--no-previews": ["--no-previews"], "default": [], "--report": ["--report"]}


def vares_script() -> str:
    beside = Path(sys.executable).parent / ("vares.exe" if sys.platform == "win32" else "vares")
    return str(beside) if beside.is_file() else "vares"


def run(path: Path, out: Path, flags: list[str]) -> tuple[float, float]:
    command = [vares_script(), "pattern", str(path), "-o", str(out), "--force", "-q", *flags]
    start = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    wall = time.perf_counter() - start
    summary = json.loads((out / "summary.json").read_text())
    return wall, summary["elapsed_seconds"] + summary.get("warm_up_seconds", 0.0)


#: What a `vares pattern` run loads, without vares: the floor of its time.
LIBRARIES = """\
import numpy as np, scipy.sparse, scipy.sparse.csgraph, scipy.spatial, numba
import ezdxf, typer, rich, meshio, shapely, PIL.Image

@numba.njit(cache=True)
def first(x):
    return x.sum()

first(np.ones(3))
"""


def libraries_alone(folder: Path, repeat: int) -> float:
    script = folder / "libraries.py"
    script.write_text(LIBRARIES)
    subprocess.run([sys.executable, str(script)], check=True)  # compiles once, cached after
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run([sys.executable, str(script)], check=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--sizes", nargs="+", default=list(SIZES), choices=list(SIZES))
    args = parser.parse_args()
    print(f"# python benchmarks/around_the_solve.py --repeat {args.repeat} --sizes "
          f"{' '.join(args.sizes)}")  # fmt: skip
    print("| surface | variant | whole command s | solve s | rest s |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        floor = libraries_alone(folder, args.repeat)
        print(f"| (no surface) | the libraries alone | {floor:.2f} | | |")
        for size in args.sizes:
            label, make = SIZES[size]
            mesh = make()
            path = folder / f"{size}.obj"
            meshio.write(path, meshio.Mesh(mesh.points, list(mesh.cells.items())))
            run(path, folder / "warm", [])  # compiles on a fresh install, loads afterwards
            medians = {}
            for variant, flags in VARIANTS.items():
                runs = [run(path, folder / size, flags) for _ in range(args.repeat)]
                wall = statistics.median(r[0] for r in runs)
                solve = statistics.median(r[1] for r in runs)
                medians[variant] = wall
                print(f"| {label} | {variant} | {wall:.2f} | {solve:.2f} | {wall - solve:.2f} |")
                sys.stdout.flush()
            report = medians["--report"] - medians["default"]
            print(f"| {label} | report adds | {report:.2f} | | |")


if __name__ == "__main__":
    main()
