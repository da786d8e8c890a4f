"""Compensation of prestressed membranes: the four-point sail and a conic tent panel.

    python examples/prestress_study.py [--output docs/images]

Fabric: preset ``pes-pvc-type-2`` (typical values, E·t in kN/m), prestress 2.0 kN/m warp and
1.5 kN/m fill. Sail: ``four_point_sail()`` (10 m square, corners 2 m apart in height), warp
along the diagonal (1, 1, 0). Tent: ``conic_tent()`` (one of 12 panels, ring radius 1.5 m at
6 m, outer radius 10 m), warp radial (1, 0, 0). Each is solved without and with prestress.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import vares
from vares.analysis import compensation_report
from vares.geometry.examples import conic_tent, four_point_sail
from vares.io.plot import save_pattern_figure

PRESTRESS = (2.0, 1.5)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=Path("docs/images"))
    args = parser.parse_args()
    args.output.mkdir(parents=True, exist_ok=True)
    fabric = vares.materials.fabric("pes-pvc-type-2").material()
    cases = {
        "sail": (four_point_sail(), (1.0, 1.0, 0.0)),
        "tent": (conic_tent(), (1.0, 0.0, 0.0)),
    }
    for name, (mesh, direction) in cases.items():
        print(f"{name}: {mesh}, 3D area {mesh.area:.4f} m²")
        for prestress in (None, PRESTRESS):
            start = time.perf_counter()
            result = vares.solve(mesh, fabric, warp_direction=direction, prestress=prestress)
            elapsed = time.perf_counter() - start
            assert result.converged, result.reason
            report = compensation_report(result)
            label = "no prestress" if prestress is None else f"prestress {prestress} kN/m"
            print(
                f"  {label}: {result.iterations} iterations, {elapsed:.2f} s, pattern area "
                f"{result.pattern_area:.4f} m² ({100 * (result.pattern_area / mesh.area - 1):+.3f}"
                " %)"
            )
            for yarn in ("warp", "fill"):
                y = getattr(report, yarn)
                print(
                    f"    {yarn}: compensation {y.compensation_mean:.3f} % "
                    f"({y.compensation_min:.3f} … {y.compensation_max:.3f}), achieved "
                    f"{y.achieved_mean:.3f} kN/m ({y.achieved_min:.3f} … {y.achieved_max:.3f}) "
                    f"vs target {y.target_mean:.2f}, RMS deviation {y.rms_deviation:.3f} kN/m, "
                    f"slack {100 * y.slack_area_fraction:.1f} %"
                )
            if prestress is not None:
                for field in ("warp_stress", "fill_stress", "warp_compensation"):
                    save_pattern_figure(
                        args.output / f"{name}_{field}.png",
                        mesh,
                        result.material_coordinates,
                        result.fields[field],
                        field=field,
                        fibres=result.fibres,
                        dpi=100,
                        stress_unit="kN/m",
                        title=f"{name}, PES/PVC type II, prestress 2/1.5 kN/m",
                    )
    print(f"reproduce: python examples/prestress_study.py --output {args.output}")


if __name__ == "__main__":
    main()
