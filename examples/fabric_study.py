"""From biaxial test records to a compensated cutting pattern (docs/fabrics.md).

    python examples/fabric_study.py [--records examples/biaxial] [--images docs/images]

1. Writes the example records (``--records``): two specimens of a PES/PVC-like batch through
   the MSAJ/M-02 load ratios and two through an EN 17117-2 style compensation protocol, made by
   the ECR model of :mod:`vares.materials.biaxial_model` (stiffening yarns, Norton–Bailey
   creep, cyclic ratchet, noise), one of each in the German lab layout (semicolons, decimal
   commas, N/5cm, %) and one in the TSV layout (kN/m, mm/mm).
2. Reads them back, fits the fabric, writes ``pes-batch-42.toml`` beside them.
3. Checks the fit against the generator: a linear-elastic batch (noise only) of 8 specimens.
4. Cuts the four-point sail with the measured compensation and with the fitted law.
5. Draws the figures (``--images``): the records' loops with the fitted law, measured against
   fitted per load ratio, the compensation record and the compensation per cycle, the residual
   per load ratio.
6. The band of the six strips of a hyperbolic paraboloid under the scatter of the compensation
   values: 16 samples, seam lengths and the erected prestress (``--images``: the band's figure).
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np

import vares
from vares.analysis import compensation_report
from vares.analysis.scatter import ScatterOptions
from vares.app.fabric_band import fabric_band
from vares.geometry.examples import STRUCTURE_EXAMPLES
from vares.io.biaxial import read_biaxial, write_biaxial
from vares.io.fabric_plots import (
    band_plot,
    compensation_figure,
    cycles_plot,
    loops_figure,
    ratios_plot,
    residuals_figure,
)
from vares.materials.biaxial_model import (
    ECRModel,
    compensation_protocol,
    msaj_protocol,
    simulate,
    specimen_batch,
)
from vares.materials.fabric_file import fit_toml
from vares.materials.fitting import compensation_values, fit_elastic, fit_fabric
from vares.structures.panels import split_panels

PRESTRESS = (2.0, 1.5)
#: The batch's model: ECRModel.pes_pvc(); 3 % scatter of E_w, E_f, nu_wf between specimens.
MODEL = ECRModel.pes_pvc()


def write_records(folder: Path) -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    stiff, _ = specimen_batch(MODEL, msaj_protocol(), specimens=2, seed=42, sample_interval=2.0)
    held, _ = specimen_batch(
        MODEL, compensation_protocol(PRESTRESS), specimens=2, seed=43, sample_interval=2.0
    )
    preamble = {"Datum": "2026-11-30", "Material": "PES/PVC Charge 42"}
    files = [
        (stiff[0], "pes-42-A_msaj.csv", "de-lab", preamble | {"Prüfung": "MSAJ/M-02"}),
        (stiff[1], "pes-42-B_msaj.tsv", "tsv", {"test": "MSAJ/M-02", "batch": "42"}),
        (held[0], "pes-42-C_compensation.csv", "de-lab", preamble | {"Prüfung": "EN 17117-2"}),
        (held[1], "pes-42-D_compensation.tsv", "tsv", {"test": "EN 17117-2", "batch": "42"}),
    ]
    paths = []
    for record, name, layout, info in files:
        specimen = name.split("_")[0].upper()
        paths.append(write_biaxial(replace(record, name=specimen), folder / name, layout, info))
    return paths


def check_recovery() -> None:
    linear = ECRModel(E_w=600.0, E_f=450.0, nu_wf=0.35, strain_noise=5e-5)
    records, models = specimen_batch(linear, msaj_protocol(), specimens=8, seed=7)
    fitted = fit_fabric(records, name="linear", G12=30.0, G12_source="given")
    s = fitted.constants
    print("linear-elastic batch of 8 (3 % scatter, 5e-5 strain noise):")
    for name in ("E_w", "E_f", "nu_wf"):
        true = np.array([getattr(m, name) for m in models])
        errors = np.array([f.standard_errors[name] for f in fitted.fits])
        z = (np.array(s.values[name]) - true) / errors
        print(
            f"  {name}: mean {s.mean[name]:.4g} ± {s.standard_error(name):.2g} (true batch "
            f"{getattr(linear, name):g}); per specimen |fit − true| ≤ {np.abs(z).max():.2f} "
            f"standard errors (error {errors.mean():.2g})"
        )
    pes = fit_elastic(simulate(MODEL, msaj_protocol(), seed=0))
    print("ECR model (pes_pvc), one specimen, last cycles:")
    print(
        f"  linear  E_w {pes.E_w:.1f}, E_f {pes.E_f:.1f}, nu_wf {pes.nu_wf:.4f}, rms {pes.rms:.2e}"
    )
    nl = pes.nonlinear
    print(
        f"  nonlinear E_w {nl['E_w']:.1f}, E_f {nl['E_f']:.1f}, nu_wf {nl['nu_wf']:.4f}, "
        f"k_w {nl['k_w']:.3g}, k_f {nl['k_f']:.3g}, rms {nl['rms']:.2e}  (true 600, 450, "
        f"0.35, {MODEL.k_w:g}, {MODEL.k_f:g})"
    )


def cut_sail(fabric_file: Path) -> None:
    preset = vares.materials.fabric(str(fabric_file))
    mesh = vares.examples.four_point_sail()
    print("four-point sail, warp (1, 1, 0), prestress 2/1.5 kN/m:")
    for choice in ("measured", "law"):
        result = vares.solve(
            mesh, preset.material(choice), warp_direction=(1, 1, 0), prestress=PRESTRESS
        )
        r = compensation_report(result)
        area = 100 * (result.fields["pattern_area"].sum() / mesh.area - 1)
        print(
            f"  {choice:8}: warp {r.warp.compensation_mean:.3f} % ({r.warp.compensation_min:.3f}"
            f" … {r.warp.compensation_max:.3f}), fill {r.fill.compensation_mean:.3f} %, "
            f"pattern area {area:+.3f} %, force warp {r.warp.achieved_mean:.3f} fill "
            f"{r.fill.achieved_mean:.3f} kN/m"
        )


def figures(paths: list[Path], images: Path) -> None:
    images.mkdir(parents=True, exist_ok=True)
    record = read_biaxial(paths[0])
    fit = fit_elastic(record)
    loops_figure(record, fit, images / "fabric_msaj_loops.png")
    residuals_figure([fit], images / "fabric_residuals.png", noise=MODEL.strain_noise)
    held = read_biaxial(paths[2])
    values = compensation_values(held, PRESTRESS)
    compensation_figure(held, values, images / "fabric_compensation_record.png")
    ratios_plot(record, fit).savefig(images / "fabric_ratios.png", dpi=100)
    other = read_biaxial(paths[3])
    pairs = [(held, values), (other, compensation_values(other, PRESTRESS))]
    cycles_plot(pairs).savefig(images / "fabric_cycles.png", dpi=100)


def band_of_strips(fabric_file: Path, images: Path) -> None:
    preset = vares.materials.fabric(str(fabric_file))
    mesh, ids = STRUCTURE_EXAMPLES["hypar-strips"]()
    panels = split_panels(mesh, ids, {int(i): f"strip-{int(i) + 1}" for i in np.unique(ids)})
    band = fabric_band(
        panels, preset, scatter=ScatterOptions(samples=16), warp_direction=(1.0, 0.0, 0.0)
    )
    print(
        f"six hypar strips, {band.options.samples} samples of the compensation values "
        f"({band.seconds['nominal']:.1f} s nominal, {band.seconds['samples']:.1f} s samples):"
    )
    for name, d in band.band.to_dict().items():
        if name.startswith(("seam", "prestress", "strip-1 ")):
            print(f"  {name:28s} {d['nominal']:.6g} ± {d['spread']:.3g} (± 2 std)")
    band_plot(band.band).savefig(images / "fabric_band.png", dpi=100)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=Path, default=Path("examples/biaxial"))
    parser.add_argument("--images", type=Path, default=Path("docs/images"))
    args = parser.parse_args()
    paths = write_records(args.records)
    records = [read_biaxial(p) for p in paths]
    fitted = fit_fabric(
        records,
        name="pes-batch-42",
        G12=vares.materials.fabric("pes-pvc-type-2").G12,
        G12_source="from preset pes-pvc-type-2",
        prestress=PRESTRESS,
    )
    target = args.records / "pes-batch-42.toml"
    target.write_text(fit_toml(fitted), encoding="utf-8")
    m, s = fitted.constants.mean, fitted.constants.std
    print(f"pes-batch-42 ({fitted.constants.specimens} stiffness specimens):")
    for name in ("E_w", "E_f", "nu_wf", "nu_fw"):
        print(f"  {name} = {m[name]:.4g} ± {s[name]:.2g}")
    c, cs = fitted.compensation.mean, fitted.compensation.std
    law = fitted.law_compensation()
    print(
        f"  compensation warp {100 * c['warp']:.3f} ± {100 * cs['warp']:.3f} %, fill "
        f"{100 * c['fill']:.3f} ± {100 * cs['fill']:.3f} % (fitted law: {100 * law[0]:.3f} %, "
        f"{100 * law[1]:.3f} %)"
    )
    check_recovery()
    cut_sail(target)
    figures(paths, args.images)
    band_of_strips(target, args.images)


if __name__ == "__main__":
    main()
