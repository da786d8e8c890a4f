"""What a `vares pattern` command costs around its solve: reading, checking, files, previews
and the report, for a 512-triangle sail, a small roof, a 20k-triangle scan and a 100k-triangle
hypar.

    python benchmarks/around_the_solve.py [--repeat 5] [--sizes sail small scan large] [--first]
    python benchmarks/around_the_solve.py --breakdown [--repeat 5] [--sizes sail] [--no-quiet]
    python benchmarks/around_the_solve.py --libraries [--repeat 5]
    PYTHONPATH=src python benchmarks/around_the_solve.py --against OLD/src [--repeat 9]

Every run is a fresh `vares pattern FILE -o DIR --force` process (compiled kernels cached on
disk, as after the first run of an install), in three variants: `--no-previews`, the default
(SVG and PNG previews) and `--report`. Prints the median wall time of the whole process, its
CPU seconds (user + system, as the operating system counts them: the steadier figure on a
machine shared with other work), the solve's own time (``elapsed_seconds`` +
``warm_up_seconds`` of summary.json) and what the report adds; and, first, what merely loading
the libraries a small run imports costs: a script that imports them (numba is not among them:
below 2,000 cells the kernels run as numpy; ``--libraries`` gives each one's share).
``--first``: also the first run after an install, numba's cache of compiled
kernels empty (``NUMBA_CACHE_DIR`` a new folder each run). The command is the ``vares``
script installed beside this Python (a version manager's shim on PATH, such as pyenv's, adds
its own start-up: 0.08 s here), else the one on PATH; it imports the package from PYTHONPATH
first: ``PYTHONPATH=src`` measures this tree's code.

Python's compiled byte code is written and used as on any install (``PYTHONDONTWRITEBYTECODE``
removed from the commands' environment, the byte code kept in a folder of the benchmark's own,
``PYTHONPYCACHEPREFIX``); with ``--no-bytecode`` every module is compiled from source at every
start, as where that variable is set (some containers): compare the two.

``--breakdown``: where the time of a default run goes, phase by phase, wall and CPU seconds,
medians over fresh processes: starting Python, importing the command line, reading and checking
the mesh, loading the solver's compiled kernels, the solve, each output file (the first file to
need a library imports it: the DXF's time includes ezdxf's import), and the rest (arguments,
options, the job file, moving the staging folder into place, exiting); then the libraries'
import times (``-X importtime``, summed per top-level package). The command line's part is
told apart: importing typer, importing the subcommand (numpy, scipy.sparse and the options
with it), and parsing the arguments (typer coerces every parameter through a pydantic
``TypeAdapter``: pydantic's import and one adapter a parameter). ``--no-quiet``: the run
prints its progress and summary (to a pipe), as a user sees it, instead of ``-q``.

``--against SRC``: a default run of this tree and of the sources at SRC (another checkout's
``src/``, e.g. a ``git worktree`` of an earlier commit), in turn, pair by pair: the medians and
the ratio of the two, wall and CPU seconds (on a loaded machine the ratio of one run is what to
quote).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import meshio

from vares import examples

SIZES = {
    "sail": ("four-point sail, 512 triangles (OBJ)", lambda: examples.four_point_sail(n=16)),
    "small": ("roof, 4,608 triangles (OBJ)", lambda: examples.hypar(n=48)),
    "scan": ("scan, 19,573 triangles (OBJ)", lambda: examples.scan_like(triangles=20000)),
    "large": ("hypar, 100,352 triangles (OBJ)", lambda: examples.hypar(n=224)),
}
VARIANTS = {"--no-previews": ["--no-previews"], "default": [], "--report": ["--report"]}


def vares_script() -> str:
    beside = Path(sys.executable).parent / ("vares.exe" if sys.platform == "win32" else "vares")
    return str(beside) if beside.is_file() else "vares"


#: The environment of every command: byte code written and used (or not, ``--no-bytecode``).
ENVIRONMENT = dict(os.environ)


def set_bytecode(write: bool, folder: Path) -> None:
    ENVIRONMENT.pop("PYTHONDONTWRITEBYTECODE", None)
    ENVIRONMENT.pop("PYTHONPYCACHEPREFIX", None)
    if write:
        ENVIRONMENT["PYTHONPYCACHEPREFIX"] = str(folder / "bytecode")
    else:
        ENVIRONMENT["PYTHONDONTWRITEBYTECODE"] = "1"


def run(path: Path, out: Path, flags: list[str]) -> tuple[float, float, float]:
    """Wall and CPU seconds of one `vares pattern` process, and its solve's own seconds."""
    command = [vares_script(), "pattern", str(path), "-o", str(out), "--force", "-q", *flags]
    wall, cpu, _ = timed_run(command)
    summary = json.loads((out / "summary.json").read_text())
    return wall, cpu, summary["elapsed_seconds"] + summary.get("warm_up_seconds", 0.0)


def first_run(path: Path, folder: Path) -> tuple[float, float]:
    """Wall and CPU seconds of a default run as the first after an install: numba's cache of
    compiled kernels empty (``NUMBA_CACHE_DIR`` a new folder), Python's byte code written."""
    cache = Path(tempfile.mkdtemp(dir=folder))
    ENVIRONMENT["NUMBA_CACHE_DIR"] = str(cache)
    try:
        command = [vares_script(), "pattern", str(path), "-o", str(cache / "out"), "-q"]
        return timed_run(command)[:2]
    finally:
        del ENVIRONMENT["NUMBA_CACHE_DIR"]


#: pypardiso imported as vares imports it: told where MKL's runtime is, it does not search the
#: whole environment for it (vares.solver.linear).
PARDISO = """\
import os, pathlib, sys
os.environ.setdefault("PYPARDISO_MKL_RT", str(next(iter(sorted(
    pathlib.Path(sys.prefix, "lib").glob("libmkl_rt.so*"), key=lambda p: len(p.name))), "")))
import pypardiso, threadpoolctl
"""

#: What a small `vares pattern` run loads, without vares (below 2,000 cells numba is not
#: imported), in the order the run imports it, one step a line: the floor of its time.
LIBRARY_STEPS = [
    ("typer", "import typer"),
    ("numpy", "import numpy"),
    ("numpy.f2py, numpy.testing (scipy's array-API layer lists numpy's modules)",
     "import numpy.f2py, numpy.testing"),
    ("scipy.sparse", "import scipy.sparse"),
    ("scipy.sparse.csgraph (it imports scipy.sparse.linalg, scipy.linalg)",
     "import scipy.sparse.csgraph"),
    ("pydantic (typer's parameters)", "import pydantic; pydantic.TypeAdapter"),
    ("rich", "import rich.console, rich.table"),
    ("pypardiso, threadpoolctl (told where MKL is, as vares tells it)", PARDISO),
    ("shapely", "import shapely"),
    ("meshio", "import meshio"),
    ("ezdxf (pyparsing, fontTools)", "import ezdxf"),
    ("Pillow", "import PIL.Image, PIL.ImageDraw, PIL.ImageFont"),
]  # fmt: skip
LIBRARIES = "\n".join(code for _, code in LIBRARY_STEPS) + "\n"
STEPS = """\
import json, sys, time
steps = json.loads(sys.argv[1])
out = []
for code in steps:
    start = time.process_time()
    exec(code)
    out.append(time.process_time() - start)
print(json.dumps(out))
"""


def library_steps(repeat: int) -> None:
    """CPU seconds of each library a small run imports, in turn in one fresh process (what
    the earlier ones share is theirs), medians of ``repeat`` processes."""
    import json

    command = [sys.executable, "-c", STEPS, json.dumps([code for _, code in LIBRARY_STEPS])]
    subprocess.run(command, check=True, capture_output=True, env=ENVIRONMENT)  # byte code
    python = [timed_run([sys.executable, "-c", "pass"])[1] for _ in range(repeat)]
    runs = [json.loads(timed_run(command)[2].stdout) for _ in range(repeat)]
    print("| library (imported in this order, one process) | CPU s |")
    print("|---|---|")
    print(f"| starting Python | {statistics.median(python):.3f} |")
    for k, (label, _) in enumerate(LIBRARY_STEPS):
        print(f"| {label} | {statistics.median(r[k] for r in runs):.3f} |")
    print(f"| all of them | {statistics.median(sum(r) for r in runs):.3f} |")


def libraries_alone(folder: Path, repeat: int) -> tuple[float, float]:
    script = folder / "libraries.py"
    script.write_text(LIBRARIES)
    subprocess.run([sys.executable, str(script)], check=True, env=ENVIRONMENT)  # compiles once
    runs = [timed_run([sys.executable, str(script)])[:2] for _ in range(repeat)]
    return statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)


#: A default `vares pattern` run in a fresh process with each phase timed (the command line's
#: own functions wrapped, nothing else changed); prints the phases' wall and CPU seconds as JSON.
BREAKDOWN = """\
import json, os, sys, time
clocks = lambda: (time.perf_counter(), time.process_time())
started = clocks()
from vares.app.cli import main
typer_imported = clocks()
import vares.app.cli.pattern  # the subcommand's module, as main() imports it
imported = clocks()
from vares.app import outputs, runner
from vares.app.cli import common
from vares.solver import api
phases = {}
marks = {}

def timed(name, function):
    def call(*args, **kwargs):
        start = clocks()
        try:
            return function(*args, **kwargs)
        finally:
            wall, cpu = phases.get(name, (0.0, 0.0))
            end = clocks()
            phases[name] = (wall + end[0] - start[0], cpu + end[1] - start[1])
    return call

pattern = vares.app.cli.pattern
job_from_flags = pattern.job_from_flags

def first_job(*args, **kwargs):  # typer has parsed and coerced the arguments by now
    marks.setdefault("parsed", clocks())
    return job_from_flags(*args, **kwargs)

pattern.job_from_flags = timed("job", first_job)
common.show = timed("printing the summary", common.show)
runner.load_input = timed("read", runner.load_input)
runner._solve = timed("solve", runner._solve)
api._load_kernels = timed("loading the kernels", api._load_kernels)
runner.write_job_file = timed("job.toml", runner.write_job_file)
write = outputs._write
outputs._write = lambda panel, name, writer: timed(name, write)(panel, name, writer)
sys.argv = ["vares", "pattern", *sys.argv[1:]]
end = os._exit
os._exit = lambda code: None  # the command ends the process itself: print first, then end
called = clocks()
try:
    main()
except SystemExit:
    pass
phases["typer"] = (typer_imported[0] - started[0], typer_imported[1] - started[1])
phases["import"] = (imported[0] - typer_imported[0], imported[1] - typer_imported[1])
phases["arguments"] = tuple(marks["parsed"][i] - called[i] for i in range(2))
done = clocks()
phases["command"] = (done[0] - started[0], done[1] - started[1])
print(json.dumps(phases), flush=True)
end(0)
"""


def timed_run(
    command: list[str], environment: dict[str, str] | None = None
) -> tuple[float, float, subprocess.CompletedProcess]:
    """Wall and CPU seconds (user + system, the operating system's own count) of a fresh
    process, and what it printed."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(command, check=True, capture_output=True, env=environment or ENVIRONMENT)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return wall, cpu, done


def breakdown(path: Path, folder: Path, repeat: int, quiet: bool = True) -> None:
    """The phases of a default run, wall and CPU seconds, medians of ``repeat`` fresh
    processes (on a loaded machine the CPU seconds are the steadier figure); ``quiet``: with
    ``-q``, else printing its progress and summary as a user sees them (to a pipe)."""
    script = folder / "breakdown.py"
    script.write_text(BREAKDOWN)
    out = folder / "breakdown"
    command = [sys.executable, str(script), str(path), "-o", str(out), "--force"]
    command += ["-q"] if quiet else []
    subprocess.run(command, check=True, capture_output=True, env=ENVIRONMENT)  # warm
    python = [sys.executable, "-c", "pass"]
    rows: list[dict[str, tuple[float, float]]] = []
    for _ in range(repeat):
        alone = timed_run(python)[:2]
        wall, cpu, done = timed_run(command)
        phases = {k: tuple(v) for k, v in json.loads(done.stdout.decode().splitlines()[-1]).items()}
        kernels = phases.get("loading the kernels", (0.0, 0.0))
        phases["loading the kernels"] = kernels
        phases["solve"] = (phases["solve"][0] - kernels[0], phases["solve"][1] - kernels[1])
        phases["starting Python"] = alone
        phases["whole process"] = (wall, cpu)
        timed = [k for k in phases if k not in ("command", "whole process", "starting Python")]
        phases["the rest"] = tuple(
            phases["command"][i] - sum(phases[k][i] for k in timed) for i in range(2)
        )
        phases["exit"] = tuple(
            phases["whole process"][i] - alone[i] - phases["command"][i] for i in range(2)
        )
        rows.append(phases)
    order = ["whole process", "starting Python", "typer", "import", "arguments", "job", "read"]
    order += ["loading the kernels", "solve"]
    order += [k for k in rows[0] if k not in {*order, "command", "the rest", "exit"}]
    order += ["the rest", "exit"]
    names = {
        "typer": "importing typer (the command line's entry)",
        "import": "importing the subcommand (numpy, scipy.sparse, the options)",
        "arguments": "parsing the arguments (typer: pydantic's import, an adapter a parameter)",
        "job": "the job from the flags (options checked)",
        "read": "reading and checking the mesh",
        "the rest": "the rest of the command (checks, staging folder, moving it into place)",
        "exit": "ending the process, and what the clocks saw outside the command",
    }
    print("| phase | wall s | CPU s |")
    print("|---|---|---|")
    for key in order:
        wall = statistics.median(r[key][0] for r in rows)
        cpu = statistics.median(r[key][1] for r in rows)
        print(f"| {names.get(key, key)} | {wall:.3f} | {cpu:.3f} |")
    importtime(command, repeat)


def side_by_side(path: Path, folder: Path, against: str, repeat: int) -> None:
    """A default run of this tree's code (PYTHONPATH as given) and of the tree whose sources
    are at ``against`` (PYTHONPATH=against), in turn, ``repeat`` pairs: medians of the wall and
    CPU seconds of each, and of their ratio pair by pair (with its range)."""
    command = [vares_script(), "pattern", str(path), "-o", str(folder / "pair"), "--force"]
    variants = {"this tree": dict(ENVIRONMENT), "against": dict(ENVIRONMENT, PYTHONPATH=against)}
    for environment in variants.values():  # byte code written, first
        subprocess.run(command, check=True, capture_output=True, env=environment)
    runs: dict[str, list[tuple[float, float]]] = {name: [] for name in variants}
    for _ in range(repeat):
        for name, environment in variants.items():
            runs[name].append(timed_run(command, environment)[:2])
    print(f"| `vares pattern` ({repeat} pairs, in turn) | wall s | CPU s |")
    print("|---|---|---|")
    for name, figures in runs.items():
        wall = statistics.median(r[0] for r in figures)
        cpu = statistics.median(r[1] for r in figures)
        print(f"| {name if name != 'against' else against} | {wall:.3f} | {cpu:.3f} |")
    for k, label in enumerate(("wall", "CPU")):
        ratios = [a[k] / b[k] for a, b in zip(runs["this tree"], runs["against"], strict=True)]
        spread = f"{min(ratios):.3f}–{max(ratios):.3f}"
        print(f"| ratio, {label} (pair by pair: median, min–max) | "
              f"{statistics.median(ratios):.3f} | {spread} |")  # fmt: skip


def importtime(command: list[str], repeat: int) -> None:
    """The import time of each top-level package in a run (``-X importtime``, self times
    summed per package), medians."""
    totals: list[dict[str, float]] = []
    for _ in range(repeat):
        done = subprocess.run(
            [command[0], "-X", "importtime", *command[1:]],
            check=True,
            capture_output=True,
            env=ENVIRONMENT,
        )
        sums: dict[str, float] = {}
        for line in done.stderr.decode().splitlines():
            if not line.startswith("import time:") or "self [us]" in line:
                continue
            own, _, name = line[len("import time:") :].split("|")
            package = name.strip().split(".")[0]
            sums[package] = sums.get(package, 0.0) + int(own) / 1e6
        totals.append(sums)
    packages = sorted(totals[0], key=lambda k: -totals[0][k])
    print("| package imported | s (under -X importtime, which slows every import) | share |")
    print("|---|---|---|")
    everything = statistics.median(sum(t.values()) for t in totals)
    for package in packages[:12]:
        own = statistics.median(t.get(package, 0.0) for t in totals)
        print(f"| {package} | {own:.3f} | {100 * own / everything:.0f} % |")
    print(f"| all imports | {everything:.3f} | 100 % |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--sizes", nargs="+", default=None, choices=list(SIZES))
    parser.add_argument("--breakdown", action="store_true", help="phase by phase, one size")
    parser.add_argument("--no-bytecode", action="store_true", help="compile every module anew")
    parser.add_argument(
        "--no-quiet", action="store_true", help="breakdown: printing as a user sees it (no -q)"
    )
    parser.add_argument(
        "--libraries", action="store_true", help="each library a small run imports, its CPU"
    )
    parser.add_argument(
        "--against",
        metavar="SRC",
        help="a default run side by side with the sources at SRC (another tree's src/)",
    )
    parser.add_argument(
        "--first", action="store_true", help="also the first run after an install (no numba cache)"
    )
    args = parser.parse_args()
    sizes = args.sizes or (["sail"] if args.breakdown else list(SIZES))
    flags = "".join(
        f" --{name.replace('_', '-')}"
        for name in ("breakdown", "no_bytecode", "first", "no_quiet", "libraries")
        if getattr(args, name)
    ) + (f" --against {args.against}" if args.against else "")
    print(f"# python benchmarks/around_the_solve.py --repeat {args.repeat} --sizes "
          f"{' '.join(sizes)}{flags}")  # fmt: skip
    if args.libraries:
        with tempfile.TemporaryDirectory() as folder:
            set_bytecode(not args.no_bytecode, Path(folder))
            library_steps(args.repeat)
        return
    if args.breakdown or args.against:
        with tempfile.TemporaryDirectory() as folder:
            folder = Path(folder)
            set_bytecode(not args.no_bytecode, folder)
            label, make = SIZES[sizes[0]]
            mesh = make()
            path = folder / f"{sizes[0]}.obj"
            meshio.write(path, meshio.Mesh(mesh.points, list(mesh.cells.items())))
            print(f"{label}, default outputs")
            if args.against:
                side_by_side(path, folder, args.against, args.repeat)
            if args.breakdown:
                breakdown(path, folder, args.repeat, quiet=not args.no_quiet)
        return
    print("| surface | variant | whole command s | CPU s | solve s | rest s |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        set_bytecode(not args.no_bytecode, folder)
        wall, cpu = libraries_alone(folder, args.repeat)
        print(f"| (no surface) | the libraries alone | {wall:.2f} | {cpu:.2f} | | |")
        for size in sizes:
            label, make = SIZES[size]
            mesh = make()
            path = folder / f"{size}.obj"
            meshio.write(path, meshio.Mesh(mesh.points, list(mesh.cells.items())))
            run(path, folder / "warm", [])  # byte code written, kernels compiled or loaded
            if args.first:
                runs = [first_run(path, folder) for _ in range(args.repeat)]
                wall = statistics.median(r[0] for r in runs)
                cpu = statistics.median(r[1] for r in runs)
                print(f"| {label} | first run after install | {wall:.2f} | {cpu:.2f} | | |")
            medians = {}
            for variant, flags in VARIANTS.items():
                runs = [run(path, folder / size, flags) for _ in range(args.repeat)]
                wall, cpu, solve = (statistics.median(r[k] for r in runs) for k in range(3))
                medians[variant] = wall
                print(f"| {label} | {variant} | {wall:.2f} | {cpu:.2f} | {solve:.2f} | "
                      f"{wall - solve:.2f} |")  # fmt: skip
                sys.stdout.flush()
            report = medians["--report"] - medians["default"]
            print(f"| {label} | report adds | {report:.2f} | | | |")


if __name__ == "__main__":
    main()
