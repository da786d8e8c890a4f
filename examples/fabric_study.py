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
5. Draws the figures (``--images``): the records' loops with the fitted law, the compensation
   record, the residual per load ratio.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np

import vares
from vares.analysis import compensation_report
from vares.io.biaxial import read_biaxial, write_biaxial
from vares.materials.biaxial import find_cycles
from vares.materials.biaxial_model import (
    ECRModel,
    compensation_protocol,
    msaj_protocol,
    simulate,
    specimen_batch,
)
from vares.materials.fitting import fit_elastic, fit_fabric

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
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    images.mkdir(parents=True, exist_ok=True)
    record = read_biaxial(paths[0])
    fit = fit_elastic(record)
    cycles = find_cycles(record)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    colours = plt.cm.viridis(np.linspace(0, 0.9, 5))
    for k, stage in enumerate(sorted({c.stage for c in cycles})):
        members = [c for c in cycles if c.stage == stage]
        span = slice(members[0].start, members[-1].end + 1)
        last = members[-1]
        for yarn, ax in enumerate(axes):
            ax.plot(
                100 * record.strain[span, yarn],
                record.force[span, yarn],
                color=colours[k],
                lw=0.8,
                label=members[0].label,
            )
            branch = slice(last.start, last.loaded + 1)
            force = record.force[branch]
            compliance = np.array(
                [[1 / fit.E_w, -fit.nu_fw / fit.E_f], [-fit.nu_wf / fit.E_w, 1 / fit.E_f]]
            )
            model = (force - force[0]) @ compliance.T + record.strain[last.start]
            ax.plot(100 * model[:, yarn], force[:, yarn], "--", color="k", lw=0.8)
    for yarn, ax in enumerate(axes):
        ax.set_xlabel(f"{('warp', 'fill')[yarn]} strain (%)")
        ax.set_ylabel(f"{('warp', 'fill')[yarn]} force (kN/m)")
        ax.grid(alpha=0.3)
    axes[0].legend(title="warp:fill", fontsize=8)
    fig.suptitle(
        f"{record.name}: MSAJ/M-02 ratios, 3 cycles each; dashed: the fitted law on the last "
        f"cycle (E1 {fit.E_w:.0f}, E2 {fit.E_f:.0f} kN/m, ν12 {fit.nu_wf:.3f})",
        fontsize=9,
    )
    fig.savefig(images / "fabric_msaj_loops.png", dpi=110)
    plt.close(fig)

    held = read_biaxial(paths[2])
    fig, ax = plt.subplots(figsize=(8, 3.8), constrained_layout=True)
    ax.plot(held.time / 60, 100 * held.strain[:, 0], lw=0.8, label="warp strain")
    ax.plot(held.time / 60, 100 * held.strain[:, 1], lw=0.8, label="fill strain")
    ax.set_xlabel("time (min)")
    ax.set_ylabel("strain (%)")
    twin = ax.twinx()
    twin.plot(held.time / 60, held.force[:, 0], color="0.6", lw=0.6)
    twin.plot(held.time / 60, held.force[:, 1], color="0.8", lw=0.6)
    twin.set_ylabel("force (kN/m, grey)")
    from vares.materials.fitting import compensation_values

    values = compensation_values(held, PRESTRESS)
    ax.plot([values.time / 60] * 2, [100 * values.warp, 100 * values.fill], "ko")
    ax.annotate(
        f"compensation values\nwarp {100 * values.warp:.3f} %, fill {100 * values.fill:.3f} %",
        (values.time / 60, 100 * values.warp),
        xytext=(-170, 10),
        textcoords="offset points",
        fontsize=8,
    )
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.3)
    ax.set_title(f"{held.name}: EN 17117-2 style protocol at 2/1.5 kN/m", fontsize=9)
    fig.savefig(images / "fabric_compensation_record.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 3.4), constrained_layout=True)
    labels = [r.label for r in fit.residuals]
    x = np.arange(len(labels))
    for offset, rows, name in (
        (-0.2, fit.residuals, "linear law"),
        (0.2, fit.nonlinear_residuals, "nonlinear response"),
    ):
        rms = [1e4 * np.hypot(r.rms_warp, r.rms_fill) / np.sqrt(2) for r in rows]
        ax.bar(x + offset, rms, width=0.38, label=name)
    ax.axhline(1e4 * MODEL.strain_noise, color="k", lw=0.8, ls=":", label="strain noise")
    ax.set_xticks(x, labels)
    ax.set_xlabel("load ratio warp:fill")
    ax.set_ylabel("RMS strain residual (10⁻⁴)")
    ax.legend(fontsize=8)
    ax.set_title(f"{record.name}: residual of the fit per load ratio (last cycles)", fontsize=9)
    fig.savefig(images / "fabric_residuals.png", dpi=110)
    plt.close(fig)


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
    target.write_text(fitted.to_toml(), encoding="utf-8")
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


if __name__ == "__main__":
    main()
