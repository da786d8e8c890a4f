"""Planning strips of roll width (``plan_strips``, no patterns) on coarse design meshes and the
shipped tent, alone and in pairs: the layouts evaluated, the strips, the widest flattened
strip and the wall time per case, optionally side by side with other sources.

    python benchmarks/strip_planning.py [--cases sail-9,sail-9-pairs,...] [--against OLD/src]

Each case runs in a fresh process (``PYTHONPATH`` = this tree's ``src``, or ``--against``'s),
the two trees in turn, so that both see the same machine. Cases: ``sail-9`` (compas_fd's 90 m
four-point sail, ``tests/data/hypar_sail.obj``, at a 9 m roll), ``sail-9-pairs`` (the same in
pairs), ``sail-5``, ``sail-2.5``, ``wave-1`` (compas-FoFin's 10 m wave at 1 m), ``wave-1-pairs``,
``wave-0.5`` (whole strips refused: cut across, "strips" counts the pieces),
``tent-2.5-pairs`` (``tent_roof()`` at 2.5 m in pairs, as ``vares cut --example conic-tent``
plans it) and ``tent-1.5-pairs``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"
CASES = {
    "sail-9": ("hypar_sail.obj", 9.0, False),
    "sail-9-pairs": ("hypar_sail.obj", 9.0, True),
    "sail-5": ("hypar_sail.obj", 5.0, False),
    "sail-2.5": ("hypar_sail.obj", 2.5, False),
    "wave-1": ("fofin_wave.obj", 1.0, False),
    "wave-1-pairs": ("fofin_wave.obj", 1.0, True),
    "wave-0.5": ("fofin_wave.obj", 0.5, False),
    "tent-2.5-pairs": ("tent", 2.5, True),
    "tent-1.5-pairs": ("tent", 1.5, True),
}
#: One case, run in the child process: prints one JSON line.
CHILD = """
import json, sys, time
from vares.geometry.surface_lines import triangulated
from vares.structures.layout import plan_strips
name, width, pairs = sys.argv[1], float(sys.argv[2]), sys.argv[3] == "1"
if name == "tent":
    from vares.geometry.example_surfaces import tent_roof
    mesh = tent_roof()
else:
    from vares.io.meshes import read_mesh
    mesh = triangulated(read_mesh(name))
start = time.perf_counter()
plan = plan_strips(mesh, width, interlock=pairs)
print(json.dumps({"seconds": time.perf_counter() - start, "evaluations": plan.evaluations,
                  "strips": len(plan.widths), "gaps": [c for c, _ in plan.history],
                  "widest": max(plan.widths), "cells": plan.refined_cells,
                  "cut_across": getattr(plan, "cross_cut", 0)}))
"""


def run(case: str, src: Path) -> dict:
    """One case planned by the sources at ``src``, in a fresh process."""
    mesh, width, pairs = CASES[case]
    mesh = mesh if mesh == "tent" else str(DATA / mesh)
    environment = dict(os.environ, PYTHONPATH=str(src))
    done = subprocess.run(
        [sys.executable, "-c", CHILD, mesh, str(width), "1" if pairs else "0"],
        env=environment,
        capture_output=True,
        text=True,
    )
    if done.returncode:  # a refused plan is a result too: its message, the time until then
        return {"error": done.stderr.strip().splitlines()[-1]}
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=",".join(CASES))
    parser.add_argument("--against", help="another tree's src folder, planned in turn")
    args = parser.parse_args()
    cases = args.cases.split(",")
    unknown = [c for c in cases if c not in CASES]
    if unknown:
        parser.error(f"unknown case(s) {', '.join(unknown)}; known: {', '.join(CASES)}")
    trees = {"this tree": ROOT / "src"}
    if args.against:
        trees["against"] = Path(args.against).resolve()
    print(f"# {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}")
    print("| case | tree | layouts evaluated | gaps tried | strips | widest | cells | time (s) |")
    print("|---|---|---|---|---|---|---|---|")
    for case in cases:
        times = {}
        for label, src in trees.items():
            r = run(case, src)
            if "error" in r:
                print(f"| {case} | {label} | {r['error']} | | | | | |", flush=True)
                continue
            times[label] = r["seconds"]
            strips = (
                f"{r['strips']} ({r['cut_across']} cut across)" if r["cut_across"] else r["strips"]
            )
            print(
                f"| {case} | {label} | {r['evaluations']} | {r['gaps']} | {strips} | "
                f"{r['widest']:.3f} | {r['cells']:,} | {r['seconds']:.1f} |",
                flush=True,
            )
        if len(times) == 2:
            print(f"| {case} | ratio | | | | | | {times['this tree'] / times['against']:.2f} |")
    command = f"python benchmarks/strip_planning.py --cases {args.cases}"
    print(f"\n# reproduce: {command}" + (f" --against {args.against}" if args.against else ""))


if __name__ == "__main__":
    main()
