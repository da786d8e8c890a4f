"""The cutting examples of docs/cutting.md: the saddle and the conic tent at two roll widths.

    python benchmarks/cutting.py [--out DIR] [--images docs/images]

Each case is the job of ``vares cut --example NAME --roll-width W --fabric pes-pvc-type-2
--prestress 2,1.5 --allowance 20 …`` (the options are printed), run through the one runner; the
script prints per case the strips, the widest pattern with its allowances, the worst cell angle,
the seams (3D length, the line's length, pattern lengths), the nest's length, yield and waste,
how it was made (laid in pairs, or searched for: whether the search ended by itself) and the
times; with ``--images`` it copies cut_lines.png and nest.png there. ``--cases`` picks cases
(``conic-tent-2.5-alone`` and ``-1.5-alone``: the tent's strips not planned in pairs).
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import time
from pathlib import Path

from vares.app.cli.flags import job_from_flags
from vares.app.runner import run_job

COMMON = {
    "fabric": "pes-pvc-type-2",
    "prestress": "2,1.5",
    "allowance": 20.0,
    "mark_spacing": 1000.0,
}
CASES = {
    "saddle-2.5": {"example": "saddle", "roll_width": 2.5, "strip_direction": "1,1,0",
                   "edge_type": "cable", "cable_allowance": 80.0},
    "saddle-1.5": {"example": "saddle", "roll_width": 1.5, "strip_direction": "1,1,0",
                   "edge_type": "cable", "cable_allowance": 80.0},
    "saddle-2.5-planar": {"example": "saddle", "roll_width": 2.5, "strip_direction": "1,1,0",
                          "edge_type": "cable", "cable_allowance": 80.0, "seams": "planar"},
    "conic-tent-2.5": {"example": "conic-tent", "roll_width": 2.5, "edge_type": "cable",
                       "cable_allowance": 80.0, "high_edge_type": "clamp",
                       "clamp_allowance": 50.0},
    "conic-tent-1.5": {"example": "conic-tent", "roll_width": 1.5, "edge_type": "cable",
                       "cable_allowance": 80.0, "high_edge_type": "clamp",
                       "clamp_allowance": 50.0},
}  # fmt: skip
# the tent's strips alone (as before strips were planned in pairs), to compare in one run
for _name in ("conic-tent-2.5", "conic-tent-1.5"):
    CASES[f"{_name}-alone"] = {**CASES[_name], "interlock": "never"}


def run_case(name: str, settings: dict, out: Path) -> None:
    values = {**COMMON, **settings, "directory": str(out / name)}
    example = values.pop("example")
    job = job_from_flags(values, cut=True, example=example)
    flags = " ".join(f"--{k.replace('_', '-')} {v}" for k, v in {**COMMON, **settings}.items())
    print(f"\n## {name}: vares cut {flags}")
    started = time.perf_counter()
    outcome = run_job(job, force=True)
    elapsed = time.perf_counter() - started
    result = outcome.cut
    plan, nest = result.plan, result.nest
    units = job.input.units or "m"
    print(
        f"strips {len(plan.panels)} ({result.options.seams}, {plan.family.kind}); layouts tried "
        f"{plan.evaluations}; strips tried {[(n, round(w, 4)) for n, w in plan.history]}; "
        f"widest pattern per plan {[round(w, 4) for w in result.rounds]}"
    )
    print(
        f"widest pattern with allowances {max(result.widths):.4f} {units} (roll "
        f"{result.options.roll_width:g}); worst cell angle {plan.cut.worst_angle:.2f}° (surface "
        f"{result.surface_worst_angle:.2f}°); area panels/surface − 1 = "
        f"{result.panel_area / result.surface_area - 1:.1e}"
    )
    if plan.interlock:
        print(
            f"in pairs: {result.notes}; roll estimates (strips, length) {plan.compared}; "
            f"pair widths per plan {[round(w, 4) for w in result.rounds]}"
        )
    worst = max(abs(s.length_3d / s.line_length - 1) for s in result.seams)
    match = max(abs(s.length_2d[0] - s.length_2d[1]) / s.length_2d[0] for s in result.seams)
    print(f"seams {len(result.seams)}: 3D length vs its line ≤ {worst:.2e}, sides ≤ {match:.1e}")
    for seam in result.seams[:3] + result.seams[-1:]:
        print(
            f"  {seam.panels[0]} | {seam.panels[1]}: 3D {seam.length_3d:.4f}, line "
            f"{seam.line_length:.4f}, pattern {seam.length_2d[0]:.4f} / {seam.length_2d[1]:.4f}"
        )
    if nest is not None:
        print(
            f"nest: length {nest.length:.2f} {units}, yield {100 * nest.yield_:.1f} %, waste "
            f"{100 * nest.waste:.1f} % ({nest.method}, {nest.elapsed:.1f} s"
            + (
                f"; the search {'ended by itself' if nest.finished else 'stopped by its bound'}"
                f" after {nest.search_time:.1f} s of {nest.time_limit:g})"
                if nest.method == "search"
                else ")"
            )
        )
    print(
        f"converged {outcome.converged}; matching {result.structure.iterations} iterations; "
        f"cut + patterns + nest {result.elapsed:.1f} s, with the files {elapsed:.1f} s"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("cutting-benchmark"))
    parser.add_argument("--images", type=Path, default=None)
    parser.add_argument("--cases", nargs="*", default=list(CASES))
    args = parser.parse_args()
    print(f"# {platform.node()}: {os.cpu_count()} cores, Python {platform.python_version()}")
    for name in args.cases:
        run_case(name, CASES[name], args.out)
        if args.images is not None:
            for picture in ("cut_lines.png", "nest.png"):
                source = args.out / name / picture
                if source.is_file():
                    shutil.copy(source, args.images / f"cut_{name}_{picture}")


if __name__ == "__main__":
    main()
